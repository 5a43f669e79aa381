//! PDOs as the decoder knows them: each device's default mappings with their COB-IDs, changed
//! by the SDO writes seen on the bus (CiA 301 7.5.2.35–7.5.2.38), and a frame split into its
//! fields.

use odc_model::{Device, Value, ValueClass};

use crate::{Field, show};

/// One PDO's COB-ID and mapping.
#[derive(Clone, Debug)]
pub(crate) struct Mapping {
    /// Its CAN-ID (11 bits).
    pub cob: u32,
    /// The communication object (0x1400–0x15FF, 0x1800–0x19FF).
    comm: Option<u16>,
    /// The mapping object (0x1600–0x17FF, 0x1A00–0x1BFF).
    mapping: u16,
    /// Entries in effect: index, sub-index, bits.
    entries: Vec<(u16, u8, u16)>,
    /// Entries as written to sub 1..=64 (sub 0 says how many are in effect).
    staged: Vec<(u16, u8, u16)>,
    /// Bits of the entries in effect.
    pub bits: u32,
}

impl Mapping {
    fn recount(&mut self, n: usize) {
        self.entries = self.staged.iter().take(n).copied().collect();
        self.bits = self.entries.iter().map(|e| u32::from(e.2)).sum();
    }

    /// The fields of a frame's bytes, in wire order (dummy entries left out).
    pub fn fields(&self, device: &Device, bytes: &[u8]) -> Vec<Field> {
        let mut out = Vec::new();
        let mut at = 0u32;
        for &(index, sub, bits) in &self.entries {
            let (from, n) = (at, u32::from(bits));
            at += n;
            if index < 0x1000 {
                continue;
            }
            let object = format!("0x{index:04X}:{sub:02X}");
            let o = device.objects.get(&index);
            let s = o.and_then(|o| o.sub(sub));
            let name = match (o, s) {
                (Some(o), Some(s)) if o.kind.has_subs() => format!("{}/{}", o.name, s.name),
                (Some(o), _) => o.name.clone(),
                _ => String::new(),
            };
            let value = match extract(bytes, from, n) {
                None => "(beyond the frame)".to_owned(),
                Some(raw) => match s.map(|s| s.data_type) {
                    Some(dt) => {
                        let v = show(&typed(raw, n, dt.class()));
                        match (u16::try_from(raw), u8::try_from(raw)) {
                            (Ok(w), _) if n == 16 => format!("{v}{}", crate::cia402(index, w)),
                            (_, Ok(b)) if n == 8 && matches!(index, 0x6060 | 0x6061) => {
                                format!("{v} ({})", crate::mode_name(i8::from_le_bytes([b])))
                            }
                            _ => v,
                        }
                    }
                    None => format!("0x{raw:X}"),
                },
            };
            out.push(Field { object, name, value });
        }
        out
    }
}

/// `n` bits from bit `from` (bit 0 of byte 0 first), when the frame has them.
fn extract(bytes: &[u8], from: u32, n: u32) -> Option<u64> {
    if n == 0 || n > 64 || from + n > u32::try_from(bytes.len() * 8).ok()? {
        return None;
    }
    let mut v = 0u64;
    for k in 0..n {
        let bit = from + k;
        let byte = *bytes.get((bit / 8) as usize)?;
        if byte >> (bit % 8) & 1 == 1 {
            v |= 1 << k;
        }
    }
    Some(v)
}

/// The raw bits of a field as a value of its class.
fn typed(raw: u64, bits: u32, class: ValueClass) -> Value {
    match class {
        ValueClass::Bool => Value::Bool(raw != 0),
        ValueClass::Signed(_) if bits < 64 => {
            let shift = 64 - bits;
            Value::Signed(((raw << shift) as i64) >> shift)
        }
        ValueClass::Signed(_) => Value::Signed(raw as i64),
        ValueClass::Real32 if bits == 32 => Value::Real32(raw as u32),
        ValueClass::Real64 if bits == 64 => Value::Real64(raw),
        _ => Value::Unsigned(raw),
    }
}

/// The PDOs of one node.
#[derive(Clone, Debug, Default)]
pub(crate) struct Mappings {
    list: Vec<Mapping>,
}

impl Mappings {
    /// A device's PDOs as its file defines them, at node `node`.
    pub fn of(device: &Device, node: u8) -> Self {
        let list = device
            .pdos
            .iter()
            .filter_map(|p| {
                let cob = match p.cob_id.as_ref()? {
                    Value::NodeIdPlus(n) => u32::try_from(n + i64::from(node)).ok()?,
                    Value::Unsigned(u) => u32::try_from(*u).ok()?,
                    _ => return None,
                } & 0x7FF;
                let entries: Vec<(u16, u8, u16)> =
                    p.entries.iter().map(|e| (e.index, e.sub, e.bits)).collect();
                let bits = entries.iter().map(|e| u32::from(e.2)).sum();
                Some(Mapping {
                    cob,
                    comm: p.comm_index,
                    mapping: p.mapping_index,
                    staged: entries.clone(),
                    entries,
                    bits,
                })
            })
            .collect();
        Mappings { list }
    }

    /// The PDO on `cob`.
    pub fn by_cob(&self, cob: u32) -> Option<&Mapping> {
        self.list.iter().find(|m| m.cob == cob)
    }

    /// An SDO write the node confirmed: a new COB-ID, mapping count or mapping entry.
    pub fn sdo_write(&mut self, _node: u8, index: u16, sub: u8, bytes: &[u8]) {
        let value = {
            let mut b = [0u8; 4];
            for (d, s) in b.iter_mut().zip(bytes) {
                *d = *s;
            }
            u32::from_le_bytes(b)
        };
        match index {
            0x1400..=0x15FF | 0x1800..=0x19FF if sub == 1 => {
                if let Some(m) = self.list.iter_mut().find(|m| m.comm == Some(index)) {
                    m.cob = value & 0x7FF;
                }
            }
            0x1600..=0x17FF | 0x1A00..=0x1BFF => {
                let Some(m) = self.list.iter_mut().find(|m| m.mapping == index) else { return };
                if sub == 0 {
                    m.recount(value as usize);
                } else {
                    let k = usize::from(sub) - 1;
                    if m.staged.len() <= k {
                        m.staged.resize(k + 1, (0, 0, 0));
                    }
                    if let Some(slot) = m.staged.get_mut(k) {
                        *slot = ((value >> 16) as u16, (value >> 8) as u8, (value & 0xFF) as u16);
                    }
                }
            }
            _ => {}
        }
    }
}

/// The fields of an overlay's process-data layout: byte-packed, little-endian.
pub(crate) fn process_fields(layout: &crate::ProcessLayout, bytes: &[u8]) -> Vec<Field> {
    let mut at = 0u32;
    let mut out = Vec::new();
    for (name, ty) in &layout.fields {
        let (bits, class) = match ty.as_str() {
            "u8" => (8, ValueClass::Unsigned(8)),
            "u16" => (16, ValueClass::Unsigned(16)),
            "u32" => (32, ValueClass::Unsigned(32)),
            "i8" => (8, ValueClass::Signed(8)),
            "i16" => (16, ValueClass::Signed(16)),
            "i32" => (32, ValueClass::Signed(32)),
            _ => (0, ValueClass::Bytes),
        };
        let value = match extract(bytes, at, bits) {
            Some(raw) if bits > 0 => show(&typed(raw, bits, class)),
            _ => "(beyond the frame)".to_owned(),
        };
        out.push(Field { object: String::new(), name: name.clone(), value });
        at += bits;
    }
    out
}

/// The kind of a PDO CAN-ID in the predefined connection set, and its node.
pub(crate) fn name(id: u32) -> (String, Option<u8>) {
    let (kind, base) = match id {
        0x181..=0x1FF => ("TPDO1", 0x180),
        0x201..=0x27F => ("RPDO1", 0x200),
        0x281..=0x2FF => ("TPDO2", 0x280),
        0x301..=0x37F => ("RPDO2", 0x300),
        0x381..=0x3FF => ("TPDO3", 0x380),
        0x401..=0x47F => ("RPDO3", 0x400),
        0x481..=0x4FF => ("TPDO4", 0x480),
        0x501..=0x57F => ("RPDO4", 0x500),
        _ => return ("PDO".into(), None),
    };
    (kind.into(), u8::try_from(id - base).ok())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn bits_lsb_first() {
        // Statusword 0x0637 then a 32-bit position of -2.
        let b = [0x37, 0x06, 0xFE, 0xFF, 0xFF, 0xFF];
        assert_eq!(extract(&b, 0, 16), Some(0x0637));
        assert_eq!(
            typed(extract(&b, 16, 32).unwrap(), 32, ValueClass::Signed(32)),
            Value::Signed(-2)
        );
        assert_eq!(extract(&b, 4, 4), Some(0x3));
        assert_eq!(extract(&b, 40, 16), None);
    }
}
