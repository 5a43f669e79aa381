//! C301–C310: the default PDO mapping of CANopen devices (CiA 301 §7.5.2.35–§7.5.2.38,
//! CiA 306 §4.5.2, mirrored from the CANopenNode run-time checks).

use odc_model::{DataType, Device, Direction, Pdo, PdoEntry, Span, SubObject, ValueClass};

use super::rule;
use crate::Ctx;
use crate::util::{first_span, idx, initial_u64, is_canopen, pdos};

fn dir_name(d: Direction) -> &'static str {
    match d {
        Direction::Rx => "RPDO",
        Direction::Tx => "TPDO",
    }
}

/// `TPDO 0x1A00`.
fn pdo_name(p: &Pdo) -> String {
    format!("{} {}", dir_name(p.direction), idx(p.mapping_index))
}

/// The sub-index of a mapping entry in its mapping object (1-based position).
fn entry_sub(k: usize) -> Option<u8> {
    u8::try_from(k + 1).ok()
}

/// CANopen PDOs with their mapped objects (gaps excluded), for the per-entry rules.
fn mapped<'a>(
    dev: &'a Device,
    pdos: &'a [Pdo],
) -> impl Iterator<Item = (&'a Pdo, usize, &'a PdoEntry, Option<&'a SubObject>)> {
    pdos.iter().flat_map(move |p| {
        p.entries
            .iter()
            .enumerate()
            .filter(|(_, e)| !e.is_gap())
            .map(move |(k, e)| (p, k, e, dev.sub(e.index, e.sub)))
    })
}

fn entry_span(p: &Pdo, e: &PdoEntry) -> Span {
    first_span([e.span, p.span])
}

rule!(
    C301,
    "C301",
    "pdo-mapped-object-missing",
    "cia301",
    Error,
    Deny,
    pdo_mapped_object_missing,
    "a PDO mapping entry names an object the dictionary does not have",
    "Each entry 0xIIIISSLL of a PDO mapping object (0x1600–0x17FF, 0x1A00–0x1BFF) maps \
     sub-object IIII:SS with LL bits. When the dictionary has no such sub-object, the device \
     rejects the mapping (SDO abort 0x06020000 / 0x06040041 in CANopenNode's PDO_initMapping) \
     and generated PDO structs cannot be typed. Fix: correct the mapping entry or add the \
     object. Checked for EDS/DCF; for ESI see T601."
);

fn pdo_mapped_object_missing(dev: &Device, ctx: &mut Ctx) {
    if !is_canopen(dev) {
        return;
    }
    let pdos = pdos(dev);
    for (p, k, e, sub) in mapped(dev, &pdos) {
        if sub.is_none() {
            ctx.report(
                p.mapping_index,
                entry_sub(k),
                entry_span(p, e),
                format!(
                    "{} maps 0x{:04X}:{:02X}, which does not exist",
                    pdo_name(p),
                    e.index,
                    e.sub
                ),
            );
        }
    }
}

rule!(
    C302,
    "C302",
    "pdo-mapping-direction",
    "cia301",
    Error,
    Deny,
    pdo_mapping_direction,
    "a PDO maps an object that is not mappable, or not in that direction",
    "An object may go into a PDO only if its PDOMapping flag is set, and the direction follows \
     from its access type: ro/const/rwr objects are inputs of the master and go into TPDOs; \
     wo/rww objects are outputs and go into RPDOs; rw goes both ways (CiA 306 §4.5.2, CiA 301 \
     §7.4.7). A device refuses other mappings (abort 0x06040041 \"object cannot be mapped\"). \
     Fix: set PDOMapping=1 and the right AccessType on the object, or map it into the other \
     kind of PDO."
);

fn pdo_mapping_direction(dev: &Device, ctx: &mut Ctx) {
    if !is_canopen(dev) {
        return;
    }
    let pdos = pdos(dev);
    for (p, k, e, sub) in mapped(dev, &pdos) {
        let Some(s) = sub else { continue };
        if s.pdo_mapping.allows(s.access, p.direction) {
            continue;
        }
        let why = if s.pdo_mapping.is_mappable() {
            format!("access {} does not allow a {}", s.access.as_str(), dir_name(p.direction))
        } else {
            "it is not PDO-mappable".to_string()
        };
        ctx.report(
            p.mapping_index,
            entry_sub(k),
            entry_span(p, e),
            format!("{} maps 0x{:04X}:{:02X} but {why}", pdo_name(p), e.index, e.sub),
        )
        .labels
        .push(odc_model::Label {
            span: s.span,
            message: "object defined here".into(),
            primary: false,
        });
    }
}

rule!(
    C303,
    "C303",
    "pdo-entry-length",
    "cia301",
    Error,
    Deny,
    pdo_entry_length,
    "a PDO mapping entry's length differs from the mapped object's size",
    "The low byte LL of a mapping entry 0xIIIISSLL is the number of bits mapped; it must equal \
     the size of the mapped object's data type (16 for an UNSIGNED16), or of the dummy type for \
     a dummy entry. CANopenNode refuses a mismatch (PDO_initMapping compares the length with the \
     object's data length) and the PDO layout of master and device would disagree. Fix: correct \
     the length in the entry."
);

fn pdo_entry_length(dev: &Device, ctx: &mut Ctx) {
    if !is_canopen(dev) {
        return;
    }
    for p in pdos(dev).iter() {
        for (k, e) in p.entries.iter().enumerate() {
            let bits = if e.is_gap() {
                DataType::from_code(e.index).bit_size()
            } else {
                dev.sub(e.index, e.sub).and_then(SubObject::bits)
            };
            if let Some(bits) = bits
                && u32::from(e.bits) != bits
            {
                ctx.report(
                    p.mapping_index,
                    entry_sub(k),
                    entry_span(p, e),
                    format!(
                        "{} maps 0x{:04X}:{:02X} with {} bits but it has {bits}",
                        pdo_name(p),
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
    C304,
    "C304",
    "pdo-too-long",
    "cia301",
    Error,
    Deny,
    pdo_too_long,
    "a CANopen PDO maps more than 64 bits",
    "A classic CAN frame carries at most 8 bytes, so the entries of one PDO add up to at most 64 \
     bits (CiA 301 §7.2.2; 512 bits only with CAN FD, CiA 1301). A longer mapping is refused by \
     the device (abort 0x06040042 \"number and length exceed PDO\"). Fix: split the objects over \
     two PDOs."
);

fn pdo_too_long(dev: &Device, ctx: &mut Ctx) {
    if !is_canopen(dev) {
        return;
    }
    for p in pdos(dev).iter() {
        let bits = p.bits();
        if bits > 64 {
            ctx.report(
                p.mapping_index,
                None,
                p.span,
                format!("{} maps {bits} bits, more than the 64 of a CAN frame", pdo_name(p)),
            );
        }
    }
}

rule!(
    C305,
    "C305",
    "pdo-too-many-entries",
    "cia301",
    Error,
    Deny,
    pdo_too_many_entries,
    "a PDO mapping object's entry count (sub 0) is above 64",
    "Sub 0 of a PDO mapping object holds the number of mapped entries; CiA 301 §7.5.2.36 \
     allows 0..=64 (0x40). A larger value cannot be written to the device (abort 0x06040042). \
     Fix: correct sub 0's default."
);

fn pdo_too_many_entries(dev: &Device, ctx: &mut Ctx) {
    if !is_canopen(dev) {
        return;
    }
    for (&index, o) in dev.objects.range(0x1600..=0x1BFF) {
        if (0x1800..0x1A00).contains(&index) {
            continue;
        }
        if let Some(n) = initial_u64(dev, index, 0).filter(|&n| n > 0x40) {
            let span = o.sub(0).map_or(o.span, |s| s.span);
            ctx.report(
                index,
                Some(0),
                first_span([span, o.span]),
                format!("{}:00 says {n} mapped entries; at most 64 are allowed", idx(index)),
            );
        }
    }
}

rule!(
    C306,
    "C306",
    "pdo-dummy-not-enabled",
    "cia301",
    Warning,
    Warn,
    pdo_dummy_not_enabled,
    "a PDO maps a dummy entry the device does not support",
    "A mapping entry that names a data-type index (0x0001–0x0007, or up to 0x001B) is a dummy: \
     it reserves space in the PDO without mapping an object. A device supports only the dummies \
     its [DummyUsage] section enables (Dummy0005=1, CiA 306 §4.5.3); others are refused \
     (abort 0x06040041). Fix: enable the dummy in [DummyUsage], or map a real object."
);

fn pdo_dummy_not_enabled(dev: &Device, ctx: &mut Ctx) {
    if !is_canopen(dev) {
        return;
    }
    for p in pdos(dev).iter() {
        for (k, e) in p.entries.iter().enumerate() {
            if !e.is_gap() || e.index == 0 {
                continue;
            }
            if !dev.dummy_usage.get(&e.index).is_some_and(|d| d.value) {
                ctx.report(
                    p.mapping_index,
                    entry_sub(k),
                    entry_span(p, e),
                    format!(
                        "{} maps dummy {} but [DummyUsage] does not enable Dummy{:04X}",
                        pdo_name(p),
                        idx(e.index),
                        e.index
                    ),
                );
            }
        }
    }
}

rule!(
    C307,
    "C307",
    "pdo-variable-length",
    "cia301",
    Warning,
    Warn,
    pdo_variable_length,
    "a PDO maps a string or domain",
    "VISIBLE_STRING, OCTET_STRING, UNICODE_STRING and DOMAIN objects have no fixed size; a PDO \
     has a fixed layout. CANopenNode never marks them mappable, and generated PDO structs \
     cannot give them a type. Fix: map a fixed-size object instead (or, if the device really \
     maps a fixed number of bytes, describe the object with a fixed-size type)."
);

fn pdo_variable_length(dev: &Device, ctx: &mut Ctx) {
    if !is_canopen(dev) {
        return;
    }
    let pdos = pdos(dev);
    for (p, k, e, sub) in mapped(dev, &pdos) {
        let Some(s) = sub else { continue };
        if matches!(s.data_type.class(), ValueClass::Text | ValueClass::Bytes | ValueClass::Unicode)
        {
            ctx.report(
                p.mapping_index,
                entry_sub(k),
                entry_span(p, e),
                format!(
                    "{} maps 0x{:04X}:{:02X}, a {}",
                    pdo_name(p),
                    e.index,
                    e.sub,
                    s.data_type.name()
                ),
            );
        }
    }
}

rule!(
    C308,
    "C308",
    "pdo-count-mismatch",
    "cia301",
    Warning,
    Warn,
    pdo_count_mismatch,
    "NrOfRXPDO/NrOfTXPDO disagree with the PDO communication objects",
    "[DeviceInfo] NrOfRXPDO and NrOfTXPDO state how many receive and transmit PDOs the device \
     supports; the file should define that many communication objects (0x1400–0x15FF, \
     0x1800–0x19FF), written out or implied by CompactPDO. Tools size their PDO tables from \
     these numbers. Fix: correct the numbers or add the missing objects."
);

fn pdo_count_mismatch(dev: &Device, ctx: &mut Ctx) {
    if !is_canopen(dev) {
        return;
    }
    for (key, declared, range) in [
        ("NrOfRXPDO", &dev.device_info.nr_of_rx_pdo, 0x1400..=0x15FF),
        ("NrOfTXPDO", &dev.device_info.nr_of_tx_pdo, 0x1800..=0x19FF),
    ] {
        let Some(declared) = declared else { continue };
        let present = dev.objects.range(range).count();
        if usize::from(declared.value) != present {
            ctx.report_device(
                declared.span,
                format!(
                    "{key}={} but the file has {present} communication objects ({})",
                    declared.value,
                    if key == "NrOfRXPDO" { "0x1400–0x15FF" } else { "0x1800–0x19FF" }
                ),
            );
        }
    }
}

rule!(
    C309,
    "C309",
    "pdo-mapping-entry-missing",
    "cia301",
    Error,
    Deny,
    pdo_mapping_entry_missing,
    "a PDO mapping object counts more entries than it has",
    "Sub 0 of a PDO mapping object says how many of its subs 1..=n are mapped; each of them must \
     exist and hold a mapping value 0xIIIISSLL (CiA 301 §7.5.2.36). A missing or non-numeric \
     entry leaves the default mapping undefined, and a device that activates it maps garbage. \
     Fix: add the entries or lower sub 0."
);

fn pdo_mapping_entry_missing(dev: &Device, ctx: &mut Ctx) {
    if !is_canopen(dev) {
        return;
    }
    for (&index, o) in dev.objects.range(0x1600..=0x1BFF) {
        if (0x1800..0x1A00).contains(&index) {
            continue;
        }
        let Some(n) = initial_u64(dev, index, 0) else { continue };
        let missing: Vec<u8> =
            (1..=n.min(0x40) as u8).filter(|&sub| initial_u64(dev, index, sub).is_none()).collect();
        let (Some(&first), Some(&last)) = (missing.first(), missing.last()) else { continue };
        let which = if missing.len() == 1 {
            format!("entry {first} is missing or not a number")
        } else {
            format!("{} of entries {first}..={last} are missing or not numbers", missing.len())
        };
        let span = o.sub(0).map_or(o.span, |s| s.span);
        ctx.report(
            index,
            Some(first),
            first_span([span, o.span]),
            format!("{}:00 says {n} entries but {which}", idx(index)),
        );
    }
}

rule!(
    C310,
    "C310",
    "pdo-granularity",
    "cia301",
    Warning,
    Warn,
    pdo_granularity,
    "the PDO mapping disagrees with [DeviceInfo] Granularity",
    "[DeviceInfo] Granularity (CiA 306 §4.5.1) is the unit, in bits, in which the device maps \
     objects into PDOs: 8 for byte-wise mapping, 1 for bit-wise; 0 means the mapping is not \
     modifiable. Values above 64 mean nothing (a classic CAN PDO has 64 bits; EdsDcfNet and \
     lely check the range). A default mapping entry whose length is not a multiple of the \
     granularity (a 1-bit BOOLEAN on a byte-granular device) cannot be mapped by the device, \
     and writable mapping sub-objects (AccessType rw/wo) on a device with Granularity=0 \
     contradict \"not modifiable\": a master that believes one tries a remapping the other \
     forbids. Fix: state the granularity the device really has, or make the mapping entries \
     fit it (read-only mapping objects for a fixed mapping)."
);

fn pdo_granularity(dev: &Device, ctx: &mut Ctx) {
    use odc_model::Access;
    if !is_canopen(dev) {
        return;
    }
    let Some(g) = dev.device_info.granularity.as_ref() else { return };
    if g.value > 64 {
        ctx.report_device(g.span, format!("Granularity={} is above 64 bits", g.value));
        return;
    }
    if g.value == 0 {
        let writable = dev
            .objects
            .range(0x1600..=0x1BFF)
            .filter(|(i, _)| !(0x1800..0x1A00).contains(*i))
            .flat_map(|(_, o)| o.subs.values().map(move |s| (o, s)))
            .find(|(_, s)| {
                s.sub_index != 0
                    && matches!(s.access, Access::Rw | Access::Wo | Access::Rww | Access::Rwr)
            });
        if let Some((o, s)) = writable {
            ctx.report_device(
                g.span,
                format!(
                    "Granularity=0 says the PDO mapping is not modifiable, but {}:{:02X} is \
                     writable ({})",
                    idx(o.index),
                    s.sub_index,
                    s.access.as_str()
                ),
            )
            .labels
            .push(odc_model::Label {
                span: first_span([s.span, o.span]),
                message: "writable mapping entry".into(),
                primary: false,
            });
        }
        return;
    }
    for p in pdos(dev).iter() {
        for (k, e) in p.entries.iter().enumerate() {
            if e.bits % u16::from(g.value) != 0 {
                ctx.report(
                    p.mapping_index,
                    entry_sub(k),
                    entry_span(p, e),
                    format!(
                        "{} maps 0x{:04X}:{:02X} with {} bits, not a multiple of Granularity={}",
                        pdo_name(p),
                        e.index,
                        e.sub,
                        e.bits,
                        g.value
                    ),
                );
            }
        }
    }
}
