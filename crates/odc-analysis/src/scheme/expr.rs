//! The scheme's small languages: linear index expressions, ranges, and the `{arg:05}`
//! name patterns.

use std::collections::BTreeMap;

use crate::names::is_ident;

/// A linear expression: `constant + Σ coefficient·argument`.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Linear {
    /// The constant term.
    pub constant: i64,
    /// The (coefficient, argument) terms.
    pub terms: Vec<(i64, String)>,
}

impl Linear {
    /// Parses `0x2000 + 0x100 * group + number`, `0x5FFF - code`, `element + 1`.
    ///
    /// # Errors
    ///
    /// The term that is not linear or not a number or an argument name.
    pub fn parse(text: &str) -> Result<Linear, String> {
        let mut out = Linear { constant: 0, terms: Vec::new() };
        let mut rest = text.trim();
        if rest.is_empty() {
            return Err("empty expression".into());
        }
        let mut sign = 1i64;
        if let Some(r) = rest.strip_prefix('-') {
            sign = -1;
            rest = r.trim_start();
        } else if let Some(r) = rest.strip_prefix('+') {
            rest = r.trim_start();
        }
        loop {
            let end = rest.find(['+', '-']).unwrap_or(rest.len());
            let (term, tail) = rest.split_at(end);
            out.add_term(sign, term.trim())?;
            let Some(op) = tail.chars().next() else { break };
            sign = if op == '-' { -1 } else { 1 };
            rest = tail.get(1..).unwrap_or("").trim_start();
        }
        Ok(out)
    }

    fn add_term(&mut self, sign: i64, term: &str) -> Result<(), String> {
        if term.is_empty() {
            return Err("a `+` or `-` without a term after it".into());
        }
        let factors: Vec<&str> = term.split('*').map(str::trim).collect();
        let (mut coef, mut var) = (sign, None::<String>);
        for f in factors {
            if let Some(n) = number(f) {
                coef = coef.checked_mul(n).ok_or_else(|| format!("`{term}` overflows"))?;
            } else if is_ident(f) {
                if var.is_some() {
                    return Err(format!(
                        "`{term}` multiplies two arguments; the rule must be linear"
                    ));
                }
                var = Some(f.to_string());
            } else {
                return Err(format!("`{f}` is neither a number nor an argument name"));
            }
        }
        match var {
            Some(v) => self.terms.push((coef, v)),
            None => {
                self.constant =
                    self.constant.checked_add(coef).ok_or_else(|| format!("`{term}` overflows"))?;
            }
        }
        Ok(())
    }

    /// The value for the given arguments (names missing from `args` count as zero).
    pub fn eval(&self, args: &BTreeMap<&str, i64>) -> i64 {
        self.terms.iter().fold(self.constant, |acc, (c, v)| {
            acc.saturating_add(c.saturating_mul(args.get(v.as_str()).copied().unwrap_or(0)))
        })
    }

    /// The smallest and largest value over the argument ranges.
    pub fn bounds(&self, ranges: &BTreeMap<&str, (i64, i64)>) -> (i64, i64) {
        let (mut lo, mut hi) = (self.constant, self.constant);
        for (c, v) in &self.terms {
            let (a, b) = ranges.get(v.as_str()).copied().unwrap_or((0, 0));
            let (x, y) = (c.saturating_mul(a), c.saturating_mul(b));
            lo = lo.saturating_add(x.min(y));
            hi = hi.saturating_add(x.max(y));
        }
        (lo, hi)
    }
}

/// A non-negative decimal or `0x` hex number, `_` allowed.
pub fn number(s: &str) -> Option<i64> {
    let s = s.replace('_', "");
    match s.strip_prefix("0x").or_else(|| s.strip_prefix("0X")) {
        Some(hex) if !hex.is_empty() => i64::from_str_radix(hex, 16).ok(),
        Some(_) => None,
        None if s.starts_with(|c: char| c.is_ascii_digit()) => s.parse().ok(),
        None => None,
    }
}

/// `LOW..=HIGH` with non-negative bounds.
///
/// # Errors
///
/// A text not of that form, an empty range, or bounds beyond `u32`.
pub fn parse_range(text: &str) -> Result<(i64, i64), String> {
    let (lo, hi) = text
        .split_once("..=")
        .ok_or_else(|| format!("range `{text}` is not of the form `LOW..=HIGH`"))?;
    let lo = number(lo.trim()).ok_or_else(|| format!("`{lo}` in `{text}` is not a number"))?;
    let hi = number(hi.trim()).ok_or_else(|| format!("`{hi}` in `{text}` is not a number"))?;
    if lo > hi {
        return Err(format!("range `{text}` is empty"));
    }
    if hi > i64::from(u32::MAX) {
        return Err(format!("range `{text}` goes beyond u32"));
    }
    Ok((lo, hi))
}

/// A name pattern: text with `{arg}`, `{arg:05}` (zero-padded decimal), `{arg:04X}` or
/// `{arg:x}` (hex) placeholders.
///
/// # Errors
///
/// An unclosed `{`, an unknown argument or an unknown format.
pub fn render(pattern: &str, values: &BTreeMap<&str, Placeholder>) -> Result<String, String> {
    let mut out = String::new();
    let mut rest = pattern;
    while let Some(open) = rest.find('{') {
        out.push_str(rest.get(..open).unwrap_or(""));
        let after = rest.get(open + 1..).unwrap_or("");
        let close = after.find('}').ok_or_else(|| format!("`{pattern}`: unclosed `{{`"))?;
        let spec = after.get(..close).unwrap_or("");
        let (name, format) = spec.split_once(':').unwrap_or((spec, ""));
        let value =
            values.get(name.trim()).ok_or_else(|| format!("`{pattern}`: no argument `{name}`"))?;
        match value {
            Placeholder::Number(v) => out.push_str(&format_number(*v, format, pattern)?),
            Placeholder::Text(t) => out.push_str(t),
        }
        rest = after.get(close + 1..).unwrap_or("");
    }
    out.push_str(rest);
    Ok(out)
}

/// What a placeholder stands for: an argument's value or a selector's name.
#[derive(Clone, Debug)]
pub enum Placeholder {
    /// An argument's value.
    Number(i64),
    /// A selector value's name.
    Text(String),
}

fn format_number(v: i64, format: &str, pattern: &str) -> Result<String, String> {
    let bad = || format!("`{pattern}`: format `{format}` is not `05`, `04X`, `x` or empty");
    let (width, kind) = match format.find(|c: char| !c.is_ascii_digit()) {
        Some(p) => format.split_at(p),
        None => (format, ""),
    };
    let width: usize = if width.is_empty() { 0 } else { width.parse().map_err(|_| bad())? };
    match kind {
        "" => Ok(format!("{v:0width$}")),
        "X" => Ok(format!("{v:0width$X}")),
        "x" => Ok(format!("{v:0width$x}")),
        _ => Err(bad()),
    }
}
