//! Process data: the sync managers' images laid out by the current PDO assignment
//! (0x1C10 + SM) and mapping (0x1600…, 0x1A00…), copied between the images and the dictionary
//! bit by bit (ETG.1000.6 §5.6.7.4: entries packed in assignment and mapping order, a mapping
//! value being index << 16 | sub-index << 8 | bit length).

use crate::SdoAbort;
use crate::slave::Storage;

/// One mapped entry: where its bits are in its sync manager's image.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct Mapped {
    /// The sync manager.
    pub sm: u8,
    /// The object (0 for a gap).
    pub index: u16,
    /// The sub-index.
    pub sub: u8,
    /// Bits.
    pub bits: u8,
    /// First bit in the image.
    pub bit: u16,
}

/// A PDO assignment or mapping the device cannot serve.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Refused {
    /// An assigned PDO or a mapped entry the dictionary does not have, or an entry longer
    /// than its object (AL status 0x0024/0x0025, invalid input/output mapping).
    Mapping,
    /// More entries or bits than the device has room for (0x001E/0x001D, invalid
    /// input/output configuration).
    Room,
}

fn read_u8<D: Storage + ?Sized>(od: &D, index: u16, sub: u8) -> Option<u8> {
    od.raw(index, sub)?.first().copied()
}

fn read_le<D: Storage + ?Sized>(od: &D, index: u16, sub: u8) -> Option<u32> {
    let b = od.raw(index, sub)?;
    Some(b.iter().take(4).rev().fold(0u32, |acc, &x| acc << 8 | u32::from(x)))
}

/// Where the entries of a layout go: a fixed array, filled in order.
pub struct Sink<'a> {
    /// The entries so far.
    pub entries: &'a mut [Mapped],
    /// How many are used.
    pub used: usize,
}

impl Sink<'_> {
    /// Adds mapping value `v` for `sm` at `*bit`; `false` when there is no room.
    fn push(&mut self, sm: u8, v: u32, bit: &mut u32) -> Result<(), Refused> {
        let (index, sub, bits) = ((v >> 16) as u16, (v >> 8) as u8, v as u8);
        // Indices 0–7 are the dummy types of gaps (CiA 301 §7.4.7.1).
        let index = if index < 8 { 0 } else { index };
        let at = u16::try_from(*bit).map_err(|_| Refused::Room)?;
        let slot = self.entries.get_mut(self.used).ok_or(Refused::Room)?;
        *slot = Mapped { sm, index, sub, bits, bit: at };
        self.used += 1;
        *bit += u32::from(bits);
        Ok(())
    }
}

/// Lays out sync manager `sm` by the dictionary's current assignment into `sink`; returns its
/// bits, or `None` when the device has no assignment object for it (its PDOs are then the
/// fixed ones of its ESI).
///
/// # Errors
///
/// An assigned PDO or mapped entry the dictionary does not have, or more entries than the
/// device has room for.
pub fn layout<D: Storage + ?Sized>(
    od: &D,
    sm: u8,
    sink: &mut Sink<'_>,
) -> Result<Option<u32>, Refused> {
    let assign = 0x1C10 + u16::from(sm);
    let Some(count) = read_u8(od, assign, 0) else { return Ok(None) };
    let mut bit = 0u32;
    for i in 1..=count {
        let pdo = read_le(od, assign, i).ok_or(Refused::Mapping)? as u16;
        let entries = read_u8(od, pdo, 0).ok_or(Refused::Mapping)?;
        for e in 1..=entries {
            let v = read_le(od, pdo, e).ok_or(Refused::Mapping)?;
            if !mappable(od, v) {
                return Err(Refused::Mapping);
            }
            sink.push(sm, v, &mut bit)?;
        }
    }
    Ok(Some(bit))
}

/// Lays out sync manager `sm` from the fixed mapping values of its ESI (`(sm, value)` in
/// order); returns its bits.
///
/// # Errors
///
/// More entries than the device has room for.
pub fn fixed(sm: u8, mapping: &[(u8, u32)], sink: &mut Sink<'_>) -> Result<u32, Refused> {
    let mut bit = 0u32;
    for &(_, v) in mapping.iter().filter(|(s, _)| *s == sm) {
        sink.push(sm, v, &mut bit)?;
    }
    Ok(bit)
}

/// Whether `index` is a PDO mapping (0x1600–0x17FF, 0x1A00–0x1BFF) or assignment
/// (0x1C10–0x1C2F) object.
pub fn is_pdo_config(index: u16) -> bool {
    matches!(index, 0x1600..=0x17FF | 0x1A00..=0x1BFF | 0x1C10..=0x1C2F)
}

fn le(d: &[u8]) -> u32 {
    d.iter().take(4).rev().fold(0, |a, &x| a << 8 | u32::from(x))
}

/// The checks a device makes on a download to a PDO mapping or assignment object before it
/// stores it (ETG.1000.6 §5.6.7.4 and Table 41, CiA 301 §7.5.2.35–36):
///
/// - a read-only sub-index (a device whose ESI lets no master assign or map): 0x06010002,
///   before the rules below, as the CANopen node checks access before its COB-ID rules;
/// - a sub-index other than 0 while sub-index 0 is not 0: 0x06010003;
/// - an assignment of an object that is no mapping object of the direction: 0x06090030;
/// - a mapping of an entry the dictionary does not have, or longer than it: 0x06040041;
/// - a sub-index 0 that enables entries that are not all valid: the first refusal above.
///
/// # Errors
///
/// The abort code.
pub fn check_write<D: Storage + ?Sized>(
    od: &D,
    index: u16,
    sub: u8,
    data: &[u8],
) -> Result<(), SdoAbort> {
    if !is_pdo_config(index) {
        return Ok(());
    }
    if od.access(index, sub).is_some_and(|a| !a.writable()) {
        return Err(SdoAbort::WriteOfReadOnly);
    }
    if sub != 0 {
        if read_u8(od, index, 0).is_some_and(|n| n != 0) {
            return Err(SdoAbort::Other(0x0601_0003));
        }
        return check_value(od, index, le(data), true);
    }
    // Sub-index 0: every entry it enables must hold.
    let n = data.first().copied().unwrap_or(0);
    for s in 1..=n {
        let value = od.raw(index, s).ok_or(SdoAbort::InvalidValue)?;
        check_value(od, index, le(value), false)?;
    }
    Ok(())
}

/// One value of mapping or assignment object `index`: a mapping value the dictionary can
/// serve (0x06040041), an assigned PDO the dictionary has (0x06090030), and with `direction`
/// (a download of the entry itself) a mapping object of the sync manager's direction.
fn check_value<D: Storage + ?Sized>(
    od: &D,
    index: u16,
    v: u32,
    direction: bool,
) -> Result<(), SdoAbort> {
    if !matches!(index, 0x1C10..=0x1C2F) {
        return match mappable(od, v) {
            true => Ok(()),
            false => Err(SdoAbort::NotMappable),
        };
    }
    let pdo = v as u16;
    let rx = matches!(pdo, 0x1600..=0x17FF);
    let tx = matches!(pdo, 0x1A00..=0x1BFF);
    // 0x1C12 takes receive PDOs, 0x1C13 transmit PDOs; other SMs either.
    let ok = !direction
        || match index {
            0x1C12 => rx,
            0x1C13 => tx,
            _ => rx || tx,
        };
    match ok && read_u8(od, pdo, 0).is_some() {
        true => Ok(()),
        false => Err(SdoAbort::InvalidValue),
    }
}

/// A mapping value (index << 16 | sub-index << 8 | bits) the dictionary can serve: a gap
/// (dummy type index 1–7, or 0), or an entry at least `bits` long.
fn mappable<D: Storage + ?Sized>(od: &D, v: u32) -> bool {
    let (i, s, bits) = ((v >> 16) as u16, (v >> 8) as u8, (v & 0xFF) as usize);
    i < 8 || od.raw(i, s).is_some_and(|b| b.len() * 8 >= bits && bits > 0)
}

fn get_bit(b: &[u8], i: usize) -> bool {
    b.get(i / 8).is_some_and(|x| x >> (i % 8) & 1 != 0)
}

fn set_bit(b: &mut [u8], i: usize, v: bool) {
    if let Some(x) = b.get_mut(i / 8) {
        let m = 1 << (i % 8);
        *x = if v { *x | m } else { *x & !m };
    }
}

/// The entries of sync manager `sm` from its image into the dictionary (outputs in OP).
pub fn image_to_dictionary<D: Storage + ?Sized>(
    entries: &[Mapped],
    sm: u8,
    image: &[u8],
    od: &mut D,
) {
    for e in entries.iter().filter(|e| e.sm == sm && e.index != 0) {
        if let Some(dst) = od.raw_mut(e.index, e.sub) {
            copy_bits(image, usize::from(e.bit), dst, 0, usize::from(e.bits));
        }
    }
}

/// The entries of sync manager `sm` from the dictionary into its image (inputs in SAFE-OP
/// and OP).
pub fn dictionary_to_image<D: Storage + ?Sized>(
    entries: &[Mapped],
    sm: u8,
    od: &D,
    image: &mut [u8],
) {
    for e in entries.iter().filter(|e| e.sm == sm && e.index != 0) {
        if let Some(src) = od.raw(e.index, e.sub) {
            copy_bits(src, 0, image, usize::from(e.bit), usize::from(e.bits));
        }
    }
}

/// Copies `bits` bits of `src` from bit `from` into `dst` from bit `to`, LSB first; whole
/// bytes at byte boundaries as one slice copy. One copy for both directions, not generic:
/// the firmware links it once.
#[inline(never)]
fn copy_bits(src: &[u8], from: usize, dst: &mut [u8], to: usize, bits: usize) {
    if from.is_multiple_of(8) && to.is_multiple_of(8) && bits.is_multiple_of(8) {
        let (s, d, n) = (from / 8, to / 8, bits / 8);
        if let (Some(s), Some(d)) = (src.get(s..s + n), dst.get_mut(d..d + n)) {
            d.copy_from_slice(s);
        }
        return;
    }
    for i in 0..bits {
        set_bit(dst, to + i, get_bit(src, from + i));
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn bits_pack_lsb_first() {
        // ETG.1000.6: entries packed from bit 0 of the first byte, LSB first.
        let mut b = [0u8; 2];
        set_bit(&mut b, 0, true);
        set_bit(&mut b, 9, true);
        assert_eq!(b, [0x01, 0x02]);
        assert!(get_bit(&b, 9) && !get_bit(&b, 8));
    }

    #[test]
    fn copy_bits_within_and_across_bytes() {
        // Bits 4..12 of the source (0xBA: A from byte 0's high nibble, B from byte 1's low
        // one) to bit 2 of a zeroed destination: 0xBA << 2 = 0x2E8.
        let mut d = [0u8; 2];
        copy_bits(&[0xA0, 0x0B], 4, &mut d, 2, 8);
        assert_eq!(d, [0xE8, 0x02]);
        // Whole bytes at byte boundaries, the rest of the destination untouched.
        let mut d = [0xFFu8; 3];
        copy_bits(&[1, 2, 3], 8, &mut d, 8, 16);
        assert_eq!(d, [0xFF, 2, 3]);
    }
}
