//! Numbers, booleans and hex bytes as real ESI files write them, and `DefaultData` decoding.

use odc_model::{DataType, Value, ValueClass};

use odc_model::trim::trim;

/// Parses an ETG `HexDecValue`: `#x1A` (the schema's form), `0x1A` (common, not conformant),
/// decimal, optionally signed. Surrounding white space is ignored.
pub fn parse_int(text: &str) -> Option<i128> {
    let (neg, t) = match trim(text).as_bytes() {
        [b'-', rest @ ..] => (true, rest),
        [b'+', rest @ ..] => (false, rest),
        t => (false, t),
    };
    // One pass over the digits (called for most elements). At most 32 hex or 38 decimal
    // digits: the magnitude cannot overflow a u128.
    let magnitude = match t {
        [b'#' | b'0', b'x' | b'X', h @ ..] if !h.is_empty() && h.len() <= 32 => h
            .iter()
            .try_fold(0u128, |v, &b| Some(v << 4 | u128::from(char::from(b).to_digit(16)?)))?,
        [b'#' | b'0', b'x' | b'X', ..] => return None,
        d if !d.is_empty() && d.len() <= 38 => d
            .iter()
            .try_fold(0u128, |v, &b| b.is_ascii_digit().then(|| v * 10 + u128::from(b - b'0')))?,
        _ => return None,
    };
    let v = i128::try_from(magnitude).ok()?;
    Some(if neg { -v } else { v })
}

/// Parses an `xs:boolean`: `1`, `0`, `true`, `false` (any case, surrounding white space ignored).
pub fn parse_bool(text: &str) -> Option<bool> {
    let t = trim(text);
    if t == "1" || t.eq_ignore_ascii_case("true") {
        Some(true)
    } else if t == "0" || t.eq_ignore_ascii_case("false") {
        Some(false)
    } else {
        None
    }
}

/// Parses a number as [`parse_int`] does, and also the broken forms real files contain
/// (`#x0x6041`). The flag says whether the form was a broken one.
pub fn parse_int_lenient(text: &str) -> Option<(i128, bool)> {
    if let Some(v) = parse_int(text) {
        return Some((v, false));
    }
    let t = trim(text);
    let rest = t.strip_prefix("#x0x").or_else(|| t.strip_prefix("#x0X"))?;
    Some((parse_int(&format!("#x{rest}"))?, true))
}

/// Parses `xs:hexBinary` as [`parse_hex_bytes`] does; an odd number of digits gets a leading
/// zero (real files write `2` for `02`). The flag says whether that was needed.
pub fn parse_hex_bytes_lenient(text: &str) -> Option<(Vec<u8>, bool)> {
    with_hex_bytes_lenient(text, <[u8]>::to_vec)
}

/// [`parse_hex_bytes_lenient`], the bytes handed to `f` rather than returned.
pub fn with_hex_bytes_lenient<R>(text: &str, f: impl FnOnce(&[u8]) -> R) -> Option<(R, bool)> {
    // `f` is called at most once: by the first decoding that succeeds.
    let mut f = Some(f);
    if let Some(r) = with_hex_bytes(text, |b| f.take().map(|f| f(b))) {
        return r.map(|r| (r, false));
    }
    let t = trim(text);
    if !t.len().is_multiple_of(2) && !t.bytes().any(|b| b.is_ascii_whitespace()) {
        let r = with_hex_bytes(&format!("0{t}"), |b| f.take().map(|f| f(b)))??;
        return Some((r, true));
    }
    None
}

/// Parses `xs:hexBinary`: pairs of hex digits, white space allowed between them.
pub fn parse_hex_bytes(text: &str) -> Option<Vec<u8>> {
    with_hex_bytes(text, <[u8]>::to_vec)
}

/// [`parse_hex_bytes`], the bytes handed to `f` rather than returned: most are a number's few
/// bytes, decoded on the stack instead of into two vectors.
pub fn with_hex_bytes<R>(text: &str, f: impl FnOnce(&[u8]) -> R) -> Option<R> {
    let digits = text.bytes().filter(|b| !b.is_ascii_whitespace()).count();
    if !digits.is_multiple_of(2) {
        return None;
    }
    let mut stack = [0u8; 32];
    let mut heap = Vec::new();
    let out: &mut [u8] = match stack.get_mut(..digits / 2) {
        Some(s) => s,
        None => {
            heap.resize(digits / 2, 0);
            &mut heap
        }
    };
    let mut high = None;
    let mut slots = out.iter_mut();
    for b in text.bytes().filter(|b| !b.is_ascii_whitespace()) {
        let d = (b as char).to_digit(16)? as u8;
        match high.take() {
            None => high = Some(d),
            Some(h) => *slots.next()? = h * 16 + d,
        }
    }
    Some(f(out))
}

/// Decodes `DefaultData`/`MinData`/`MaxData` (little-endian bytes) into a value of `ty`.
/// `None` when the bytes do not fit the type (too many bytes for a number).
pub fn decode_data(bytes: &[u8], ty: DataType) -> Option<Value> {
    let le = |max: usize| -> Option<u64> {
        if bytes.len() > max {
            return None;
        }
        Some(bytes.iter().rev().fold(0u64, |acc, &b| (acc << 8) | u64::from(b)))
    };
    Some(match ty.class() {
        ValueClass::Bool => Value::Bool(le(8)? != 0),
        ValueClass::Unsigned(_) => Value::Unsigned(le(8)?),
        ValueClass::Signed(_) => {
            let raw = le(8)?;
            let bits = (bytes.len() * 8) as u32;
            let v = if bits == 0 || bits >= 64 {
                raw as i64
            } else {
                let shift = 64 - bits;
                ((raw << shift) as i64) >> shift
            };
            Value::Signed(v)
        }
        ValueClass::Real32 => Value::Real32(u32::try_from(le(4)?).ok()?),
        ValueClass::Real64 => Value::Real64(le(8)?),
        ValueClass::Text => {
            let end = bytes.iter().position(|&b| b == 0).unwrap_or(bytes.len());
            Value::Text(bytes[..end].iter().map(|&b| char::from(b)).collect())
        }
        ValueClass::Unicode => Value::Unicode(
            bytes.chunks(2).map(|c| u16::from_le_bytes([c[0], *c.get(1).unwrap_or(&0)])).collect(),
        ),
        ValueClass::Time | ValueClass::Bytes | ValueClass::Structured => Value::Bytes(bytes.into()),
    })
}

/// Checks that an integer value fits the width of `ty`. An INTEGERn value in `2^(n-1)..2^n`
/// is an unsigned bit pattern and becomes its two's complement; `None` when it does not fit.
pub fn fit(value: Value, ty: DataType) -> Option<Value> {
    match (ty.class(), value) {
        (ValueClass::Unsigned(bits), Value::Unsigned(u)) => {
            (bits >= 64 || u >> bits == 0).then_some(Value::Unsigned(u))
        }
        (ValueClass::Signed(bits), Value::Signed(i)) if bits < 64 => {
            let half = 1i64 << (bits - 1);
            if (-half..half).contains(&i) {
                Some(Value::Signed(i))
            } else if (half..2 * half).contains(&i) {
                Some(Value::Signed(i - 2 * half))
            } else {
                None
            }
        }
        (_, v) => Some(v),
    }
}

/// Reads a `DefaultValue`/`MinValue`/`MaxValue` text (CODESYS-style files) as a value of `ty`.
pub fn parse_value_text(text: &str, ty: DataType) -> Option<Value> {
    let t = trim(text);
    Some(match ty.class() {
        ValueClass::Bool => match parse_bool(t) {
            Some(b) => Value::Bool(b),
            None => Value::Bool(parse_int(t)? != 0),
        },
        ValueClass::Unsigned(bits) => {
            // Negative values (`-1` for an UDINT, seen in real files) are taken as their
            // two's complement in the type's width.
            let v = parse_int(t)?;
            let bits = bits.min(64);
            let min = -(1i128 << (bits - 1));
            if (min..0).contains(&v) {
                Value::Unsigned(((v + (1i128 << bits)) as u128) as u64)
            } else {
                Value::Unsigned(u64::try_from(v).ok()?)
            }
        }
        ValueClass::Signed(_) => Value::Signed(i64::try_from(parse_int(t)?).ok()?),
        ValueClass::Real32 => match parse_int(t) {
            Some(i) if t.starts_with("#x") || t.starts_with("0x") => {
                Value::Real32(u32::try_from(i).ok()?)
            }
            _ => Value::Real32(t.parse::<f32>().ok()?.to_bits()),
        },
        ValueClass::Real64 => match parse_int(t) {
            Some(i) if t.starts_with("#x") || t.starts_with("0x") => {
                Value::Real64(u64::try_from(i).ok()?)
            }
            _ => Value::Real64(t.parse::<f64>().ok()?.to_bits()),
        },
        ValueClass::Text => Value::Text(text.into()),
        ValueClass::Bytes | ValueClass::Time | ValueClass::Structured => {
            Value::Bytes(parse_hex_bytes(t)?.into_boxed_slice())
        }
        ValueClass::Unicode => Value::Unicode(text.encode_utf16().collect()),
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn hexdec_forms() {
        assert_eq!(parse_int("#x1A"), Some(26));
        assert_eq!(parse_int("#X1a"), Some(26));
        assert_eq!(parse_int("0x1A"), Some(26));
        assert_eq!(parse_int(" 42 "), Some(42));
        assert_eq!(parse_int("-5"), Some(-5));
        assert_eq!(parse_int("-#x10"), Some(-16));
        assert_eq!(parse_int("#xFFFFFFFFFFFFFFFF"), Some(u64::MAX as i128));
        assert_eq!(parse_int("#x"), None);
        assert_eq!(parse_int("12a"), None);
        assert_eq!(parse_int(""), None);
        assert_eq!(parse_int("-"), None);
        assert_eq!(parse_int("1.5"), None);
    }

    #[test]
    fn booleans() {
        assert_eq!(parse_bool("1"), Some(true));
        assert_eq!(parse_bool("true"), Some(true));
        assert_eq!(parse_bool(" TRUE "), Some(true));
        assert_eq!(parse_bool("0"), Some(false));
        assert_eq!(parse_bool("false"), Some(false));
        assert_eq!(parse_bool("yes"), None);
    }

    #[test]
    fn hex_bytes() {
        assert_eq!(parse_hex_bytes("001a"), Some(vec![0x00, 0x1A]));
        assert_eq!(parse_hex_bytes("00 1A\n"), Some(vec![0x00, 0x1A]));
        assert_eq!(parse_hex_bytes(""), Some(vec![]));
        assert_eq!(parse_hex_bytes("0"), None);
        assert_eq!(parse_hex_bytes("zz"), None);
        // Past the 32 bytes decoded on the stack, with blanks between the pairs.
        let long: String = (0..=255u8).map(|b| format!("{b:02X} ")).collect();
        assert_eq!(parse_hex_bytes(&long), Some((0..=255u8).collect::<Vec<u8>>()));
        assert_eq!(parse_hex_bytes(&format!("{long}z0")), None);
        assert_eq!(parse_hex_bytes(&format!("{long}0")), None);
        assert_eq!(with_hex_bytes_lenient("102", <[u8]>::len), Some((2, true)));
        assert_eq!(with_hex_bytes_lenient("1 02", <[u8]>::len), None);
    }

    #[test]
    fn default_data_is_little_endian() {
        let b = parse_hex_bytes("001a").unwrap_or_default();
        assert_eq!(decode_data(&b, DataType::Unsigned16), Some(Value::Unsigned(0x1A00)));
        assert_eq!(decode_data(&[0xFF, 0xFF], DataType::Integer16), Some(Value::Signed(-1)));
        assert_eq!(decode_data(&[0xFE], DataType::Integer8), Some(Value::Signed(-2)));
        assert_eq!(decode_data(&[0x01], DataType::Boolean), Some(Value::Bool(true)));
        assert_eq!(
            decode_data(&[0, 0, 0x80, 0x3F], DataType::Real32),
            Some(Value::Real32(1.0f32.to_bits()))
        );
        assert_eq!(
            decode_data(b"EL3102\0\0", DataType::VisibleString),
            Some(Value::Text("EL3102".into()))
        );
        assert_eq!(
            decode_data(&[1, 2], DataType::OctetString),
            Some(Value::Bytes(Box::new([1, 2])))
        );
        assert_eq!(decode_data(&[0; 9], DataType::Unsigned64), None);
    }

    #[test]
    fn values_fit_their_type() {
        assert_eq!(fit(Value::Unsigned(255), DataType::Unsigned8), Some(Value::Unsigned(255)));
        assert_eq!(fit(Value::Unsigned(256), DataType::Unsigned8), None);
        assert_eq!(fit(Value::Signed(65533), DataType::Integer16), Some(Value::Signed(-3)));
        assert_eq!(fit(Value::Signed(-32768), DataType::Integer16), Some(Value::Signed(-32768)));
        assert_eq!(fit(Value::Signed(-4294967295), DataType::Integer32), None);
        assert_eq!(fit(Value::Signed(1 << 40), DataType::Integer64), Some(Value::Signed(1 << 40)));
    }

    #[test]
    fn value_text() {
        assert_eq!(parse_value_text("#x10", DataType::Unsigned8), Some(Value::Unsigned(16)));
        assert_eq!(parse_value_text("-3", DataType::Integer32), Some(Value::Signed(-3)));
        assert_eq!(parse_value_text("-3", DataType::Unsigned8), Some(Value::Unsigned(253)));
        assert_eq!(
            parse_value_text("-1", DataType::Unsigned32),
            Some(Value::Unsigned(0xFFFF_FFFF))
        );
        assert_eq!(parse_value_text("-129", DataType::Unsigned8), None);
        assert_eq!(parse_int_lenient("#x0x6041"), Some((0x6041, true)));
        assert_eq!(parse_int_lenient("#x6041"), Some((0x6041, false)));
        assert_eq!(parse_hex_bytes_lenient("2"), Some((vec![2], true)));
        assert_eq!(
            parse_value_text("1.5", DataType::Real32),
            Some(Value::Real32(1.5f32.to_bits()))
        );
    }
}
