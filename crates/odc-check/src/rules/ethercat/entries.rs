//! PDO entries: in the dictionary, of the right length and direction, on a sync manager,
//! aligned (T601–T604, T621).

use super::*;

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

pub(super) fn pdo_entry_not_in_dictionary(dev: &Device, ctx: &mut Ctx) {
    if !has_dictionary(dev) {
        return;
    }
    for p in &dev.pdos {
        for e in p.entries.iter().filter(|e| !e.is_gap()) {
            // The objects odc synthesised for a CoE device (a PDO's mapping object) are not
            // the file's dictionary.
            if crate::util::file_sub(dev, e.index, e.sub).is_none() {
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

pub(super) fn pdo_entry_bit_length(dev: &Device, ctx: &mut Ctx) {
    if !is_esi(dev) {
        return;
    }
    for p in &dev.pdos {
        for e in p.entries.iter().filter(|e| !e.is_gap()) {
            // Not an object odc synthesised for a CoE device (mapping objects, 0x1C1n: their
            // sizes are odc's); those synthesised from the entries of an ESI without a
            // dictionary are checked, two entries of one object may disagree.
            let Some(bits) = dev
                .objects
                .get(&e.index)
                .filter(|o| o.origin != Origin::CoeImplied)
                .and_then(|o| o.sub(e.sub))
                .and_then(SubObject::bits)
            else {
                continue;
            };
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

pub(super) fn pdo_entry_direction(dev: &Device, ctx: &mut Ctx) {
    if !has_dictionary(dev) {
        return;
    }
    for p in dev.pdos.iter().filter(|p| !p.fixed) {
        for e in p.entries.iter().filter(|e| !e.is_gap()) {
            let Some(s) = crate::util::file_sub(dev, e.index, e.sub) else { continue };
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

pub(super) fn pdo_sync_manager(dev: &Device, ctx: &mut Ctx) {
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

pub(super) fn pdo_entry_alignment(dev: &Device, ctx: &mut Ctx) {
    if ec(dev).is_none() {
        return;
    }
    for p in &dev.pdos {
        let mut cursor = Cursor::new();
        for e in &p.entries {
            let Some(BitRange { offset, .. }) = cursor.place(u32::from(e.bits)) else { break };
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
        }
    }
}
