//! The typing rules: which Rust value type holds a sub-object of the model.

use odc_model::{DataType, SubObject, Value};

/// The Rust type that holds a value of a sub-object.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum RustTy {
    /// `bool`.
    Bool,
    /// `u8`..`u64`, or the runtime's `U24`..`U56`, by width.
    Unsigned(u32),
    /// `i8`..`i64`, or the runtime's `I24`..`I56`, by width.
    Signed(u32),
    /// `f32`.
    F32,
    /// `f64`.
    F64,
    /// `VisibleString<N>`.
    Text(usize),
    /// `OctetString<N>`.
    Bytes(usize),
    /// `UnicodeString<N>`: at most `N` bytes of UTF-16LE.
    Unicode(usize),
    /// `Domain`: data of any length, which the application keeps (the dictionary stores
    /// none).
    Domain,
    /// `TimeOfDay`.
    TimeOfDay,
    /// `TimeDifference`.
    TimeDifference,
    /// `cia402::Controlword`: 0x6040 of a CiA 402 drive, UNSIGNED16 on the wire.
    Controlword,
    /// `cia402::Statusword`: 0x6041 of a CiA 402 drive, UNSIGNED16 on the wire.
    Statusword,
}

impl RustTy {
    /// The type for a sub-object, or `None` when the runtime has no value type for it
    /// (structured and profile types: the checker reports such an entry, D014).
    pub fn of(sub: &SubObject) -> Option<RustTy> {
        Some(match sub.data_type {
            DataType::Boolean => RustTy::Bool,
            DataType::Bit(1) => RustTy::Bool,
            DataType::Bit(_) => RustTy::Unsigned(8),
            DataType::Unsigned8 => RustTy::Unsigned(8),
            DataType::Unsigned16 => RustTy::Unsigned(16),
            DataType::Unsigned24 => RustTy::Unsigned(24),
            DataType::Unsigned32 => RustTy::Unsigned(32),
            DataType::Unsigned40 => RustTy::Unsigned(40),
            DataType::Unsigned48 => RustTy::Unsigned(48),
            DataType::Unsigned56 => RustTy::Unsigned(56),
            DataType::Unsigned64 => RustTy::Unsigned(64),
            DataType::Integer8 => RustTy::Signed(8),
            DataType::Integer16 => RustTy::Signed(16),
            DataType::Integer24 => RustTy::Signed(24),
            DataType::Integer32 => RustTy::Signed(32),
            DataType::Integer40 => RustTy::Signed(40),
            DataType::Integer48 => RustTy::Signed(48),
            DataType::Integer56 => RustTy::Signed(56),
            DataType::Integer64 => RustTy::Signed(64),
            DataType::Real32 => RustTy::F32,
            DataType::Real64 => RustTy::F64,
            DataType::VisibleString => RustTy::Text(string_len(sub)),
            DataType::OctetString => RustTy::Bytes(string_len(sub)),
            DataType::UnicodeString => RustTy::Unicode(string_len(sub)),
            DataType::Domain => RustTy::Domain,
            DataType::TimeOfDay => RustTy::TimeOfDay,
            DataType::TimeDifference => RustTy::TimeDifference,
            _ => return None,
        })
    }

    /// The type of the sub-object `sub` of object `index`: [`RustTy::of`], except that the
    /// controlword 0x6040 and statusword 0x6041 of a CiA 402 drive (`cia402`) are the
    /// runtime's `Controlword` and `Statusword` when the file types them UNSIGNED16 as the
    /// profile does (another type keeps its own; the checker reports it, D502).
    pub fn of_entry(sub: &SubObject, index: u16, var: bool, cia402: bool) -> Option<RustTy> {
        let word = cia402 && var && sub.sub_index == 0 && sub.data_type == DataType::Unsigned16;
        match index {
            0x6040 if word => Some(RustTy::Controlword),
            0x6041 if word => Some(RustTy::Statusword),
            _ => RustTy::of(sub),
        }
    }

    /// The width of the type on the wire in bits, for the PDO types.
    pub fn natural_bits(self) -> Option<u32> {
        Some(match self {
            RustTy::Bool => 1,
            RustTy::Unsigned(n) | RustTy::Signed(n) => n,
            RustTy::F32 => 32,
            RustTy::F64 => 64,
            RustTy::Controlword | RustTy::Statusword => 16,
            _ => return None,
        })
    }

    /// The type for a PDO field of `bits` bits whose object is unknown: the narrowest unsigned
    /// integer that holds it.
    pub fn raw(bits: u32) -> Option<RustTy> {
        Some(match bits {
            1 => RustTy::Bool,
            2..=8 => RustTy::Unsigned(8),
            9..=16 => RustTy::Unsigned(16),
            17..=32 => RustTy::Unsigned(32),
            33..=64 => RustTy::Unsigned(64),
            _ => return None,
        })
    }

    /// Whether the type can be a PDO field (the runtime implements `PdoValue` for it).
    pub fn is_pdo_value(self) -> bool {
        matches!(
            self,
            RustTy::Bool
                | RustTy::Unsigned(_)
                | RustTy::Signed(_)
                | RustTy::F32
                | RustTy::F64
                | RustTy::Controlword
                | RustTy::Statusword
        )
    }

    /// Whether the type is one of Rust's own integers (literals need no constructor).
    pub fn is_native_int(self) -> bool {
        matches!(self, RustTy::Unsigned(8 | 16 | 32 | 64) | RustTy::Signed(8 | 16 | 32 | 64))
    }
}

/// The length in bytes of a string sub-object: stated bit size, else its default's length.
fn string_len(sub: &SubObject) -> usize {
    if let Some(bits) = sub.bit_size {
        return (bits as usize).div_ceil(8);
    }
    match sub.initial_value().map(|v| &v.value) {
        Some(Value::Text(s)) => s.len(),
        Some(Value::Bytes(b)) => b.len(),
        Some(Value::Unicode(u)) => u.len() * 2,
        _ => 0,
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use odc_model::Access;

    #[test]
    fn cia402_words_only_where_the_profile_types_them() {
        let u16_sub = SubObject::new(0, "Controlword", DataType::Unsigned16, Access::Rww);
        let i16_sub = SubObject::new(0, "Controlword", DataType::Integer16, Access::Rww);
        assert_eq!(RustTy::of_entry(&u16_sub, 0x6040, true, true), Some(RustTy::Controlword));
        assert_eq!(RustTy::of_entry(&u16_sub, 0x6041, true, true), Some(RustTy::Statusword));
        // Another type keeps its own; so does a device without the profile, a record's
        // sub-object, and any other index.
        assert_eq!(RustTy::of_entry(&i16_sub, 0x6040, true, true), Some(RustTy::Signed(16)));
        assert_eq!(RustTy::of_entry(&u16_sub, 0x6040, true, false), Some(RustTy::Unsigned(16)));
        assert_eq!(RustTy::of_entry(&u16_sub, 0x6040, false, true), Some(RustTy::Unsigned(16)));
        assert_eq!(RustTy::of_entry(&u16_sub, 0x6042, true, true), Some(RustTy::Unsigned(16)));
        assert_eq!(RustTy::Statusword.natural_bits(), Some(16));
    }

    #[test]
    fn pdo_widths() {
        assert_eq!(RustTy::raw(1), Some(RustTy::Bool));
        assert_eq!(RustTy::raw(9), Some(RustTy::Unsigned(16)));
        assert_eq!(RustTy::raw(65), None);
        assert!(!RustTy::Text(4).is_pdo_value());
        let mut s = SubObject::new(0, "Name", DataType::VisibleString, Access::Ro);
        s.bit_size = Some(20);
        assert_eq!(RustTy::of(&s), Some(RustTy::Text(3)));
    }
}
