//! SDO Information (ETG.1000.6 §5.6.3), for a device whose ESI says `CoE@SdoInfo`: the
//! object lists (Get OD List), object descriptions (Get OD) and entry descriptions (Get ED),
//! from what the application's [`Describe`] says.
//!
//! CoE service 8. The SDO Information header is an opcode (bits 0–6) with the "incomplete"
//! flag (bit 7), a reserved byte and the fragments still to come (u16); a reply longer than
//! the mailbox is sent in fragments, each following when the master has read the previous.
//! No fragment is kept: each is written again from the description, windowed to its bytes.

use super::coe::Out;
use crate::SdoAbort;

/// CoE header of an SDO Information reply (number 0, service 8).
const INFO: [u8; 2] = [0x00, 0x80];

const GET_OD_LIST: u8 = 0x01;
const GET_OD_LIST_RESPONSE: u8 = 0x02;
const GET_OD: u8 = 0x03;
const GET_OD_RESPONSE: u8 = 0x04;
const GET_ED: u8 = 0x05;
const GET_ED_RESPONSE: u8 = 0x06;
const ERROR: u8 = 0x07;

/// One object as the information service describes it (ETG.1000.6 Table 44).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct ObjectDescription<'a> {
    /// Index.
    pub index: u16,
    /// Data type (of the object, or of its entries).
    pub data_type: u16,
    /// Highest sub-index.
    pub max_sub: u8,
    /// Object code: 7 VAR, 8 ARRAY, 9 RECORD.
    pub code: u8,
    /// Name.
    pub name: &'a str,
    /// The lists (Get OD List types) it is on besides "all": bit 2 RxPDO mappable, 3 TxPDO
    /// mappable, 4 backup, 5 settings.
    pub lists: u8,
}

/// One entry as the information service describes it (ETG.1000.6 Table 46).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct EntryDescription<'a> {
    /// Data type.
    pub data_type: u16,
    /// Bit length.
    pub bits: u16,
    /// Object access (ETG.1000.6 Table 48): read in PRE-OP, SAFE-OP, OP (bits 0–2), write in
    /// them (bits 3–5), RxPDO and TxPDO mappable (6, 7), backup (8), setting (9).
    pub access: u16,
    /// Name.
    pub name: &'a str,
}

/// What SDO Information serves: the descriptions of the dictionary's objects (generated from
/// the ESI: [`crate::slave::Description`], a generated module's `slave::DESCRIPTION`; or
/// built from the model in the simulator).
pub trait Describe {
    /// The object at position `pos` in index order.
    fn object_at(&self, pos: usize) -> Option<ObjectDescription<'_>>;
    /// The object `index`.
    fn object(&self, index: u16) -> Option<ObjectDescription<'_>>;
    /// The entry `index:sub`.
    fn entry(&self, index: u16, sub: u8) -> Option<EntryDescription<'_>>;
}

/// A request whose reply is still being sent in fragments.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub(super) struct Pending {
    opcode: u8,
    index: u16,
    sub: u8,
    /// The fragment to send next.
    next: u16,
    /// How many fragments in all.
    count: u16,
}

impl Pending {
    /// Whether fragments are still to be sent.
    pub(super) fn more(&self) -> bool {
        self.next < self.count
    }
}

/// Writes the bytes of a payload that fall into a window.
struct Window<'a, 'b> {
    out: &'a mut Out<'b>,
    skip: usize,
    take: usize,
    total: usize,
}

impl Window<'_, '_> {
    /// `bytes` at the payload's current position: the part inside the window goes out.
    fn push(&mut self, bytes: &[u8]) {
        let from = self.skip.saturating_sub(self.total);
        let to = (self.skip + self.take).saturating_sub(self.total).min(bytes.len());
        if let Some(part) = bytes.get(from..to) {
            self.out.push(part);
        }
        self.total += bytes.len();
    }
}

fn payload(p: &Pending, d: &dyn Describe, w: &mut Window<'_, '_>) -> Result<u8, SdoAbort> {
    match p.opcode {
        GET_OD_LIST => {
            let list_type = p.index;
            w.push(&list_type.to_le_bytes());
            if list_type > 5 {
                return Err(SdoAbort::InvalidValue);
            }
            // One pass over the objects: type 0 counts the objects of each list, types 1 to 5,
            // the others list the indices of theirs.
            let mut counts = [0u16; 5];
            for o in (0..).map_while(|i| d.object_at(i)) {
                for (t, n) in (1..).zip(counts.iter_mut()) {
                    if t == 1 || o.lists >> t & 1 != 0 {
                        *n = n.saturating_add(1);
                        if t == list_type {
                            w.push(&o.index.to_le_bytes());
                        }
                    }
                }
            }
            if list_type == 0 {
                for n in counts {
                    w.push(&n.to_le_bytes());
                }
            }
            Ok(GET_OD_LIST_RESPONSE)
        }
        GET_OD => {
            let o = d.object(p.index).ok_or(SdoAbort::NoSuchObject)?;
            let [i0, i1] = p.index.to_le_bytes();
            let [t0, t1] = o.data_type.to_le_bytes();
            w.push(&[i0, i1, t0, t1, o.max_sub, o.code]);
            w.push(o.name.as_bytes());
            Ok(GET_OD_RESPONSE)
        }
        GET_ED => {
            d.object(p.index).ok_or(SdoAbort::NoSuchObject)?;
            let e = d.entry(p.index, p.sub).ok_or(SdoAbort::NoSuchSub)?;
            let [i0, i1] = p.index.to_le_bytes();
            let [t0, t1] = e.data_type.to_le_bytes();
            let [b0, b1] = e.bits.to_le_bytes();
            let [a0, a1] = e.access.to_le_bytes();
            // Value info 0: the description and the name, no unit, default or limits.
            w.push(&[i0, i1, p.sub, 0, t0, t1, b0, b1, a0, a1]);
            w.push(e.name.as_bytes());
            Ok(GET_ED_RESPONSE)
        }
        _ => Err(SdoAbort::InvalidCommand),
    }
}

/// Starts the reply to the information request `data` (after the CoE header): the first
/// fragment (or the error) into `out`, which is as long as the mailbox's data may be; returns
/// the request when more fragments follow.
pub(super) fn start(data: &[u8], d: &dyn Describe, out: &mut Out<'_>) -> Option<Pending> {
    let body = data.get(4..).unwrap_or(&[]);
    let u16_at = |i: usize| match body.get(i..i + 2) {
        Some(&[lo, hi]) => u16::from_le_bytes([lo, hi]),
        _ => 0,
    };
    let opcode = data.first().map_or(0, |o| o & 0x7F);
    let index = match opcode {
        GET_OD_LIST if body.len() < 2 => 0xFFFF,
        _ => u16_at(0),
    };
    let mut p =
        Pending { opcode, index, sub: body.get(2).copied().unwrap_or(0), next: 0, count: 0 };
    // A dry run for the payload's length.
    let mut none = Out { buf: &mut [], len: 0 };
    let mut w = Window { out: &mut none, skip: 0, take: 0, total: 0 };
    if let Err(abort) = payload(&p, d, &mut w) {
        let [a0, a1, a2, a3] = abort.to_u32().to_le_bytes();
        out.push(&[INFO[0], INFO[1], ERROR, 0, 0, 0, a0, a1, a2, a3]);
        return None;
    }
    let per = per_fragment(out);
    p.count = u16::try_from(w.total.div_ceil(per).max(1)).unwrap_or(u16::MAX);
    next(&mut p, d, out);
    (p.next < p.count).then_some(p)
}

fn per_fragment(out: &Out<'_>) -> usize {
    out.buf.len().saturating_sub(INFO.len() + 4).max(2)
}

/// Writes the next fragment of `p` into `out`.
pub(super) fn next(p: &mut Pending, d: &dyn Describe, out: &mut Out<'_>) {
    let per = per_fragment(out);
    let left = p.count.saturating_sub(p.next + 1);
    let incomplete = if left > 0 { 0x80 } else { 0 };
    // The reply's opcode (the request's plus one) is written after the payload decided it.
    let at = out.len + INFO.len();
    let [l0, l1] = left.to_le_bytes();
    out.push(&[INFO[0], INFO[1], 0, 0, l0, l1]);
    let skip = usize::from(p.next) * per;
    let mut w = Window { out, skip, take: per, total: 0 };
    let opcode = payload(p, d, &mut w).unwrap_or(ERROR);
    if let Some(b) = out.buf.get_mut(at) {
        *b = opcode | incomplete;
    }
    p.next += 1;
}
