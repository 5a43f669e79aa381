//! T601–T618: EtherCAT devices (ETG.2000 ESI, ETG.1000 data link and application layer).
//!
//! The PDO rules mirror the CANopen ones (C301–C303) on the `<RxPdo>`/`<TxPdo>` elements; the
//! others check what only an ESI has: sync managers (`<Sm>`), the default PDO assignment (the
//! PDOs' `Sm` attributes and the objects 0x1C10–0x1C2F), `Exclude` relations, the mailbox and
//! the distributed-clock operation modes (`<Dc><OpMode>`). They run only on devices read from
//! an ESI.
//!
//! Sync manager n is the n-th `<Sm>` element; its assignment object is 0x1C10 + n (0x1C12 for
//! SM 2, 0x1C13 for SM 3). The default PDO set of a sync manager is the PDOs whose `Sm`
//! attribute names it (ETG.2000: "if set, the PDO is included in the process image").

use std::collections::BTreeSet;

use odc_model::ethercat::{EtherCat, SmUsage, SyncManager};
use odc_model::{Device, Direction, Label, Origin, Pdo, Span, SubObject};

use super::rule;
use crate::Ctx;
use crate::util::{first_span, idx, initial_u64, is_esi};

/// The EtherCAT part of an ESI device.
fn ec(dev: &Device) -> Option<&EtherCat> {
    if is_esi(dev) { dev.ethercat.as_deref() } else { None }
}

/// Whether the ESI has a dictionary of its own (not one synthesised from the PDO entries).
fn has_dictionary(dev: &Device) -> bool {
    is_esi(dev) && dev.objects.values().any(|o| o.origin != Origin::PdoEntry)
}

fn pdo_kind(p: &Pdo) -> &'static str {
    match p.direction {
        Direction::Rx => "RxPdo",
        Direction::Tx => "TxPdo",
    }
}

/// `RxPdo 0x1600`.
fn pdo_name(p: &Pdo) -> String {
    format!("{} {}", pdo_kind(p), idx(p.mapping_index))
}

/// The sync-manager type that carries PDOs of a direction.
fn usage_for(dir: Direction) -> SmUsage {
    match dir {
        Direction::Rx => SmUsage::Outputs,
        Direction::Tx => SmUsage::Inputs,
    }
}

/// The PDO direction a sync manager carries, if it carries process data.
fn direction_of(usage: &SmUsage) -> Option<Direction> {
    match usage {
        SmUsage::Outputs => Some(Direction::Rx),
        SmUsage::Inputs => Some(Direction::Tx),
        _ => None,
    }
}

fn usage_name(u: &SmUsage) -> &str {
    match u {
        SmUsage::MBoxOut => "MBoxOut",
        SmUsage::MBoxIn => "MBoxIn",
        SmUsage::Outputs => "Outputs",
        SmUsage::Inputs => "Inputs",
        SmUsage::MBoxState => "MBoxState",
        SmUsage::Other(t) if t.is_empty() => "(no type)",
        SmUsage::Other(t) => t,
    }
}

/// Whether a sync manager can carry PDOs of `dir`: by its type, or, when the type is not one
/// ETG.2000 defines (IgH's `ethercat xml` writes none, some vendors their own names), by the
/// direction bits of its ControlByte (bits 2–3: 01 the master writes, 00 it reads).
fn carries(sm: &SyncManager, dir: Direction) -> bool {
    match (&sm.usage, sm.control_byte.as_ref()) {
        (SmUsage::Other(_), Some(cb)) => (cb.value >> 2) & 0x3 == u8::from(dir == Direction::Rx),
        (SmUsage::Other(_), None) => true,
        (usage, _) => direction_of(usage) == Some(dir),
    }
}

fn is_mailbox(u: &SmUsage) -> bool {
    matches!(u, SmUsage::MBoxOut | SmUsage::MBoxIn)
}

/// The PDOs the device assigns to sync manager `sm` by default, in file order.
fn assigned(dev: &Device, sm: u8) -> impl Iterator<Item = &Pdo> {
    dev.pdos.iter().filter(move |p| p.sync_manager == Some(sm))
}

/// The bytes the default PDOs of `sm` occupy (bit-packed, rounded up to whole bytes).
fn assigned_bytes(dev: &Device, sm: u8) -> u64 {
    assigned(dev, sm).map(|p| u64::from(p.bits())).sum::<u64>().div_ceil(8)
}

/// Every PDO index the file defines: the device's and its modules'.
fn all_pdo_indexes(dev: &Device, ec: &EtherCat) -> BTreeSet<u16> {
    dev.pdos
        .iter()
        .chain(ec.modules.iter().flat_map(|m| m.pdos.iter()))
        .map(|p| p.mapping_index)
        .collect()
}

/// Whether the device has modules or slots: PDO indexes then also come from modules and are
/// shifted per slot, so an index the device does not define may still be right.
fn is_modular(ec: &EtherCat) -> bool {
    ec.slots.is_some() || !ec.modules.is_empty()
}

rule!(
    T601,
    "T601",
    "esi-pdo-entry-not-in-dictionary",
    "etg",
    Warning,
    Warn,
    pdo_entry_not_in_dictionary,
    "an ESI PDO entry names an object the dictionary does not have",
    "An <Entry> of an <RxPdo>/<TxPdo> maps object Index:SubIndex of the device's CoE \
     dictionary (ETG.2000 PdoType). When the ESI has a dictionary (<Profile><Dictionary>) but \
     not that object, a master that configures the mapping over CoE (0x1600/0x1A00 writes) gets \
     an SDO abort, and generated code cannot type the entry from the dictionary. Devices without \
     a dictionary are not checked (their objects are synthesised from the PDO entries). Fix: add \
     the object to the dictionary or correct the entry."
);

fn pdo_entry_not_in_dictionary(dev: &Device, ctx: &mut Ctx) {
    if !has_dictionary(dev) {
        return;
    }
    for p in &dev.pdos {
        for e in p.entries.iter().filter(|e| !e.is_gap()) {
            if dev.sub(e.index, e.sub).is_none() {
                ctx.report(
                    p.mapping_index,
                    None,
                    first_span([e.span, p.span]),
                    format!(
                        "PDO {} maps 0x{:04X}:{:02X}, which the dictionary does not have",
                        idx(p.mapping_index),
                        e.index,
                        e.sub
                    ),
                );
            }
        }
    }
}

rule!(
    T602,
    "T602",
    "esi-pdo-entry-bit-length",
    "etg",
    Warning,
    Warn,
    pdo_entry_bit_length,
    "an ESI PDO entry's BitLen differs from the dictionary object's size",
    "The BitLen of a PDO <Entry> must equal the BitSize of the object it maps (ETG.2000; \
     ETG.1000.6 PDO mapping). When they differ, the process image the master computes from the \
     ESI and the one the device builds from its dictionary disagree, and every later entry of \
     the PDO is read at the wrong offset. Fix: correct BitLen or the object's BitSize."
);

fn pdo_entry_bit_length(dev: &Device, ctx: &mut Ctx) {
    if !is_esi(dev) {
        return;
    }
    for p in &dev.pdos {
        for e in p.entries.iter().filter(|e| !e.is_gap()) {
            let Some(bits) = dev.sub(e.index, e.sub).and_then(SubObject::bits) else { continue };
            if u32::from(e.bits) != bits {
                ctx.report(
                    p.mapping_index,
                    None,
                    first_span([e.span, p.span]),
                    format!(
                        "PDO {} maps 0x{:04X}:{:02X} with BitLen {} but the object has {bits} bits",
                        idx(p.mapping_index),
                        e.index,
                        e.sub,
                        e.bits
                    ),
                );
            }
        }
    }
}

rule!(
    T603,
    "T603",
    "esi-pdo-entry-direction",
    "etg",
    Warning,
    Warn,
    pdo_entry_direction,
    "an ESI PDO maps an object whose PdoMapping flag does not allow that direction",
    "Objects of a CoE dictionary say in <Flags><PdoMapping> whether they may be mapped into an \
     RxPDO (R), a TxPDO (T) or both (RT); without the flag they are not mappable (ETG.2000 \
     ObjectType Flags, ETG.1000.6 §5.6.7.4). A device refuses to map such an object when the \
     master writes the mapping (SDO abort 0x06040041 \"object cannot be mapped into the PDO\"), \
     and the object's access (a read-only object in an RxPdo) usually shows the entry is in the \
     wrong PDO. Devices without a dictionary are not checked. Fix: set the PdoMapping flag, or \
     move the entry to a PDO of the other direction."
);

fn pdo_entry_direction(dev: &Device, ctx: &mut Ctx) {
    if !has_dictionary(dev) {
        return;
    }
    for p in dev.pdos.iter().filter(|p| !p.fixed) {
        for e in p.entries.iter().filter(|e| !e.is_gap()) {
            let Some(s) = dev.sub(e.index, e.sub) else { continue };
            if s.pdo_mapping.allows(s.access, p.direction) {
                continue;
            }
            let why = if s.pdo_mapping.is_mappable() {
                format!("its PdoMapping flag only allows {:?} PDOs", s.pdo_mapping)
            } else {
                "it has no PdoMapping flag".to_string()
            };
            ctx.report(
                p.mapping_index,
                None,
                first_span([e.span, p.span]),
                format!("{} maps 0x{:04X}:{:02X} but {why}", pdo_name(p), e.index, e.sub),
            )
            .labels
            .push(Label {
                span: s.span,
                message: "object defined here".into(),
                primary: false,
            });
        }
    }
}

rule!(
    T604,
    "T604",
    "esi-pdo-sync-manager",
    "etg",
    Error,
    Deny,
    pdo_sync_manager,
    "a PDO's Sm attribute names a sync manager that does not exist or carries the other direction",
    "The Sm attribute of an <RxPdo>/<TxPdo> names the sync manager (the n-th <Sm> element) the \
     PDO is assigned to by default. RxPDOs (outputs of the master) go into a sync manager of type \
     Outputs, TxPDOs into one of type Inputs (ETG.2000; ETG.1000.4 sync manager). A PDO assigned \
     to a mailbox or to a missing sync manager cannot be exchanged: the device answers the \
     configuration with AL status 0x001D/0x001E (invalid output/input configuration). Fix: \
     correct the Sm attribute or the <Sm> element's type."
);

fn pdo_sync_manager(dev: &Device, ctx: &mut Ctx) {
    let Some(ec) = ec(dev) else { return };
    if ec.sync_managers.is_empty() {
        return;
    }
    for p in &dev.pdos {
        let Some(n) = p.sync_manager else { continue };
        let want = usage_for(p.direction);
        let problem = match ec.sync_managers.get(usize::from(n)) {
            None => format!(
                "{} is assigned to SM {n}, but the device describes only SM 0..={}",
                pdo_name(p),
                // Not empty: checked above.
                ec.sync_managers.len() - 1
            ),
            Some(sm) if !carries(sm, p.direction) => format!(
                "{} is assigned to SM {n}, which is of type {}, not {}",
                pdo_name(p),
                usage_name(&sm.usage),
                usage_name(&want)
            ),
            Some(_) => continue,
        };
        let d = ctx.report(p.mapping_index, None, p.span, problem);
        if let Some(sm) = ec.sync_managers.get(usize::from(n)) {
            d.labels.push(Label {
                span: sm.span,
                message: format!("SM {n} defined here"),
                primary: false,
            });
        }
    }
}

rule!(
    T605,
    "T605",
    "esi-sm-pdo-size",
    "etg",
    Error,
    Deny,
    sm_pdo_size,
    "the default PDOs of a sync manager do not fit its MinSize..MaxSize",
    "A process-data sync manager is as long as the PDOs assigned to it (their bits packed, \
     rounded up to bytes). <Sm MinSize MaxSize> bound that length (ETG.2000); the ESC area \
     behind it is no larger. When the default PDO set (the PDOs whose Sm attribute names the \
     sync manager) is longer than MaxSize or shorter than MinSize, a master that uses the \
     defaults configures a length the device refuses (AL status 0x001D/0x001E invalid \
     output/input configuration). Fix: correct MinSize/MaxSize, or the PDOs' Sm attributes."
);

fn sm_pdo_size(dev: &Device, ctx: &mut Ctx) {
    let Some(ec) = ec(dev) else { return };
    for sm in &ec.sync_managers {
        if direction_of(&sm.usage).is_none() || assigned(dev, sm.number).next().is_none() {
            continue;
        }
        let bytes = assigned_bytes(dev, sm.number);
        let n = sm.number;
        let problem = match (sm.min_size, sm.max_size) {
            (_, Some(max)) if bytes > u64::from(max) => format!(
                "the default PDOs of SM {n} ({}) take {bytes} bytes; MaxSize is {max}",
                usage_name(&sm.usage)
            ),
            (Some(min), _) if bytes < u64::from(min) => format!(
                "the default PDOs of SM {n} ({}) take {bytes} bytes; MinSize is {min}",
                usage_name(&sm.usage)
            ),
            _ => continue,
        };
        ctx.report_device(sm.span, problem);
    }
}

rule!(
    T606,
    "T606",
    "esi-sm-size-range",
    "etg",
    Error,
    Deny,
    sm_size_range,
    "a sync manager's MinSize, DefaultSize and MaxSize are not in order",
    "<Sm MinSize DefaultSize MaxSize> give the smallest, the default and the largest length of \
     a sync manager in bytes (ETG.2000); they must satisfy MinSize ≤ DefaultSize ≤ MaxSize. \
     A master takes the default for mailboxes and checks process-data lengths against the \
     bounds, so inverted bounds make every length invalid. Fix: correct the attributes."
);

fn sm_size_range(dev: &Device, ctx: &mut Ctx) {
    let Some(ec) = ec(dev) else { return };
    for sm in &ec.sync_managers {
        let n = sm.number;
        let problem = match (sm.min_size, sm.default_size, sm.max_size) {
            (Some(min), _, Some(max)) if min > max => {
                format!("SM {n}: MinSize {min} is larger than MaxSize {max}")
            }
            (Some(min), Some(def), _) if def < min => {
                format!("SM {n}: DefaultSize {def} is smaller than MinSize {min}")
            }
            (_, Some(def), Some(max)) if def > max => {
                format!("SM {n}: DefaultSize {def} is larger than MaxSize {max}")
            }
            _ => continue,
        };
        ctx.report_device(sm.span, problem);
    }
}

/// The PDO indexes a 0x1C1n object assigns by default (subs 1..=sub 0), with the spans of
/// their values; `None` when sub 0 has no default.
fn assignment(dev: &Device, index: u16) -> Option<Vec<(u16, Span)>> {
    let o = dev.objects.get(&index)?;
    let count = initial_u64(dev, index, 0)?;
    let mut out = Vec::new();
    for sub in 1..=count.min(254) as u8 {
        let Some(s) = o.sub(sub) else { continue };
        let Some(v) = s.initial_value() else { continue };
        let Some(pdo) = crate::util::as_u64(&v.value).and_then(|v| u16::try_from(v).ok()) else {
            continue;
        };
        if pdo != 0 {
            out.push((pdo, first_span([v.span, s.span, o.span])));
        }
    }
    Some(out)
}

/// The process-data sync managers with their assignment object index 0x1C10 + n.
fn pd_sync_managers(ec: &EtherCat) -> impl Iterator<Item = (&SyncManager, Direction, u16)> {
    ec.sync_managers
        .iter()
        .filter(|sm| sm.number < 32)
        .filter_map(|sm| direction_of(&sm.usage).map(|d| (sm, d, 0x1C10 + u16::from(sm.number))))
}

rule!(
    T607,
    "T607",
    "esi-pdo-assign-unknown",
    "etg",
    Error,
    Deny,
    pdo_assign_unknown,
    "a PDO assignment object (0x1C12, 0x1C13, ...) lists a PDO the device does not have",
    "Object 0x1C10 + n lists the PDOs assigned to sync manager n (ETG.1000.6 §5.6.7.4.6): \
     0x1C12 the RxPDOs of SM 2, 0x1C13 the TxPDOs of SM 3. Each listed index must be a PDO of \
     the file of the direction the sync manager carries (0x1600–0x17FF for outputs, \
     0x1A00–0x1BFF for inputs). An unknown or wrong-direction index in the default assignment \
     makes the device start with a process image no master can describe, and a master that \
     reads the assignment (PdoUpload) fails. Modular devices (slots) are not checked, their \
     PDOs are shifted per slot. Fix: correct the default values (DefaultData) of the assignment \
     object."
);

fn pdo_assign_unknown(dev: &Device, ctx: &mut Ctx) {
    let Some(ec) = ec(dev) else { return };
    if !has_dictionary(dev) || is_modular(ec) {
        return;
    }
    let known = all_pdo_indexes(dev, ec);
    for (sm, dir, index) in pd_sync_managers(ec) {
        let Some(list) = assignment(dev, index) else { continue };
        for (pdo, span) in list {
            let found = dev.pdos.iter().find(|p| p.mapping_index == pdo);
            let why = match found {
                None if !known.contains(&pdo) => "which the file does not define".to_string(),
                Some(p) if p.direction != dir => format!(
                    "a {} but SM {} carries {}",
                    pdo_kind(p),
                    sm.number,
                    usage_name(&sm.usage)
                ),
                _ => continue,
            };
            ctx.report(
                index,
                None,
                span,
                format!("{} assigns PDO {}, {why}", idx(index), idx(pdo)),
            );
        }
    }
}

rule!(
    T608,
    "T608",
    "esi-pdo-assign-default",
    "etg",
    Warning,
    Warn,
    pdo_assign_default,
    "a PDO assignment object's default differs from the PDOs' Sm attributes",
    "An ESI states the default PDO assignment twice: in the Sm attributes of the <RxPdo>/<TxPdo> \
     elements, and in the default values of the assignment objects 0x1C10 + n of its \
     dictionary (0x1C12 for SM 2, 0x1C13 for SM 3), in order. A master that takes the process \
     image from the ESI without downloading the assignment (CoE PdoAssign off) and a device \
     that starts with its dictionary's defaults then disagree about which PDOs are exchanged, \
     and in which order. Fix: make the Sm attributes and the assignment object's DefaultData \
     agree."
);

fn pdo_assign_default(dev: &Device, ctx: &mut Ctx) {
    let Some(ec) = ec(dev) else { return };
    if !has_dictionary(dev) || is_modular(ec) {
        return;
    }
    for (sm, _, index) in pd_sync_managers(ec) {
        let Some(list) = assignment(dev, index) else { continue };
        let listed: Vec<u16> = list.iter().map(|l| l.0).collect();
        let by_sm: Vec<u16> = assigned(dev, sm.number).map(|p| p.mapping_index).collect();
        if listed == by_sm {
            continue;
        }
        let show = |v: &[u16]| {
            if v.is_empty() {
                "none".to_string()
            } else {
                v.iter().map(|&i| idx(i)).collect::<Vec<_>>().join(", ")
            }
        };
        let same_set = {
            let (mut a, mut b) = (listed.clone(), by_sm.clone());
            a.sort_unstable();
            b.sort_unstable();
            a == b
        };
        let what = if same_set { "in another order than" } else { "differently from" };
        let span = dev.objects.get(&index).map_or(sm.span, |o| o.span);
        ctx.report(
            index,
            None,
            first_span([span, sm.span]),
            format!(
                "{} assigns {} to SM {} by default, {what} the PDOs' Sm attributes ({})",
                idx(index),
                show(&listed),
                sm.number,
                show(&by_sm)
            ),
        );
    }
}

rule!(
    T609,
    "T609",
    "esi-pdo-exclude-unknown",
    "etg",
    Warning,
    Warn,
    pdo_exclude_unknown,
    "a PDO's Exclude names a PDO the file does not define",
    "<Exclude> elements of an <RxPdo>/<TxPdo> name the PDOs that cannot be assigned together \
     with it (ETG.2000: \"PDO indices excluded if this PDO is in a sync manager\"). An index \
     that is no PDO of the file (of the device or of one of its modules) is a typo or a \
     left-over, and the exclusion it was meant to express is lost, so a configuration tool lets \
     the user assign PDOs the device refuses together. Fix: correct or remove the Exclude."
);

fn pdo_exclude_unknown(dev: &Device, ctx: &mut Ctx) {
    let Some(ec) = ec(dev) else { return };
    let known = all_pdo_indexes(dev, ec);
    for p in &dev.pdos {
        for &x in &p.excludes {
            if !known.contains(&x) {
                ctx.report(
                    p.mapping_index,
                    None,
                    p.span,
                    format!("{} excludes {}, which the file does not define", pdo_name(p), idx(x)),
                );
            }
        }
    }
}

rule!(
    T610,
    "T610",
    "esi-pdo-exclude-asymmetric",
    "etg",
    Note,
    Warn,
    pdo_exclude_asymmetric,
    "a PDO excludes another that does not exclude it back",
    "Exclusion is mutual: if PDO A cannot be assigned together with B, B cannot be assigned \
     together with A. ETG.2000 lists the exclusions on each PDO, and configuration tools check \
     only the PDO being added against the ones already assigned, so a one-sided Exclude is \
     enforced or not depending on the order in which the user picks the PDOs. Fix: add the \
     missing Exclude to the other PDO."
);

fn pdo_exclude_asymmetric(dev: &Device, ctx: &mut Ctx) {
    if ec(dev).is_none() {
        return;
    }
    for p in &dev.pdos {
        for &x in &p.excludes {
            let Some(other) = dev.pdos.iter().find(|o| o.mapping_index == x) else { continue };
            if x != p.mapping_index && !other.excludes.contains(&p.mapping_index) {
                ctx.report(
                    other.mapping_index,
                    None,
                    other.span,
                    format!(
                        "{} excludes {}, but {} does not exclude {}",
                        pdo_name(p),
                        pdo_name(other),
                        pdo_name(other),
                        idx(p.mapping_index)
                    ),
                )
                .labels
                .push(Label {
                    span: p.span,
                    message: format!("{} excludes it here", idx(p.mapping_index)),
                    primary: false,
                });
            }
        }
    }
}

rule!(
    T611,
    "T611",
    "esi-default-pdos-excluded",
    "etg",
    Error,
    Deny,
    default_pdos_excluded,
    "two PDOs of the default assignment exclude each other",
    "The PDOs with an Sm attribute (and the Mandatory ones) form the default process image. If \
     one of them excludes another of them (<Exclude>), the default configuration is one the \
     device itself declares invalid: a master that takes the defaults is refused in the \
     PREOP→SAFEOP transition. Fix: remove the Sm attribute from one of the two PDOs, or \
     correct the Exclude."
);

fn default_pdos_excluded(dev: &Device, ctx: &mut Ctx) {
    if ec(dev).is_none() {
        return;
    }
    let default = |p: &Pdo| p.sync_manager.is_some() || p.mandatory;
    let mut seen = BTreeSet::new();
    for p in dev.pdos.iter().filter(|p| default(p)) {
        for &x in &p.excludes {
            let Some(other) = dev.pdos.iter().find(|o| o.mapping_index == x && default(o)) else {
                continue;
            };
            let pair = (p.mapping_index.min(x), p.mapping_index.max(x));
            if x == p.mapping_index || !seen.insert(pair) {
                continue;
            }
            ctx.report(
                p.mapping_index,
                None,
                p.span,
                format!(
                    "{} and {} are both assigned by default, but {} excludes {}",
                    pdo_name(p),
                    pdo_name(other),
                    idx(p.mapping_index),
                    idx(x)
                ),
            )
            .labels
            .push(Label {
                span: other.span,
                message: "assigned here".into(),
                primary: false,
            });
        }
    }
}

/// Whether the device's `<Mailbox>` declares any protocol.
fn speaks_mailbox(ec: &EtherCat) -> bool {
    ec.mailbox
        .as_ref()
        .is_some_and(|m| m.coe.is_some() || m.soe.is_some() || m.foe || m.eoe || m.aoe || m.voe)
}

rule!(
    T612,
    "T612",
    "esi-mailbox-sync-managers",
    "etg",
    Error,
    Deny,
    mailbox_sync_managers,
    "a device with a mailbox protocol lacks SM 0 = MBoxOut and SM 1 = MBoxIn",
    "The mailbox (CoE, FoE, EoE, SoE, AoE, VoE) runs over two sync managers: SM 0 carries \
     master→device (type MBoxOut), SM 1 device→master (MBoxIn) (ETG.1000.4 §6.7; ETG.2000). A \
     device whose <Mailbox> declares a protocol but whose first two <Sm> elements are not these \
     cannot be reached: the master sets up SM 0/1 from the ESI and finds no mailbox there \
     (AL status 0x0016 invalid mailbox configuration). Fix: describe SM 0 and SM 1 as the \
     mailbox, or remove the protocols."
);

fn mailbox_sync_managers(dev: &Device, ctx: &mut Ctx) {
    let Some(ec) = ec(dev) else { return };
    if !speaks_mailbox(ec) {
        return;
    }
    let span = ec.mailbox.as_ref().map_or(Span::DUMMY, |m| m.span);
    for (n, want) in [(0usize, SmUsage::MBoxOut), (1, SmUsage::MBoxIn)] {
        let problem = match ec.sync_managers.get(n) {
            None => format!("the device has a mailbox but no SM {n} ({})", usage_name(&want)),
            Some(sm) if sm.usage != want => format!(
                "the device has a mailbox but SM {n} is of type {}, not {}",
                usage_name(&sm.usage),
                usage_name(&want)
            ),
            Some(_) => continue,
        };
        let at = ec.sync_managers.get(n).map_or(span, |sm| sm.span);
        ctx.report_device(first_span([at, span]), problem);
    }
}

/// The smallest mailbox that carries an expedited SDO: mailbox header (6 bytes), CoE header
/// (2) and the SDO request (8) — ETG.1000.6 §5.6.2.
const MIN_COE_MAILBOX: u32 = 16;

rule!(
    T613,
    "T613",
    "esi-mailbox-size",
    "etg",
    Error,
    Deny,
    mailbox_size,
    "a mailbox sync manager has no size, or one too small for CoE",
    "The length of the mailbox sync managers SM 0/SM 1 is the <Sm DefaultSize> (a master \
     writes it to the ESC and to the SII's standard mailbox sizes). A mailbox sync manager \
     without DefaultSize (or MinSize/MaxSize) leaves the length to guesswork; one shorter than \
     16 bytes cannot carry the 6-byte mailbox header, the 2-byte CoE header and an 8-byte \
     expedited SDO (ETG.1000.6 §5.6.2), so no SDO reaches the device. Fix: give DefaultSize \
     (128 or more is usual)."
);

fn mailbox_size(dev: &Device, ctx: &mut Ctx) {
    let Some(ec) = ec(dev) else { return };
    let coe = ec.mailbox.as_ref().is_some_and(|m| m.coe.is_some());
    for sm in ec.sync_managers.iter().filter(|sm| is_mailbox(&sm.usage)) {
        let n = sm.number;
        let size = sm.default_size.or(sm.max_size).or(sm.min_size);
        let problem = match size {
            None => format!("mailbox SM {n} ({}) has no size", usage_name(&sm.usage)),
            Some(s) if coe && s < MIN_COE_MAILBOX => format!(
                "mailbox SM {n} ({}) is {s} bytes; CoE needs at least {MIN_COE_MAILBOX}",
                usage_name(&sm.usage)
            ),
            Some(_) => continue,
        };
        ctx.report_device(sm.span, problem);
    }
}

rule!(
    T614,
    "T614",
    "esi-sm-control-byte",
    "etg",
    Error,
    Deny,
    sm_control_byte,
    "a sync manager's ControlByte disagrees with its type",
    "The ControlByte of an <Sm> is written to the ESC's sync manager control register (0x0804 + \
     8n, ETG.1000.4): bits 0–1 are the mode (00 buffered, 10 mailbox), bits 2–3 the direction \
     (00 the master reads, 01 the master writes). MBoxOut needs mailbox mode and master writes \
     (0x26 is usual), MBoxIn mailbox mode and master reads (0x22), Outputs master writes (0x64, \
     0x24), Inputs master reads (0x20, 0x00); process data may use either mode. Modes 01/11 and \
     directions 10/11 are reserved. With a wrong ControlByte the ESC moves the data the wrong way \
     or never hands a buffer over. Fix: correct the ControlByte."
);

fn sm_control_byte(dev: &Device, ctx: &mut Ctx) {
    let Some(ec) = ec(dev) else { return };
    for sm in &ec.sync_managers {
        let Some(cb) = sm.control_byte.as_ref() else { continue };
        let (mode, dir) = (cb.value & 0x3, (cb.value >> 2) & 0x3);
        let problem = if mode & 1 != 0 || dir & 2 != 0 {
            Some("sets a reserved mode or direction".to_string())
        } else {
            let (want_mode, want_dir) = match sm.usage {
                SmUsage::MBoxOut => (Some(2), 1),
                SmUsage::MBoxIn => (Some(2), 0),
                SmUsage::Outputs => (None, 1),
                SmUsage::Inputs => (None, 0),
                _ => continue,
            };
            if dir != want_dir {
                Some(format!(
                    "says the master {} but {} data flow the other way",
                    if dir == 1 { "writes" } else { "reads" },
                    usage_name(&sm.usage)
                ))
            } else if want_mode.is_some_and(|m| m != mode) {
                Some("is buffered mode, but a mailbox needs mailbox mode".to_string())
            } else {
                None
            }
        };
        if let Some(why) = problem {
            ctx.report_device(
                first_span([cb.span, sm.span]),
                format!(
                    "SM {} ({}): ControlByte 0x{:02X} {why}",
                    sm.number,
                    usage_name(&sm.usage),
                    cb.value
                ),
            );
        }
    }
}

/// Sync managers that start below this address point at ESC registers (the digital I/O
/// outputs 0x0F00–0x0F03, inputs 0x1000–0x1003), not at three-buffer memory.
const DIGITAL_IO_END: u16 = 0x1004;

/// The ESC memory a sync manager occupies by default: its length (DefaultSize, or the default
/// PDOs' bytes when larger; a mailbox without DefaultSize its MinSize), three times over for a
/// buffered process-data sync manager.
fn sm_area(dev: &Device, sm: &SyncManager) -> Option<(u32, u32)> {
    let start = u32::from(sm.start_address.as_ref()?.value);
    let len = if direction_of(&sm.usage).is_some() {
        u64::from(sm.default_size.unwrap_or(0)).max(assigned_bytes(dev, sm.number))
    } else {
        u64::from(sm.default_size.or(sm.min_size).unwrap_or(0))
    };
    let buffered = sm.control_byte.as_ref().is_none_or(|c| c.value & 0x3 == 0);
    let len = if buffered && !is_mailbox(&sm.usage) { len * 3 } else { len };
    let len = u32::try_from(len).ok()?;
    (len > 0).then_some((start, start.saturating_add(len)))
}

rule!(
    T615,
    "T615",
    "esi-sm-overlap",
    "etg",
    Warning,
    Warn,
    sm_address,
    "the memory areas of two enabled sync managers overlap",
    "Each sync manager guards an area of ESC memory from StartAddress on (ETG.1000.4): a \
     mailbox or single-buffered sync manager occupies its length, a buffered (3-buffer) one \
     three times its length. Two enabled sync managers must not share memory, or they corrupt \
     each other's data. The length taken is the default one: DefaultSize, or the default PDOs' \
     size when larger (for a mailbox without DefaultSize, MinSize). (Addresses below 0x1000 are not reported: simple digital terminals point a \
     sync manager at the ESC's digital I/O register 0x0F00.) Fix: correct StartAddress or the \
     sizes."
);

fn sm_address(dev: &Device, ctx: &mut Ctx) {
    let Some(ec) = ec(dev) else { return };
    let mut areas: Vec<(&SyncManager, u32, u32)> = Vec::new();
    for sm in ec.sync_managers.iter().filter(|sm| !sm.virtual_sm) {
        let Some(start) = sm.start_address.as_ref() else { continue };
        if !sm.enable || start.value < DIGITAL_IO_END {
            continue;
        }
        let Some((a, b)) = sm_area(dev, sm) else { continue };
        if let Some((other, c, d)) = areas.iter().find(|(_, c, d)| a < *d && *c < b) {
            ctx.report_device(
                first_span([start.span, sm.span]),
                format!(
                    "SM {} (0x{a:04X}..0x{b:04X}) overlaps SM {} (0x{c:04X}..0x{d:04X})",
                    sm.number, other.number
                ),
            )
            .labels
            .push(Label {
                span: other.span,
                message: "this one".into(),
                primary: false,
            });
        }
        areas.push((sm, a, b));
    }
}

/// AssignActivate bits (ESC registers 0x0980/0x0981): 0x0100 cyclic operation, 0x0200
/// SYNC0, 0x0400 SYNC1; reserved: 0x0980 bits 1–3 and 6–7.
const AA_CYCLIC: u32 = 0x0100;
const AA_SYNC: u32 = 0x0600;
const AA_RESERVED: u32 = 0x00CE;

rule!(
    T616,
    "T616",
    "esi-dc-assign-activate",
    "etg",
    Error,
    Deny,
    dc_assign_activate,
    "a DC operation mode's AssignActivate is not a valid 0x0980/0x0981 value",
    "AssignActivate of a <Dc><OpMode> is the 16-bit value a master writes to the ESC's DC \
     registers 0x0980 (sync/latch unit assignment) and 0x0981 (activation) (ETG.2000, \
     ETG.1000.4 distributed clocks): 0x0100 starts cyclic operation, 0x0200 SYNC0, 0x0400 \
     SYNC1; #x300 is the usual SYNC0 mode, #x700 SYNC0+SYNC1, 0 free run or SM-synchronous. \
     SYNC0/SYNC1 without cyclic operation never produce a pulse; a value above 0xFFFF does not \
     fit the registers; bits 1–3 and 6–7 of 0x0980 are reserved. Fix: correct AssignActivate."
);

fn dc_assign_activate(dev: &Device, ctx: &mut Ctx) {
    let Some(dc) = ec(dev).and_then(|e| e.dc.as_ref()) else { return };
    for m in &dc.op_modes {
        let Some(aa) = m.assign_activate else { continue };
        let why = if aa > 0xFFFF {
            "does not fit the two registers 0x0980/0x0981"
        } else if aa & AA_SYNC != 0 && aa & AA_CYCLIC == 0 {
            "activates SYNC0/SYNC1 without cyclic operation (0x0100)"
        } else if aa & AA_RESERVED != 0 {
            "sets reserved bits of 0x0980"
        } else {
            continue;
        };
        ctx.report_device(
            first_span([m.span, dc.span]),
            format!("DC mode `{}`: AssignActivate 0x{aa:04X} {why}", m.name),
        );
    }
}

rule!(
    T617,
    "T617",
    "esi-dc-op-mode-name",
    "etg",
    Error,
    Deny,
    dc_op_mode_name,
    "a DC operation mode has no name",
    "Masters and configuration tools select a <Dc><OpMode> by its Name (TwinCAT's DC tab, a \
     module's DcOpModeName, ENI files); ETG.2000 makes the Name mandatory. A mode without one \
     cannot be selected. Two modes of one name are not reported: Beckhoff's files give \
     alternative versions of a mode the same name and tell them apart by TwinCAT build \
     numbers (VendorSpecific UseFromBuildNo/IgnoreFromBuildNo). Fix: name the mode."
);

fn dc_op_mode_name(dev: &Device, ctx: &mut Ctx) {
    let Some(dc) = ec(dev).and_then(|e| e.dc.as_ref()) else { return };
    for (k, m) in dc.op_modes.iter().enumerate() {
        if m.name.trim().is_empty() {
            ctx.report_device(
                first_span([m.span, dc.span]),
                format!("DC mode {} has no name", k + 1),
            );
        }
    }
}

rule!(
    T618,
    "T618",
    "esi-sm-type-object",
    "etg",
    Warning,
    Warn,
    sm_type_object,
    "object 0x1C00 (sync manager types) disagrees with the <Sm> elements",
    "Sub-index n of 0x1C00 (sync manager communication type, ETG.1000.6 §5.6.7.4.5) gives the \
     type of SM n−1: 1 mailbox out, 2 mailbox in, 3 outputs, 4 inputs, 0 unused. Masters that \
     configure a device from its dictionary (SDO information, PdoUpload) read it, those that \
     use the ESI read the <Sm> elements; when the two disagree the device is configured \
     differently depending on the master. Fix: make 0x1C00's default values match the <Sm> \
     types."
);

fn sm_type_object(dev: &Device, ctx: &mut Ctx) {
    let Some(ec) = ec(dev) else { return };
    if !has_dictionary(dev) || ec.sync_managers.is_empty() {
        return;
    }
    let Some(o) = dev.objects.get(&0x1C00) else { return };
    let Some(count) = initial_u64(dev, 0x1C00, 0) else { return };
    for sub in 1..=count.min(32) as u8 {
        let Some(s) = o.sub(sub) else { continue };
        let Some(v) = s.initial_value() else { continue };
        let Some(code) = crate::util::as_u64(&v.value) else { continue };
        let n = usize::from(sub - 1);
        let want = match ec.sync_managers.get(n).map(|sm| &sm.usage) {
            Some(SmUsage::MBoxOut) => 1,
            Some(SmUsage::MBoxIn) => 2,
            Some(SmUsage::Outputs) => 3,
            Some(SmUsage::Inputs) => 4,
            // The ESC may have more sync managers than the ESI describes.
            None | Some(_) => continue,
        };
        if code != want {
            let what = ec.sync_managers.get(n).map_or("", |sm| usage_name(&sm.usage));
            let d = ctx.report(
                0x1C00,
                Some(sub),
                first_span([v.span, s.span, o.span]),
                format!(
                    "0x1C00:{sub:02X} says type {code} for SM {n}, which is of type {what} ({want})"
                ),
            );
            if let Some(sm) = ec.sync_managers.get(n) {
                d.labels.push(Label {
                    span: sm.span,
                    message: format!("SM {n} defined here"),
                    primary: false,
                });
            }
        }
    }
}

rule!(
    T619,
    "T619",
    "esi-subitem-duplicate",
    "etg",
    Warning,
    Warn,
    subitem_duplicate,
    "two SubItems of one dictionary DataType share a Name or a SubIdx",
    "The SubItems of a structured <DataType> are the sub-objects of every object of that type. \
     ETG.2000 makes SubItem/Name a key within its DataType: an object's <Info><SubItem> values \
     are matched to the type's SubItems by that name, so with two of one name the defaults go \
     to one of them at random (tools differ). Two SubItems with one SubIdx describe two \
     sub-objects at one sub-index. Fix: give each SubItem its own Name and SubIdx."
);

fn subitem_duplicate(dev: &Device, ctx: &mut Ctx) {
    let Some(ec) = ec(dev) else { return };
    for t in &ec.data_types {
        for (k, s) in t.sub_items.iter().enumerate() {
            let earlier = &t.sub_items[..k];
            let why = if !s.name.is_empty() && earlier.iter().any(|e| e.name == s.name) {
                format!("two SubItems are named `{}`", s.name)
            } else if let Some(i) =
                s.sub_idx.filter(|&i| earlier.iter().any(|e| e.sub_idx == Some(i)))
            {
                format!("two SubItems have SubIdx {i}")
            } else {
                continue;
            };
            ctx.report_device(t.span, format!("DataType `{}`: {why}", t.name));
        }
    }
}

rule!(
    T620,
    "T620",
    "esi-subitem-layout",
    "etg",
    Warning,
    Warn,
    subitem_layout,
    "a DataType's SubItems overlap or reach past its BitSize",
    "Each SubItem of a structured <DataType> occupies BitSize bits from BitOffs on; together \
     they make the object's CompleteAccess image (ETG.1000.6 SDO complete access) of the \
     type's BitSize bits. SubItems that overlap, or that end past the type's BitSize, describe \
     no possible image: a master reading or writing the object with CompleteAccess splits the \
     bytes differently from the device. Fix: correct BitOffs/BitSize of the SubItems or the \
     type's BitSize."
);

fn subitem_layout(dev: &Device, ctx: &mut Ctx) {
    let Some(ec) = ec(dev) else { return };
    for t in &ec.data_types {
        let mut items: Vec<(u32, u32, &str)> = t
            .sub_items
            .iter()
            .filter_map(|s| Some((s.bit_offset?, s.bit_size?, s.name.as_str())))
            .filter(|&(_, size, _)| size > 0)
            .collect();
        items.sort_by_key(|&(off, _, _)| off);
        let past = t.bit_size.and_then(|total| {
            items
                .iter()
                .find(|&&(off, size, _)| u64::from(off) + u64::from(size) > u64::from(total))
                .map(|&(off, size, name)| {
                    format!(
                        "SubItem `{name}` (bits {off}..{}) ends past BitSize {total}",
                        off + size
                    )
                })
        });
        let overlap = items.windows(2).find(|w| w[0].0 + w[0].1 > w[1].0).map(|w| {
            format!(
                "SubItems `{}` (bits {}..{}) and `{}` (from bit {}) overlap",
                w[0].2,
                w[0].0,
                w[0].0 + w[0].1,
                w[1].2,
                w[1].0
            )
        });
        if let Some(why) = past.or(overlap) {
            ctx.report_device(t.span, format!("DataType `{}`: {why}", t.name));
        }
    }
}

rule!(
    T621,
    "T621",
    "esi-pdo-entry-alignment",
    "etg",
    Warning,
    Warn,
    pdo_entry_alignment,
    "a PDO entry of 8 bits or more does not start on a byte boundary",
    "Entries of 8 bits or more are expected to start on a byte boundary within their PDO: the \
     ESC moves process data bytewise, slave stacks (Beckhoff SSC, SOES) map them to aligned C \
     variables, and masters that type the process image (ethercrab's wire derive) refuse \
     unaligned multi-bit fields. Files keep them aligned with gap entries (Index 0) after bit \
     fields. An unaligned entry is read at a different offset by tools that align and by tools \
     that do not. Fix: insert a gap entry so that the entry starts on a byte boundary."
);

fn pdo_entry_alignment(dev: &Device, ctx: &mut Ctx) {
    if ec(dev).is_none() {
        return;
    }
    for p in &dev.pdos {
        let mut offset: u32 = 0;
        for e in &p.entries {
            if !e.is_gap() && e.bits >= 8 && !offset.is_multiple_of(8) {
                ctx.report(
                    p.mapping_index,
                    None,
                    first_span([e.span, p.span]),
                    format!(
                        "{} maps 0x{:04X}:{:02X} ({} bits) at bit offset {offset}",
                        pdo_name(p),
                        e.index,
                        e.sub,
                        e.bits
                    ),
                );
                break;
            }
            offset = offset.saturating_add(u32::from(e.bits));
        }
    }
}
