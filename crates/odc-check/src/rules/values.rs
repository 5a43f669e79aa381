//! C201–C210: values, types and limits; mandatory objects; identity (CiA 306 §4.5.2,
//! CiA 301 §7.4, §7.5).

use odc_model::{DataType, Device, ObjectKind, Spanned, SubObject, Value, ValueClass};

use super::rule;
use crate::Ctx;
use crate::util::{
    NODE_IDS, addr, all_subs, first_span, idx, int_range, integer, is_canopen, kind_name,
    nodes_text, number, show, sized_like_type, sub_of, value_span,
};

/// The values of a sub-object with the key names they come from.
fn values(s: &SubObject) -> [(&'static str, Option<&Spanned<Value>>); 4] {
    [
        ("DefaultValue", s.default.as_ref()),
        ("LowLimit", s.low_limit.as_deref()),
        ("HighLimit", s.high_limit.as_deref()),
        ("ParameterValue", s.parameter_value.as_ref()),
    ]
}

/// Why `v` is not a value of `dt` (a `$NODEID` value is taken at node-ID `node`).
fn misfit(dt: DataType, v: &Value, node: u8) -> Option<String> {
    match (dt.class(), v) {
        (_, Value::Invalid(_)) => None,
        (ValueClass::Bool | ValueClass::Unsigned(_) | ValueClass::Signed(_), _) => {
            let (lo, hi) = int_range(dt)?;
            match integer(dt, v, node) {
                Some(i) if i < lo || i > hi => {
                    Some(format!("{i} is out of the range of {} ({lo}..={hi})", dt.name()))
                }
                Some(_) => None,
                None => Some(format!("{} is not a value of {}", show(v), dt.name())),
            }
        }
        (ValueClass::Real32 | ValueClass::Real64, _) => match v {
            Value::Real32(_) | Value::Real64(_) | Value::Unsigned(_) | Value::Signed(_) => None,
            _ => Some(format!("{} is not a value of {}", show(v), dt.name())),
        },
        _ => None,
    }
}

rule!(
    C201,
    "C201",
    "value-out-of-type-range",
    "cia301",
    Error,
    Deny,
    value_out_of_type_range,
    "a default, limit or parameter value does not fit the sub-object's data type",
    "DefaultValue, LowLimit, HighLimit and ParameterValue are values of the sub-object's \
     DataType (CiA 306 §4.5.2): an UNSIGNED8 holds 0..=255, an INTEGER16 -32768..=32767, a \
     BOOLEAN 0 or 1. A value outside the range cannot be stored in the object; SDO writes of it \
     abort (0x06090030/0x06070010) and generated code does not compile. Fix: correct the value \
     or the DataType. Values the front-end could not read at all are reported by the front-end; \
     `$NODEID` values by C204."
);

fn value_out_of_type_range(dev: &Device, ctx: &mut Ctx) {
    for (o, s) in all_subs(dev).filter(|(_, s)| sized_like_type(s)) {
        for (key, v) in values(s) {
            let Some(v) = v else { continue };
            if v.value.is_node_relative() {
                continue;
            }
            if let Some(why) = misfit(s.data_type, &v.value, 0) {
                ctx.report(
                    o.index,
                    sub_of(o, s.sub_index),
                    value_span(o, s, Some(v)),
                    format!("{} {key}: {why}", addr(o, s.sub_index)),
                );
            }
        }
    }
}

/// The node-IDs for which `check(node)` holds: all of 1..=127 when nothing is `$NODEID`-relative
/// would be wasteful, so callers pass `relative` and get `[0]` back when it is false.
fn nodes(relative: bool) -> Vec<u8> {
    if relative { NODE_IDS.collect() } else { vec![0] }
}

rule!(
    C202,
    "C202",
    "limits-inverted",
    "cia301",
    Error,
    Deny,
    limits_inverted,
    "LowLimit is greater than HighLimit",
    "LowLimit and HighLimit bound the values an SDO download may write (CiA 306 §4.5.2); with \
     LowLimit > HighLimit no value is allowed, and devices answer every write with an abort \
     0x06090036/0x06090032. Usually the two are swapped or one has the wrong sign for a signed \
     type. Fix: swap or correct them."
);

fn limits_inverted(dev: &Device, ctx: &mut Ctx) {
    for (o, s) in all_subs(dev).filter(|(_, s)| sized_like_type(s)) {
        let (Some(lo), Some(hi)) = (&s.low_limit, &s.high_limit) else { continue };
        let relative = lo.value.is_node_relative() || hi.value.is_node_relative();
        let bad: Vec<u8> = nodes(relative)
            .into_iter()
            .filter(|&n| {
                matches!(
                    (number(s.data_type, &lo.value, n), number(s.data_type, &hi.value, n)),
                    (Some(l), Some(h)) if l > h
                )
            })
            .collect();
        if !bad.is_empty() {
            let when = if relative { format!(" for {}", nodes_text(&bad)) } else { String::new() };
            ctx.report(
                o.index,
                sub_of(o, s.sub_index),
                value_span(o, s, Some(lo)),
                format!(
                    "{} LowLimit {} is greater than HighLimit {}{when}",
                    addr(o, s.sub_index),
                    show(&lo.value),
                    show(&hi.value)
                ),
            );
        }
    }
}

rule!(
    C203,
    "C203",
    "value-outside-limits",
    "cia301",
    Error,
    Deny,
    value_outside_limits,
    "DefaultValue or ParameterValue lies outside LowLimit..=HighLimit",
    "A sub-object's DefaultValue (and, in a DCF, its ParameterValue) must itself be a value the \
     object accepts, i.e. lie within LowLimit..=HighLimit (CiA 306 §4.5.2). Otherwise the \
     device starts in a state no SDO write could produce, and a configuration tool that \
     downloads the DCF values gets an abort. `$NODEID` values are checked for every node-ID \
     1..=127. Fix: correct the value or widen the limits."
);

fn value_outside_limits(dev: &Device, ctx: &mut Ctx) {
    for (o, s) in all_subs(dev).filter(|(_, s)| sized_like_type(s)) {
        if s.low_limit.is_none() && s.high_limit.is_none() {
            continue;
        }
        for (key, v) in [("DefaultValue", &s.default), ("ParameterValue", &s.parameter_value)] {
            let Some(v) = v else { continue };
            let relative = [Some(v), s.low_limit.as_deref(), s.high_limit.as_deref()]
                .into_iter()
                .flatten()
                .any(|x| x.value.is_node_relative());
            let bad: Vec<u8> = nodes(relative)
                .into_iter()
                .filter(|&n| {
                    let Some(x) = number(s.data_type, &v.value, n) else { return false };
                    let lo = s.low_limit.as_ref().and_then(|l| number(s.data_type, &l.value, n));
                    let hi = s.high_limit.as_ref().and_then(|h| number(s.data_type, &h.value, n));
                    lo.is_some_and(|l| x < l) || hi.is_some_and(|h| x > h)
                })
                .collect();
            if !bad.is_empty() {
                let when =
                    if relative { format!(" for {}", nodes_text(&bad)) } else { String::new() };
                ctx.report(
                    o.index,
                    sub_of(o, s.sub_index),
                    value_span(o, s, Some(v)),
                    format!(
                        "{} {key} {} is outside LowLimit..=HighLimit ({}..={}){when}",
                        addr(o, s.sub_index),
                        show(&v.value),
                        s.low_limit.as_ref().map_or(String::new(), |l| show(&l.value)),
                        s.high_limit.as_ref().map_or(String::new(), |h| show(&h.value)),
                    ),
                );
            }
        }
    }
}

rule!(
    C204,
    "C204",
    "nodeid-value-out-of-range",
    "cia301",
    Error,
    Deny,
    nodeid_value_out_of_range,
    "a `$NODEID` value does not fit the data type for every node-ID 1..=127",
    "A value written `$NODEID+n` is resolved when the node-ID is known; CiA 306 §4.5.2 allows \
     any node-ID 1..=127, so the value must fit the sub-object's type for all of them \
     (`$NODEID+0xF0` in an UNSIGNED8 overflows from node-ID 16 on). lely's dcf-tools are the \
     only other checker of this. Fix: use a wider type or a smaller offset."
);

fn nodeid_value_out_of_range(dev: &Device, ctx: &mut Ctx) {
    for (o, s) in all_subs(dev).filter(|(_, s)| sized_like_type(s)) {
        for (key, v) in values(s) {
            let Some(v) = v else { continue };
            if !v.value.is_node_relative() {
                continue;
            }
            // `$NODEID+k` takes the values k+1..=k+127, and the values a type accepts (written
            // as unsigned or signed) form one interval: when the first and the last node-ID
            // fit, all do.
            let (first, last) = (*NODE_IDS.start(), *NODE_IDS.end());
            if misfit(s.data_type, &v.value, first).is_none()
                && misfit(s.data_type, &v.value, last).is_none()
            {
                continue;
            }
            let bad: Vec<u8> =
                NODE_IDS.filter(|&n| misfit(s.data_type, &v.value, n).is_some()).collect();
            if let Some(&first) = bad.first() {
                let why = misfit(s.data_type, &v.value, first).unwrap_or_default();
                ctx.report(
                    o.index,
                    sub_of(o, s.sub_index),
                    value_span(o, s, Some(v)),
                    format!(
                        "{} {key} does not fit for {}: at node-ID {first}, {why}",
                        addr(o, s.sub_index),
                        nodes_text(&bad)
                    ),
                );
            }
        }
    }
}

rule!(
    C205,
    "C205",
    "missing-mandatory-object",
    "cia301",
    Error,
    Deny,
    missing_mandatory_object,
    "a mandatory object (0x1000, 0x1001 or 0x1018) is missing",
    "CiA 301 §7.5.2 makes three objects mandatory for every CANopen device: 0x1000 device type, \
     0x1001 error register and 0x1018 identity object. Masters read 0x1000 and 0x1018 at boot to \
     identify the device; without them the device cannot be configured automatically. Fix: add \
     the missing objects. Checked for EDS and DCF files."
);

fn missing_mandatory_object(dev: &Device, ctx: &mut Ctx) {
    if !is_canopen(dev) {
        return;
    }
    for (index, what) in
        [(0x1000, "device type"), (0x1001, "error register"), (0x1018, "identity object")]
    {
        if !dev.objects.contains_key(&index) {
            let span =
                dev.object_lists.mandatory.as_ref().map_or(odc_model::Span::DUMMY, |l| l.span);
            ctx.report(
                index,
                None,
                span,
                format!("mandatory object {} ({what}) is missing", idx(index)),
            );
        }
    }
}

/// Well-known objects: kind and the data type of some subs.
struct Shape {
    index: u16,
    kind: ObjectKind,
    subs: &'static [(u8, DataType)],
}

const SHAPES: &[Shape] = &[
    Shape { index: 0x1000, kind: ObjectKind::Var, subs: &[(0, DataType::Unsigned32)] },
    Shape { index: 0x1001, kind: ObjectKind::Var, subs: &[(0, DataType::Unsigned8)] },
    Shape { index: 0x1005, kind: ObjectKind::Var, subs: &[(0, DataType::Unsigned32)] },
    Shape { index: 0x1006, kind: ObjectKind::Var, subs: &[(0, DataType::Unsigned32)] },
    Shape { index: 0x100C, kind: ObjectKind::Var, subs: &[(0, DataType::Unsigned16)] },
    Shape { index: 0x100D, kind: ObjectKind::Var, subs: &[(0, DataType::Unsigned8)] },
    Shape { index: 0x1014, kind: ObjectKind::Var, subs: &[(0, DataType::Unsigned32)] },
    Shape { index: 0x1017, kind: ObjectKind::Var, subs: &[(0, DataType::Unsigned16)] },
    Shape {
        index: 0x1018,
        kind: ObjectKind::Record,
        subs: &[
            (1, DataType::Unsigned32),
            (2, DataType::Unsigned32),
            (3, DataType::Unsigned32),
            (4, DataType::Unsigned32),
        ],
    },
];

rule!(
    C206,
    "C206",
    "wrong-object-type",
    "cia301",
    Warning,
    Warn,
    wrong_object_type,
    "a communication object does not have the kind or data type CiA 301 gives it",
    "CiA 301 §7.5.2 fixes the object code and data type of the communication objects: 0x1000 \
     device type VAR UNSIGNED32, 0x1001 error register VAR UNSIGNED8, 0x1005/0x1006 SYNC \
     COB-ID/period UNSIGNED32, 0x100C guard time UNSIGNED16, 0x100D life time factor UNSIGNED8, \
     0x1014 EMCY COB-ID UNSIGNED32, 0x1017 heartbeat time UNSIGNED16, 0x1018 identity RECORD \
     with UNSIGNED32 subs 1–4. Masters access these objects with the standard length; a \
     different type makes SDO transfers fail with a length mismatch. Fix: correct ObjectType \
     and DataType."
);

fn wrong_object_type(dev: &Device, ctx: &mut Ctx) {
    for shape in SHAPES {
        let Some(o) = crate::util::object(dev, shape.index) else { continue };
        let var_like = shape.kind == ObjectKind::Var && !o.kind.has_subs();
        if o.kind != shape.kind && !var_like {
            ctx.report(
                o.index,
                None,
                o.span,
                format!(
                    "{} is a {}; CiA 301 makes it a {}",
                    idx(o.index),
                    kind_name(o.kind),
                    kind_name(shape.kind)
                ),
            );
            continue;
        }
        for &(sub, dt) in shape.subs {
            if let Some(s) = o.sub(sub)
                && s.data_type != dt
            {
                ctx.report(
                    o.index,
                    sub_of(o, sub),
                    first_span([s.data_type_span, s.span, o.span]),
                    format!(
                        "{} is {}; CiA 301 makes it {}",
                        addr(o, sub),
                        s.data_type.name(),
                        dt.name()
                    ),
                );
            }
        }
    }
}

rule!(
    C207,
    "C207",
    "identity-mismatch",
    "cia301",
    Warning,
    Warn,
    identity_mismatch,
    "[DeviceInfo] vendor, product or revision number disagrees with 0x1018",
    "The identity object 0x1018 holds vendor-ID (sub 1), product code (sub 2) and revision \
     number (sub 3); [DeviceInfo] VendorNumber, ProductNumber and RevisionNumber (for an ESI: \
     Vendor Id, ProductCode, RevisionNo) say the same thing. Masters match a device on the bus \
     to its file by the values read from 0x1018; when the file's two statements differ, it \
     matches one of them and not the other. Fix: make the defaults of 0x1018 subs 1–3 equal the \
     [DeviceInfo] numbers. For an ESI the revision is not compared: EtherCAT masters take it from \
     the EEPROM, and vendor files share one dictionary among many revisions (T625 notes it)."
);

fn identity_mismatch(dev: &Device, ctx: &mut Ctx) {
    let Some(o) = crate::util::object(dev, 0x1018) else { return };
    let info = &dev.device_info;
    for (sub, key, declared) in [
        (1, "VendorNumber", &info.vendor_number),
        (2, "ProductNumber", &info.product_number),
        (3, "RevisionNumber", &info.revision_number),
    ] {
        // EtherCAT masters identify the revision from the EEPROM (SII), and vendor files reuse
        // one dictionary for many revisions: for an ESI only vendor and product are compared.
        if sub == 3 && crate::util::is_esi(dev) {
            continue;
        }
        let (Some(declared), Some(s)) = (declared, o.sub(sub)) else { continue };
        let Some(v) = s.default.as_ref() else { continue };
        let Value::Unsigned(value) = v.value else { continue };
        if value != u64::from(declared.value) {
            let d = ctx.report(
                0x1018,
                Some(sub),
                value_span(o, s, Some(v)),
                format!(
                    "0x1018:{sub:02X} defaults to 0x{value:08X} but {key} is 0x{:08X}",
                    declared.value
                ),
            );
            d.labels.push(odc_model::Label {
                span: declared.span,
                message: format!("{key} given here"),
                primary: false,
            });
            if crate::util::is_esi(dev) && value == u64::from(declared.value.swap_bytes()) {
                d.notes.push(
                    "the bytes are reversed: ESI DefaultData is little-endian (least significant \
                     byte first)"
                        .into(),
                );
            }
        }
    }
}

rule!(
    C208,
    "C208",
    "limits-on-non-numeric",
    "cia301",
    Warning,
    Warn,
    limits_on_non_numeric,
    "LowLimit or HighLimit on a sub-object whose type is not numeric",
    "LowLimit and HighLimit only mean something for numeric types (integers, BOOLEAN, REAL); \
     lely rejects them elsewhere. On a string, domain or structured type they are ignored by \
     devices and tools read them differently. Fix: remove them."
);

fn limits_on_non_numeric(dev: &Device, ctx: &mut Ctx) {
    for (o, s) in all_subs(dev) {
        if number(s.data_type, &Value::Unsigned(0), 0).is_some() {
            continue;
        }
        if let Some(l) = s.low_limit.as_ref().or(s.high_limit.as_ref()) {
            ctx.report(
                o.index,
                sub_of(o, s.sub_index),
                value_span(o, s, Some(l)),
                format!("{} is {} but has limits", addr(o, s.sub_index), s.data_type.name()),
            );
        }
    }
}

rule!(
    C209,
    "C209",
    "upload-download-file",
    "cia301",
    Warning,
    Warn,
    upload_download_file,
    "UploadFile/DownloadFile on an object that is not a DOMAIN of the matching access",
    "CiA 306 §4.5.2 lets a DOMAIN sub-object name a file instead of holding its value: with \
     UploadFile the device's data is the file's content (what an SDO upload returns), so the \
     object is read-only (AccessType ro or const); with DownloadFile what an SDO download \
     writes goes to the file, so the object is write-only (wo). Both are for DOMAINs only: \
     other types carry their value in DefaultValue/ParameterValue. lely-core's DCF reader \
     applies exactly these conditions and rejects anything else, so the file loads in one tool \
     and not in another. Fix: make the object a DOMAIN with AccessType ro/const (UploadFile) \
     or wo (DownloadFile), or drop the key."
);

fn upload_download_file(dev: &Device, ctx: &mut Ctx) {
    use odc_model::Access;
    if !is_canopen(dev) {
        return;
    }
    for (o, s) in all_subs(dev) {
        let keys = [
            (
                "UploadFile",
                s.rare().upload_file.as_ref(),
                matches!(s.access, Access::Ro | Access::Const),
                "ro or const",
            ),
            ("DownloadFile", s.rare().download_file.as_ref(), s.access == Access::Wo, "wo"),
        ];
        for (key, file, access_ok, wanted) in keys {
            let Some(file) = file else { continue };
            let span = first_span([file.span, s.span, o.span]);
            let at = addr(o, s.sub_index);
            if s.data_type != DataType::Domain {
                ctx.report(
                    o.index,
                    sub_of(o, s.sub_index),
                    span,
                    format!("{at} has {key} but is {}, not DOMAIN", s.data_type.name()),
                );
            } else if !access_ok {
                ctx.report(
                    o.index,
                    sub_of(o, s.sub_index),
                    span,
                    format!(
                        "{at} has {key} but AccessType={}; {key} needs {wanted}",
                        s.access.as_str()
                    ),
                );
            }
        }
    }
}

rule!(
    C210,
    "C210",
    "visible-string-not-visible",
    "cia301",
    Warning,
    Warn,
    visible_string_not_visible,
    "a VISIBLE_STRING default or parameter value holds characters other than visible ASCII",
    "CiA 301 builds VISIBLE_STRING from VISIBLE_CHAR, the ISO 646 characters 0x20..=0x7E (and 0 \
     as padding). Real files put tabs, line breaks or UTF-8 ('µm', '€') in such defaults. odc \
     keeps the file's text as the device's value, so an SDO upload returns those bytes, but a \
     master that decodes the string as ASCII shows them garbled, and the same text written back \
     by a master is refused (odc's `VisibleString::new` accepts visible ASCII only). Fix: write \
     the text in visible ASCII, or make the object an OCTET_STRING or UNICODE_STRING if it \
     really holds other characters."
);

fn visible_string_not_visible(dev: &Device, ctx: &mut Ctx) {
    for (o, s) in all_subs(dev).filter(|(_, s)| s.data_type == DataType::VisibleString) {
        for (key, v) in [("DefaultValue", &s.default), ("ParameterValue", &s.parameter_value)] {
            let Some(v) = v else { continue };
            let Value::Text(text) = &v.value else { continue };
            let Some(bad) = text.chars().find(|c| !matches!(c, ' '..='~')) else { continue };
            ctx.report(
                o.index,
                sub_of(o, s.sub_index),
                value_span(o, s, Some(v)),
                format!(
                    "{} {key} {:?} holds {:?} (U+{:04X}), not visible ASCII",
                    addr(o, s.sub_index),
                    text,
                    bad,
                    u32::from(bad)
                ),
            );
        }
    }
}
