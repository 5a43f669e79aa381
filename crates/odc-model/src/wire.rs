//! A model [`Value`] as the bytes of an SDO transfer or a PDO field, and back (CiA 301 7.1:
//! little-endian, an integer in the bytes of its width, a string as its characters, TIME_OF_DAY
//! as 28 bits of milliseconds and 16 bits of days). For tools that move values by a device
//! file's types: `odc sdo`, `odc monitor`.

use crate::{DataType, Value, ValueClass};

/// The bytes of `v` as data type `dt`; `None` when the value is no value of the type (too
/// wide, negative for an unsigned type, a text for a number, a `$NODEID` value not resolved).
pub fn encode(v: &Value, dt: DataType) -> Option<Vec<u8>> {
    let bytes = |bits: u32| (bits as usize).div_ceil(8);
    match (dt.class(), v) {
        (ValueClass::Bool, Value::Bool(b)) => Some(vec![u8::from(*b)]),
        (ValueClass::Bool, Value::Unsigned(u @ (0 | 1))) => Some(vec![*u as u8]),
        (ValueClass::Unsigned(bits), Value::Unsigned(u)) => {
            (bits >= 64 || *u >> bits == 0).then(|| u.to_le_bytes()[..bytes(bits)].to_vec())
        }
        (ValueClass::Unsigned(_), Value::Signed(i)) if *i >= 0 => {
            encode(&Value::Unsigned(i.unsigned_abs()), dt)
        }
        (ValueClass::Signed(bits), Value::Signed(i)) => {
            let (lo, hi) = if bits >= 64 {
                (i64::MIN, i64::MAX)
            } else {
                (-(1i64 << (bits - 1)), (1i64 << (bits - 1)) - 1)
            };
            (lo..=hi).contains(i).then(|| i.to_le_bytes()[..bytes(bits)].to_vec())
        }
        (ValueClass::Signed(_), Value::Unsigned(u)) => {
            i64::try_from(*u).ok().and_then(|i| encode(&Value::Signed(i), dt))
        }
        (ValueClass::Real32, Value::Real32(bits)) => Some(bits.to_le_bytes().to_vec()),
        (ValueClass::Real64, Value::Real64(bits)) => Some(bits.to_le_bytes().to_vec()),
        (ValueClass::Text, Value::Text(t)) => Some(t.as_bytes().to_vec()),
        (ValueClass::Bytes, Value::Bytes(b)) => Some(b.to_vec()),
        (ValueClass::Bytes, Value::Text(t)) => Some(t.as_bytes().to_vec()),
        (ValueClass::Unicode, Value::Unicode(u)) => {
            Some(u.iter().flat_map(|c| c.to_le_bytes()).collect())
        }
        (ValueClass::Time, Value::Time { ms, days }) if *ms < 1 << 28 => {
            let mut b = ms.to_le_bytes().to_vec();
            b.extend_from_slice(&days.to_le_bytes());
            Some(b)
        }
        _ => None,
    }
}

/// The value `bytes` hold as data type `dt`; `None` when they are too few for the type (an
/// integer takes the bytes of its width; more are not its value either).
pub fn decode(bytes: &[u8], dt: DataType) -> Option<Value> {
    let int = |bits: u32| -> Option<u64> {
        let n = (bits as usize).div_ceil(8);
        if bytes.len() != n {
            return None;
        }
        let mut b = [0u8; 8];
        b.get_mut(..n)?.copy_from_slice(bytes);
        Some(u64::from_le_bytes(b))
    };
    Some(match dt.class() {
        ValueClass::Bool => match bytes {
            [b] => Value::Bool(*b != 0),
            _ => return None,
        },
        ValueClass::Unsigned(bits) => Value::Unsigned(int(bits)?),
        ValueClass::Signed(bits) => {
            let raw = int(bits)?;
            let shift = 64 - bits.min(64);
            Value::Signed(((raw << shift) as i64) >> shift)
        }
        ValueClass::Real32 => Value::Real32(u32::from_le_bytes(bytes.try_into().ok()?)),
        ValueClass::Real64 => Value::Real64(u64::from_le_bytes(bytes.try_into().ok()?)),
        ValueClass::Text => Value::Text(String::from_utf8_lossy(bytes).into()),
        ValueClass::Bytes | ValueClass::Structured => Value::Bytes(bytes.into()),
        ValueClass::Unicode => {
            if !bytes.len().is_multiple_of(2) {
                return None;
            }
            Value::Unicode(
                bytes.chunks_exact(2).map(|c| u16::from_le_bytes([c[0], c[1]])).collect(),
            )
        }
        ValueClass::Time => {
            let b: [u8; 6] = bytes.try_into().ok()?;
            let ms = u32::from_le_bytes([b[0], b[1], b[2], b[3]]) & 0x0FFF_FFFF;
            Value::Time { ms, days: u16::from_le_bytes([b[4], b[5]]) }
        }
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn integers_in_the_bytes_of_their_width() {
        assert_eq!(encode(&Value::Unsigned(0x1234), DataType::Unsigned16), Some(vec![0x34, 0x12]));
        assert_eq!(encode(&Value::Unsigned(0x1_0000), DataType::Unsigned16), None);
        assert_eq!(encode(&Value::Signed(-2), DataType::Integer16), Some(vec![0xFE, 0xFF]));
        assert_eq!(encode(&Value::Signed(-32769), DataType::Integer16), None);
        assert_eq!(encode(&Value::Signed(-1), DataType::Integer24), Some(vec![0xFF; 3]));
        assert_eq!(encode(&Value::Signed(-1), DataType::Unsigned8), None);
        assert_eq!(decode(&[0xFE, 0xFF], DataType::Integer16), Some(Value::Signed(-2)));
        assert_eq!(
            decode(&[0xFF, 0xFF, 0x7F], DataType::Integer24),
            Some(Value::Signed(0x7F_FFFF))
        );
        assert_eq!(
            decode(&[0x00, 0x00, 0x80], DataType::Integer24),
            Some(Value::Signed(-0x80_0000))
        );
        assert_eq!(decode(&[1, 2, 3], DataType::Unsigned16), None, "too many bytes");
        let max = Value::Unsigned(u64::MAX);
        assert_eq!(
            decode(&encode(&max, DataType::Unsigned64).unwrap(), DataType::Unsigned64),
            Some(max)
        );
    }

    #[test]
    fn reals_strings_time() {
        let f = Value::Real32(1.5f32.to_bits());
        assert_eq!(encode(&f, DataType::Real32), Some(1.5f32.to_le_bytes().to_vec()));
        assert_eq!(decode(&1.5f32.to_le_bytes(), DataType::Real32), Some(f));
        assert_eq!(
            encode(&Value::Text("ab".into()), DataType::VisibleString),
            Some(b"ab".to_vec())
        );
        assert_eq!(decode(b"LXM", DataType::VisibleString), Some(Value::Text("LXM".into())));
        // TIME_OF_DAY: 28 bits of ms, 4 reserved, 16 bits of days since 1984-01-01.
        let t = Value::Time { ms: 1000, days: 2 };
        assert_eq!(encode(&t, DataType::TimeOfDay), Some(vec![0xE8, 0x03, 0, 0, 2, 0]));
        assert_eq!(decode(&[0xE8, 0x03, 0, 0xF0, 2, 0], DataType::TimeOfDay), Some(t));
        assert_eq!(decode(&[1, 0], DataType::Boolean), None);
        assert_eq!(decode(&[1], DataType::Boolean), Some(Value::Bool(true)));
    }
}
