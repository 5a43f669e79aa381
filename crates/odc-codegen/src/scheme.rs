//! Vendor parameter schemes: how a maker numbers its own parameters, as data.
//!
//! Drive makers address their parameters by their own numbers and map them onto object
//! indexes by a rule: LXM23A keypad parameter `P1-44` is object `0x212C` (`0x2000 + 0x100·a +
//! bc`, the decimal `bc` taken as a binary number), ServoOne parameter `P 455` is `0x21C7`
//! (`0x2000 + n`), Lenze code `C00011` is `0x5FF4` (`0x5FFF − n`), a LinMot UPID `0x1CA4` is
//! `0x3CA4` with the sub-index choosing RAM, ROM, min, max or default. A device declares its
//! rule in the overlay beside its file (`<stem>.odc.toml`, the file that also holds its quirk
//! allowances), and the generator turns it into a module; no per-vendor code exists anywhere:
//!
//! ```toml
//! [[scheme]]
//! module = "lenze"                        # the generated module
//! function = "code"                       # lenze::code(11) -> Some(0x5FF4:00)
//! doc = "Lenze code Cnnnnn at 0x5FFF - nnnnn, subcode = sub-index (manual p. 65)."
//! index = "0x5FFF - code"                 # linear: constants, arguments, constant * argument
//! args = [{ name = "code", range = "0..=16383" }]
//! const-name = "C{code:05}"               # a typed alias per object the file defines
//! # Optional: the sub-index of an ARRAY/RECORD object's elements, sub = element + offset:
//! element = { name = "subcode", range = "1..=255", offset = 0, function = "code_sub", const-name = "C{code:05}_{subcode}" }
//! # Or instead: sub-indexes with a meaning of their own, as an enum argument:
//! # selector = { type = "Sub", values = [{ name = "ram", sub = 1, doc = "RAM value" }] }
//! ```
//!
//! For each scheme the module holds:
//! - `index(args) -> Option<u16>`: the rule itself, `None` outside the declared ranges;
//! - `<function>(args) -> Option<ObjectAddr>`: the object (sub-index 0), or with a selector
//!   `<function>(args, sel)` at the selected sub-index;
//! - with an element, `<element function>(args, element) -> Option<ObjectAddr>`;
//! - one typed `Entry<T>` alias per object (and element or selected sub-object) of the device
//!   file that the rule reaches, named by `const-name`, so `sdo.write(lenze::C00088, 102)` is
//!   type-checked against the file's data type;
//! - `ENTRIES` and `lookup(addr)`: the file's description (data type, access, name) of an
//!   address computed at run time.
//!
//! The generator checks a scheme before using it: expressions parse and name only declared
//! arguments, every argument range keeps the index within `0..=0xFFFF` and the element's
//! sub-index within `0..=0xFF`, names are Rust identifiers and unique (`G604`).

use std::collections::{BTreeMap, BTreeSet};

use odc_model::Diagnostic;
use proc_macro2::{Ident, Literal, Span, TokenStream};
use quote::quote;
use serde::Deserialize;

use crate::od::typed_subs;
use crate::types::int_literal;
use crate::{Ctx, doc};

/// The part of a device's overlay file (`<stem>.odc.toml`) that code generation reads; the
/// checker's keys (`strict`, `[rules]`, `[allow-object]`) in the same file are ignored here.
#[derive(Clone, Debug, Default, PartialEq, Eq, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub struct Overlay {
    /// The vendor parameter schemes, one generated module each.
    #[serde(default)]
    pub scheme: Vec<Scheme>,
    /// PDO layouts the device file cannot map (`[[process-data]]`, see
    /// [`ProcessData`](crate::ProcessData)), in a generated module `process`.
    #[serde(default)]
    pub process_data: Vec<crate::ProcessData>,
}

impl Overlay {
    /// Reads an overlay from TOML text.
    ///
    /// # Errors
    ///
    /// The TOML error, with its position, when the text is not TOML or a `[[scheme]]` table
    /// has an unknown key or a value of the wrong type.
    pub fn from_toml(text: &str) -> Result<Overlay, toml::de::Error> {
        toml::from_str(text)
    }
}

/// One vendor numbering rule (see the module documentation for the TOML form).
#[derive(Clone, Debug, PartialEq, Eq, Deserialize)]
#[serde(rename_all = "kebab-case", deny_unknown_fields)]
pub struct Scheme {
    /// The generated module's name (snake case).
    pub module: String,
    /// The name of the function that maps a parameter number to its object.
    pub function: String,
    /// What the scheme is, for the module's documentation (say where the manual states it).
    #[serde(default)]
    pub doc: String,
    /// The object index as a linear expression of the arguments.
    pub index: String,
    /// The arguments of the index, in the order the functions take them.
    pub args: Vec<Arg>,
    /// The name pattern of the typed aliases of objects (`C{code:05}`); none when absent.
    #[serde(default)]
    pub const_name: Option<String>,
    /// The numbering of the elements (sub-indexes) of ARRAY and RECORD objects.
    #[serde(default)]
    pub element: Option<Element>,
    /// Sub-indexes that choose an operation on the parameter rather than an element.
    #[serde(default)]
    pub selector: Option<Selector>,
    /// Indexes the rule reaches that hold other objects (`"0x4F01..=0x4F08"` or `"0x2000"`):
    /// the functions answer `None` for them and no alias is made.
    #[serde(default)]
    pub exclude: Vec<String>,
}

/// An argument of a scheme and the values it may take.
#[derive(Clone, Debug, PartialEq, Eq, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Arg {
    /// Its name (snake case), as the expressions and name patterns use it.
    pub name: String,
    /// `LOW..=HIGH`, non-negative.
    pub range: String,
}

/// Elements of ARRAY/RECORD parameters: `sub = element + offset`.
#[derive(Clone, Debug, PartialEq, Eq, Deserialize)]
#[serde(rename_all = "kebab-case", deny_unknown_fields)]
pub struct Element {
    /// The element argument's name.
    pub name: String,
    /// `LOW..=HIGH` of the element number.
    pub range: String,
    /// Added to the element number to give the sub-index.
    #[serde(default)]
    pub offset: i64,
    /// The function's name; `<function>_<name>` when absent.
    #[serde(default)]
    pub function: Option<String>,
    /// The name pattern of element aliases; the object pattern plus `_{<name>}` when absent.
    #[serde(default)]
    pub const_name: Option<String>,
}

/// Sub-indexes with a meaning (LinMot: 1 RAM value, 2 ROM value, …), as a generated enum.
#[derive(Clone, Debug, PartialEq, Eq, Deserialize)]
#[serde(rename_all = "kebab-case", deny_unknown_fields)]
pub struct Selector {
    /// The enum's name (camel case).
    #[serde(rename = "type")]
    pub type_name: String,
    /// The name of the function argument; `sel` when absent.
    #[serde(default)]
    pub arg: Option<String>,
    /// The values.
    pub values: Vec<SelectorValue>,
}

/// One value of a [`Selector`].
#[derive(Clone, Debug, PartialEq, Eq, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SelectorValue {
    /// Its name (snake case); the variant is its camel case, aliases use its upper case.
    pub name: String,
    /// The sub-index it selects.
    pub sub: u8,
    /// What it is.
    #[serde(default)]
    pub doc: String,
}

/// A linear expression: `constant + Σ coefficient·argument`.
#[derive(Clone, Debug, PartialEq, Eq)]
pub(crate) struct Linear {
    constant: i64,
    terms: Vec<(i64, String)>,
}

impl Linear {
    /// Parses `0x2000 + 0x100 * group + number`, `0x5FFF - code`, `element + 1`.
    pub(crate) fn parse(text: &str) -> Result<Linear, String> {
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
    pub(crate) fn eval(&self, args: &BTreeMap<&str, i64>) -> i64 {
        self.terms.iter().fold(self.constant, |acc, (c, v)| {
            acc.saturating_add(c.saturating_mul(args.get(v.as_str()).copied().unwrap_or(0)))
        })
    }

    /// The smallest and largest value over the argument ranges.
    fn bounds(&self, ranges: &BTreeMap<&str, (i64, i64)>) -> (i64, i64) {
        let (mut lo, mut hi) = (self.constant, self.constant);
        for (c, v) in &self.terms {
            let (a, b) = ranges.get(v.as_str()).copied().unwrap_or((0, 0));
            let (x, y) = (c.saturating_mul(a), c.saturating_mul(b));
            lo = lo.saturating_add(x.min(y));
            hi = hi.saturating_add(x.max(y));
        }
        (lo, hi)
    }

    /// `0x2000 + 0x100 * (group as i64) + (number as i64)` as tokens, in `i64`.
    fn tokens(&self) -> TokenStream {
        let c = signed_literal(self.constant);
        let terms = self.terms.iter().map(|(coef, v)| {
            let v = ident(v);
            match *coef {
                1 => quote!(+ (#v as i64)),
                -1 => quote!(- (#v as i64)),
                c if c < 0 => {
                    let m = signed_literal(c.saturating_neg());
                    quote!(- #m * (#v as i64))
                }
                c => {
                    let m = signed_literal(c);
                    quote!(+ #m * (#v as i64))
                }
            }
        });
        quote!(#c #(#terms)*)
    }
}

fn signed_literal(v: i64) -> TokenStream {
    if v < 0 {
        let m = int_literal(v.unsigned_abs());
        quote!(-#m)
    } else {
        let m = int_literal(v.unsigned_abs());
        quote!(#m)
    }
}

fn number(s: &str) -> Option<i64> {
    let s = s.replace('_', "");
    match s.strip_prefix("0x").or_else(|| s.strip_prefix("0X")) {
        Some(hex) if !hex.is_empty() => i64::from_str_radix(hex, 16).ok(),
        Some(_) => None,
        None if s.starts_with(|c: char| c.is_ascii_digit()) => s.parse().ok(),
        None => None,
    }
}

fn is_ident(s: &str) -> bool {
    s.starts_with(|c: char| c.is_ascii_alphabetic() || c == '_')
        && s.chars().all(|c| c.is_ascii_alphanumeric() || c == '_')
        && syn::parse_str::<Ident>(s).is_ok()
}

fn ident(s: &str) -> Ident {
    Ident::new(s, Span::call_site())
}

/// `LOW..=HIGH` with non-negative bounds.
fn parse_range(text: &str) -> Result<(i64, i64), String> {
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

/// The narrowest unsigned Rust type for values up to `hi`.
fn arg_type(hi: i64) -> (TokenStream, i64) {
    if hi <= i64::from(u8::MAX) {
        (quote!(u8), i64::from(u8::MAX))
    } else if hi <= i64::from(u16::MAX) {
        (quote!(u16), i64::from(u16::MAX))
    } else {
        (quote!(u32), i64::from(u32::MAX))
    }
}

/// A name pattern: text with `{arg}`, `{arg:05}` (zero-padded decimal), `{arg:04X}` or
/// `{arg:x}` (hex) placeholders.
fn render(pattern: &str, values: &BTreeMap<&str, Placeholder>) -> Result<String, String> {
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
enum Placeholder {
    Number(i64),
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

/// A scheme checked and ready to generate.
struct Checked<'a> {
    scheme: &'a Scheme,
    index: Linear,
    exclude: Vec<(i64, i64)>,
    args: Vec<(String, (i64, i64))>,
    element: Option<(String, (i64, i64), i64, String)>,
}

const RESERVED_MODULES: &[&str] = &["od", "pdo", "cia402", "slave", "master"];
const RESERVED_ITEMS: &[&str] = &["index", "lookup", "ENTRIES"];
/// Enumerating the arguments' ranges finds the parameters the device file defines; a rule
/// with more combinations than this is refused rather than slowing every build down.
const MAX_COMBINATIONS: i64 = 1 << 22;

fn check(s: &Scheme) -> Result<Checked<'_>, String> {
    if !is_ident(&s.module) || RESERVED_MODULES.contains(&s.module.as_str()) {
        return Err(format!("module `{}` is not a free Rust identifier", s.module));
    }
    if !is_ident(&s.function) || RESERVED_ITEMS.contains(&s.function.as_str()) {
        return Err(format!("function `{}` is not a free Rust identifier", s.function));
    }
    if s.args.is_empty() {
        return Err("a scheme needs at least one argument".into());
    }
    let index = Linear::parse(&s.index).map_err(|e| format!("index `{}`: {e}", s.index))?;
    let mut args = Vec::new();
    let mut names = BTreeSet::new();
    for a in &s.args {
        if !is_ident(&a.name) || !names.insert(a.name.clone()) {
            return Err(format!(
                "argument `{}` is not a Rust identifier or is declared twice",
                a.name
            ));
        }
        args.push((a.name.clone(), parse_range(&a.range)?));
    }
    for (_, v) in &index.terms {
        if !names.contains(v) {
            return Err(format!("index `{}` names `{v}`, which is no argument", s.index));
        }
    }
    let ranges: BTreeMap<&str, (i64, i64)> = args.iter().map(|(n, r)| (n.as_str(), *r)).collect();
    let (lo, hi) = index.bounds(&ranges);
    if lo < 0 || hi > 0xFFFF {
        return Err(format!(
            "index `{}` ranges over {lo}..={hi} for the declared arguments, beyond 0..=0xFFFF",
            s.index
        ));
    }
    let combinations = args.iter().try_fold(1i64, |acc, (_, (a, b))| acc.checked_mul(b - a + 1));
    if combinations.is_none_or(|c| c > MAX_COMBINATIONS) {
        return Err(format!("the argument ranges allow more than {MAX_COMBINATIONS} parameters"));
    }
    let mut exclude = Vec::new();
    for e in &s.exclude {
        let r = if e.contains("..=") {
            parse_range(e)?
        } else {
            let v = number(e.trim()).ok_or_else(|| format!("exclude `{e}` is not an index"))?;
            (v, v)
        };
        if r.1 > 0xFFFF {
            return Err(format!("exclude `{e}` is not an index range"));
        }
        exclude.push(r);
    }
    let element = match (&s.element, &s.selector) {
        (Some(_), Some(_)) => return Err("a scheme has an element or a selector, not both".into()),
        (Some(e), None) => {
            if !is_ident(&e.name) || names.contains(&e.name) {
                return Err(format!("element `{}` is not a free Rust identifier", e.name));
            }
            let r = parse_range(&e.range)?;
            if r.0 + e.offset < 0 || r.1 + e.offset > 0xFF {
                return Err(format!(
                    "element `{}` + {} leaves the sub-index range 0..=0xFF",
                    e.name, e.offset
                ));
            }
            let f = e.function.clone().unwrap_or_else(|| format!("{}_{}", s.function, e.name));
            if !is_ident(&f) || f == s.function || RESERVED_ITEMS.contains(&f.as_str()) {
                return Err(format!("element function `{f}` is not a free Rust identifier"));
            }
            Some((e.name.clone(), r, e.offset, f))
        }
        (None, Some(sel)) => {
            if !is_ident(&sel.type_name) {
                return Err(format!("selector type `{}` is not a Rust identifier", sel.type_name));
            }
            let arg = sel.arg.as_deref().unwrap_or("sel");
            if !is_ident(arg) || names.contains(arg) {
                return Err(format!("selector argument `{arg}` is not a free Rust identifier"));
            }
            let mut seen = BTreeSet::new();
            for v in &sel.values {
                if crate::names::camel(&v.name).is_empty() || !seen.insert(v.sub) {
                    return Err(format!(
                        "selector value `{}` is unnamed or repeats a sub-index",
                        v.name
                    ));
                }
            }
            None
        }
        (None, None) => None,
    };
    Ok(Checked { scheme: s, index, exclude, args, element })
}

/// A typed alias of a device entry reached by a scheme.
struct Alias {
    name: String,
    index: u16,
    sub: u8,
    what: String,
}

/// The aliases: every typed entry of the device whose index the rule produces, named by the
/// patterns (objects by `const-name`, elements by the element pattern, selected sub-objects
/// by the pattern with `{<selector arg>}` as the value's upper-case name).
fn aliases(ctx: &Ctx<'_>, c: &Checked<'_>) -> Result<Vec<Alias>, String> {
    let s = c.scheme;
    let Some(pattern) = &s.const_name else { return Ok(Vec::new()) };
    // Which parameter each index belongs to: enumerate the (bounded) argument space, like an
    // odometer with the last argument turning fastest; the first parameter to reach an index
    // names it.
    let mut by_index: BTreeMap<u16, BTreeMap<&str, i64>> = BTreeMap::new();
    let mut current: Vec<i64> = c.args.iter().map(|(_, (lo, _))| *lo).collect();
    'all: loop {
        let values: BTreeMap<&str, i64> =
            c.args.iter().map(|(n, _)| n.as_str()).zip(current.iter().copied()).collect();
        let i = c.index.eval(&values);
        if let Ok(i) = u16::try_from(i)
            && ctx.device.objects.contains_key(&i)
            && !c.exclude.iter().any(|(lo, hi)| (*lo..=*hi).contains(&i64::from(i)))
        {
            by_index.entry(i).or_insert(values);
        }
        for (v, (_, (lo, hi))) in current.iter_mut().zip(&c.args).rev() {
            if *v < *hi {
                *v += 1;
                continue 'all;
            }
            *v = *lo;
        }
        break;
    }
    let mut out = Vec::new();
    for (&index, values) in &by_index {
        let Some(object) = ctx.device.objects.get(&index) else { continue };
        fn placeholders<'k>(
            values: &BTreeMap<&'k str, i64>,
            extra: Option<(&'k str, Placeholder)>,
        ) -> BTreeMap<&'k str, Placeholder> {
            let mut m: BTreeMap<&str, Placeholder> =
                values.iter().map(|(k, v)| (*k, Placeholder::Number(*v))).collect();
            if let Some((k, v)) = extra {
                m.insert(k, v);
            }
            m
        }
        for (sub, _) in typed_subs(object, ctx.names.cia402) {
            let si = sub.sub_index;
            let name = if !object.kind.has_subs() {
                render(pattern, &placeholders(values, None))?
            } else if let Some((ename, (lo, hi), offset, _)) = &c.element {
                let e = i64::from(si) - offset;
                if e < *lo || e > *hi {
                    continue;
                }
                let p = s
                    .element
                    .as_ref()
                    .and_then(|e| e.const_name.clone())
                    .unwrap_or_else(|| format!("{pattern}_{{{ename}}}"));
                render(&p, &placeholders(values, Some((ename.as_str(), Placeholder::Number(e)))))?
            } else if let Some(sel) = &s.selector {
                let Some(v) = sel.values.iter().find(|v| v.sub == si) else { continue };
                let arg = sel.arg.as_deref().unwrap_or("sel");
                let text = Placeholder::Text(crate::names::screaming(&v.name));
                let p = if pattern.contains(&format!("{{{arg}")) {
                    pattern.clone()
                } else {
                    format!("{pattern}_{{{arg}}}")
                };
                render(&p, &placeholders(values, Some((arg, text))))?
            } else {
                continue;
            };
            let what = if object.kind.has_subs() {
                format!("{} / {}", object.name, sub.name)
            } else {
                sub.name.to_string()
            };
            out.push(Alias { name, index, sub: si, what });
        }
    }
    let mut seen = BTreeSet::new();
    for a in &out {
        if !is_ident(&a.name) || a.name.chars().any(|c| c.is_ascii_lowercase()) {
            return Err(format!("alias `{}` is not an upper-case Rust identifier", a.name));
        }
        if !seen.insert(a.name.as_str()) || RESERVED_ITEMS.contains(&a.name.as_str()) {
            return Err(format!("alias `{}` is given to two entries", a.name));
        }
    }
    Ok(out)
}

/// The modules of every scheme, or `G604` diagnostics.
pub(crate) fn generate(
    ctx: &Ctx<'_>,
    schemes: &[Scheme],
    errors: &mut Vec<Diagnostic>,
) -> TokenStream {
    let mut out = TokenStream::new();
    let mut modules = BTreeSet::new();
    for s in schemes {
        let result = check(s).and_then(|c| {
            if !modules.insert(s.module.clone()) {
                return Err(format!("two schemes generate module `{}`", s.module));
            }
            let aliases = aliases(ctx, &c)?;
            Ok(module(ctx, &c, &aliases))
        });
        match result {
            Ok(tokens) => out.extend(tokens),
            Err(e) => errors.push(
                Diagnostic::error("G604", format!("parameter scheme `{}`: {e}", s.module))
                    .with_note(
                        "schemes are declared in the `<stem>.odc.toml` beside the device file",
                    ),
            ),
        }
    }
    out
}

fn module(ctx: &Ctx<'_>, c: &Checked<'_>, aliases: &[Alias]) -> TokenStream {
    let rt = &ctx.rt;
    let s = c.scheme;
    let m = ident(&s.module);
    let f = ident(&s.function);
    let params: Vec<TokenStream> = c
        .args
        .iter()
        .map(|(n, (_, hi))| {
            let (ty, _) = arg_type(*hi);
            let n = ident(n);
            quote!(#n: #ty)
        })
        .collect();
    let names: Vec<Ident> = c.args.iter().map(|(n, _)| ident(n)).collect();
    let checks: Vec<TokenStream> = c
        .args
        .iter()
        .filter_map(|(n, (lo, hi))| {
            let (_, max) = arg_type(*hi);
            (*lo > 0 || *hi < max).then(|| {
                let n = ident(n);
                let (lo, hi) = (int_literal(lo.unsigned_abs()), int_literal(hi.unsigned_abs()));
                quote!(matches!(#n, #lo..=#hi))
            })
        })
        .collect();
    let guard = match checks.as_slice() {
        [] => TokenStream::new(),
        [one] => quote! {
            if !#one {
                return None;
            }
        },
        many => quote! {
            if !(#(#many)&&*) {
                return None;
            }
        },
    };
    let expr = c.index.tokens();
    let excluded: Vec<TokenStream> = c
        .exclude
        .iter()
        .map(|(lo, hi)| {
            let (l, h) = (int_literal(lo.unsigned_abs()), int_literal(hi.unsigned_abs()));
            if lo == hi { quote!(#l) } else { quote!(#l..=#h) }
        })
        .collect();
    let result = if excluded.is_empty() {
        quote! {
            // The generator checked that the declared ranges keep the value within 0..=0xFFFF.
            Some((#expr) as u16)
        }
    } else {
        quote! {
            // The generator checked that the declared ranges keep the value within 0..=0xFFFF.
            let index = (#expr) as u16;
            if matches!(index, #(#excluded)|*) {
                return None;
            }
            Some(index)
        }
    };
    let ranges = s
        .args
        .iter()
        .map(|a| format!("`{}` in `{}`", a.name, a.range.trim()))
        .collect::<Vec<_>>()
        .join(", ");
    let excluded_text = if s.exclude.is_empty() {
        String::new()
    } else {
        format!(" and for {} (other objects)", s.exclude.join(", "))
    };
    let index_doc = doc(&format!(
        "The object index of a parameter: `{}`, for {ranges}; `None` outside those ranges{excluded_text}.",
        s.index
    ));
    let mut items = vec![quote! {
        #index_doc
        pub const fn index(#(#params),*) -> Option<u16> {
            #guard
            #result
        }
    }];
    match (&c.element, &s.selector) {
        (Some((ename, (lo, hi), offset, efn)), _) => {
            let fdoc = doc(
                "The object of a parameter (sub-index 0; a VAR's value, an ARRAY's or RECORD's \
                 entry count), or `None` outside the ranges of [`index`].",
            );
            items.push(quote! {
                #fdoc
                pub const fn #f(#(#params),*) -> Option<#rt::ObjectAddr> {
                    match self::index(#(#names),*) {
                        Some(i) => Some(#rt::ObjectAddr::new(i, 0)),
                        None => None,
                    }
                }
            });
            let (ety, emax) = arg_type(*hi);
            let e = ident(ename);
            let efn = ident(efn);
            let echeck = (*lo > 0 || *hi < emax).then(|| {
                let (l, h) = (int_literal(lo.unsigned_abs()), int_literal(hi.unsigned_abs()));
                quote! {
                    if !matches!(#e, #l..=#h) {
                        return None;
                    }
                }
            });
            let (sub, sub_text) = if *offset == 0 {
                (quote!(#e), format!("`{ename}`"))
            } else {
                let off = signed_literal(*offset);
                (quote!(((#e as i64) + #off) as u8), format!("`{ename} + {offset}`"))
            };
            let edoc = doc(&format!(
                "Element `{ename}` ({lo}..={hi}) of an ARRAY or RECORD parameter: sub-index \
                 {sub_text}."
            ));
            items.push(quote! {
                #edoc
                pub const fn #efn(#(#params,)* #e: #ety) -> Option<#rt::ObjectAddr> {
                    #echeck
                    match self::index(#(#names),*) {
                        // The generator checked that the element range plus the offset
                        // stays within 0..=0xFF.
                        Some(i) => Some(#rt::ObjectAddr::new(i, #sub)),
                        None => None,
                    }
                }
            });
        }
        (None, Some(sel)) => {
            let ty = ident(&sel.type_name);
            let arg = ident(sel.arg.as_deref().unwrap_or("sel"));
            let variants: Vec<TokenStream> = sel
                .values
                .iter()
                .map(|v| {
                    let name = ident(&crate::names::camel(&v.name));
                    let lit = Literal::u8_unsuffixed(v.sub);
                    let d = doc(&if v.doc.is_empty() {
                        format!("Sub-index {}.", v.sub)
                    } else {
                        format!("{} (sub-index {}).", v.doc, v.sub)
                    });
                    quote!(#d #name = #lit,)
                })
                .collect();
            let tdoc = doc("What the sub-index of a parameter's object selects.");
            let fdoc = doc(&format!(
                "The sub-object `{}` selects of a parameter, or `None` outside the ranges of \
                 [`index`].",
                sel.arg.as_deref().unwrap_or("sel")
            ));
            items.push(quote! {
                #tdoc
                #[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
                #[repr(u8)]
                pub enum #ty { #(#variants)* }

                #fdoc
                pub const fn #f(#(#params,)* #arg: #ty) -> Option<#rt::ObjectAddr> {
                    match self::index(#(#names),*) {
                        Some(i) => Some(#rt::ObjectAddr::new(i, #arg as u8)),
                        None => None,
                    }
                }
            });
        }
        (None, None) => {
            let fdoc = doc("The object of a parameter, or `None` outside the ranges of [`index`].");
            items.push(quote! {
                #fdoc
                pub const fn #f(#(#params),*) -> Option<#rt::ObjectAddr> {
                    match self::index(#(#names),*) {
                        Some(i) => Some(#rt::ObjectAddr::new(i, 0)),
                        None => None,
                    }
                }
            });
        }
    }
    let mut infos = Vec::new();
    for a in aliases {
        let Some(entry) = ctx.names.entries.get(&(a.index, a.sub)) else { continue };
        let path = entry.path();
        let ty = entry.ty.tokens(rt);
        let name = ident(&a.name);
        let d = doc(&format!("{}: `0x{:04X}:{:02X}`, {}.", a.name, a.index, a.sub, a.what));
        items.push(quote! {
            #d
            pub const #name: #rt::Entry<#ty> = #path;
        });
        infos.push(quote!(#path.info()));
    }
    let n = Literal::usize_unsuffixed(infos.len());
    items.push(quote! {
        /// The entries of the device file that the scheme reaches, sorted by address.
        pub static ENTRIES: [#rt::EntryInfo; #n] = [#(#infos),*];

        /// The device file's description of an address (data type, access, name), if the file
        /// defines it.
        pub fn lookup(addr: #rt::ObjectAddr) -> Option<&'static #rt::EntryInfo> {
            ENTRIES.binary_search_by(|e| e.addr.cmp(&addr)).ok().and_then(|i| ENTRIES.get(i))
        }
    });
    let text = if s.doc.is_empty() {
        format!("Parameters of {} by their vendor numbers.", ctx.device.name())
    } else {
        s.doc.clone()
    };
    let mdoc = doc(&format!(
        "{text}\n\nIndex rule: `{}`. Generated from the `[[scheme]]` of the device's overlay.",
        s.index
    ));
    quote! {
        #mdoc
        pub mod #m {
            #(#items)*
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn vals(pairs: &[(&'static str, i64)]) -> BTreeMap<&'static str, i64> {
        pairs.iter().copied().collect()
    }

    #[test]
    fn linear_expressions() {
        let e = Linear::parse("0x2000 + 0x100 * group + number").unwrap();
        assert_eq!(e.eval(&vals(&[("group", 1), ("number", 44)])), 0x212C);
        let e = Linear::parse("0x5FFF - code").unwrap();
        assert_eq!(e.eval(&vals(&[("code", 11)])), 0x5FF4);
        assert_eq!(e.eval(&vals(&[("code", 13382)])), 0x2BB9);
        let e = Linear::parse(" - 2 * a + 7 * 3 ").unwrap();
        assert_eq!(e.eval(&vals(&[("a", 4)])), 13);
        assert!(Linear::parse("a * b").is_err());
        assert!(Linear::parse("0x20 + ").is_err());
        assert!(Linear::parse("2 / a").is_err());
        assert!(Linear::parse("").is_err());
    }

    #[test]
    fn name_patterns() {
        let mut v = BTreeMap::new();
        v.insert("code", Placeholder::Number(11));
        v.insert("upid", Placeholder::Number(0x1CA4));
        v.insert("sel", Placeholder::Text("RAM".into()));
        assert_eq!(render("C{code:05}", &v).unwrap(), "C00011");
        assert_eq!(render("U{upid:04X}_{sel}", &v).unwrap(), "U1CA4_RAM");
        assert_eq!(render("P{code}", &v).unwrap(), "P11");
        assert!(render("C{nope}", &v).is_err());
        assert!(render("C{code:5q}", &v).is_err());
        assert!(render("C{code", &v).is_err());
    }

    fn scheme(index: &str, range: &str) -> Scheme {
        Scheme {
            module: "vendor".into(),
            function: "param".into(),
            doc: String::new(),
            index: index.into(),
            args: vec![Arg { name: "n".into(), range: range.into() }],
            const_name: None,
            element: None,
            selector: None,
            exclude: Vec::new(),
        }
    }

    #[test]
    fn checks_refuse_bad_schemes() {
        assert!(check(&scheme("0x2000 + n", "0..=0x3FFF")).is_ok());
        let e = check(&scheme("0x2000 + n", "0..=0xFFFF")).err().unwrap();
        assert!(e.contains("beyond 0..=0xFFFF"), "{e}");
        assert!(check(&scheme("0x2000 + m", "0..=5")).err().unwrap().contains("no argument"));
        assert!(check(&scheme("0x2000 + n", "5..=1")).err().unwrap().contains("empty"));
        let mut s = scheme("0x2000 + n", "0..=5");
        s.module = "od".into();
        assert!(check(&s).is_err());
        let mut s = scheme("0x2000 + n", "0..=5");
        s.element = Some(Element {
            name: "e".into(),
            range: "0..=255".into(),
            offset: 1,
            function: None,
            const_name: None,
        });
        assert!(check(&s).err().unwrap().contains("sub-index range"));
    }

    #[test]
    fn overlay_reads_schemes_and_ignores_check_keys() {
        let text = r#"
            strict = false
            [allow-object]
            D504 = ["0x6502"]
            [[scheme]]
            module = "lenze"
            function = "code"
            index = "0x5FFF - code"
            args = [{ name = "code", range = "0..=16383" }]
            element = { name = "subcode", range = "1..=255" }
        "#;
        let o = Overlay::from_toml(text).unwrap();
        assert_eq!(o.scheme.len(), 1);
        assert_eq!(o.scheme[0].element.as_ref().map(|e| e.offset), Some(0));
        let typo =
            "[[scheme]]\nmodule = \"a\"\nfunction = \"b\"\nindex = \"1\"\nargs = []\nconst = 1\n";
        assert!(Overlay::from_toml(typo).is_err());
    }
}
