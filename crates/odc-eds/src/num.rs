//! Hand-written number readers: integers (decimal, `0x` hex, leading-zero octal, C suffixes,
//! `$NODEID` in either order), booleans, reals, hex bytes.

use odc_model::trim::trim;

/// Something about how a number was written that deserves a warning.
pub(crate) const OCTAL: u8 = 1;
/// A C suffix (`U`, `L`, `LL`, ...) was cut.
pub(crate) const SUFFIX: u8 = 2;
/// `offset+$NODEID` instead of `$NODEID+offset`.
pub(crate) const NODEID_ORDER: u8 = 4;
/// The literal was hexadecimal (signed types read hex as a bit pattern).
pub(crate) const HEX: u8 = 8;

/// The flags [`Lower`](crate::lower) warns about ([`HEX`] is only information).
pub(crate) const WARN_FLAGS: u8 = OCTAL | SUFFIX | NODEID_ORDER;

/// The value of a hex digit (either case): one table look-up instead of three range tests,
/// for the hex numbers that make up most of an EDS file's values and section names.
#[inline(always)]
pub(crate) fn hex_digit(c: u8) -> Option<u8> {
    /// 0xFF: not a hex digit.
    const TABLE: [u8; 256] = {
        let mut t = [0xFFu8; 256];
        let mut i = 0;
        while i < 10 {
            t[b'0' as usize + i] = i as u8;
            i += 1;
        }
        let mut i = 0;
        while i < 6 {
            t[b'a' as usize + i] = 10 + i as u8;
            t[b'A' as usize + i] = 10 + i as u8;
            i += 1;
        }
        t
    };
    let d = TABLE[usize::from(c)];
    (d != 0xFF).then_some(d)
}

/// A read integer literal.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) struct Int {
    /// The value (or the offset, when `node_id`).
    pub value: i128,
    /// `$NODEID` appeared.
    pub node_id: bool,
    /// Warning flags ([`OCTAL`], [`SUFFIX`], [`NODEID_ORDER`], [`HEX`]).
    pub flags: u8,
}

/// Reads one integer literal without `$NODEID`: optional sign, `0x` hex, leading-zero octal or
/// decimal, optional C suffix.
///
/// Inlined, so that callers read the common shapes ([`parse_common`]) without a call; the
/// general reader stays out of line.
#[inline]
pub(crate) fn parse_plain(s: &str) -> Option<(i128, u8)> {
    match parse_common(s.as_bytes()) {
        Some(v) => Some(v),
        None => parse_general(s),
    }
}

/// [`parse_plain`] for what [`parse_common`] does not read.
fn parse_general(s: &str) -> Option<(i128, u8)> {
    let mut b = s.as_bytes();
    let mut flags = 0u8;
    let mut neg = false;
    if let Some((&c, rest)) = b.split_first()
        && (c == b'-' || c == b'+')
    {
        neg = c == b'-';
        b = rest;
        while let Some((&b' ', rest)) = b.split_first() {
            b = rest;
        }
    }
    // C suffixes: up to three of u/U/l/L at the end.
    let mut cut = 0;
    while cut < 3 && b.len() > cut + 1 && matches!(b[b.len() - 1 - cut], b'u' | b'U' | b'l' | b'L')
    {
        cut += 1;
    }
    if cut > 0 {
        b = &b[..b.len() - cut];
        flags |= SUFFIX;
    }
    if b.is_empty() {
        return None;
    }
    // u64 arithmetic: a value past u64::MAX does not read.
    let value: u64 = if b.len() > 2 && b[0] == b'0' && (b[1] == b'x' || b[1] == b'X') {
        flags |= HEX;
        let mut v: u64 = 0;
        for &c in &b[2..] {
            let d = hex_digit(c)?;
            v = v.checked_mul(16)?.checked_add(u64::from(d))?;
        }
        v
    } else {
        let mut v: u64 = 0;
        let octal = b.len() > 1 && b[0] == b'0' && b.iter().all(|c| (b'0'..=b'7').contains(c));
        let base = if octal { 8 } else { 10 };
        if b.len() > 1 && b[0] == b'0' {
            flags |= OCTAL;
        }
        for &c in b {
            if !c.is_ascii_digit() {
                return None;
            }
            v = v.checked_mul(base)?.checked_add(u64::from(c - b'0'))?;
        }
        if octal && v < 8 {
            // 00..07: both readings agree; no warning worth giving.
            flags &= !OCTAL;
        }
        v
    };
    let v = value as i128;
    Some((if neg { -v } else { v }, flags))
}

/// The two shapes most numbers in real files have, read in one pass: `0x` and up to 16 hex
/// digits, or a decimal of up to 19 digits without a leading zero. Anything else (signs,
/// suffixes, octal, longer) is `None` and left to the general reader, which gives the same
/// result for these two shapes.
#[inline]
fn parse_common(b: &[u8]) -> Option<(i128, u8)> {
    match b {
        [b'0', b'x' | b'X', digits @ ..] if !digits.is_empty() && digits.len() <= 16 => {
            let mut v = 0u64;
            for &c in digits {
                let d = hex_digit(c)?;
                v = (v << 4) | u64::from(d);
            }
            Some((i128::from(v), HEX))
        }
        [b'1'..=b'9', ..] | [b'0'] if b.len() <= 19 => {
            let mut v = 0u64;
            for &c in b {
                if !c.is_ascii_digit() {
                    return None;
                }
                v = v * 10 + u64::from(c - b'0');
            }
            Some((i128::from(v), 0))
        }
        _ => None,
    }
}

fn find_nodeid(s: &str) -> Option<usize> {
    let b = s.as_bytes();
    let mut i = memchr::memchr(b'$', b)?;
    loop {
        if b.len() >= i + 7 && b[i + 1..i + 7].eq_ignore_ascii_case(b"NODEID") {
            return Some(i);
        }
        i = i + 1 + memchr::memchr(b'$', &b[i + 1..])?;
    }
}

/// Reads an integer literal, possibly `$NODEID`-relative: `$NODEID`, `$NODEID+n`, `$NODEID-n`,
/// `n+$NODEID` (any case, blanks allowed around `+`).
pub(crate) fn parse_int(s: &str) -> Option<Int> {
    // Most values are a plain hex or decimal number: nothing to trim, no `$NODEID` to look for
    // (what `parse_common` reads is digits only, and the general path reads it alike).
    if let Some((value, flags)) = parse_common(s.as_bytes()) {
        return Some(Int { value, node_id: false, flags });
    }
    let s = trim(s);
    let Some(at) = find_nodeid(s) else {
        let (value, flags) = parse_plain(s)?;
        return Some(Int { value, node_id: false, flags });
    };
    let before = s[..at].trim();
    let after = s[at + 7..].trim();
    match (before.is_empty(), after.is_empty()) {
        (true, true) => Some(Int { value: 0, node_id: true, flags: 0 }),
        (true, false) => {
            let (neg, rest) = match after.as_bytes()[0] {
                b'+' => (false, &after[1..]),
                b'-' => (true, &after[1..]),
                _ => return None,
            };
            let (v, flags) = parse_plain(rest.trim())?;
            Some(Int { value: if neg { -v } else { v }, node_id: true, flags })
        }
        (false, true) => {
            let num = before.strip_suffix('+')?.trim();
            let (v, flags) = parse_plain(num)?;
            Some(Int { value: v, node_id: true, flags: flags | NODEID_ORDER })
        }
        (false, false) => None,
    }
}

/// Reads a boolean: `0`, `1` (in any number notation), `true`, `false` (any case). Other
/// numbers do not fit BOOLEAN.
pub(crate) fn parse_bool(s: &str) -> Option<bool> {
    // `0` and `1` first, as for `parse_int`.
    if let Some((v, _)) = parse_common(s.as_bytes()) {
        return match v {
            0 => Some(false),
            1 => Some(true),
            _ => None,
        };
    }
    let s = trim(s);
    if s.eq_ignore_ascii_case("true") {
        return Some(true);
    }
    if s.eq_ignore_ascii_case("false") {
        return Some(false);
    }
    match parse_plain(s) {
        Some((0, _)) => Some(false),
        Some((1, _)) => Some(true),
        _ => None,
    }
}

/// Reads a float in decimal notation (Rust syntax: `1`, `-1.5`, `1e-3`, `inf`, `NaN`). A
/// finite number too large for the type (`1e309`) does not read: Rust would make it infinite.
pub(crate) fn parse_f64(s: &str) -> Option<f64> {
    let f = trim(s).parse::<f64>().ok()?;
    (f.is_finite() || names_infinity(s)).then_some(f)
}

/// Reads a float in decimal notation as `f32` (`1e39` does not read, as for [`parse_f64`]).
pub(crate) fn parse_f32(s: &str) -> Option<f32> {
    let f = trim(s).parse::<f32>().ok()?;
    (f.is_finite() || names_infinity(s)).then_some(f)
}

fn names_infinity(s: &str) -> bool {
    s.to_ascii_lowercase().contains("inf")
}

/// Reads hex bytes: contiguous (`0A1B`) or separated by blanks (`0A 1B`), an optional `0x`
/// prefix on the whole. An odd number of contiguous digits takes a leading zero.
pub(crate) fn parse_hex_bytes(s: &str) -> Option<Vec<u8>> {
    let s = s.trim();
    let s = s.strip_prefix("0x").or_else(|| s.strip_prefix("0X")).unwrap_or(s);
    let mut out = Vec::with_capacity(s.len() / 2);
    for group in s.split_ascii_whitespace() {
        let g = group.as_bytes();
        let mut i = 0;
        if g.len() % 2 == 1 {
            out.push(hex_digit(g[0])?);
            i = 1;
        }
        while i + 1 < g.len() {
            out.push((hex_digit(g[i])? << 4) | hex_digit(g[i + 1])?);
            i += 2;
        }
    }
    Some(out)
}

/// Whether a group of hex digits of an OCTET_STRING/DOMAIN value (see [`parse_hex_bytes`])
/// has an odd number of digits, which that reading pads with a leading zero nibble.
pub(crate) fn hex_has_odd_group(s: &str) -> bool {
    let s = s.trim();
    let s = s.strip_prefix("0x").or_else(|| s.strip_prefix("0X")).unwrap_or(s);
    s.split_ascii_whitespace().any(|g| g.len() % 2 == 1)
}

/// Cuts a trailing comment (` # ...` or ` ; ...`, blank before the mark required) from a value.
pub(crate) fn strip_inline_comment(s: &str) -> Option<&str> {
    let b = s.as_bytes();
    let i = b.iter().enumerate().position(|(i, &c)| {
        (c == b'#' || c == b';') && i > 0 && (b[i - 1] == b' ' || b[i - 1] == b'\t')
    })?;
    Some(s[..i].trim_end())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn hex_digit_reads_hex_digits_only() {
        for c in 0..=255u8 {
            assert_eq!(hex_digit(c), (c as char).to_digit(16).map(|d| d as u8), "{c}");
        }
    }

    #[test]
    fn fast_paths_read_as_the_general_path() {
        for s in ["0", "1", "2", "0x1", "0X0a", "123", "01", " 1", "1 ", "true", "0x"] {
            let general = parse_plain(s.trim());
            assert_eq!(parse_int(s).map(|n| (n.value, n.flags)), general, "{s:?}");
            let b = match general {
                Some((0, _)) => Some(false),
                Some((1, _)) => Some(true),
                _ if s.trim().eq_ignore_ascii_case("true") => Some(true),
                _ => None,
            };
            assert_eq!(parse_bool(s), b, "{s:?}");
        }
    }

    fn int(s: &str) -> Option<(i128, bool, u8)> {
        parse_int(s).map(|i| (i.value, i.node_id, i.flags))
    }

    #[test]
    fn decimal_hex_octal() {
        assert_eq!(int("42"), Some((42, false, 0)));
        assert_eq!(int("-42"), Some((-42, false, 0)));
        assert_eq!(int("0x1A"), Some((26, false, HEX)));
        assert_eq!(int("0X1a"), Some((26, false, HEX)));
        assert_eq!(int("010"), Some((8, false, OCTAL)));
        assert_eq!(int("007"), Some((7, false, 0)));
        assert_eq!(int("09"), Some((9, false, OCTAL)));
        assert_eq!(int("0"), Some((0, false, 0)));
        assert_eq!(int("0xFFFFFFFFFFFFFFFF"), Some((u64::MAX as i128, false, HEX)));
        assert_eq!(int("0x1FFFFFFFFFFFFFFFF"), None);
        assert_eq!(int("0x"), None);
        assert_eq!(int("12a"), None);
        assert_eq!(int(""), None);
        assert_eq!(int("-"), None);
    }

    #[test]
    fn the_common_shapes_read_as_the_general_reader_reads_them() {
        let cases = [
            "0",
            "7",
            "10",
            "42",
            "1234567890123456789",
            "9999999999999999999",
            "0x0",
            "0X1a",
            "0x0007",
            "0xFFFFFFFFFFFFFFFF",
            "0xffffffffffffffff",
            "0x1FFFFFFFFFFFFFFFF",
            "0x",
            "0xG",
            "12a",
            "010",
            "00",
            "09",
            "-1",
            "+1",
            "1L",
            "0x1U",
            "18446744073709551615",
            "18446744073709551616",
            "",
            " 1",
        ];
        for c in cases {
            let fast = parse_common(c.as_bytes());
            if let Some(f) = fast {
                // Only numbers the general reader accepts, with the same value and flags.
                let mut general = c.as_bytes().to_vec();
                general.insert(0, b'+'); // takes the general path
                let g = parse_plain(std::str::from_utf8(&general).unwrap_or(""));
                assert_eq!(Some(f), g, "{c}");
            }
            assert!(fast.is_none() || parse_plain(c) == fast, "{c}");
        }
        assert_eq!(parse_common(b"0x0007"), Some((7, HEX)));
        assert_eq!(parse_common(b"42"), Some((42, 0)));
        assert_eq!(parse_common(b"010"), None);
        assert_eq!(parse_common(b"1L"), None);
    }

    #[test]
    fn suffixes() {
        assert_eq!(int("0x0LL"), Some((0, false, HEX | SUFFIX)));
        assert_eq!(int("10U"), Some((10, false, SUFFIX)));
        assert_eq!(int("10UL"), Some((10, false, SUFFIX)));
        assert_eq!(int("10ULL"), Some((10, false, SUFFIX)));
        assert_eq!(int("L"), None);
    }

    #[test]
    fn nodeid_forms() {
        assert_eq!(int("$NODEID"), Some((0, true, 0)));
        assert_eq!(int("$nodeid+0x180"), Some((0x180, true, HEX)));
        assert_eq!(int("$NodeId + 384"), Some((384, true, 0)));
        assert_eq!(int("0x180+$NODEID"), Some((0x180, true, HEX | NODEID_ORDER)));
        assert_eq!(int("0x180 + $NODEID"), Some((0x180, true, HEX | NODEID_ORDER)));
        assert_eq!(int("$NODEID-1"), Some((-1, true, 0)));
        assert_eq!(int("$NODEID*2"), None);
        assert_eq!(int("1+$NODEID+2"), None);
        assert_eq!(int("$NODE"), None);
    }

    #[test]
    fn bools_reals_bytes() {
        assert_eq!(parse_bool("TRUE"), Some(true));
        assert_eq!(parse_bool("0"), Some(false));
        assert_eq!(parse_bool("yes"), None);
        assert_eq!(parse_f32("1.5"), Some(1.5));
        assert_eq!(parse_f64("-1e3"), Some(-1000.0));
        assert_eq!(parse_hex_bytes("0A1b"), Some(vec![0x0A, 0x1B]));
        assert_eq!(parse_hex_bytes("0A 1B ff"), Some(vec![0x0A, 0x1B, 0xFF]));
        assert_eq!(parse_hex_bytes("abc"), Some(vec![0x0A, 0xBC]));
        assert_eq!(parse_hex_bytes(""), Some(vec![]));
        assert_eq!(parse_hex_bytes("xyz"), None);
    }

    #[test]
    fn inline_comments() {
        assert_eq!(strip_inline_comment("0x07 # VAR"), Some("0x07"));
        assert_eq!(strip_inline_comment("rw ; x"), Some("rw"));
        assert_eq!(strip_inline_comment("a#b"), None);
    }
}
