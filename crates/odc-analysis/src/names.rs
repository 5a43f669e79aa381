//! The identifier rules: how a name a device file gives becomes a Rust identifier.
//!
//! A name is split into words (at non-alphanumeric characters and at camel-case boundaries),
//! then joined in the case the item needs. Rust keywords get a trailing underscore; a leading
//! digit gets a leading underscore. The generator names its items by these rules, and the
//! scheme resolution names its aliases by them, so a data sheet lists the names the code has.

/// Terms that are one word, though the camel-case rule would split them (`CANopen` would be
/// `CA` `Nopen`, `EtherCAT` `Ether` `CAT`, Schneider's `DCOMcontrol` `DCO` `Mcontrol`).
/// Matched at the start of a word: spelt as here, or in any case when no lower-case letter
/// follows (`CANOpen`, `Canopen`, but not the `canopen` of `canopener`).
const COMPOUNDS: &[&str] = &["CANopen", "EtherCAT", "EtherNet", "DeviceNet", "FSoE", "DCOM"];

/// Splits a name into lower-case ASCII words.
///
/// A word starts at an upper-case letter after a lower-case one (`ModesOfOperation`), and at
/// the last capital of a run that a lower-case letter follows (`PDOMapping`: `PDO`
/// `Mapping`), except for the plural of an acronym (`PDOs`, `LEDs`: one word) and the terms
/// of `COMPOUNDS`.
pub fn words(name: &str) -> Vec<String> {
    let mut out = Vec::new();
    for chunk in name.split(|c: char| !c.is_ascii_alphanumeric()) {
        let chars: Vec<char> = chunk.chars().collect();
        let mut word = String::new();
        let mut i = 0;
        while let Some(&c) = chars.get(i) {
            let prev = i.checked_sub(1).and_then(|p| chars.get(p)).copied();
            let next = chars.get(i + 1).copied();
            let at_start = prev.is_none_or(|p| {
                p.is_ascii_digit() || (c.is_ascii_uppercase() && !p.is_ascii_uppercase())
            });
            if let Some(len) = compound_at(&chars[i..]).filter(|_| at_start) {
                if !word.is_empty() {
                    out.push(std::mem::take(&mut word));
                }
                out.push(chars[i..i + len].iter().collect::<String>().to_ascii_lowercase());
                i += len;
                continue;
            }
            let after_next = chars.get(i + 2).copied();
            let plural = next == Some('s') && after_next.is_none_or(|a| !a.is_ascii_lowercase());
            let boundary = c.is_ascii_uppercase()
                && prev.is_some_and(|p| {
                    p.is_ascii_lowercase()
                        || (p.is_ascii_uppercase()
                            && next.is_some_and(|n| n.is_ascii_lowercase())
                            && !plural)
                });
            if boundary && !word.is_empty() {
                out.push(std::mem::take(&mut word));
            }
            word.push(c.to_ascii_lowercase());
            i += 1;
        }
        if !word.is_empty() {
            out.push(word);
        }
    }
    out
}

/// The length of the term of `COMPOUNDS` that `chars` starts with (see there).
fn compound_at(chars: &[char]) -> Option<usize> {
    COMPOUNDS.iter().find_map(|term| {
        let len = term.len();
        let head = chars.get(..len)?;
        let exact = head.iter().copied().eq(term.chars());
        let same = head.iter().zip(term.chars()).all(|(a, b)| a.eq_ignore_ascii_case(&b));
        let ends = chars.get(len).is_none_or(|c| !c.is_ascii_lowercase());
        (exact || (same && ends)).then_some(len)
    })
}

/// Rust's strict and reserved keywords (edition 2024: `gen` too).
pub const KEYWORDS: &[&str] = &[
    "as", "async", "await", "break", "const", "continue", "crate", "dyn", "else", "enum", "extern",
    "false", "fn", "for", "gen", "if", "impl", "in", "let", "loop", "match", "mod", "move", "mut",
    "pub", "ref", "return", "self", "Self", "static", "struct", "super", "trait", "true", "type",
    "unsafe", "use", "where", "while", "abstract", "become", "box", "do", "final", "macro",
    "override", "priv", "try", "typeof", "unsized", "virtual", "yield",
];

fn finish(mut s: String) -> String {
    if s.starts_with(|c: char| c.is_ascii_digit()) {
        s.insert(0, '_');
    }
    if KEYWORDS.contains(&s.as_str()) {
        s.push('_');
    }
    s
}

/// `SCREAMING_SNAKE_CASE`, or `""` when the name has no usable character.
pub fn screaming(name: &str) -> String {
    let w = words(name);
    if w.is_empty() {
        return String::new();
    }
    finish(w.join("_").to_ascii_uppercase())
}

/// `snake_case`, or `""`.
pub fn snake(name: &str) -> String {
    let w = words(name);
    if w.is_empty() {
        return String::new();
    }
    finish(w.join("_"))
}

/// `CamelCase`, or `""`.
pub fn camel(name: &str) -> String {
    let w = words(name);
    if w.is_empty() {
        return String::new();
    }
    let mut s = String::new();
    for word in w {
        let mut chars = word.chars();
        if let Some(first) = chars.next() {
            s.push(first.to_ascii_uppercase());
            s.push_str(chars.as_str());
        }
    }
    finish(s)
}

/// Whether `s` is a Rust identifier that is no keyword (nor `_`).
pub fn is_ident(s: &str) -> bool {
    s.starts_with(|c: char| c.is_ascii_alphabetic() || c == '_')
        && s.chars().all(|c| c.is_ascii_alphanumeric() || c == '_')
        && s != "_"
        && !KEYWORDS.contains(&s)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn identifiers() {
        assert!(is_ident("lenze"));
        assert!(is_ident("_x1"));
        assert!(!is_ident("_"));
        assert!(!is_ident("fn"));
        assert!(!is_ident("gen"));
        assert!(!is_ident("1a"));
        assert!(!is_ident("a-b"));
        assert_eq!(screaming("Modes of operation"), "MODES_OF_OPERATION");
        assert_eq!(camel("type"), "Type");
        assert_eq!(snake("Type"), "type_");
        assert_eq!(snake("2nd value"), "_2nd_value");
    }
}
