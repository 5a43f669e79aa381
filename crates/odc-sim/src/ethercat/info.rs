//! The descriptions SDO Information serves (ETG.1000.6 §5.6.3), for a device whose ESI says
//! `CoE@SdoInfo`, taken from the model the dictionary was built from: what generated code
//! would hold as `const` data in a firmware. The service itself is the firmware stack's
//! ([`odc::ethercat::subdevice::info`]).

use odc_model::{Access, Device, Direction, ObjectKind};

use odc::ethercat::subdevice::{Describe, EntryDescription, ObjectDescription};

/// One object as the information service describes it.
#[derive(Debug)]
struct ObjectInfo {
    index: u16,
    data_type: u16,
    max_sub: u8,
    code: u8,
    name: String,
    rx: bool,
    tx: bool,
    backup: bool,
    setting: bool,
    entries: Vec<EntryInfo>,
}

#[derive(Debug)]
struct EntryInfo {
    sub: u8,
    data_type: u16,
    bits: u16,
    access: u16,
    name: String,
}

/// The information service of one device.
#[derive(Debug)]
pub struct ModelInfo {
    objects: Vec<ObjectInfo>,
}

/// ETG.1000.6 Table 48 object access: read in PRE-OP, SAFE-OP, OP (bits 0–2), write in
/// them (bits 3–5), RxPDO and TxPDO mappable (6, 7), backup (8), setting (9).
fn access_bits(access: Access, rx: bool, tx: bool, backup: bool, setting: bool) -> u16 {
    let read = if matches!(access, Access::Wo) { 0 } else { 0x0007 };
    let write = if matches!(access, Access::Rw | Access::Wo | Access::Rwr | Access::Rww) {
        0x0038
    } else {
        0
    };
    read | write
        | u16::from(rx) << 6
        | u16::from(tx) << 7
        | u16::from(backup) << 8
        | u16::from(setting) << 9
}

impl ModelInfo {
    /// The descriptions of `device`'s objects.
    pub fn new(device: &Device) -> Self {
        let flags = device.ethercat.as_ref().map(|e| e.object_flags.as_slice()).unwrap_or(&[]);
        let flag = |index: u16, sub: u8| flags.iter().find(|f| f.index == index && f.sub == sub);
        let objects = device
            .objects
            .values()
            .filter(|o| !o.subs.is_empty())
            .map(|o| {
                let entries: Vec<EntryInfo> = o
                    .subs
                    .values()
                    .map(|s| {
                        let f = flag(o.index, s.sub_index);
                        let rx = s.pdo_mapping.allows(s.access, Direction::Rx);
                        let tx = s.pdo_mapping.allows(s.access, Direction::Tx);
                        let backup = f.and_then(|f| f.backup).unwrap_or(false);
                        let setting = f.and_then(|f| f.setting).unwrap_or(false);
                        EntryInfo {
                            sub: s.sub_index,
                            data_type: s.data_type.code(),
                            bits: s
                                .bit_size
                                .or(s.data_type.bit_size())
                                .map_or(0, |b| u16::try_from(b).unwrap_or(u16::MAX)),
                            access: access_bits(s.access, rx, tx, backup, setting),
                            name: s.name.to_string(),
                        }
                    })
                    .collect();
                let any = |bit: u16| entries.iter().any(|e| e.access & bit != 0);
                let first_typed =
                    o.subs.values().find(|s| s.sub_index > 0).or(o.subs.values().next());
                ObjectInfo {
                    index: o.index,
                    data_type: match o.kind {
                        ObjectKind::Var => o.subs.values().next().map_or(0, |s| s.data_type.code()),
                        _ => first_typed.map_or(0, |s| s.data_type.code()),
                    },
                    max_sub: o.subs.keys().copied().max().unwrap_or(0),
                    code: o.kind.code(),
                    name: o.name.clone(),
                    rx: any(1 << 6),
                    tx: any(1 << 7),
                    backup: any(1 << 8),
                    setting: any(1 << 9),
                    entries,
                }
            })
            .collect();
        Self { objects }
    }
}

impl ObjectInfo {
    fn description(&self) -> ObjectDescription<'_> {
        ObjectDescription {
            index: self.index,
            data_type: self.data_type,
            max_sub: self.max_sub,
            code: self.code,
            name: &self.name,
            lists: u8::from(self.rx) << 2
                | u8::from(self.tx) << 3
                | u8::from(self.backup) << 4
                | u8::from(self.setting) << 5,
        }
    }
}

impl Describe for ModelInfo {
    fn object_at(&self, pos: usize) -> Option<ObjectDescription<'_>> {
        self.objects.get(pos).map(ObjectInfo::description)
    }

    fn object(&self, index: u16) -> Option<ObjectDescription<'_>> {
        let pos = self.objects.binary_search_by_key(&index, |o| o.index).ok()?;
        self.object_at(pos)
    }

    fn entry(&self, index: u16, sub: u8) -> Option<EntryDescription<'_>> {
        let pos = self.objects.binary_search_by_key(&index, |o| o.index).ok()?;
        let e = self.objects.get(pos)?.entries.iter().find(|e| e.sub == sub)?;
        Some(EntryDescription {
            data_type: e.data_type,
            bits: e.bits,
            access: e.access,
            name: &e.name,
        })
    }
}
