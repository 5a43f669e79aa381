//! Values as text: the one spelling every writer, data sheet, diff and doc comment uses.

use std::fmt::Write as _;

use odc_model::Value;

/// A value in the canonical CiA 306 form (the EDS and XDD writers write it; data sheets,
/// diffs and generated doc comments show it): unsigned integers in hex (`0x1A`), booleans as
/// `0`/`1`, REALs in decimal (a NaN as its bit pattern), octet strings as hex digits, a
/// TIME as `days ms`, `$NODEID` offsets as `$NODEID+0x180`, strings and invalid text as
/// they are.
pub fn value_text(v: &Value) -> String {
    match v {
        Value::Bool(b) => u8::from(*b).to_string(),
        Value::Unsigned(u) => format!("0x{u:X}"),
        Value::Signed(i) => i.to_string(),
        Value::Real32(bits) => {
            let f = f32::from_bits(*bits);
            if f.is_nan() { format!("0x{bits:08X}") } else { format!("{f}") }
        }
        Value::Real64(bits) => {
            let f = f64::from_bits(*bits);
            if f.is_nan() { format!("0x{bits:016X}") } else { format!("{f}") }
        }
        Value::Text(s) | Value::Invalid(s) => s.to_string(),
        Value::Bytes(b) => {
            let mut s = String::with_capacity(b.len() * 2);
            for x in b {
                let _ = write!(s, "{x:02X}");
            }
            s
        }
        Value::Unicode(u) => String::from_utf16_lossy(u),
        Value::Time { ms, days } => format!("{days} {ms}"),
        Value::NodeIdPlus(n) => match *n {
            0 => "$NODEID".to_owned(),
            n if n > 0 => format!("$NODEID+0x{n:X}"),
            n => format!("$NODEID-0x{:X}", n.unsigned_abs()),
        },
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn canonical_forms() {
        assert_eq!(value_text(&Value::Unsigned(26)), "0x1A");
        assert_eq!(value_text(&Value::Bool(true)), "1");
        assert_eq!(value_text(&Value::Signed(-5)), "-5");
        assert_eq!(value_text(&Value::Real32(0x3FC0_0000)), "1.5");
        assert_eq!(value_text(&Value::Real32(0x7FC0_0000)), "0x7FC00000");
        assert_eq!(value_text(&Value::Bytes(vec![0x0A, 0xFF].into())), "0AFF");
        assert_eq!(value_text(&Value::Time { ms: 5, days: 2 }), "2 5");
        assert_eq!(value_text(&Value::NodeIdPlus(0)), "$NODEID");
        assert_eq!(value_text(&Value::NodeIdPlus(0x180)), "$NODEID+0x180");
        assert_eq!(value_text(&Value::NodeIdPlus(-2)), "$NODEID-0x2");
    }
}
