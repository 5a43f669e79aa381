//! `str::trim` and its halves, with a fast path for text that has no white space at its ends:
//! nearly every value, number and name of an EDS or ESI file. The general functions decode
//! characters (they remove Unicode white space too) and are calls that do not inline, made
//! several times for every entry or element; these return the text itself after one look at a
//! byte or two, and leave everything else to the general functions, so the results are always
//! the same. Here, in the model crate, because both front-ends and the model's own parsers
//! (such as [`Access::parse`](crate::Access::parse)) use them.

/// Whether `b` can neither be nor begin white space that `str::trim` removes: a visible ASCII
/// character (not the space, not a control, not part of a multi-byte character).
#[inline]
fn solid(b: Option<&u8>) -> bool {
    b.is_some_and(u8::is_ascii_graphic)
}

/// Whether `s.trim()` is `s` for certain (a `false` may still be wrong: see [`trim`]).
#[inline]
pub fn is_trimmed(s: &str) -> bool {
    solid(s.as_bytes().first()) && solid(s.as_bytes().last())
}

/// `s.trim()`.
#[inline]
pub fn trim(s: &str) -> &str {
    if is_trimmed(s) { s } else { s.trim() }
}

/// `s.trim_start()`.
#[inline]
pub fn trim_start(s: &str) -> &str {
    if solid(s.as_bytes().first()) { s } else { s.trim_start() }
}

/// `s.trim_end()`.
#[inline]
pub fn trim_end(s: &str) -> &str {
    if solid(s.as_bytes().last()) { s } else { s.trim_end() }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn same_as_std() {
        for s in [
            "",
            " ",
            "x",
            " x",
            "x ",
            " x ",
            "\u{a0}x\u{a0}",
            "\u{3000}",
            "é",
            "xé",
            "\tx\r\n",
            "\u{b}x\u{c}",
            "#x10",
            "a b",
            "\u{85}x",
            "x\u{2028}",
            "0x1F",
            "\t$NODEID+1 ",
            "1\u{3000}",
        ] {
            assert_eq!(trim(s), s.trim(), "{s:?}");
            assert_eq!(trim_start(s), s.trim_start(), "{s:?}");
            assert_eq!(trim_end(s), s.trim_end(), "{s:?}");
        }
    }
}
