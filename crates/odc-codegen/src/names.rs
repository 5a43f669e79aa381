//! Rust identifiers from the names a device file gives its objects.
//!
//! A name is split into words (at non-alphanumeric characters and at camel-case boundaries),
//! then joined in the case the item needs. Names that come out empty get a fallback built
//! from the index; Rust keywords get a trailing underscore; a leading digit gets a leading
//! underscore. Collisions are resolved by [`Namer`], deterministically.

use std::collections::BTreeMap;

/// Splits a name into lower-case ASCII words.
pub fn words(name: &str) -> Vec<String> {
    let mut out = Vec::new();
    for chunk in name.split(|c: char| !c.is_ascii_alphanumeric()) {
        let chars: Vec<char> = chunk.chars().collect();
        let mut word = String::new();
        for (i, &c) in chars.iter().enumerate() {
            let prev = i.checked_sub(1).and_then(|p| chars.get(p)).copied();
            let next = chars.get(i + 1).copied();
            let boundary = c.is_ascii_uppercase()
                && prev.is_some_and(|p| {
                    p.is_ascii_lowercase()
                        || (p.is_ascii_uppercase() && next.is_some_and(|n| n.is_ascii_lowercase()))
                });
            if boundary && !word.is_empty() {
                out.push(std::mem::take(&mut word));
            }
            word.push(c.to_ascii_lowercase());
        }
        if !word.is_empty() {
            out.push(word);
        }
    }
    out
}

const KEYWORDS: &[&str] = &[
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

/// Gives unique names to a set of items, in one namespace.
///
/// Every item proposes a base name and a disambiguating suffix (its index, its sub-index).
/// Items whose base names collide all get their suffix, so a name never depends on which item
/// came first; if even that collides, a counter is appended.
pub struct Namer {
    proposals: Vec<(String, String)>,
}

impl Namer {
    /// An empty namer.
    pub fn new() -> Self {
        Namer { proposals: Vec::new() }
    }

    /// Adds an item; returns its position, for [`Namer::finish`].
    pub fn propose(&mut self, base: String, suffix: String) -> usize {
        self.proposals.push((base, suffix));
        self.proposals.len() - 1
    }

    /// The unique names, in proposal order. `join` is put between base and suffix.
    pub fn finish(self, join: &str, reserved: &[&str]) -> Vec<String> {
        let mut count: BTreeMap<&str, usize> = BTreeMap::new();
        for (base, _) in &self.proposals {
            *count.entry(base.as_str()).or_default() += 1;
        }
        let mut taken: std::collections::BTreeSet<String> =
            reserved.iter().map(|s| s.to_string()).collect();
        let mut out = Vec::with_capacity(self.proposals.len());
        for (base, suffix) in &self.proposals {
            let unique = count.get(base.as_str()) == Some(&1) && !taken.contains(base);
            let mut name = if base.is_empty() {
                suffix.clone()
            } else if unique {
                base.clone()
            } else {
                format!("{base}{join}{suffix}")
            };
            let stem = name.clone();
            let mut n = 2;
            while taken.contains(&name) {
                name = format!("{stem}{join}{n}");
                n += 1;
            }
            taken.insert(name.clone());
            out.push(name);
        }
        out
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn cases() {
        assert_eq!(screaming("Controlword"), "CONTROLWORD");
        assert_eq!(screaming("COB-ID used by PDO"), "COB_ID_USED_BY_PDO");
        assert_eq!(screaming("ModesOfOperation"), "MODES_OF_OPERATION");
        assert_eq!(screaming("PDOMapping 1"), "PDO_MAPPING_1");
        assert_eq!(snake("Vendor ID"), "vendor_id");
        assert_eq!(snake("Type"), "type_");
        assert_eq!(snake("1st value"), "_1st_value");
        assert_eq!(camel("Receive PDO mapping"), "ReceivePdoMapping");
        assert_eq!(camel("self"), "Self_");
        assert_eq!(screaming("µ€"), "");
        assert_eq!(snake("Max. speed (rpm)"), "max_speed_rpm");
    }

    #[test]
    fn collisions_are_order_independent() {
        let mut n = Namer::new();
        n.propose("A".into(), "1400".into());
        n.propose("B".into(), "1401".into());
        n.propose("A".into(), "1402".into());
        n.propose(String::new(), "OBJ_2000".into());
        assert_eq!(n.finish("_", &[]), ["A_1400", "B", "A_1402", "OBJ_2000"]);
        let mut n = Namer::new();
        n.propose("X".into(), "1".into());
        n.propose("X_1".into(), "2".into());
        n.propose("X".into(), "1".into());
        assert_eq!(n.finish("_", &["TABLE"]), ["X_1", "X_1_2", "X_1_3"]);
    }
}
