//! CompactPDO (CiA 306 §4.5.2): PDO communication and mapping objects that the file leaves out
//! are implied by `NrOfRXPDO`/`NrOfTXPDO` and the `CompactPDO` bits. odc does what lely-core's
//! DCF reader does (`co_dev_parse_cfg`, `co_rpdo_build`, `co_tpdo_build`), so that a file
//! means the same to odc as to the stack that runs it.
//!
//! Only when `CompactPDO` is non-zero, for each direction:
//!
//! - **Which PDOs.** A PDO n (0-based) is *written out* when the file has its communication
//!   object (0x1400+n / 0x1800+n) or its mapping object (0x1600+n / 0x1A00+n). Written-out
//!   PDOs count towards `NrOfRXPDO`/`NrOfTXPDO`; the rest of the count goes to the lowest PDO
//!   numbers that are not written out. So `NrOfRXPDO=3` with `[1400]` and `[1405]` written out
//!   implies one more RPDO, number 1 (0x1401/0x1601).
//! - **What is added.** Every written-out PDO gets the half the file leaves out (a `[1405]`
//!   without `[1605]` gets an implied 0x1605); every implied PDO gets both objects. Objects
//!   the file has are never changed.
//! - **Communication object.** Sub 0 (const UNSIGNED8) is the highest sub-index the bits name;
//!   bit 0 COB-ID (sub 1, UNSIGNED32), bit 1 transmission type (sub 2, UNSIGNED8), bit 2
//!   inhibit time (sub 3, UNSIGNED16), bit 3 the reserved sub 4 (UNSIGNED8), bit 4 event timer
//!   (sub 5, UNSIGNED16), bit 5 SYNC start value (sub 6, UNSIGNED8), all rw. The COB-IDs of
//!   PDOs 1–4 are the CiA 301 predefined ones (`$NODEID+0x200`.. for RPDOs, `$NODEID+0x180`..
//!   for TPDOs), later ones `0x80000000` (not valid). Every other value is 0, the transmission
//!   type too (lely gives it no value, which is 0; odc used to say 0xFF).
//! - **Mapping object.** Sub 0 (rw UNSIGNED8) is 0 (nothing mapped) and the entries 1..=0x40
//!   (rw UNSIGNED32, "Application object n") are 0: room for the 64 entries CiA 301 allows.
//!   They are implied sub-objects ([`odc_model::SubObjects::set_implied`]), made when read.
//!
//! Synthesised objects carry [`Origin::CompactPdo`] and are not written back.

use odc_model::{
    Access, DataType, Device, Object, ObjectKind, Origin, Span, Spanned, SubObject, Value,
};

/// PDO numbers per direction (CiA 301: 0x1400–0x15FF is 512 communication objects).
const MAX_PDOS: u16 = 512;

/// The entries of an implied mapping object (CiA 301 allows 64).
const MAPPING_ENTRIES: u8 = 0x40;

fn sub(i: u8, name: &str, dt: DataType, access: Access, v: Value, span: Span) -> SubObject {
    let mut s = SubObject::new(i, name, dt, access);
    s.default = Some(Spanned::new(v, span));
    s.span = span;
    s
}

fn object(index: u16, name: &str, subs: Vec<SubObject>, span: Span) -> Object {
    let mut object = Object::new(index, name, ObjectKind::Record, span);
    object.subs = subs.into_iter().map(|s| (s.sub_index, s)).collect();
    object.origin = Origin::CompactPdo;
    object
}

/// One direction's object ranges and names.
struct Dir {
    comm_base: u16,
    map_base: u16,
    /// COB-ID of PDO 1 less the node-ID.
    cob_base: i64,
    name: &'static str,
    /// The name of communication sub 4 (lely's).
    sub4: &'static str,
}

const RX: Dir = Dir {
    comm_base: 0x1400,
    map_base: 0x1600,
    cob_base: 0x200,
    name: "RPDO",
    sub4: "Compatibility entry",
};
const TX: Dir =
    Dir { comm_base: 0x1800, map_base: 0x1A00, cob_base: 0x180, name: "TPDO", sub4: "Reserved" };

/// Adds the objects `CompactPDO` implies.
pub(crate) fn synthesise(dev: &mut Device) {
    let Some(bits) = dev.device_info.compact_pdo.as_ref().filter(|b| b.value != 0) else {
        return;
    };
    let (bits, span) = (bits.value, bits.span);
    let rx = dev.device_info.nr_of_rx_pdo.as_ref().map_or(0, |n| n.value);
    let tx = dev.device_info.nr_of_tx_pdo.as_ref().map_or(0, |n| n.value);
    for (count, dir) in [(rx, &RX), (tx, &TX)] {
        let written = |dev: &Device, n: u16| {
            dev.objects.contains_key(&(dir.comm_base + n))
                || dev.objects.contains_key(&(dir.map_base + n))
        };
        let mut implied =
            count.saturating_sub((0..MAX_PDOS).filter(|&n| written(dev, n)).count() as u16);
        for n in 0..MAX_PDOS {
            if !written(dev, n) {
                if implied == 0 {
                    continue;
                }
                implied -= 1;
            }
            add_missing(dev, dir, n, bits, span);
        }
    }
}

/// Adds PDO `n`'s communication and mapping objects where the file has none.
fn add_missing(dev: &mut Device, dir: &Dir, n: u16, bits: u8, span: Span) {
    let comm = dir.comm_base + n;
    if let std::collections::btree_map::Entry::Vacant(slot) = dev.objects.entry(comm) {
        let (u8t, u16t) = (DataType::Unsigned8, DataType::Unsigned16);
        let cob = if n < 4 {
            Value::NodeIdPlus(dir.cob_base + 0x100 * i64::from(n))
        } else {
            Value::Unsigned(0x8000_0000)
        };
        let cob_name = format!("COB-ID used by {}", dir.name);
        let named: [(u8, &str, DataType, Value); 6] = [
            (1, &cob_name, DataType::Unsigned32, cob),
            (2, "Transmission type", u8t, Value::Unsigned(0)),
            (3, "Inhibit time", u16t, Value::Unsigned(0)),
            (4, dir.sub4, u8t, Value::Unsigned(0)),
            (5, "Event timer", u16t, Value::Unsigned(0)),
            (6, "SYNC start value", u8t, Value::Unsigned(0)),
        ];
        let mut subs: Vec<SubObject> = named
            .into_iter()
            .filter(|(i, ..)| bits & (1 << (i - 1)) != 0)
            .map(|(i, name, dt, v)| sub(i, name, dt, Access::Rw, v, span))
            .collect();
        let highest = subs.last().map_or(0, |s| s.sub_index);
        subs.insert(
            0,
            sub(
                0,
                "Highest sub-index supported",
                u8t,
                Access::Const,
                Value::Unsigned(u64::from(highest)),
                span,
            ),
        );
        slot.insert(object(comm, &format!("{} communication parameter", dir.name), subs, span));
    }
    let map = dir.map_base + n;
    if let std::collections::btree_map::Entry::Vacant(slot) = dev.objects.entry(map) {
        let sub0 = sub(
            0,
            "Highest sub-index supported",
            DataType::Unsigned8,
            Access::Rw,
            Value::Unsigned(0),
            span,
        );
        let mut o = object(map, &format!("{} mapping parameter", dir.name), vec![sub0], span);
        let entry = sub(1, "", DataType::Unsigned32, Access::Rw, Value::Unsigned(0), span);
        o.subs.set_implied(entry, MAPPING_ENTRIES, "Application object ");
        slot.insert(o);
    }
}
