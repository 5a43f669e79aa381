//! Process data objects: the [`Pdo`] trait implemented by `#[derive(Pdo)]` and generated code.

use crate::bits::sign_extend;
use core::fmt;

/// One PDO mapping entry, the value of a 0x1600/0x1A00 sub-index split into its parts.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct MappingEntry {
    /// Mapped object index (0x0001–0x0007 for CiA dummy entries).
    pub index: u16,
    /// Mapped sub-index.
    pub sub: u8,
    /// Length in bits.
    pub bits: u8,
}

impl MappingEntry {
    /// An entry for `index:sub` with `bits` bits.
    pub const fn new(index: u16, sub: u8, bits: u8) -> Self {
        Self { index, sub, bits }
    }

    /// The 32-bit value written to the mapping object: `index << 16 | sub << 8 | bits`.
    pub const fn to_u32(self) -> u32 {
        ((self.index as u32) << 16) | ((self.sub as u32) << 8) | self.bits as u32
    }

    /// Split a mapping object value.
    pub const fn from_u32(v: u32) -> Self {
        Self { index: (v >> 16) as u16, sub: (v >> 8) as u8, bits: v as u8 }
    }

    /// Whether this is a gap: CiA 301 dummy mapping onto a data-type index (0x0001–0x0007),
    /// or an ESI gap entry (index 0).
    pub const fn is_dummy(self) -> bool {
        self.index <= 0x0007
    }
}

/// Why packing failed.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
#[non_exhaustive]
pub enum PackError {
    /// The output buffer is shorter than the PDO.
    BufferTooSmall {
        /// Bytes the PDO needs.
        needed: usize,
        /// Bytes given.
        got: usize,
    },
    /// A field value does not fit its mapped width (a `u32` mapped with 24 bits holding 2^24).
    OutOfRange {
        /// The field's name.
        field: &'static str,
    },
}

/// Why unpacking failed.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
#[non_exhaustive]
pub enum UnpackError {
    /// The input is shorter than the PDO (CiA 301 EMCY 0x8210 on a device).
    BufferTooSmall {
        /// Bytes the PDO needs.
        needed: usize,
        /// Bytes given.
        got: usize,
    },
    /// A field holds bits that are no value of its type (an enum without catch-all).
    InvalidValue {
        /// The field's name.
        field: &'static str,
    },
}

impl fmt::Display for PackError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Self::BufferTooSmall { needed, got } => {
                write!(f, "PDO needs {needed} bytes, buffer has {got}")
            }
            Self::OutOfRange { field } => {
                write!(f, "value of `{field}` does not fit its mapped width")
            }
        }
    }
}

impl fmt::Display for UnpackError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Self::BufferTooSmall { needed, got } => {
                write!(f, "PDO needs {needed} bytes, got {got}")
            }
            Self::InvalidValue { field } => write!(f, "invalid value for `{field}`"),
        }
    }
}

impl core::error::Error for PackError {}
impl core::error::Error for UnpackError {}

/// A fixed-layout process data image (one RPDO/TPDO, or one EtherCAT sync-manager image).
///
/// Layout is LSB0 and little-endian; entries follow each other in `MAPPING` order and may
/// start at any bit. Implement it with `#[derive(odc::Pdo)]` (feature `derive`, on by default),
/// whose `#[pdo(...)]` keys are:
///
/// | key | where | meaning |
/// |---|---|---|
/// | `bits = N` / `bytes = N` | struct | total size; the fields must fit, the rest is zero padding |
/// | `max_bits = N` | struct | size limit, default 64 (classic CAN); EtherCAT code sets more |
/// | `crate = "path"` | struct | path of the runtime, default `::odc` |
/// | `index = 0x6040` | field | mapped object index (required) |
/// | `sub = N` | field | mapped sub-index, default 0 |
/// | `bits = N` / `bytes = N` | field | mapped width; inferred for `bool`, integers and floats |
/// | `pad_bits = N` / `pad_bytes = N` | field | gap before the field (CiA dummy mapping) |
/// | `offset = N` | field | absolute bit offset (ESI `BitOffs`); must not overlap the previous field |
///
/// A field's type is any [`PdoValue`]: `bool`, integers, floats, the [`cia402`](crate::cia402)
/// types, and enums with `#[derive(odc::PdoValue)]`. Layout errors (overlaps, a struct over
/// `max_bits`, a value wider than its `bits`) are compile errors that point at the key.
///
/// ```
/// use odc::{MappingEntry, Pdo};
///
/// /// A TPDO: statusword, 4 bits of digital inputs after a 4-bit gap, position actual value.
/// #[derive(Debug, PartialEq, odc::Pdo)]
/// struct DriveTx {
///     #[pdo(index = 0x6041)]
///     statusword: u16,
///     #[pdo(index = 0x60FD, sub = 1, bits = 4, pad_bits = 4)]
///     inputs: u8,
///     #[pdo(index = 0x6064)]
///     position: i32,
/// }
///
/// assert_eq!((DriveTx::BITS, DriveTx::LEN), (56, 7));
/// assert_eq!(DriveTx::MAPPING[0].to_u32(), 0x6041_0010);
/// // The gap: four 1-bit dummy entries (BOOLEAN, 0x0001).
/// assert_eq!(DriveTx::MAPPING[1..5], [MappingEntry::new(0x0001, 0, 1); 4]);
/// assert_eq!(DriveTx::MAPPING[5].to_u32(), 0x60FD_0104);
/// let tx = DriveTx::unpack(&[0x37, 0x16, 0xA0, 0xE8, 0x03, 0x00, 0x00])?;
/// assert_eq!(tx, DriveTx { statusword: 0x1637, inputs: 0xA, position: 1000 });
/// assert_eq!(tx.pack()?, [0x37, 0x16, 0xA0, 0xE8, 0x03, 0x00, 0x00]);
/// # Ok::<(), Box<dyn std::error::Error>>(())
/// ```
pub trait Pdo: Sized {
    /// Bits used, gaps included.
    const BITS: usize;
    /// Bytes on the wire (`BITS` rounded up).
    const LEN: usize;
    /// Mapping entries in wire order, gaps as CiA dummy entries.
    const MAPPING: &'static [MappingEntry];
    /// `[u8; LEN]`, so `pack` needs no buffer argument.
    type Buffer: Copy + AsRef<[u8]> + AsMut<[u8]> + fmt::Debug;

    /// Pack into a fresh buffer; gap bits are zero.
    fn pack(&self) -> Result<Self::Buffer, PackError>;

    /// Pack into the first `LEN` bytes of `buf`; gap bits are zeroed, later bytes untouched.
    fn pack_into(&self, buf: &mut [u8]) -> Result<(), PackError>;

    /// Unpack from the first `LEN` bytes of `buf`; longer input is accepted, shorter is not.
    fn unpack(buf: &[u8]) -> Result<Self, UnpackError>;
}

/// A type that can be a PDO field: raw bits ⇄ value.
///
/// `to_raw` gives the value zero-extended (unsigned) or sign-extended (signed) to 64 bits; the
/// packer masks it to the mapped width after checking that it fits.
pub trait PdoValue: Sized {
    /// Natural width in bits (the width inferred when a field gives none).
    const BITS: u32;
    /// Whether narrower mappings sign-extend.
    const SIGNED: bool;

    /// The value as raw bits, extended to 64 bits.
    fn to_raw(&self) -> u64;

    /// The value from the low `bits` bits of `raw` (higher bits are zero); `None` if the bits
    /// are not a value of the type.
    fn from_raw(raw: u64, bits: u32) -> Option<Self>;
}

macro_rules! unsigned_pdo {
    ($($t:ty),*) => {$(
        impl PdoValue for $t {
            const BITS: u32 = <$t>::BITS;
            const SIGNED: bool = false;
            #[inline(always)]
            fn to_raw(&self) -> u64 {
                *self as u64
            }
            #[inline(always)]
            fn from_raw(raw: u64, _bits: u32) -> Option<Self> {
                <$t>::try_from(raw).ok()
            }
        }
    )*};
}

macro_rules! signed_pdo {
    ($($t:ty),*) => {$(
        impl PdoValue for $t {
            const BITS: u32 = <$t>::BITS;
            const SIGNED: bool = true;
            #[inline(always)]
            fn to_raw(&self) -> u64 {
                *self as i64 as u64
            }
            #[inline(always)]
            fn from_raw(raw: u64, bits: u32) -> Option<Self> {
                <$t>::try_from(sign_extend(raw, bits)).ok()
            }
        }
    )*};
}

unsigned_pdo!(u8, u16, u32, u64);
signed_pdo!(i8, i16, i32, i64);

impl PdoValue for bool {
    const BITS: u32 = 1;
    const SIGNED: bool = false;
    #[inline(always)]
    fn to_raw(&self) -> u64 {
        u64::from(*self)
    }
    /// Any non-zero pattern is `true`, so a BOOLEAN mapped on 8 bits reads like C would.
    #[inline(always)]
    fn from_raw(raw: u64, _bits: u32) -> Option<Self> {
        Some(raw != 0)
    }
}

impl PdoValue for f32 {
    const BITS: u32 = 32;
    const SIGNED: bool = false;
    #[inline(always)]
    fn to_raw(&self) -> u64 {
        u64::from(self.to_bits())
    }
    #[inline(always)]
    fn from_raw(raw: u64, _bits: u32) -> Option<Self> {
        u32::try_from(raw).ok().map(f32::from_bits)
    }
}

impl PdoValue for f64 {
    const BITS: u32 = 64;
    const SIGNED: bool = false;
    #[inline(always)]
    fn to_raw(&self) -> u64 {
        self.to_bits()
    }
    #[inline(always)]
    fn from_raw(raw: u64, _bits: u32) -> Option<Self> {
        Some(f64::from_bits(raw))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn mapping_entry_u32() {
        let e = MappingEntry::new(0x6040, 0, 16);
        assert_eq!(e.to_u32(), 0x6040_0010);
        assert_eq!(MappingEntry::from_u32(0x607A_0020), MappingEntry::new(0x607A, 0, 32));
        assert!(MappingEntry::new(0x0005, 0, 8).is_dummy());
        assert!(!e.is_dummy());
        assert!(MappingEntry::new(0, 0, 4).is_dummy());
        assert!(!MappingEntry::new(0x0008, 0, 32).is_dummy());
    }

    #[test]
    fn values() {
        assert_eq!((-1i8).to_raw(), u64::MAX);
        assert_eq!(i8::from_raw(0xFF, 8), Some(-1));
        assert_eq!(i16::from_raw(0x8, 4), Some(-8));
        assert_eq!(i8::from_raw(0x1FF, 16), None);
        assert_eq!(u8::from_raw(0x100, 16), None);
        assert_eq!(u16::from_raw(0xFFFF, 16), Some(0xFFFF));
        assert_eq!(bool::from_raw(2, 8), Some(true));
        assert_eq!(f32::from_raw(0x3FC0_0000, 32), Some(1.5));
        assert_eq!(f64::from_raw(1.5f64.to_raw(), 64), Some(1.5));
    }
}
