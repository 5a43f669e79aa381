//! Bit-layout engine shared by `odc-derive`, `odc-codegen` and `odc-check`.
//!
//! One implementation of the layout rules, so the derive, the generator and the checker
//! cannot disagree about where a PDO entry sits on the wire.
//!
//! Rules (CiA 301 and ETG.1000 agree, and they are not configurable here):
//! - bit numbering is LSB0 and multi-byte values are little-endian, so bit `n` of the image is
//!   bit `n % 8` of byte `n / 8`;
//! - entries follow each other in mapping order and may start at **any** bit offset, crossing
//!   byte boundaries (CiA PDO mappings allow that, unlike many bit-field crates);
//! - gaps are explicit (`pad_before`, CiA dummy mapping or an explicit offset).
//!
//! The crate is `no_std` and allocation-free: callers pass the output slice.
#![no_std]
// Bad input is a diagnostic, never a panic: no unwrap, expect or panic outside tests. A
// proven invariant may opt out with an `#[allow]` and a comment saying why.
#![cfg_attr(not(test), deny(clippy::unwrap_used, clippy::expect_used, clippy::panic))]

use core::fmt;

/// Bit count of a classic CAN frame payload: the default PDO limit.
pub const CLASSIC_CAN_BITS: u32 = 64;
/// Bit count of a CAN FD frame payload.
pub const CAN_FD_BITS: u32 = 512;

/// A field as the caller declares it, before placement.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub struct FieldSpec {
    /// Width on the wire, in bits (must be ≥ 1).
    pub bits: u32,
    /// Explicit gap before the field, in bits.
    pub pad_before: u32,
    /// Absolute bit offset, when the source states one (ESI `BitOffs`, `#[pdo(offset = N)]`).
    /// Must not be before the end of the previous field; a later offset leaves a gap.
    pub offset: Option<u32>,
}

impl FieldSpec {
    /// A field placed right after the previous one.
    pub const fn new(bits: u32) -> Self {
        Self { bits, pad_before: 0, offset: None }
    }

    /// The same field with `pad` bits of gap before it.
    pub const fn with_pad(self, pad: u32) -> Self {
        Self { pad_before: pad, ..self }
    }

    /// The same field pinned at an absolute bit offset.
    pub const fn at(self, offset: u32) -> Self {
        Self { offset: Some(offset), ..self }
    }
}

/// A placed bit range inside a process-data image.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub struct BitRange {
    /// First bit (LSB0 over the whole image).
    pub offset: u32,
    /// Width in bits.
    pub bits: u32,
}

impl BitRange {
    /// A range of `bits` bits starting at `offset`.
    pub const fn new(offset: u32, bits: u32) -> Self {
        Self { offset, bits }
    }

    /// One past the last bit; saturates instead of wrapping so overlap tests stay sound.
    pub const fn end(&self) -> u32 {
        self.offset.saturating_add(self.bits)
    }

    /// Whether the two ranges share at least one bit.
    pub const fn overlaps(&self, other: &BitRange) -> bool {
        self.bits != 0 && other.bits != 0 && self.offset < other.end() && other.offset < self.end()
    }

    /// Index of the first byte touched.
    pub const fn first_byte(&self) -> u32 {
        self.offset / 8
    }

    /// Number of bytes touched (a 16-bit field at bit 4 touches 3 bytes).
    pub const fn byte_span(&self) -> u32 {
        if self.bits == 0 {
            return 0;
        }
        (self.end() - 1) / 8 - self.offset / 8 + 1
    }

    /// Whether the range starts and ends on byte boundaries (whole-byte copy possible).
    pub const fn is_byte_aligned(&self) -> bool {
        self.offset.is_multiple_of(8) && self.bits.is_multiple_of(8)
    }

    /// Mask of this range inside a 64-bit little-endian word, or `None` if it does not fit.
    pub const fn mask_in_u64(&self) -> Option<u64> {
        if self.end() > 64 {
            return None;
        }
        Some(mask(self.bits) << self.offset)
    }
}

/// Totals of a computed layout.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub struct Totals {
    /// Bits used, including gaps, up to the end of the last field.
    pub bits: u32,
    /// Bytes needed to hold `bits`.
    pub bytes: u32,
}

/// Why a layout was rejected. Field numbers are positions in the input slice.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
#[non_exhaustive]
pub enum LayoutError {
    /// A field has zero width.
    ZeroWidth {
        /// The field.
        field: usize,
    },
    /// A field starts before the previous one ends.
    Overlap {
        /// The earlier field.
        first: usize,
        /// The field that starts too early.
        second: usize,
    },
    /// The layout ends after the allowed or declared size.
    Overflow {
        /// The first field that crosses the limit.
        field: usize,
        /// Where that field ends.
        end: u32,
        /// The limit in bits.
        limit: u32,
    },
    /// The output slice is shorter than the field list.
    OutputTooShort,
    /// Offsets do not fit in `u32`.
    ArithmeticOverflow {
        /// The field being placed.
        field: usize,
    },
}

impl fmt::Display for LayoutError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match *self {
            Self::ZeroWidth { field } => write!(f, "field {field} has zero width"),
            Self::Overlap { first, second } => {
                write!(f, "field {second} overlaps field {first}")
            }
            Self::Overflow { field, end, limit } => {
                write!(f, "field {field} ends at bit {end}, past the limit of {limit} bits")
            }
            Self::OutputTooShort => f.write_str("output slice shorter than the field list"),
            Self::ArithmeticOverflow { field } => {
                write!(f, "bit offset of field {field} overflows")
            }
        }
    }
}

impl core::error::Error for LayoutError {}

/// Sequential placement, one field at a time; `const` so derives and tables can use it in consts.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
pub struct Cursor {
    next: u32,
}

impl Cursor {
    /// A cursor at bit 0.
    pub const fn new() -> Self {
        Self { next: 0 }
    }

    /// The next free bit.
    pub const fn position(&self) -> u32 {
        self.next
    }

    /// Skip `bits` bits of gap; `None` on `u32` overflow.
    pub const fn pad(&mut self, bits: u32) -> Option<()> {
        match self.next.checked_add(bits) {
            Some(n) => {
                self.next = n;
                Some(())
            }
            None => None,
        }
    }

    /// Place a field of `bits` bits at the current position.
    pub const fn place(&mut self, bits: u32) -> Option<BitRange> {
        let at = self.next;
        match self.pad(bits) {
            Some(()) => Some(BitRange::new(at, bits)),
            None => None,
        }
    }
}

/// Place `fields` in order into `out`, checking widths, overlaps and an optional `limit`.
///
/// Stops at the first offending field; callers that report every error (the derive) call
/// [`place_one`] in their own loop.
pub fn layout(
    fields: &[FieldSpec],
    out: &mut [BitRange],
    limit: Option<u32>,
) -> Result<Totals, LayoutError> {
    if out.len() < fields.len() {
        return Err(LayoutError::OutputTooShort);
    }
    let mut cursor = Cursor::new();
    for (i, (f, slot)) in fields.iter().zip(out.iter_mut()).enumerate() {
        let prev = if i == 0 { None } else { Some(i - 1) };
        *slot = place_one(&mut cursor, f, i, prev)?;
        if let Some(limit) = limit {
            check_limit(slot, i, limit)?;
        }
    }
    Ok(totals(cursor.position()))
}

/// Place one field after `cursor`; `prev` names the previous field for overlap errors.
pub fn place_one(
    cursor: &mut Cursor,
    f: &FieldSpec,
    field: usize,
    prev: Option<usize>,
) -> Result<BitRange, LayoutError> {
    if f.bits == 0 {
        return Err(LayoutError::ZeroWidth { field });
    }
    cursor.pad(f.pad_before).ok_or(LayoutError::ArithmeticOverflow { field })?;
    if let Some(off) = f.offset {
        if off < cursor.position() {
            return Err(LayoutError::Overlap { first: prev.unwrap_or(field), second: field });
        }
        cursor.pad(off - cursor.position()).ok_or(LayoutError::ArithmeticOverflow { field })?;
    }
    cursor.place(f.bits).ok_or(LayoutError::ArithmeticOverflow { field })
}

/// Error if `range` (field number `field`) ends past `limit` bits.
pub const fn check_limit(range: &BitRange, field: usize, limit: u32) -> Result<(), LayoutError> {
    if range.end() > limit {
        Err(LayoutError::Overflow { field, end: range.end(), limit })
    } else {
        Ok(())
    }
}

/// First pair of overlapping ranges, for layouts given with absolute offsets (ESI entries).
/// Quadratic, which is fine for PDOs (≤ 64 entries on CAN, a few hundred on EtherCAT).
pub fn find_overlap(ranges: &[BitRange]) -> Option<(usize, usize)> {
    for (i, a) in ranges.iter().enumerate() {
        for (j, b) in ranges.iter().enumerate().skip(i + 1) {
            if a.overlaps(b) {
                return Some((i, j));
            }
        }
    }
    None
}

/// Totals for an image ending at bit `bits`.
pub const fn totals(bits: u32) -> Totals {
    Totals { bits, bytes: bytes_for_bits(bits) }
}

/// Bytes needed to hold `bits` bits.
pub const fn bytes_for_bits(bits: u32) -> u32 {
    bits.div_ceil(8)
}

/// Mask of the low `bits` bits of a `u64` (`bits ≥ 64` gives all ones).
pub const fn mask(bits: u32) -> u64 {
    if bits >= 64 { u64::MAX } else { (1u64 << bits) - 1 }
}

/// Whether a value whose natural width is `natural` bits can be mapped with `bits` bits
/// without silent truncation of the type's range (`u8` with 9 bits is refused, too).
pub const fn width_compatible(natural: u32, bits: u32) -> bool {
    bits >= 1 && bits <= natural
}

/// Split a gap of `bits` bits into CiA 301 dummy entries `(index, bits)`: UNSIGNED32 (0x0007),
/// UNSIGNED16 (0x0006), UNSIGNED8 (0x0005) and BOOLEAN (0x0001), widest first.
/// Returns the number of entries written to `out`, or `None` if `out` is too short.
pub fn dummy_entries(mut bits: u32, out: &mut [(u16, u8)]) -> Option<usize> {
    let mut n = 0;
    while bits > 0 {
        let (index, w) = match bits {
            32.. => (0x0007, 32u8),
            16.. => (0x0006, 16),
            8.. => (0x0005, 8),
            _ => (0x0001, 1),
        };
        *out.get_mut(n)? = (index, w);
        n += 1;
        bits -= u32::from(w);
    }
    Some(n)
}

/// How many dummy entries [`dummy_entries`] produces for a gap of `bits` bits.
pub const fn dummy_entry_count(bits: u32) -> usize {
    let b32 = bits / 32;
    let b16 = (bits % 32) / 16;
    let b8 = (bits % 16) / 8;
    let b1 = bits % 8;
    (b32 + b16 + b8 + b1) as usize
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn sequential_layout_crosses_bytes() {
        let fields = [FieldSpec::new(3), FieldSpec::new(16), FieldSpec::new(5).with_pad(4)];
        let mut out = [BitRange::new(0, 0); 3];
        let t = layout(&fields, &mut out, Some(64)).unwrap();
        assert_eq!(out, [BitRange::new(0, 3), BitRange::new(3, 16), BitRange::new(23, 5)]);
        assert_eq!(t, Totals { bits: 28, bytes: 4 });
        assert_eq!(out[1].byte_span(), 3);
        assert_eq!(out[1].first_byte(), 0);
    }

    #[test]
    fn explicit_offset_gap_and_overlap() {
        let ok = [FieldSpec::new(8), FieldSpec::new(8).at(16)];
        let mut out = [BitRange::new(0, 0); 2];
        assert_eq!(layout(&ok, &mut out, None).unwrap().bits, 24);
        assert_eq!(out[1].offset, 16);

        let bad = [FieldSpec::new(16), FieldSpec::new(8).at(8)];
        assert_eq!(layout(&bad, &mut out, None), Err(LayoutError::Overlap { first: 0, second: 1 }));
    }

    #[test]
    fn limit_and_zero_width() {
        let fields = [FieldSpec::new(32), FieldSpec::new(33)];
        let mut out = [BitRange::new(0, 0); 2];
        assert_eq!(
            layout(&fields, &mut out, Some(64)),
            Err(LayoutError::Overflow { field: 1, end: 65, limit: 64 })
        );
        assert!(layout(&fields, &mut out, Some(65)).is_ok());
        assert_eq!(
            layout(&[FieldSpec::new(0)], &mut out, None),
            Err(LayoutError::ZeroWidth { field: 0 })
        );
        assert_eq!(layout(&fields, &mut out[..1], None), Err(LayoutError::OutputTooShort));
    }

    #[test]
    fn arithmetic_overflow_is_an_error() {
        let fields = [FieldSpec::new(8).with_pad(u32::MAX)];
        let mut out = [BitRange::new(0, 0); 1];
        assert_eq!(
            layout(&fields, &mut out, None),
            Err(LayoutError::ArithmeticOverflow { field: 0 })
        );
    }

    #[test]
    fn masks() {
        assert_eq!(mask(0), 0);
        assert_eq!(mask(1), 1);
        assert_eq!(mask(12), 0xFFF);
        assert_eq!(mask(64), u64::MAX);
        assert_eq!(BitRange::new(4, 8).mask_in_u64(), Some(0xFF0));
        assert_eq!(BitRange::new(60, 8).mask_in_u64(), None);
        assert!(BitRange::new(8, 16).is_byte_aligned());
        assert!(!BitRange::new(4, 8).is_byte_aligned());
    }

    #[test]
    fn overlap_search() {
        let r = [BitRange::new(0, 8), BitRange::new(8, 8), BitRange::new(12, 4)];
        assert_eq!(find_overlap(&r), Some((1, 2)));
        assert_eq!(find_overlap(&r[..2]), None);
        assert!(!BitRange::new(0, 0).overlaps(&BitRange::new(0, 8)));
    }

    #[test]
    fn dummies_cover_the_gap() {
        let mut out = [(0u16, 0u8); 16];
        for gap in 0..100u32 {
            let n = dummy_entries(gap, &mut out).unwrap();
            assert_eq!(n, dummy_entry_count(gap));
            assert_eq!(out[..n].iter().map(|e| u32::from(e.1)).sum::<u32>(), gap);
        }
        assert_eq!(dummy_entries(40, &mut out[..1]), None);
        assert_eq!(dummy_entries(8, &mut out), Some(1));
        assert_eq!(out[0], (0x0005, 8));
    }

    #[test]
    fn width_rules() {
        assert!(width_compatible(8, 8));
        assert!(width_compatible(32, 24));
        assert!(!width_compatible(8, 9));
        assert!(!width_compatible(8, 0));
        assert_eq!(bytes_for_bits(0), 0);
        assert_eq!(bytes_for_bits(9), 2);
    }
}
