//! The objects ETG.1000.6 gives every CoE device with sync managers and an ESI dictionary may
//! leave out (ETG.2000 does not require them), synthesised from the ESI's `Sm` elements and
//! PDOs so that every back-end (checks, generated firmware, the simulator) sees the same
//! dictionary a master reads over CoE: SOEM's `config_map` and ethercrab ask for 0x1C00, then
//! each process data sync manager's assignment object, then each assigned PDO's mapping.

use super::*;

/// Adds what `device` lacks of: 0x1C00, the sync managers' communication types (one sub-index
/// per `Sm` element); 0x1C10 + n, the PDO assignment of each outputs or inputs sync manager n
/// that is not virtual, holding [`odc_model::ethercat::default_assignment`]; and the mapping
/// object of each PDO at a CoE mapping index (0x1600–0x17FF, 0x1A00–0x1BFF; an assignment
/// object, or a master, may name any of them). All
/// read-only, marked [`Origin::CoeImplied`]. Nothing for a device without CoE or without sync
/// managers; objects the dictionary has are kept as the file gives them.
pub(super) fn complete_coe(device: &mut Device) {
    let Some(ec) = device.ethercat.as_deref() else { return };
    let coe = ec.mailbox.as_ref().is_some_and(|m| m.coe.is_some());
    if !coe || ec.sync_managers.is_empty() {
        return;
    }
    let sms = &ec.sync_managers;
    let objects = &mut device.objects;
    objects.entry(0x1C00).or_insert_with(|| {
        let types = sms.iter().map(|sm| u64::from(sm.usage.communication_type()));
        array(0x1C00, "Sync manager communication type", DataType::Unsigned8, types)
    });
    let assignment = default_assignment(sms, &device.pdos);
    for sm in sms.iter().filter(|s| matches!(s.usage, SmUsage::Outputs | SmUsage::Inputs)) {
        // 0x1C10..=0x1C2F: ETG.1000.6 has assignment objects for sync managers 0 to 31.
        if sm.virtual_sm || sm.number >= 32 {
            continue;
        }
        let index = 0x1C10 + u16::from(sm.number);
        objects.entry(index).or_insert_with(|| {
            let pdos = assignment.get(&sm.number).into_iter().flatten().map(|&p| u64::from(p));
            let name = format!("Sync manager {} PDO assignment", sm.number);
            array(index, &name, DataType::Unsigned16, pdos)
        });
    }
    // CoE's mapping objects only: a PDO index elsewhere is no CoE object (a SoE drive's IDN).
    let coe_mapping = |i: u16| matches!(i, 0x1600..=0x17FF | 0x1A00..=0x1BFF);
    for pdo in device.pdos.iter().filter(|p| coe_mapping(p.mapping_index)) {
        objects.entry(pdo.mapping_index).or_insert_with(|| mapping_object(pdo, Origin::CoeImplied));
    }
}

/// A read-only ARRAY of `values` (at most 254: sub-indexes 1..=254) with its count in sub 0.
fn array(index: u16, name: &str, ty: DataType, values: impl Iterator<Item = u64>) -> Object {
    let mut object = Object {
        origin: Origin::CoeImplied,
        ..Object::new(index, name, ObjectKind::Array, Span::DUMMY)
    };
    for (n, v) in (1..=254u8).zip(values) {
        let mut s = SubObject::new(n, sub_index_name(n), ty, Access::Ro);
        s.default = Some(Spanned::synthetic(Value::Unsigned(v)));
        object.subs.insert(n, s);
    }
    let count = object.subs.len() as u64;
    let mut s0 = SubObject::new(0, "SubIndex 000", DataType::Unsigned8, Access::Ro);
    s0.default = Some(Spanned::synthetic(Value::Unsigned(count)));
    object.subs.insert(0, s0);
    object
}
