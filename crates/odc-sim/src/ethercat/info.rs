//! SDO Information (ETG.1000.6 §5.6.3), for a device whose ESI says `CoE@SdoInfo`: the
//! object lists (Get OD List), object descriptions (Get OD) and entry descriptions (Get ED),
//! from the model the dictionary was built from.
//!
//! CoE service 8. The SDO Information header is an opcode (bits 0–6) with the "incomplete"
//! flag (bit 7), a reserved byte and the fragments still to come (u16); a reply longer than
//! the mailbox is sent in fragments, each following when the master has read the previous.

use odc_model::{Access, Device, Direction, ObjectKind};

/// CoE header of an SDO Information reply (number 0, service 8).
const INFO: [u8; 2] = [0x00, 0x80];

const GET_OD_LIST: u8 = 0x01;
const GET_OD_LIST_RESPONSE: u8 = 0x02;
const GET_OD: u8 = 0x03;
const GET_OD_RESPONSE: u8 = 0x04;
const GET_ED: u8 = 0x05;
const GET_ED_RESPONSE: u8 = 0x06;
const ERROR: u8 = 0x07;

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
pub struct SdoInfo {
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

impl SdoInfo {
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
                    code: match o.kind {
                        ObjectKind::Var => 7,
                        ObjectKind::Array => 8,
                        ObjectKind::Record => 9,
                        ObjectKind::Domain => 2,
                        ObjectKind::DefType => 5,
                        ObjectKind::DefStruct => 6,
                        ObjectKind::Null => 0,
                    },
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

    fn list(&self, list_type: u16) -> Option<Vec<u16>> {
        let pick = |f: fn(&ObjectInfo) -> bool| -> Vec<u16> {
            self.objects.iter().filter(|o| f(o)).map(|o| o.index).collect()
        };
        Some(match list_type {
            1 => pick(|_| true),
            2 => pick(|o| o.rx),
            3 => pick(|o| o.tx),
            4 => pick(|o| o.backup),
            5 => pick(|o| o.setting),
            _ => return None,
        })
    }

    /// The reply fragments (CoE data each) to the information request `data` (after the
    /// CoE header), each at most `room` bytes.
    pub fn handle(&self, data: &[u8], room: usize) -> Vec<Vec<u8>> {
        let opcode = data.first().map_or(0, |o| o & 0x7F);
        let body = data.get(4..).unwrap_or(&[]);
        let u16_at = |i: usize| match body.get(i..i + 2) {
            Some(&[lo, hi]) => Some(u16::from_le_bytes([lo, hi])),
            _ => None,
        };
        let (reply_op, payload) = match opcode {
            GET_OD_LIST => {
                let list_type = u16_at(0).unwrap_or(0xFFFF);
                let mut p = list_type.to_le_bytes().to_vec();
                if list_type == 0 {
                    // The number of objects in each list, types 1 to 5.
                    for t in 1..=5 {
                        let n = self.list(t).map_or(0, |l| l.len());
                        p.extend(u16::try_from(n).unwrap_or(u16::MAX).to_le_bytes());
                    }
                } else if let Some(list) = self.list(list_type) {
                    p.extend(list.iter().flat_map(|i| i.to_le_bytes()));
                } else {
                    return vec![error(odc::SdoAbort::InvalidValue)];
                }
                (GET_OD_LIST_RESPONSE, p)
            }
            GET_OD => {
                let index = u16_at(0).unwrap_or(0);
                let Some(o) = self.objects.iter().find(|o| o.index == index) else {
                    return vec![error(odc::SdoAbort::NoSuchObject)];
                };
                let mut p = index.to_le_bytes().to_vec();
                p.extend(o.data_type.to_le_bytes());
                p.extend([o.max_sub, o.code]);
                p.extend(o.name.as_bytes());
                (GET_OD_RESPONSE, p)
            }
            GET_ED => {
                let index = u16_at(0).unwrap_or(0);
                let sub = body.get(2).copied().unwrap_or(0);
                let Some(o) = self.objects.iter().find(|o| o.index == index) else {
                    return vec![error(odc::SdoAbort::NoSuchObject)];
                };
                let Some(e) = o.entries.iter().find(|e| e.sub == sub) else {
                    return vec![error(odc::SdoAbort::NoSuchSub)];
                };
                let mut p = index.to_le_bytes().to_vec();
                // Value info 0: the description and the name, no unit, default or limits.
                p.extend([sub, 0]);
                p.extend(e.data_type.to_le_bytes());
                p.extend(e.bits.to_le_bytes());
                p.extend(e.access.to_le_bytes());
                p.extend(e.name.as_bytes());
                (GET_ED_RESPONSE, p)
            }
            _ => return vec![error(odc::SdoAbort::InvalidCommand)],
        };
        fragments(reply_op, &payload, room)
    }
}

/// `payload` in fragments of `room` bytes (CoE and information headers included).
fn fragments(opcode: u8, payload: &[u8], room: usize) -> Vec<Vec<u8>> {
    let per = room.saturating_sub(INFO.len() + 4).max(2);
    let chunks: Vec<&[u8]> = match payload.is_empty() {
        true => vec![&[]],
        false => payload.chunks(per).collect(),
    };
    let n = chunks.len();
    chunks
        .into_iter()
        .enumerate()
        .map(|(i, chunk)| {
            let left = u16::try_from(n - 1 - i).unwrap_or(u16::MAX);
            let incomplete = if left > 0 { 0x80 } else { 0 };
            let mut r = INFO.to_vec();
            r.extend([opcode | incomplete, 0]);
            r.extend(left.to_le_bytes());
            r.extend(chunk);
            r
        })
        .collect()
}

/// An SDO Information error request with the abort code.
fn error(abort: odc::SdoAbort) -> Vec<u8> {
    let mut r = INFO.to_vec();
    r.extend([ERROR, 0, 0, 0]);
    r.extend(abort.to_u32().to_le_bytes());
    r
}
