//! Process data: the sync managers' images laid out by the current PDO assignment
//! (0x1C10 + SM) and mapping (0x1600…, 0x1A00…), copied between the ESC's memory and the
//! dictionary bit by bit (ETG.1000.6 §5.6.7.4: entries packed in assignment and mapping
//! order, a mapping value being index << 16 | sub-index << 8 | bit length).

use crate::ModelDictionary;

/// One mapped entry: where its bits are in the SM image.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Mapped {
    /// The object (0 for a gap).
    pub index: u16,
    /// The sub-index.
    pub sub: u8,
    /// First bit in the image.
    pub bit: usize,
    /// Bits.
    pub bits: usize,
}

/// The layout of one sync manager's image.
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub struct Layout {
    /// The entries.
    pub entries: Vec<Mapped>,
    /// The image's bits.
    pub bits: usize,
}

impl Layout {
    /// The image's bytes.
    pub fn bytes(&self) -> u16 {
        u16::try_from(self.bits.div_ceil(8)).unwrap_or(u16::MAX)
    }
}

fn read_u8(od: &ModelDictionary, index: u16, sub: u8) -> Option<u8> {
    od.raw(index, sub)?.first().copied()
}

fn read_le(od: &ModelDictionary, index: u16, sub: u8) -> Option<u32> {
    let b = od.raw(index, sub)?;
    Some(b.iter().take(4).rev().fold(0u32, |acc, &x| acc << 8 | u32::from(x)))
}

/// A PDO assignment or mapping the device cannot serve.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Refused;

/// The layout sync manager `sm` has by the dictionary's current assignment; `None` when the
/// device has no assignment object for it (then its ESI's PDOs of that SM are fixed:
/// [`fixed_layout`]).
///
/// # Errors
///
/// An assigned PDO or mapped entry the dictionary does not have (the device refuses the
/// configuration).
pub fn layout(od: &ModelDictionary, sm: u8) -> Result<Option<Layout>, Refused> {
    let assign = 0x1C10 + u16::from(sm);
    let mut out = Layout::default();
    let Some(count) = read_u8(od, assign, 0) else { return Ok(None) };
    for i in 1..=count {
        let pdo = read_le(od, assign, i).ok_or(Refused)? as u16;
        let entries = read_u8(od, pdo, 0).ok_or(Refused)?;
        for e in 1..=entries {
            let v = read_le(od, pdo, e).ok_or(Refused)?;
            let (index, sub, bits) = ((v >> 16) as u16, (v >> 8) as u8, (v & 0xFF) as usize);
            // Indices 1–7 are the dummy types of gaps (CiA 301 data types DOMAIN 0x000F, UNICODE_STRING 0x000B).
            let gap = index < 8;
            if !mappable(od, v) {
                return Err(Refused);
            }
            out.entries.push(Mapped {
                index: if gap { 0 } else { index },
                sub,
                bit: out.bits,
                bits,
            });
            out.bits += bits;
        }
    }
    Ok(Some(out))
}

/// The layout of sync manager `sm` as the ESI assigns PDOs to it (`RxPdo@Sm`, `TxPdo@Sm`, in
/// file order): what a device without CoE serves, and what its SII's PDO categories tell
/// the master.
pub fn fixed_layout(device: &odc_model::Device, sm: u8) -> Layout {
    let mut out = Layout::default();
    for pdo in device.pdos.iter().filter(|p| p.sync_manager == Some(sm)) {
        for e in &pdo.entries {
            let bits = usize::from(e.bits);
            let index = if e.is_gap() { 0 } else { e.index };
            out.entries.push(Mapped { index, sub: e.sub, bit: out.bits, bits });
            out.bits += bits;
        }
    }
    out
}

/// Whether `index` is a PDO mapping (0x1600–0x17FF, 0x1A00–0x1BFF) or assignment
/// (0x1C10–0x1C2F) object.
pub fn is_pdo_config(index: u16) -> bool {
    matches!(index, 0x1600..=0x17FF | 0x1A00..=0x1BFF | 0x1C10..=0x1C2F)
}

/// The checks a device makes on a download to a PDO mapping or assignment object before it
/// stores it (ETG.1000.6 §5.6.7.4 and Table 41, CiA 301 §7.5.2.35–36):
///
/// - a sub-index other than 0 while sub-index 0 is not 0: 0x06010003;
/// - an assignment of an object that is no mapping object of the direction: 0x06090030;
/// - a mapping of an entry the dictionary does not have, or longer than it: 0x06040041;
/// - a sub-index 0 that enables entries that are not all valid: the first refusal above.
///
/// # Errors
///
/// The abort code.
pub fn check_write(
    od: &ModelDictionary,
    index: u16,
    sub: u8,
    data: &[u8],
) -> Result<(), odc::SdoAbort> {
    use odc::SdoAbort;
    if !is_pdo_config(index) {
        return Ok(());
    }
    let le = |d: &[u8]| d.iter().take(4).rev().fold(0u32, |a, &x| a << 8 | u32::from(x));
    if sub != 0 {
        if read_u8(od, index, 0).is_some_and(|n| n != 0) {
            return Err(SdoAbort::Other(0x0601_0003));
        }
        return match index {
            0x1C10..=0x1C2F => {
                let pdo = le(data) as u16;
                let rx = matches!(pdo, 0x1600..=0x17FF);
                let tx = matches!(pdo, 0x1A00..=0x1BFF);
                // 0x1C12 takes receive PDOs, 0x1C13 transmit PDOs; other SMs by what they
                // hold now.
                let ok = match index {
                    0x1C12 => rx,
                    0x1C13 => tx,
                    _ => rx || tx,
                };
                match ok && read_u8(od, pdo, 0).is_some() {
                    true => Ok(()),
                    false => Err(SdoAbort::InvalidValue),
                }
            }
            _ => match mappable(od, le(data)) {
                true => Ok(()),
                false => Err(SdoAbort::NotMappable),
            },
        };
    }
    // Sub-index 0: every entry it enables must hold.
    let n = data.first().copied().unwrap_or(0);
    for s in 1..=n {
        let value = od.raw(index, s).ok_or(SdoAbort::InvalidValue)?;
        match index {
            0x1C10..=0x1C2F => {
                let pdo = le(value) as u16;
                if read_u8(od, pdo, 0).is_none() {
                    return Err(SdoAbort::InvalidValue);
                }
            }
            _ if !mappable(od, le(value)) => return Err(SdoAbort::NotMappable),
            _ => {}
        }
    }
    Ok(())
}

/// A mapping value (index << 16 | sub-index << 8 | bits) the dictionary can serve: a gap
/// (dummy type index 1–7, or 0), or an entry at least `bits` long.
fn mappable(od: &ModelDictionary, v: u32) -> bool {
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

/// The image's entries into the dictionary (outputs in OP).
pub fn image_to_dictionary(layout: &Layout, image: &[u8], od: &mut ModelDictionary) {
    for e in layout.entries.iter().filter(|e| e.index != 0) {
        if let Some(dst) = od.raw_mut(e.index, e.sub) {
            if e.bit % 8 == 0 && e.bits % 8 == 0 {
                let (from, n) = (e.bit / 8, e.bits / 8);
                if let (Some(s), Some(d)) = (image.get(from..from + n), dst.get_mut(..n)) {
                    d.copy_from_slice(s);
                }
                continue;
            }
            for i in 0..e.bits {
                set_bit(dst, i, get_bit(image, e.bit + i));
            }
        }
    }
}

/// The dictionary's entries into the image (inputs in SAFE-OP and OP).
pub fn dictionary_to_image(layout: &Layout, od: &ModelDictionary, image: &mut [u8]) {
    for e in layout.entries.iter().filter(|e| e.index != 0) {
        if let Some(src) = od.raw(e.index, e.sub) {
            if e.bit % 8 == 0 && e.bits % 8 == 0 {
                let (to, n) = (e.bit / 8, e.bits / 8);
                if let (Some(d), Some(s)) = (image.get_mut(to..to + n), src.get(..n)) {
                    d.copy_from_slice(s);
                }
                continue;
            }
            for i in 0..e.bits {
                set_bit(image, e.bit + i, get_bit(src, i));
            }
        }
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
}
