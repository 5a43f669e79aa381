//! Checking a scheme before it is used (G604): names, ranges, expressions, and the typed
//! aliases of the objects it reaches.

use super::*;

/// A scheme checked and ready to generate.
pub struct Checked<'a> {
    /// The scheme.
    pub scheme: &'a Scheme,
    /// The index rule.
    pub index: Linear,
    /// The excluded index ranges, inclusive.
    pub exclude: Vec<(i64, i64)>,
    /// The arguments and their inclusive ranges, in declaration order.
    pub args: Vec<(String, (i64, i64))>,
    /// The element: its name, inclusive range, sub-index offset and function name.
    pub element: Option<(String, (i64, i64), i64, String)>,
}

/// Module names a scheme cannot take: the generated modules.
pub const RESERVED_MODULES: &[&str] = &["od", "pdo", "cia402", "slave", "master"];
/// Item names a scheme function or alias cannot take: the generated module's own.
pub const RESERVED_ITEMS: &[&str] = &["index", "lookup", "ENTRIES", "WRITE_SIZE"];
/// Enumerating the arguments' ranges finds the parameters the device file defines; a rule
/// with more combinations than this is refused rather than slowing every build down.
const MAX_COMBINATIONS: i64 = 1 << 22;

/// Checks a scheme (G604): names, ranges, expressions.
///
/// # Errors
///
/// What is wrong, as one sentence.
pub fn check(s: &Scheme) -> Result<Checked<'_>, String> {
    if !is_ident(&s.module) || RESERVED_MODULES.contains(&s.module.as_str()) {
        return Err(format!("module `{}` is not a free Rust identifier", s.module));
    }
    if !is_ident(&s.function) || RESERVED_ITEMS.contains(&s.function.as_str()) {
        return Err(format!("function `{}` is not a free Rust identifier", s.function));
    }
    if s.args.is_empty() {
        return Err("a scheme needs at least one argument".into());
    }
    if s.write_size.is_some_and(|n| !(1..=4).contains(&n)) {
        return Err("`write-size` is the width of an expedited transfer, 1..=4 bytes".into());
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
pub struct Alias {
    /// The name (the pattern filled in).
    pub name: String,
    /// Object index.
    pub index: u16,
    /// Sub-index.
    pub sub: u8,
    /// The object's name, and the sub-object's for an element.
    pub what: String,
}

/// The aliases: every typed entry of the device whose index the rule produces, named by the
/// patterns (objects by `const-name`, elements by the element pattern, selected sub-objects
/// by the pattern with `{<selector arg>}` as the value's upper-case name).
///
/// # Errors
///
/// A name pattern that does not render, or renders no upper-case identifier or one name twice.
pub fn aliases(device: &Device, c: &Checked<'_>) -> Result<Vec<Alias>, String> {
    let s = c.scheme;
    let cia402 = crate::cia402::is_cia402(device);
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
            && device.objects.contains_key(&i)
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
        let Some(object) = device.objects.get(&index) else { continue };
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
        for (sub, _) in typed_subs(object, cia402) {
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
