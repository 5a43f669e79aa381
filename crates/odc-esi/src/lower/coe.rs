//! The PDO configuration objects of a CoE device as its ESI gives them, so that every back-end
//! (checks, generated firmware, the simulator) sees the same dictionary a master reads and
//! writes over CoE:
//!
//! - the objects ETG.1000.6 gives every CoE device with sync managers and an ESI dictionary
//!   may leave out (ETG.2000 does not require them), synthesised from the ESI's `Sm` elements
//!   and PDOs: SOEM's `config_map` and ethercrab ask for 0x1C00, then each process data sync
//!   manager's assignment object, then each assigned PDO's mapping;
//! - writable where the ESI lets a master assign (`CoE@PdoAssign`) or map (`CoE@PdoConfig`, a
//!   PDO not `Fixed`), as a generated `master::PLAN` does in PRE-OP;
//! - the file's own assignment and mapping objects that have no default, started with the
//!   ESI's `Sm` attributes and PDO entries (a note, [`codes::ESI_DEFAULT`], says so; the
//!   file's own sub 0 stays in [`odc_model::ethercat::EtherCat::esi_defaults`]).

use super::*;
use odc_model::Severity;
use odc_model::ethercat::EsiDefault;

/// Completes the PDO configuration objects of `device` (see the module's doc): the file's
/// empty ones filled first, then the missing ones synthesised, then the synthesised ones made
/// writable where the ESI allows it.
pub(super) fn complete_coe(device: &mut Device, ctx: &mut Ctx<'_>) {
    esi_defaults(device, ctx);
    synthesise_coe(device);
    writable(device);
}

/// Adds what `device` lacks of: 0x1C00, the sync managers' communication types (one sub-index
/// per `Sm` element); 0x1C10 + n, the PDO assignment of each outputs or inputs sync manager n
/// that is not virtual, holding [`odc_model::ethercat::default_assignment`]; and the mapping
/// object of each PDO at a CoE mapping index (0x1600–0x17FF, 0x1A00–0x1BFF; an assignment
/// object, or a master, may name any of them). All read-only here, marked
/// [`Origin::CoeImplied`]. Nothing for a device without CoE or without sync managers; objects
/// the dictionary has are kept as the file gives them.
fn synthesise_coe(device: &mut Device) {
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

/// The PDOs a master may assign to sync manager `sm`: those of its direction (outputs carry
/// RxPDOs, inputs TxPDOs) whose `Sm` attribute names it or is absent. ETG.2000's `PdoType`:
/// `@Sm` is the PDO's default sync manager, `@Mandatory` says it must be in one, `@Fixed`
/// that its entries cannot be changed; the ESI lists no other PDOs, and gives no size of
/// 0x1C10 + n. So an assignment object has room for every such PDO (and for its default
/// assignment, should the `Sm` attributes name a PDO of the other direction).
fn assignable(sm: &SyncManager, pdos: &[Pdo]) -> usize {
    let dir = match sm.usage {
        SmUsage::Outputs => Direction::Rx,
        _ => Direction::Tx,
    };
    pdos.iter()
        .filter(|p| p.direction == dir && p.sync_manager.is_none_or(|n| n == sm.number))
        .count()
}

/// The assignment objects (0x1C10 + n) and mapping objects odc synthesised, writable where the
/// ESI says a master may write them (ETG.1000.6 §5.6.7.4: the master writes the assignment and
/// the mapping in PRE-OP when the device supports it; ETG.2000 `Mailbox/CoE@PdoAssign`,
/// `@PdoConfig`; a `Fixed` PDO's mapping stays read-only). A writable assignment object gets
/// room for every PDO a master may assign ([`assignable`]), the extra sub-indexes 0x0000 by
/// default; a mapping object keeps room for its PDO's entries. The runtime refuses such writes
/// outside PRE-OP itself. Objects of the file keep the access it gives them.
fn writable(device: &mut Device) {
    let Some(ec) = device.ethercat.as_deref() else { return };
    let Some(coe) = ec.mailbox.as_ref().and_then(|m| m.coe.as_ref()) else { return };
    let objects = &mut device.objects;
    if coe.pdo_assign {
        for sm in ec.sync_managers.iter().filter(|s| !s.virtual_sm && s.number < 32) {
            if !matches!(sm.usage, SmUsage::Outputs | SmUsage::Inputs) {
                continue;
            }
            let index = 0x1C10 + u16::from(sm.number);
            let Some(o) = objects.get_mut(&index).filter(|o| o.origin.is_esi_synthesised()) else {
                continue;
            };
            let room = assignable(sm, &device.pdos).min(254) as u8;
            for n in 1..=room {
                o.subs.entry(n).or_insert_with(|| {
                    let mut s =
                        SubObject::new(n, sub_index_name(n), DataType::Unsigned16, Access::Rw);
                    s.default = Some(Spanned::synthetic(Value::Unsigned(0)));
                    s
                });
            }
            o.subs.values_mut().for_each(|s| s.access = Access::Rw);
        }
    }
    if coe.pdo_config {
        for pdo in device.pdos.iter().filter(|p| !p.fixed) {
            if let Some(o) = objects
                .get_mut(&pdo.mapping_index)
                .filter(|o| o.origin.is_esi_synthesised() && o.kind == ObjectKind::Record)
            {
                o.subs.values_mut().for_each(|s| s.access = Access::Rw);
            }
        }
    }
}

/// Whether sub-indexes 1..=`count` of `o` exist, each at least `bits` long.
fn has_room(o: &Object, count: u8, bits: u32) -> bool {
    (1..=count).all(|k| o.sub(k).and_then(SubObject::bits).is_some_and(|b| b >= bits))
}

/// Writes `values` into subs 1.. of `o` and their count into sub 0, as odc's (no span).
fn fill(o: &mut Object, values: &[u64]) {
    for (k, &v) in (1..=254u8).zip(values) {
        if let Some(s) = o.subs.get_mut(&k) {
            s.default = Some(Spanned::synthetic(Value::Unsigned(v)));
            s.parameter_value = None;
        }
    }
    if let Some(s0) = o.subs.get_mut(&0) {
        s0.default = Some(Spanned::synthetic(Value::Unsigned(values.len() as u64)));
        s0.parameter_value = None;
    }
}

/// The file's own assignment objects whose sub 0 has no default or 0, and mapping objects
/// whose sub 0 has no default, start with what the ESI's PDO elements say: the default
/// assignment ([`default_assignment`], the PDOs' `Sm` attributes) and the PDO's entries. The
/// PDO elements are the ESI's word on them, and the SII's PDO categories tell a master the
/// same; a device that started empty mapped nothing and met 0x001D at SAFE-OP under SOEM's
/// default bring-up (Weidmüller's UR20-FBC-EC declares 0x16FF with no `Info`; devices with an
/// empty 0x1C12/0x1C13). An object without room for the values (too few or too short subs)
/// keeps the file's default. Each filled object gets a note and an entry in
/// [`EtherCat::esi_defaults`].
fn esi_defaults(device: &mut Device, ctx: &mut Ctx<'_>) {
    let Some(ec) = device.ethercat.as_deref_mut() else { return };
    let objects = &mut device.objects;
    let mut filled = Vec::new();
    for (sm, pdos) in default_assignment(&ec.sync_managers, &device.pdos) {
        let index = 0x1C10 + u16::from(sm);
        let Some(o) = objects.get_mut(&index).filter(|o| o.origin == Origin::File) else {
            continue;
        };
        let Some(s0) = o.sub(0) else { continue };
        let file_count = s0.initial_value().cloned();
        let Ok(count) = u8::try_from(pdos.len()) else { continue };
        if s0.initial_value().and_then(|v| v.value.as_u64()).is_some_and(|n| n != 0)
            || count == 0
            || !has_room(o, count, 16)
        {
            continue;
        }
        let what = match &file_count {
            None => "has no default",
            Some(_) => "is empty by default",
        };
        let list: Vec<String> = pdos.iter().map(|p| format!("0x{p:04X}")).collect();
        ctx.push(
            Diagnostic::new(
                Severity::Note,
                codes::ESI_DEFAULT,
                format!(
                    "0x{index:04X} {what}: the device starts with the PDOs the ESI assigns to SM \
                     {sm} ({})",
                    list.join(", ")
                ),
            )
            .with_label(o.span, "this object"),
        );
        fill(o, &pdos.iter().map(|&p| u64::from(p)).collect::<Vec<_>>());
        filled.push(EsiDefault { index, file_count });
    }
    for pdo in &device.pdos {
        let index = pdo.mapping_index;
        let Some(o) = objects.get_mut(&index).filter(|o| o.origin == Origin::File) else {
            continue;
        };
        if o.sub(0).is_none_or(|s| s.initial_value().is_some()) {
            continue;
        }
        let Ok(count) = u8::try_from(pdo.entries.len()) else { continue };
        if count == 0 || !has_room(o, count, 32) {
            continue;
        }
        ctx.push(
            Diagnostic::new(
                Severity::Note,
                codes::ESI_DEFAULT,
                format!(
                    "0x{index:04X} has no default: the device starts with the {count} entries \
                     of the ESI's PDO 0x{index:04X}"
                ),
            )
            .with_label(o.span, "this object")
            .with_secondary(pdo.span, "the PDO's entries"),
        );
        let values: Vec<u64> = pdo.entries.iter().map(|e| u64::from(e.mapping_value())).collect();
        fill(o, &values);
        filled.push(EsiDefault { index, file_count: None });
    }
    ec.esi_defaults = filled;
}
