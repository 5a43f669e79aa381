//! CompactPDO (CiA 306 §4.5.2, as lely reads it): PDO communication and mapping objects that
//! the file leaves out are implied by `NrOfRXPDO`/`NrOfTXPDO` and the `CompactPDO` bits.
//!
//! Only when `CompactPDO` is non-zero: for each of the first `NrOfRXPDO` receive PDOs (and
//! `NrOfTXPDO` transmit PDOs) whose communication object (0x1400+n / 0x1800+n) is absent, one
//! is synthesised with the sub-objects the bits name: bit 0 COB-ID (sub 1), bit 1 transmission
//! type (sub 2), bit 2 inhibit time (sub 3), bit 3 the reserved sub 4, bit 4 event timer
//! (sub 5), bit 5 SYNC start value (sub 6); sub 0 (highest sub-index) always. COB-IDs of the
//! first four PDOs are the CiA 301 predefined ones (`$NODEID+0x200`.. for RPDOs,
//! `$NODEID+0x180`.. for TPDOs), later ones are `0x80000000` (invalid). The transmission type
//! defaults to 0xFF, the others to 0. An absent mapping object (0x1600+n / 0x1A00+n) is
//! synthesised with sub 0 = 0 and eight empty (0) entries. Synthesised objects carry
//! [`Origin::CompactPdo`] and are not written back.

use odc_model::{
    Access, DataType, Device, Object, ObjectKind, Origin, Span, Spanned, SubObject, Value,
};

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

/// Adds the objects `CompactPDO` implies.
pub(crate) fn synthesise(dev: &mut Device) {
    let Some(bits) = dev.device_info.compact_pdo.as_ref().filter(|b| b.value != 0) else {
        return;
    };
    let (bits, span) = (bits.value, bits.span);
    let rx = dev.device_info.nr_of_rx_pdo.as_ref().map_or(0, |n| n.value);
    let tx = dev.device_info.nr_of_tx_pdo.as_ref().map_or(0, |n| n.value);
    for (count, comm_base, map_base, cob_base, dir) in
        [(rx, 0x1400u16, 0x1600u16, 0x200i64, "RPDO"), (tx, 0x1800, 0x1A00, 0x180, "TPDO")]
    {
        for n in 0..count.min(0x200) {
            let comm = comm_base + n;
            if let std::collections::btree_map::Entry::Vacant(slot) = dev.objects.entry(comm) {
                let mut subs = Vec::new();
                let u8t = DataType::Unsigned8;
                let u16t = DataType::Unsigned16;
                if bits & 0x01 != 0 {
                    let cob = if n < 4 {
                        Value::NodeIdPlus(cob_base + 0x100 * i64::from(n))
                    } else {
                        Value::Unsigned(0x8000_0000)
                    };
                    subs.push(sub(
                        1,
                        &format!("COB-ID used by {dir}"),
                        DataType::Unsigned32,
                        Access::Rw,
                        cob,
                        span,
                    ));
                }
                if bits & 0x02 != 0 {
                    subs.push(sub(
                        2,
                        "Transmission type",
                        u8t,
                        Access::Rw,
                        Value::Unsigned(0xFF),
                        span,
                    ));
                }
                if bits & 0x04 != 0 {
                    subs.push(sub(3, "Inhibit time", u16t, Access::Rw, Value::Unsigned(0), span));
                }
                if bits & 0x08 != 0 {
                    subs.push(sub(
                        4,
                        "Compatibility entry",
                        u8t,
                        Access::Rw,
                        Value::Unsigned(0),
                        span,
                    ));
                }
                if bits & 0x10 != 0 {
                    subs.push(sub(5, "Event timer", u16t, Access::Rw, Value::Unsigned(0), span));
                }
                if bits & 0x20 != 0 {
                    subs.push(sub(
                        6,
                        "SYNC start value",
                        u8t,
                        Access::Rw,
                        Value::Unsigned(0),
                        span,
                    ));
                }
                let highest = subs.iter().map(|s| s.sub_index).max().unwrap_or(0);
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
                let name = format!("{dir} communication parameter");
                slot.insert(object(comm, &name, subs, span));
            }
            let map = map_base + n;
            if let std::collections::btree_map::Entry::Vacant(slot) = dev.objects.entry(map) {
                let mut subs = vec![sub(
                    0,
                    "Number of mapped application objects in PDO",
                    DataType::Unsigned8,
                    Access::Rw,
                    Value::Unsigned(0),
                    span,
                )];
                for i in 1..=8u8 {
                    subs.push(sub(
                        i,
                        &format!("Application object {i}"),
                        DataType::Unsigned32,
                        Access::Rw,
                        Value::Unsigned(0),
                        span,
                    ));
                }
                let name = format!("{dir} mapping parameter");
                slot.insert(object(map, &name, subs, span));
            }
        }
    }
}
