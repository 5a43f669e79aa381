//! What only EtherCAT has: PDOs with their sync managers, init commands, mailbox, distributed
//! clocks and slots.

use super::*;

pub(super) fn lower_pdos<'t>(
    parent: Element<'t>,
    ctx: &mut Ctx<'_>,
    types: &Types<'t>,
    refs: &PdoRefs<'t>,
    attributes: &mut Vec<PdoAttributes>,
) -> Vec<Pdo> {
    let mut pdos = Vec::new();
    for pdo_el in parent.children() {
        let direction = match pdo_el.name() {
            "RxPdo" => Direction::Rx,
            "TxPdo" => Direction::Tx,
            _ => continue,
        };
        // The definition: the element itself, or the `Pdo` its `Ref` names (old files).
        let c = match pdo_el.attr("Ref") {
            Some(r) if pdo_el.child("Index").is_none() => match refs.get(trim(r.value)) {
                Some(def) => *def,
                None => {
                    ctx.push(
                        Diagnostic::error(
                            codes::MISSING_ELEMENT,
                            format!("no `Pdo` with RefName `{}`", r.value),
                        )
                        .with_label(r.span, "referred to here"),
                    );
                    continue;
                }
            },
            _ => pdo_el,
        };
        let Some(index_el) = c.child("Index") else {
            ctx.missing(c, "Index");
            continue;
        };
        let Some(mapping_index) = ctx.el_num::<u16>(index_el, "PDO index") else { continue };
        // Entries are rarely skipped: sized to the elements, no regrowth copies.
        let mut entries = Vec::with_capacity(c.children_named("Entry").count());
        for e in c.children_named("Entry") {
            let [ie, sub, bl, dt_el, name] =
                e.pick(["Index", "SubIndex", "BitLen", "DataType", "Name"]);
            let Some(ie) = ie else {
                ctx.missing(e, "Index");
                continue;
            };
            let Some(index) = ctx.el_num::<u16>(ie, "entry index") else { continue };
            let sub = ctx.opt_num::<u8>(sub, "entry sub-index");
            let Some(bl) = bl else {
                ctx.missing(e, "BitLen");
                continue;
            };
            let Some(bits) = ctx.el_num::<u16>(bl, "BitLen") else { continue };
            let dt_el = dt_el.filter(|t| !t.text().is_empty());
            let data_type = dt_el.and_then(|t| match types.resolve(t.text()) {
                Some(Resolved::Simple(ty, _)) => Some(ty),
                Some(Resolved::Array(..) | Resolved::Struct(..)) => Some(DataType::Domain),
                None => {
                    unknown_type(t.text(), t.text_span(), ctx, false);
                    None
                }
            });
            entries.push(PdoEntry {
                index,
                sub: sub.unwrap_or(0),
                bits,
                name: name.map(|n| n.text().to_string()).filter(|n| !n.is_empty()),
                data_type,
                span: e.span(),
            });
        }
        let extra = PdoAttributes {
            index: mapping_index,
            rx: direction == Direction::Rx,
            virtual_pdo: ctx.attr_bool(pdo_el, "Virtual").unwrap_or(false),
            os_fac: ctx.attr_u32(pdo_el, "OSFac"),
            os_min: ctx.attr_u32(pdo_el, "OSMin"),
            os_max: ctx.attr_u32(pdo_el, "OSMax"),
            os_index_inc: ctx.attr_u32(pdo_el, "OSIndexInc"),
            span: pdo_el.span(),
        };
        if extra.virtual_pdo
            || extra.os_fac.is_some()
            || extra.os_min.is_some()
            || extra.os_max.is_some()
            || extra.os_index_inc.is_some()
        {
            attributes.push(extra);
        }
        pdos.push(Pdo {
            direction,
            mapping_index,
            comm_index: None,
            name: first_name(c),
            cob_id: None,
            transmission_type: None,
            inhibit_time: None,
            event_timer: None,
            sync_start: None,
            entries,
            sync_manager: ctx.attr_num(pdo_el, "Sm"),
            fixed: ctx.attr_bool(pdo_el, "Fixed").unwrap_or(false),
            mandatory: ctx.attr_bool(pdo_el, "Mandatory").unwrap_or(false),
            excludes: c
                .children_named("Exclude")
                .filter_map(|x| ctx.el_num::<u16>(x, "Exclude"))
                .collect(),
            span: pdo_el.span(),
        });
    }
    pdos
}

/// The state transitions of ETG.2000's `TransitionType`: INIT, PRE-OP, SAFE-OP, OP and BOOT
/// pairs.
const TRANSITIONS: &[&str] =
    &["IP", "PI", "PS", "SP", "SO", "OS", "OP", "PO", "SI", "OI", "IB", "BI", "II", "PP", "SS"];

pub(super) fn init_cmd(c: Element<'_>, ctx: &mut Ctx<'_>) -> InitCmd {
    let mut transitions = Vec::new();
    for t in c.children_named("Transition") {
        if !TRANSITIONS.contains(&t.text().trim()) {
            ctx.push(
                Diagnostic::warning(
                    codes::UNKNOWN_TRANSITION,
                    format!("`{}` is not a state transition", t.text()),
                )
                .with_label(t.text_span(), "expected IP, PS, SO, SP, OS, ... (ETG.2000)"),
            );
        }
        transitions.push(t.text().to_string());
    }
    if transitions.is_empty() {
        ctx.missing(c, "Transition");
    }
    InitCmd {
        transitions,
        index: c
            .child("Index")
            .or_else(|| c.child("IDN"))
            .or_else(|| c.child("Type"))
            .and_then(|i| ctx.el_u32(i, "InitCmd index")),
        sub_index: ctx.child_u32(c, "SubIndex"),
        data: c.child("Data").map(|d| ctx.hex(d)).unwrap_or_default(),
        comment: c.child("Comment").map(|t| t.text().to_string()),
        complete_access: ctx.attr_bool(c, "CompleteAccess").unwrap_or(false),
        fixed: ctx.attr_bool(c, "Fixed").unwrap_or(false),
        span: c.span(),
    }
}

pub(super) fn mailbox(mb: Element<'_>, ctx: &mut Ctx<'_>) -> Mailbox {
    let mut m = Mailbox {
        data_link_layer: ctx.attr_bool(mb, "DataLinkLayer").unwrap_or(false),
        span: mb.span(),
        ..Mailbox::default()
    };
    if let Some(c) = mb.child("CoE") {
        m.coe = Some(CoE {
            sdo_info: ctx.attr_bool(c, "SdoInfo").unwrap_or(false),
            pdo_assign: ctx.attr_bool(c, "PdoAssign").unwrap_or(false),
            pdo_config: ctx.attr_bool(c, "PdoConfig").unwrap_or(false),
            pdo_upload: ctx.attr_bool(c, "PdoUpload").unwrap_or(false),
            complete_access: ctx.attr_bool(c, "CompleteAccess").unwrap_or(false),
            segmented_sdo: ctx.attr_bool(c, "SegmentedSdo").unwrap_or(false),
            eds_file: c.attr("EdsFile").map(|a| a.value.to_string()),
            init_cmds: c.children_named("InitCmd").map(|i| init_cmd(i, ctx)).collect(),
        });
    }
    if let Some(s) = mb.child("SoE") {
        m.soe = Some(SoE {
            channel_count: ctx.attr_u32(s, "ChannelCount"),
            init_cmds: s.children_named("InitCmd").map(|i| init_cmd(i, ctx)).collect(),
        });
    }
    m.foe = mb.child("FoE").is_some();
    m.eoe = mb.child("EoE").is_some();
    m.aoe = mb.child("AoE").is_some();
    for (name, out) in [("EoE", &mut m.eoe_init_cmds), ("AoE", &mut m.aoe_init_cmds)] {
        if let Some(p) = mb.child(name) {
            *out = p.children_named("InitCmd").map(|i| init_cmd(i, ctx)).collect();
        }
    }
    m.voe = mb.child("VoE").is_some();
    m
}

pub(super) fn lower_dc(dc: Element<'_>, ctx: &mut Ctx<'_>) -> Dc {
    let mut out = Dc { span: dc.span(), ..Dc::default() };
    for o in dc.children_named("OpMode") {
        let factor = |name: &str, ctx: &mut Ctx<'_>| -> Option<i64> {
            o.child(name).and_then(|e| ctx.attr_num::<i64>(e, "Factor"))
        };
        out.op_modes.push(DcOpMode {
            name: o.child("Name").map(|n| n.text().to_string()).unwrap_or_default(),
            desc: o.child("Desc").map(|n| n.text().to_string()),
            assign_activate: ctx.child_u32(o, "AssignActivate"),
            cycle_time_sync0: ctx.child_u32(o, "CycleTimeSync0"),
            cycle_time_sync0_factor: factor("CycleTimeSync0", ctx),
            shift_time_sync0: ctx.child_num(o, "ShiftTimeSync0"),
            shift_time_sync0_factor: factor("ShiftTimeSync0", ctx),
            cycle_time_sync1: ctx.child_u32(o, "CycleTimeSync1"),
            cycle_time_sync1_factor: factor("CycleTimeSync1", ctx),
            shift_time_sync1: ctx.child_num(o, "ShiftTimeSync1"),
            shift_time_sync1_factor: factor("ShiftTimeSync1", ctx),
            sms: o.children_named("Sm").filter_map(|sm| sm_assignment(sm, ctx)).collect(),
            span: o.span(),
        });
    }
    out
}

/// An `Sm No=` with its `Pdo`s (DC op-modes, alternative mappings); `None` without a
/// readable `No`.
fn sm_assignment(sm: Element<'_>, ctx: &mut Ctx<'_>) -> Option<SmAssignment> {
    let Some(number) = ctx.attr_num::<u8>(sm, "No") else {
        if sm.attr("No").is_none() {
            ctx.missing(sm, "No");
        }
        return None;
    };
    // An empty `<Pdo/>` (Beckhoff writes one) assigns nothing: the sync manager stays empty.
    let pdos = sm
        .children_named("Pdo")
        .filter(|p| !p.text().trim().is_empty())
        .filter_map(|p| Some((ctx.el_num::<u16>(p, "PDO index")?, ctx.attr_u32(p, "OSFac"))))
        .collect();
    Some(SmAssignment { number, sync_type: ctx.child_u32(sm, "SyncType"), pdos, span: sm.span() })
}

/// Beckhoff's `Info/VendorSpecific/TwinCAT/AlternativeSmMapping`s.
pub(super) fn alternative_sm_mappings(
    info: Element<'_>,
    ctx: &mut Ctx<'_>,
) -> Vec<AlternativeSmMapping> {
    let mut out = Vec::new();
    for vs in info.children_named("VendorSpecific") {
        for tc in vs.children_named("TwinCAT") {
            for m in tc.children_named("AlternativeSmMapping") {
                out.push(AlternativeSmMapping {
                    name: m.child("Name").map(|n| n.text().to_string()).unwrap_or_default(),
                    // Beckhoff writes `Default=""` for "not the default".
                    default: m.attr("Default").is_some_and(|a| !a.value.trim().is_empty())
                        && ctx.attr_bool(m, "Default").unwrap_or(false),
                    sms: m.children_named("Sm").filter_map(|sm| sm_assignment(sm, ctx)).collect(),
                    span: m.span(),
                });
            }
        }
    }
    out
}

pub(super) fn lower_slots(s: Element<'_>, ctx: &mut Ctx<'_>) -> Slots {
    let mut out = Slots {
        slot_index_increment: ctx.attr_u32(s, "SlotIndexIncrement"),
        slot_pdo_increment: ctx.attr_u32(s, "SlotPdoIncrement"),
        max_slot_count: ctx.attr_u32(s, "MaxSlotCount"),
        span: s.span(),
        ..Slots::default()
    };
    for slot in s.children_named("Slot") {
        let mut sl = Slot {
            name: first_name(slot),
            min_instances: ctx.attr_u32(slot, "MinInstances"),
            max_instances: ctx.attr_u32(slot, "MaxInstances"),
            slot_index_increment: ctx.attr_u32(slot, "SlotIndexIncrement"),
            slot_pdo_increment: ctx.attr_u32(slot, "SlotPdoIncrement"),
            span: slot.span(),
            ..Slot::default()
        };
        for mi in slot.children_named("ModuleIdent") {
            if let Some(v) = ctx.el_u32(mi, "ModuleIdent") {
                sl.module_idents.push(v);
                if ctx.attr_bool(mi, "Default") == Some(true) {
                    sl.default_module = Some(v);
                }
            }
        }
        sl.module_classes =
            slot.children_named("ModuleClass").map(|c| c.text().to_string()).collect();
        out.slots.push(sl);
    }
    out
}
