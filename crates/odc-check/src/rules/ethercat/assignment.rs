//! PDO assignment and `Exclude` (T607–T611, T626).

use super::*;

/// One entry of an assignment object: its sub-index, the PDO index it holds, its value's span.
struct Counted {
    sub: u8,
    pdo: u16,
    span: Span,
}

/// The entries a 0x1C1n object counts by default (subs 1..=sub 0): sub-index, PDO index (0x0000
/// included) and the span of the value; with sub 0's count. `None` when sub 0 has no default,
/// or the object is not the file's (one odc synthesised holds the PDOs' `Sm` attributes:
/// nothing to compare). An object whose defaults odc filled from the `Sm` attributes
/// (`EtherCat::esi_defaults`) counts what the file's sub 0 said: none, or 0.
fn counted_entries(dev: &Device, index: u16) -> Option<(u64, Vec<Counted>)> {
    let o = crate::util::object(dev, index)?;
    if let Some(filled) = dev.esi_default(index) {
        let count = filled.file_count.as_ref().and_then(|v| v.value.as_u64())?;
        return Some((count, Vec::new()));
    }
    let count = initial_u64(dev, index, 0)?;
    let mut out = Vec::new();
    for sub in 1..=count.min(254) as u8 {
        let Some(s) = o.sub(sub) else { continue };
        let Some(v) = s.initial_value() else { continue };
        let Some(pdo) = v.value.as_u64().and_then(|v| u16::try_from(v).ok()) else {
            continue;
        };
        out.push(Counted { sub, pdo, span: first_span([v.span, s.span, o.span]) });
    }
    Some((count, out))
}

/// The PDO indexes a 0x1C1n object assigns by default, with the spans of their values (0x0000
/// entries left out); `None` as for [`counted_entries`].
pub(super) fn assignment(dev: &Device, index: u16) -> Option<Vec<(u16, Span)>> {
    let (_, entries) = counted_entries(dev, index)?;
    Some(entries.into_iter().filter(|e| e.pdo != 0).map(|e| (e.pdo, e.span)).collect())
}

/// The process-data sync managers with their assignment object index 0x1C10 + n.
pub(super) fn pd_sync_managers(
    ec: &EtherCat,
) -> impl Iterator<Item = (&SyncManager, Direction, u16)> {
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

pub(super) fn pdo_assign_unknown(dev: &Device, ctx: &mut Ctx) {
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
    T626,
    "T626",
    "esi-pdo-assign-zero",
    "etg",
    Warning,
    Warn,
    pdo_assign_zero,
    "a PDO assignment object's sub 0 counts entries whose default is 0x0000",
    "Sub-index 0 of 0x1C10 + n is the number of PDOs assigned to sync manager n, and sub-indexes \
     1 to that number hold their mapping objects' indexes (ETG.1000.6 §5.6.7.4.6); 0x0000 is \
     no PDO. Masters disagree on such an entry (SOEM skips it; a device that checks the \
     assignment refuses it, SDO abort or AL status 0x0025 invalid configuration), so the \
     device's default assignment means different process images to different masters. Fix: \
     count only the assigned PDOs in sub 0, or give every counted entry a PDO index."
);

pub(super) fn pdo_assign_zero(dev: &Device, ctx: &mut Ctx) {
    let Some(ec) = ec(dev) else { return };
    if !has_dictionary(dev) {
        return;
    }
    for (_, _, index) in pd_sync_managers(ec) {
        let Some((count, entries)) = counted_entries(dev, index) else { continue };
        let zeros: Vec<u8> = entries.iter().filter(|e| e.pdo == 0).map(|e| e.sub).collect();
        let Some(o) = crate::util::object(dev, index).filter(|_| !zeros.is_empty()) else {
            continue;
        };
        let Some(s0) = o.sub(0) else { continue };
        let subs: Vec<String> = zeros.iter().map(|s| format!(":{s:02}")).collect();
        let span = first_span([s0.initial_value().map_or(s0.span, |v| v.span), s0.span, o.span]);
        ctx.report(
            index,
            Some(0),
            span,
            format!(
                "{} counts {count} PDO{}, but {} {} 0x0000",
                idx(index),
                if count == 1 { "" } else { "s" },
                subs.join(", "),
                if zeros.len() == 1 { "is" } else { "are" }
            ),
        );
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

pub(super) fn pdo_assign_default(dev: &Device, ctx: &mut Ctx) {
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

pub(super) fn pdo_exclude_unknown(dev: &Device, ctx: &mut Ctx) {
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

pub(super) fn pdo_exclude_asymmetric(dev: &Device, ctx: &mut Ctx) {
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

pub(super) fn default_pdos_excluded(dev: &Device, ctx: &mut Ctx) {
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
