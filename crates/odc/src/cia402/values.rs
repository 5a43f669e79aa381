//! The PDO and SDO encodings of the 402 types, so generated descriptors and PDO fields can
//! be typed with them.

use super::{Controlword, ModeOfOperation, Statusword, SupportedModes};
use crate::{DataType, ObjValue, PdoValue, ValueError};

macro_rules! word_pdo {
    ($($t:ty),*) => {$(
        impl PdoValue for $t {
            const BITS: u32 = 16;
            const SIGNED: bool = false;
            #[inline(always)]
            fn to_raw(&self) -> u64 {
                u64::from(self.0)
            }
            #[inline(always)]
            fn from_raw(raw: u64, _bits: u32) -> Option<Self> {
                u16::try_from(raw).ok().map(Self)
            }
        }
    )*};
}
word_pdo!(Controlword, Statusword);

macro_rules! word_u16 {
    ($($t:ident),*) => {$(
        impl From<u16> for $t {
            fn from(bits: u16) -> Self {
                Self(bits)
            }
        }

        impl From<$t> for u16 {
            fn from(word: $t) -> u16 {
                word.0
            }
        }
    )*};
}
word_u16!(Controlword, Statusword);

/// SDO encodings, so generated descriptors can be typed `Entry<Controlword>` and so on.
macro_rules! obj_value_via {
    ($t:ty, $inner:ty, $dt:ident, $to:expr, $from:expr) => {
        impl ObjValue for $t {
            const DATA_TYPE: DataType = DataType::$dt;
            const MAX_LEN: usize = core::mem::size_of::<$inner>();
            fn encode(&self, buf: &mut [u8]) -> Result<usize, ValueError> {
                let to: fn(&$t) -> $inner = $to;
                to(self).encode(buf)
            }
            fn decode(buf: &[u8]) -> Result<Self, ValueError> {
                let from: fn($inner) -> $t = $from;
                <$inner>::decode(buf).map(from)
            }
        }
    };
}
obj_value_via!(Controlword, u16, Unsigned16, |c| c.0, Controlword);
obj_value_via!(Statusword, u16, Unsigned16, |s| s.0, Statusword);
obj_value_via!(ModeOfOperation, i8, Integer8, |m| m.to_i8(), ModeOfOperation::from_i8);
obj_value_via!(SupportedModes, u32, Unsigned32, |m| m.0, SupportedModes);

impl PdoValue for ModeOfOperation {
    const BITS: u32 = 8;
    const SIGNED: bool = true;
    #[inline(always)]
    fn to_raw(&self) -> u64 {
        self.to_i8() as i64 as u64
    }
    #[inline(always)]
    fn from_raw(raw: u64, bits: u32) -> Option<Self> {
        i8::from_raw(raw, bits).map(Self::from_i8)
    }
}
