//! The node's parameters: how it reads the communication objects of the dictionary, the
//! objects written since it last read them, and the view of the dictionary the SDO server and
//! the PDO engine get (0x1001 and 0x1003 answered by the node, CiA 301's rules between values).

use super::{emcy, pdo};
use crate::cia402::{ModeOfOperation, SupportedModes};
use crate::slave::ObjectDictionary;
use crate::{MappingEntry, SdoAbort};

/// Reads up to 4 bytes of `index:sub` as a little-endian number; `None` when the dictionary
/// has no such entry or cannot read it.
pub(super) fn get_u32<D: ObjectDictionary + ?Sized>(dict: &D, index: u16, sub: u8) -> Option<u32> {
    let mut buf = [0u8; 8];
    let n = dict.read(index, sub, &mut buf).ok()?;
    Some(le_u32(buf.get(..n).unwrap_or(&buf)))
}

/// The first up-to-4 bytes of `data` as a little-endian number.
fn le_u32(data: &[u8]) -> u32 {
    crate::bits::load_le_u64(data) as u32
}

pub(super) fn get_u16<D: ObjectDictionary + ?Sized>(dict: &D, index: u16, sub: u8) -> Option<u16> {
    get_u32(dict, index, sub).map(|v| v as u16)
}

pub(super) fn get_u8<D: ObjectDictionary + ?Sized>(dict: &D, index: u16, sub: u8) -> Option<u8> {
    get_u32(dict, index, sub).map(|v| v as u8)
}

/// Communication objects written since the node last read them.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub(super) struct Dirty(pub(super) u8);

impl Dirty {
    pub(super) const HEARTBEAT: u8 = 1;
    pub(super) const CONSUMERS: u8 = 2;
    pub(super) const GUARDING: u8 = 4;
    pub(super) const SYNC: u8 = 8;
    pub(super) const EMCY: u8 = 16;
    pub(super) const PDO: u8 = 32;
    /// Not a write: the node starts (boot-up, a reset), so the PDOs start afresh.
    pub(super) const RESTART: u8 = 128;

    fn of(index: u16) -> u8 {
        match index {
            0x1017 => Self::HEARTBEAT,
            0x1016 => Self::CONSUMERS,
            0x100C | 0x100D => Self::GUARDING,
            0x1005 | 0x1006 | 0x1019 => Self::SYNC,
            0x1014 | 0x1015 => Self::EMCY,
            0x1400..=0x1BFF => Self::PDO,
            _ => 0,
        }
    }
}

/// Whether a COB-ID names an 11-bit CAN-ID that CiA 301 restricts to NMT, SDO, error control
/// and LSS (0x000–0x07F, 0x101–0x180, 0x581–0x5FF, 0x601–0x67F, 0x6E0–0x6FF, 0x701–0x7FF): no
/// PDO, SYNC or EMCY may use one (0x06090030, as CANopenNode answers).
fn restricted_11_bit(cob_id: u32) -> bool {
    cob_id & (1 << 29) == 0
        && matches!(
            cob_id & 0x7FF,
            0x000..=0x07F | 0x101..=0x180 | 0x581..=0x5FF | 0x601..=0x67F | 0x6E0..=0x6FF | 0x701..=0x7FF
        )
}

impl<D: ObjectDictionary + ?Sized> View<'_, D> {
    /// CiA 301's rules for values of communication objects that depend on other values.
    fn check_parameter(&self, index: u16, sub: u8, data: &[u8]) -> Result<(), SdoAbort> {
        let new = le_u32(data);
        match (index, sub) {
            // A PDO's CAN-ID may change only while it is invalid (CiA 301 7.5.2.35/37:
            // 0x06090030 otherwise).
            (0x1400..=0x15FF | 0x1800..=0x19FF, 1) => {
                let old = get_u32(&*self.dict, index, 1);
                let valid = |c: u32| c & (1 << 31) == 0;
                if let Some(old) = old
                    && valid(old)
                    && valid(new)
                    && old & 0x3FFF_FFFF != new & 0x3FFF_FFFF
                {
                    return Err(SdoAbort::InvalidValue);
                }
                if valid(new) && restricted_11_bit(new) {
                    return Err(SdoAbort::InvalidValue);
                }
            }
            // SYNC and EMCY on a restricted CAN-ID likewise (EMCY: while it is valid). Both go
            // out as 11-bit frames, so a 29-bit COB-ID (bit 29) or bits 11-28 set are refused
            // too, as CANopenNode does: the frame would go out on the low 11 bits.
            (0x1005 | 0x1014, 0) if new & 0x3FFF_F800 != 0 => {
                return Err(SdoAbort::InvalidValue);
            }
            (0x1005, 0) if restricted_11_bit(new) => return Err(SdoAbort::InvalidValue),
            (0x1014, 0) if new & (1 << 31) == 0 && restricted_11_bit(new) => {
                return Err(SdoAbort::InvalidValue);
            }
            // Modes of operation (CiA 402-2 object 0x6060): a profile mode the drive does not
            // announce in 0x6502 is refused (0x06090030). 0 (no mode) and the manufacturer's
            // negative modes are the application's to judge.
            (0x6060, 0) => {
                let mode = data.first().map_or(0, |&m| m as i8);
                if mode > 0
                    && let Some(supported) = get_u32(&*self.dict, 0x6502, 0)
                    && !SupportedModes(supported).supports(ModeOfOperation::from_i8(mode))
                {
                    return Err(SdoAbort::InvalidValue);
                }
            }
            // Two heartbeat consumer entries for one node (CiA 301 7.5.2.14: 0x06040043).
            (0x1016, s) if s > 0 => {
                let node = new >> 16 & 0xFF;
                let time = new & 0xFFFF;
                let count = get_u8(&*self.dict, 0x1016, 0).unwrap_or(0);
                let clash = (1..=count).filter(|&o| o != s).any(|o| {
                    get_u32(&*self.dict, 0x1016, o)
                        .is_some_and(|v| v >> 16 & 0xFF == node && v & 0xFFFF != 0)
                });
                if time != 0 && node != 0 && clash {
                    return Err(SdoAbort::ParameterIncompatible);
                }
            }
            _ => {}
        }
        Ok(())
    }
}

impl<D: ObjectDictionary + ?Sized> View<'_, D> {
    /// 0x1010 store parameters / 0x1011 restore default parameters (CiA 301, objects 0x1010 and 0x1011):
    /// the signature "save" / "load" (ASCII, as the 4 bytes of the download) asks the
    /// application to do it ([`Events::storage`](super::Events::storage)); any other value
    /// is refused with 0x08000020. The dictionary's value stays what a read answers: the
    /// storage capability.
    fn storage_command(&mut self, index: u16, sub: u8, data: &[u8]) -> Result<(), SdoAbort> {
        if let Err(e @ (SdoAbort::NoSuchObject | SdoAbort::NoSuchSub)) =
            self.dict.read(index, sub, &mut [0u8; 8])
        {
            return Err(e);
        }
        let (signature, command) = if index == 0x1010 {
            (b"save", super::Storage::Save(sub))
        } else {
            (b"load", super::Storage::Restore(sub))
        };
        if data.len() != 4 {
            return Err(SdoAbort::LengthMismatch);
        }
        if data != signature {
            return Err(SdoAbort::DataTransfer);
        }
        self.storage = Some(command);
        Ok(())
    }

    /// Whether mapping `entry` into a transmit (`tx`) or receive PDO is allowed: the object
    /// exists (0x06020000), its file allows mapping it that way and the entry maps no more
    /// bits than it has (0x06040041), as CiA 301 §7.5.2.36/38 say the write of the entry
    /// is refused. A dummy entry (0x0001–0x0007) maps nothing.
    fn check_entry(&self, entry: MappingEntry, tx: bool) -> Result<(), SdoAbort> {
        if entry.is_dummy() {
            return Ok(());
        }
        let bits = self.dict.pdo_mappable(entry.index, entry.sub, tx).map_err(|e| match e {
            // The abort is about the entry being written: "sub-index does not exist" would
            // say the mapping object lacks it.
            SdoAbort::NoSuchSub => SdoAbort::NoSuchObject,
            e => e,
        })?;
        if entry.bits == 0 || u32::from(entry.bits) > bits {
            return Err(SdoAbort::NotMappable);
        }
        Ok(())
    }

    /// CiA 301 §7.5.2.36/38 on a write into mapping object `index`: an entry (sub 1–64)
    /// names an object that may be mapped (0 leaves it empty); enabling the mapping (sub 0
    /// > 0) needs every entry it counts to be one, and at most 64 bits (0x06040042).
    fn check_mapping(&self, index: u16, sub: u8, data: &[u8]) -> Result<(), SdoAbort> {
        let tx = index >= 0x1A00;
        let value = le_u32(data);
        // A value of another length is the dictionary's to refuse (0x06070010).
        if data.len() != if sub > 0 { 4 } else { 1 } {
            return Ok(());
        }
        if sub > 0 {
            return match value {
                0 => Ok(()),
                v => self.check_entry(MappingEntry::from_u32(v), tx),
            };
        }
        let count = data.first().copied().unwrap_or(0);
        if count > pdo::MAX_MAPPED {
            return Err(SdoAbort::PdoLengthExceeded);
        }
        let mut bits = 0u32;
        for s in 1..=count {
            let entry = MappingEntry::from_u32(get_u32(&*self.dict, index, s).unwrap_or(0));
            self.check_entry(entry, tx)?;
            bits += u32::from(entry.bits);
        }
        if bits > 64 {
            return Err(SdoAbort::PdoLengthExceeded);
        }
        Ok(())
    }
}

/// The dictionary as the SDO server and the PDO engine see it: the node answers 0x1001 and
/// 0x1003 itself, and notes writes to the communication objects.
pub(super) struct View<'a, D: ?Sized> {
    pub(super) dict: &'a mut D,
    pub(super) emcy: &'a mut emcy::Emcy,
    pub(super) dirty: &'a mut Dirty,
    pub(super) written: bool,
    /// A store (0x1010) or restore (0x1011) command with its signature, for the
    /// application.
    pub(super) storage: Option<super::Storage>,
    /// The mappings of these PDOs may not change (CiA 301 7.5.2.36: only while the PDO is
    /// invalid): bit n of word 0 for TPDO n+1, of word 1 for RPDO n+1.
    pub(super) locked: [u64; 2],
}

impl<D: ObjectDictionary + ?Sized> ObjectDictionary for View<'_, D> {
    fn read(&self, index: u16, sub: u8, buf: &mut [u8]) -> Result<usize, SdoAbort> {
        match self.emcy.read(index, sub, buf) {
            Some(r) => r,
            None => self.dict.read(index, sub, buf),
        }
    }

    fn access(&self, index: u16, sub: u8) -> Option<crate::Access> {
        self.dict.access(index, sub)
    }

    fn write(&mut self, index: u16, sub: u8, data: &[u8]) -> Result<(), SdoAbort> {
        if (index, sub) == (0x1003, 0) && self.emcy.read(0x1003, 0, &mut [0]).is_some() {
            return self.emcy.write_history_count(data);
        }
        // Access first, as the dictionary would refuse it (a read-only COB-ID: 0x06010002).
        if self.dict.access(index, sub).is_some_and(|a| !a.writable()) {
            return Err(SdoAbort::WriteOfReadOnly);
        }
        if matches!(index, 0x1010 | 0x1011) && sub > 0 {
            return self.storage_command(index, sub, data);
        }
        self.check_parameter(index, sub, data)?;
        if let Some((word, n)) = match index {
            0x1600..=0x17FF => Some((1, index - 0x1600)),
            0x1A00..=0x1BFF => Some((0, index - 0x1A00)),
            _ => None,
        } && n < 64
            && self.locked[word] >> n & 1 == 1
        {
            // CiA 301: a mapping may only change while its PDO is invalid (COB-ID bit 31).
            return Err(SdoAbort::UnsupportedAccess);
        }
        if matches!(index, 0x1600..=0x17FF | 0x1A00..=0x1BFF) {
            self.check_mapping(index, sub, data)?;
        }
        self.dict.write(index, sub, data)?;
        self.dirty.0 |= Dirty::of(index);
        self.written = true;
        Ok(())
    }
}
