//! C110–C119: the shape of objects and sub-objects (CiA 306 §4.5.2, CiA 301 §7.4.3).

use odc_model::{DataType, Device, ObjectKind, Origin, Spanned, Value};

use super::rule;
use crate::Ctx;
use crate::util::{first_span, idx, is_canopen, kind_name, objects, sub_of, value_span};

rule!(
    C110,
    "C110",
    "sub-number-mismatch",
    "cia301",
    Warning,
    Warn,
    sub_number_mismatch,
    "SubNumber is not the number of sub-objects the file defines",
    "SubNumber of an ARRAY or RECORD counts the sub-object sections that follow ([iiiisub0], \
     [iiiisub1], …). It is a count, not the highest sub-index: gaps are legal (CiA 306 \
     §4.5.2; ros_canopen#445 shows the misreading). When the count is off, readers that rely on \
     it allocate the wrong number of entries or stop early. Fix: set SubNumber to the number of \
     [iiiisubN] sections of the object."
);

fn sub_number_mismatch(dev: &Device, ctx: &mut Ctx) {
    for o in objects(dev) {
        if !o.kind.has_subs() || o.origin != Origin::File || o.compact_sub_obj.is_some() {
            continue;
        }
        if let Some(Spanned { value, span }) = &o.sub_number
            && usize::from(*value) != o.subs.len()
        {
            ctx.report(
                o.index,
                None,
                first_span([*span, o.span]),
                format!("{} has SubNumber={value} but {} sub-objects", idx(o.index), o.subs.len()),
            );
        }
    }
}

rule!(
    C111,
    "C111",
    "sub0-type",
    "cia301",
    Warning,
    Warn,
    sub0_type,
    "sub-index 0 of an ARRAY or RECORD is not UNSIGNED8",
    "Sub-index 0 of an ARRAY or RECORD holds the number of sub-indexes (or the highest \
     sub-index supported) and is UNSIGNED8 by CiA 301 §7.4.3. Another type makes an SDO upload \
     of sub 0 return a different length than masters expect, and generated code reads it \
     wrongly. Fix: DataType=0x0005 in [iiiisub0]."
);

fn sub0_type(dev: &Device, ctx: &mut Ctx) {
    for o in objects(dev) {
        if !o.kind.has_subs() {
            continue;
        }
        if let Some(s) = o.sub(0)
            && s.data_type != DataType::Unsigned8
        {
            ctx.report(
                o.index,
                Some(0),
                first_span([s.data_type_span, s.span, o.span]),
                format!("{}:00 is {}, not UNSIGNED8", idx(o.index), s.data_type.name()),
            );
        }
    }
}

/// Objects whose sub 0 counts entries in use rather than naming the highest sub-index.
fn sub0_is_a_count(index: u16) -> bool {
    matches!(index, 0x1003 | 0x1600..=0x17FF | 0x1A00..=0x1BFF | 0x1C10..=0x1C2F)
}

rule!(
    C112,
    "C112",
    "sub0-value",
    "cia301",
    Warning,
    Warn,
    sub0_value,
    "the value of sub-index 0 is not the highest sub-index the object has",
    "Sub-index 0 of an ARRAY or RECORD says the highest sub-index supported (CiA 301 §7.4.3). \
     When its default disagrees with the sub-objects the file defines, a master that reads sub 0 \
     and walks the sub-indexes misses entries or gets SDO aborts. Exceptions, where sub 0 counts \
     entries in use: 0x1003 (pre-defined error field), the PDO mapping objects \
     0x1600–0x17FF/0x1A00–0x1BFF and the EtherCAT assignment objects 0x1C10–0x1C2F. An ARRAY \
     whose sub 0 is below its highest sub-index is taken as a variable-length array with fewer \
     elements in use; sub 0 above the highest sub-index (elements missing) and any difference in \
     a RECORD are reported. Fix: set DefaultValue of [iiiisub0] to the highest sub-index."
);

fn sub0_value(dev: &Device, ctx: &mut Ctx) {
    for o in objects(dev) {
        if !o.kind.has_subs() || sub0_is_a_count(o.index) {
            continue;
        }
        let Some(s0) = o.sub(0) else { continue };
        let Some(v) = s0.default.as_ref() else { continue };
        let Value::Unsigned(n) = v.value else { continue };
        let highest = o.subs.keys().copied().filter(|&k| k != 0).max().unwrap_or(0);
        // Fewer elements in use than defined is how variable-length ARRAYs (0x1010, 0x1F51,
        // vendor tables) start out; a RECORD's structure is fixed.
        let short_array = o.kind == ObjectKind::Array && n < u64::from(highest);
        if n != u64::from(highest) && !short_array {
            ctx.report(
                o.index,
                Some(0),
                value_span(o, s0, Some(v)),
                format!(
                    "{}:00 defaults to {n} but the highest sub-index is {highest}",
                    idx(o.index)
                ),
            );
        }
    }
}

rule!(
    C113,
    "C113",
    "sub-index-ff",
    "cia301",
    Warning,
    Warn,
    sub_index_ff,
    "an object defines sub-index 0xFF, which CiA 301 reserves",
    "Sub-index 0xFF of every object is reserved by CiA 301 §7.4.3 for the object's structure \
     (data type and object code, read with an SDO upload). A file that defines its own \
     sub-object there collides with that. Fix: move the sub-object to a free sub-index in \
     1..=0xFE."
);

fn sub_index_ff(dev: &Device, ctx: &mut Ctx) {
    for o in objects(dev) {
        if let Some(s) = o.sub(0xFF) {
            ctx.report(
                o.index,
                Some(0xFF),
                first_span([s.span, o.span]),
                format!("{} defines sub-index 0xFF", idx(o.index)),
            );
        }
    }
}

rule!(
    C114,
    "C114",
    "array-not-uniform",
    "cia301",
    Warning,
    Warn,
    array_not_uniform,
    "the elements of an ARRAY do not all have the same data type",
    "An ARRAY (ObjectType=0x8) is a sequence of elements of one data type (CiA 301 §7.4.3); only \
     sub-index 0 (the count) differs. Elements of different types make the object a RECORD: \
     code generators that emit an array of one element type get it wrong. Fix: give every \
     element the same DataType, or declare the object a RECORD (ObjectType=0x9)."
);

fn array_not_uniform(dev: &Device, ctx: &mut Ctx) {
    for o in objects(dev) {
        if o.kind != ObjectKind::Array {
            continue;
        }
        let mut elements = o.subs.values().filter(|s| s.sub_index != 0);
        let Some(first) = elements.next() else { continue };
        for s in elements {
            if s.data_type != first.data_type {
                ctx.report(
                    o.index,
                    Some(s.sub_index),
                    first_span([s.data_type_span, s.span, o.span]),
                    format!(
                        "ARRAY {} element {} is {} but element {} is {}",
                        idx(o.index),
                        s.sub_index,
                        s.data_type.name(),
                        first.sub_index,
                        first.data_type.name()
                    ),
                );
            }
        }
    }
}

rule!(
    C115,
    "C115",
    "sub-number-or-compact",
    "cia301",
    Warning,
    Warn,
    sub_number_or_compact,
    "an ARRAY/RECORD needs exactly one of SubNumber and CompactSubObj",
    "CiA 306 §4.5.2 describes the sub-objects of an ARRAY or RECORD either one section each \
     (counted by SubNumber) or compactly (CompactSubObj=N: sub-indexes 1..N share the header's \
     type and access). Both at once, or neither, leave it open how many sub-objects there are; \
     CompactSubObj on a VAR means nothing. Fix: keep the one that matches how the sub-objects \
     are written."
);

fn sub_number_or_compact(dev: &Device, ctx: &mut Ctx) {
    if !is_canopen(dev) {
        return;
    }
    for o in objects(dev) {
        if o.origin != Origin::File {
            continue;
        }
        match (&o.sub_number, &o.compact_sub_obj, o.kind.has_subs()) {
            (Some(n), Some(c), true) => {
                ctx.report(
                    o.index,
                    None,
                    first_span([c.span, n.span, o.span]),
                    format!("{} has both SubNumber and CompactSubObj", idx(o.index)),
                );
            }
            (None, None, true) => {
                ctx.report(
                    o.index,
                    None,
                    o.span,
                    format!("{} has neither SubNumber nor CompactSubObj", idx(o.index)),
                );
            }
            (_, Some(c), false) => {
                ctx.report(
                    o.index,
                    None,
                    first_span([c.span, o.span]),
                    format!("{} is not an ARRAY or RECORD but has CompactSubObj", idx(o.index)),
                );
            }
            _ => {}
        }
    }
}

rule!(
    C116,
    "C116",
    "var-with-subs",
    "cia301",
    Error,
    Deny,
    var_with_subs,
    "a VAR, DOMAIN or DEFTYPE object has sub-objects",
    "Objects of kind VAR (0x7), DOMAIN (0x2), DEFTYPE (0x5) and NULL (0x0) are single values \
     addressed at sub-index 0 (CiA 301 §7.4.3); they have no sub-objects. A file that gives \
     one [iiiisubN] sections (or SubNumber) contradicts itself: either the ObjectType is wrong \
     (it should be ARRAY 0x8 or RECORD 0x9) or the sub sections are stray. Fix: correct the \
     ObjectType or remove the sub sections."
);

fn var_with_subs(dev: &Device, ctx: &mut Ctx) {
    for o in objects(dev) {
        if o.kind.has_subs() {
            continue;
        }
        for s in o.subs.values().filter(|s| s.sub_index != 0) {
            ctx.report(
                o.index,
                Some(s.sub_index),
                first_span([s.span, o.span]),
                format!(
                    "{} is a {} but has sub-index {}",
                    idx(o.index),
                    kind_name(o.kind),
                    s.sub_index
                ),
            );
        }
    }
}

rule!(
    C117,
    "C117",
    "missing-sub0",
    "cia301",
    Warning,
    Warn,
    missing_sub0,
    "an ARRAY or RECORD has no sub-index 0",
    "Sub-index 0 of an ARRAY or RECORD tells a master how many sub-indexes the object has \
     (CiA 301 §7.4.3); every such object has one. Without it, an SDO upload of sub 0 aborts and \
     generic tools cannot walk the object. Fix: add [iiiisub0] (UNSIGNED8, ro, default = the \
     highest sub-index)."
);

fn missing_sub0(dev: &Device, ctx: &mut Ctx) {
    for o in objects(dev) {
        if matches!(o.kind, ObjectKind::Array | ObjectKind::Record) && o.sub(0).is_none() {
            ctx.report(o.index, None, o.span, format!("{} has no sub-index 0", idx(o.index)));
        }
    }
}

/// The ObjFlags bits CiA 306 §4.5.2 defines: bit 0 refuse write on download, bit 1 refuse read
/// on scan.
const OBJ_FLAGS_DEFINED: u32 = 0b11;

rule!(
    C118,
    "C118",
    "obj-flags-reserved",
    "cia301",
    Warning,
    Warn,
    obj_flags_reserved,
    "ObjFlags sets bits that CiA 306 reserves",
    "ObjFlags (CiA 306 §4.5.2) tells configuration tools how to treat an object: bit 0 \
     \"refuse write on download\" (a tool does not write the value when it downloads a \
     configuration), bit 1 \"refuse read on scan\" (a tool does not read it when it scans the \
     device). Bits 2–31 are reserved in EDS/DCF and must be 0 (bit 2 exists only in XDD/XDC, \
     CiA 311); EdsDcfNet checks the same. A tool that meets a reserved bit may ignore the flags \
     or refuse the file, and a later revision may give the bit a meaning. Fix: clear the \
     reserved bits (ObjFlags=0, 1, 2 or 3)."
);

fn obj_flags_reserved(dev: &Device, ctx: &mut Ctx) {
    if !is_canopen(dev) {
        return;
    }
    for o in objects(dev) {
        let object_flags = o.obj_flags.as_ref().map(|f| (None, f, o.span));
        let sub_flags = o.subs.values().filter_map(|s| {
            s.rare().obj_flags.as_ref().map(|f| (sub_of(o, s.sub_index), f, s.span))
        });
        for (sub, f, fallback) in object_flags.into_iter().chain(sub_flags) {
            let reserved = f.value & !OBJ_FLAGS_DEFINED;
            if reserved != 0 {
                let at = sub.map_or_else(|| idx(o.index), |s| format!("{}:{s:02X}", idx(o.index)));
                ctx.report(
                    o.index,
                    sub,
                    first_span([f.span, fallback, o.span]),
                    format!(
                        "{at} has ObjFlags=0x{:X}, which sets reserved bits 0x{reserved:X}",
                        f.value
                    ),
                );
            }
        }
    }
}

/// The type of each sub-object of a PDO communication record (CiA 301 §7.5.2.35, §7.5.2.37),
/// `None` for sub 4, which is reserved and whose type CiA 301 leaves to compatibility.
fn pdo_comm_sub_type(sub: u8) -> Option<DataType> {
    match sub {
        1 => Some(DataType::Unsigned32),
        2 | 6 => Some(DataType::Unsigned8),
        3 | 5 => Some(DataType::Unsigned16),
        _ => None,
    }
}

/// The name of a PDO communication sub-object.
fn pdo_comm_sub_name(sub: u8) -> &'static str {
    match sub {
        1 => "COB-ID",
        2 => "transmission type",
        3 => "inhibit time",
        4 => "reserved",
        5 => "event timer",
        _ => "SYNC start value",
    }
}

rule!(
    C119,
    "C119",
    "pdo-comm-record",
    "cia301",
    Warning,
    Warn,
    pdo_comm_record,
    "a PDO communication object does not have the shape CiA 301 gives it",
    "The PDO communication parameter objects (RPDO 0x1400–0x15FF, TPDO 0x1800–0x19FF, \
     CiA 301 §7.5.2.35/§7.5.2.37) are RECORDs with sub 1 COB-ID (UNSIGNED32) and sub 2 \
     transmission type (UNSIGNED8), both mandatory, and optionally sub 3 inhibit time \
     (UNSIGNED16), sub 4 reserved (compatibility entry), sub 5 event timer (UNSIGNED16) and, \
     for TPDOs only, sub 6 SYNC start value (UNSIGNED8). Nothing lies past the last of these. A \
     sub-object of another type makes an SDO of the expected length abort, and one that CiA 301 \
     does not define (an RPDO sub 6, CANopenEditor#45; libedssharp#135 on sub 4) is \
     not configured by masters. Sub 0 (the highest sub-index) is left to C112. \
     Objects odc synthesised from CompactPDO are not checked. \
     Fix: give the sub-objects the types above and remove the others."
);

fn pdo_comm_record(dev: &Device, ctx: &mut Ctx) {
    if !is_canopen(dev) {
        return;
    }
    for o in objects(dev) {
        let (tx, last) = match o.index {
            0x1400..=0x15FF => (false, 5u8),
            0x1800..=0x19FF => (true, 6u8),
            _ => continue,
        };
        if o.origin != Origin::File {
            continue;
        }
        let (what, a_what) = if tx { ("TPDO", "a TPDO") } else { ("RPDO", "an RPDO") };
        if !o.kind.has_subs() {
            ctx.report(
                o.index,
                None,
                o.span,
                format!(
                    "{what} communication object {} is a {}, not a RECORD",
                    idx(o.index),
                    kind_name(o.kind)
                ),
            );
            continue;
        }
        for sub in [1u8, 2] {
            if o.sub(sub).is_none() {
                ctx.report(
                    o.index,
                    None,
                    o.span,
                    format!(
                        "{what} communication object {} has no sub {sub} ({})",
                        idx(o.index),
                        pdo_comm_sub_name(sub)
                    ),
                );
            }
        }
        for s in o.subs.values().filter(|s| s.sub_index != 0) {
            let span = first_span([s.span, o.span]);
            let at = format!("{}:{:02X}", idx(o.index), s.sub_index);
            if s.sub_index > last {
                let why = if s.sub_index == 6 {
                    "an RPDO has no SYNC start value".to_string()
                } else {
                    format!("{a_what} communication object ends at sub {last}")
                };
                ctx.report(o.index, Some(s.sub_index), span, format!("{at} is not defined: {why}"));
            } else if let Some(dt) = pdo_comm_sub_type(s.sub_index)
                && s.data_type != dt
            {
                ctx.report(
                    o.index,
                    Some(s.sub_index),
                    first_span([s.data_type_span, span]),
                    format!(
                        "{at} ({}) is {}, not {}",
                        pdo_comm_sub_name(s.sub_index),
                        s.data_type.name(),
                        dt.name()
                    ),
                );
            }
        }
    }
}
