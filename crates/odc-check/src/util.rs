//! Small helpers shared by the rules.

use std::borrow::Cow;

use odc_model::{
    DataType, Device, Format, Object, Pdo, Span, Spanned, SubObject, Value, ValueClass,
    pdo::resolve_canopen_pdos,
};

/// The node-IDs a `$NODEID` value must be right for.
pub(crate) const NODE_IDS: std::ops::RangeInclusive<u8> = 1..=127;

/// Whether the device is a CANopen one (EDS, DCF, or built without a format).
pub(crate) fn is_canopen(dev: &Device) -> bool {
    !matches!(dev.format, Some(Format::Esi))
}

/// Whether the device was read from an ESI.
pub(crate) fn is_esi(dev: &Device) -> bool {
    matches!(dev.format, Some(Format::Esi))
}

/// The device's PDOs: as the front-end filled them, else (CANopen) resolved from 0x1400–0x1BFF.
pub(crate) fn pdos(dev: &Device) -> Cow<'_, [Pdo]> {
    if dev.pdos.is_empty() && is_canopen(dev) {
        Cow::Owned(resolve_canopen_pdos(dev))
    } else {
        Cow::Borrowed(&dev.pdos)
    }
}

/// The first span that is not the dummy one.
pub(crate) fn first_span(spans: impl IntoIterator<Item = Span>) -> Span {
    spans.into_iter().find(|s| !s.is_dummy()).unwrap_or(Span::DUMMY)
}

/// The span of a value if it has one, else of its sub-object, else of its object.
pub(crate) fn value_span(o: &Object, s: &SubObject, v: Option<&Spanned<Value>>) -> Span {
    first_span([v.map_or(Span::DUMMY, |v| v.span), s.span, o.span])
}

/// `0x1A00`.
pub(crate) fn idx(index: u16) -> String {
    format!("0x{index:04X}")
}

/// `0x1A00:01` for a sub-object of a structured object, `0x1A00` for a VAR.
pub(crate) fn addr(o: &Object, sub: u8) -> String {
    if o.kind.has_subs() { format!("0x{:04X}:{sub:02X}", o.index) } else { idx(o.index) }
}

/// The sub-index to record in a diagnostic: none for a VAR.
pub(crate) fn sub_of(o: &Object, sub: u8) -> Option<u8> {
    o.kind.has_subs().then_some(sub)
}

/// The initial (ParameterValue over DefaultValue) value of `index`:`sub` as an integer,
/// `$NODEID` excluded.
pub(crate) fn initial_u64(dev: &Device, index: u16, sub: u8) -> Option<u64> {
    dev.sub(index, sub)?.initial_value()?.value.as_u64()
}

/// The integer range of a type, for integer and boolean types.
pub(crate) fn int_range(dt: DataType) -> Option<(i128, i128)> {
    match dt.class() {
        ValueClass::Bool => Some((0, 1)),
        ValueClass::Unsigned(n) => Some((0, (1i128 << n) - 1)),
        ValueClass::Signed(n) => Some((-(1i128 << (n - 1)), (1i128 << (n - 1)) - 1)),
        _ => None,
    }
}

/// The value as an integer of type `dt`, with `$NODEID` taken as `node`. For a signed n-bit
/// type, a value in 2^(n-1)..2^n is its two's-complement bit pattern (`0xFFFF` in an
/// INTEGER16 is -1; ESI files write negative limits that way).
pub(crate) fn integer(dt: DataType, v: &Value, node: u8) -> Option<i128> {
    let i = v.as_i128(node)?;
    match (dt.class(), v) {
        (ValueClass::Signed(n), Value::Unsigned(_) | Value::Signed(_))
            if i >= 1i128 << (n - 1) && i < 1i128 << n =>
        {
            Some(i - (1i128 << n))
        }
        _ => Some(i),
    }
}

/// The value as a number to compare with limits, with `$NODEID` taken as `node`.
pub(crate) fn number(dt: DataType, v: &Value, node: u8) -> Option<f64> {
    match dt.class() {
        ValueClass::Real32 | ValueClass::Real64 => v.as_f64(),
        ValueClass::Bool | ValueClass::Unsigned(_) | ValueClass::Signed(_) => {
            integer(dt, v, node).map(|i| i as f64)
        }
        _ => None,
    }
}

/// Whether a sub-object's stated size agrees with its data type's (ESI arrays and strings
/// typed by their element type do not: their values are not checked against the type).
pub(crate) fn sized_like_type(s: &SubObject) -> bool {
    s.bit_size.is_none_or(|b| Some(b) == s.data_type.bit_size())
}

/// The objects the file describes: all but those the ESI front-end synthesised (from the PDO
/// entries of an ESI without a dictionary, or the CoE objects its dictionary leaves out, see
/// [`odc_model::Origin::is_esi_synthesised`]), whose structure and values are odc's, not the file's.
pub(crate) fn objects(dev: &Device) -> impl Iterator<Item = &Object> {
    dev.objects.values().filter(|o| !o.origin.is_esi_synthesised())
}

/// The object at `index` if the file describes it (see [`objects`]).
pub(crate) fn object(dev: &Device, index: u16) -> Option<&Object> {
    dev.objects.get(&index).filter(|o| !o.origin.is_esi_synthesised())
}

/// The sub-object `index:sub` if the file describes its object (see [`objects`]).
pub(crate) fn file_sub(dev: &Device, index: u16, sub: u8) -> Option<&SubObject> {
    object(dev, index)?.sub(sub)
}

/// Iterates over every sub-object of every object the file describes (see [`objects`]).
pub(crate) fn all_subs(dev: &Device) -> impl Iterator<Item = (&Object, &SubObject)> {
    objects(dev).flat_map(|o| o.subs.values().map(move |s| (o, s)))
}

/// Formats a set of node-IDs compactly: `every node-ID`, `node-ID 5`, `node-IDs 3..=127`.
pub(crate) fn nodes_text(nodes: &[u8]) -> String {
    match (nodes.first(), nodes.last()) {
        (Some(&1), Some(&127)) if nodes.len() == 127 => "every node-ID".to_string(),
        (Some(a), Some(b)) if a == b => format!("node-ID {a}"),
        (Some(a), Some(b)) if usize::from(b - a) + 1 == nodes.len() => {
            format!("node-IDs {a}..={b}")
        }
        (Some(a), _) => format!("{} node-IDs (e.g. {a})", nodes.len()),
        _ => "no node-ID".to_string(),
    }
}

/// The CiA 306 name of an object kind: `VAR`, `ARRAY`, `RECORD`, ...
pub(crate) fn kind_name(k: odc_model::ObjectKind) -> &'static str {
    k.name()
}

/// A value for messages: integers in decimal, `$NODEID+n`, others debug-printed.
pub(crate) fn show(v: &Value) -> String {
    match v {
        Value::Unsigned(u) => u.to_string(),
        Value::Signed(i) => i.to_string(),
        Value::Bool(b) => b.to_string(),
        Value::NodeIdPlus(n) if *n < 0 => format!("$NODEID-{}", n.unsigned_abs()),
        Value::NodeIdPlus(n) => format!("$NODEID+0x{n:X}"),
        Value::Real32(b) => f32::from_bits(*b).to_string(),
        Value::Real64(b) => f64::from_bits(*b).to_string(),
        Value::Text(t) => format!("{t:?}"),
        other => format!("{other:?}"),
    }
}
