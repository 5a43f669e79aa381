//! The dictionary: `<Object>`s with their sub-items, flags and values, and the objects a device
//! without a dictionary gets from its PDO entries.

use super::*;

pub(super) fn access_of(text: &str, span: Span, ctx: &mut Ctx<'_>) -> Access {
    match Access::parse(text) {
        Some(a) => a,
        None => {
            ctx.push(
                Diagnostic::warning(codes::UNKNOWN_ACCESS, format!("unknown access `{text}`"))
                    .with_label(span, "read as ro"),
            );
            Access::Ro
        }
    }
}

pub(super) fn pdo_mapping_of(text: &str, span: Span, ctx: &mut Ctx<'_>) -> PdoMapping {
    let t = trim(text);
    let is = |s: &str| t.eq_ignore_ascii_case(s);
    match t {
        "" => PdoMapping::No,
        _ if is("R") => PdoMapping::Rx,
        _ if is("T") => PdoMapping::Tx,
        _ if is("RT") || is("TR") => PdoMapping::Both,
        _ => {
            ctx.push(
                Diagnostic::warning(
                    codes::UNKNOWN_PDO_MAPPING,
                    format!("unknown PdoMapping `{text}`"),
                )
                .with_label(span, "read as not mappable"),
            );
            PdoMapping::No
        }
    }
}

/// The ESI-only flags of a device's sub-objects in the order given; see [`flags_by_key`].
pub(super) type FlagsOut = Vec<ObjectFlags>;

/// The flags sorted by index and sub-index, the last one given for a sub-object winning.
pub(super) fn flags_by_key(mut flags: FlagsOut) -> Vec<ObjectFlags> {
    // Stable: of equal keys, the last given stays last.
    flags.sort_by_key(|f| (f.index, f.sub));
    let mut out: Vec<ObjectFlags> = Vec::with_capacity(flags.len());
    for f in flags {
        match out.last_mut() {
            Some(last) if (last.index, last.sub) == (f.index, f.sub) => *last = f,
            _ => out.push(f),
        }
    }
    out
}

/// A `Flags` element read once and applied to every sub-object it covers (an array's elements
/// share their object's, or their SubItem's): reading it again per element cost more than the
/// sub-objects themselves. The problems found are reported again for each sub-object, as they
/// were when each read the element.
pub(super) struct ReadFlags {
    access: Option<Access>,
    pdo_mapping: Option<PdoMapping>,
    /// The ESI-only flags, index and sub-index 0.
    esi: ObjectFlags,
    diagnostics: Vec<Diagnostic>,
}

impl ReadFlags {
    fn read(flags: Element<'_>, src: &str) -> ReadFlags {
        let mut diags = odc_model::Capped::new();
        let ctx = &mut Ctx { src, diags: &mut diags, subs: 0 };
        let mut esi = ObjectFlags::default();
        let mut access = None;
        let [access_el, pdo_mapping, category, transition, backup, setting] =
            flags.pick(["Access", "PdoMapping", "Category", "Transition", "Backup", "Setting"]);
        if let Some(a) = access_el {
            access = Some(access_of(a.text(), a.text_span(), ctx));
            esi.read_restrictions = a.attr("ReadRestrictions").map(|x| Name::from(x.value));
            esi.write_restrictions = a.attr("WriteRestrictions").map(|x| Name::from(x.value));
        }
        let pdo_mapping = pdo_mapping.map(|p| pdo_mapping_of(p.text(), p.text_span(), ctx));
        esi.category = category.map(|c| Name::from(c.text()));
        esi.transition = transition.map(|c| Name::from(c.text()));
        esi.backup = backup.and_then(|b| ctx.el_bool(b));
        esi.setting = setting.and_then(|b| ctx.el_bool(b));
        ReadFlags { access, pdo_mapping, esi, diagnostics: diags.finish() }
    }

    /// Applies the flags to a sub-object of object `index`; records the ESI-only flags.
    fn apply(&self, index: u16, sub: &mut SubObject, ctx: &mut Ctx<'_>, out: &mut FlagsOut) {
        if let Some(f) = self.apply_but_esi(sub, ctx) {
            out.push(ObjectFlags { index, sub: sub.sub_index, ..f.clone() });
        }
    }

    /// [`Self::apply`] for the only sub-object the flags cover: nothing copied.
    fn apply_once(self, index: u16, sub: &mut SubObject, ctx: &mut Ctx<'_>, out: &mut FlagsOut) {
        if self.apply_but_esi(sub, ctx).is_some() {
            out.push(ObjectFlags { index, sub: sub.sub_index, ..self.esi });
        }
    }

    /// Applies all but the ESI-only flags; returns those unless they are all absent.
    fn apply_but_esi(&self, sub: &mut SubObject, ctx: &mut Ctx<'_>) -> Option<&ObjectFlags> {
        if let Some(a) = self.access {
            sub.access = a;
        }
        if let Some(p) = self.pdo_mapping {
            sub.pdo_mapping = p;
        }
        for d in &self.diagnostics {
            ctx.push(d.clone());
        }
        (self.esi != ObjectFlags::default()).then_some(&self.esi)
    }
}

/// Reads a value element: `*Data` as little-endian bytes, `*Value`/`DefaultString` as text.
pub(super) fn value_of(el: Element<'_>, ty: DataType, ctx: &mut Ctx<'_>) -> Spanned<Value> {
    let text = el.text();
    let is_data = el.name().ends_with("Data");
    let v = if is_data {
        num::with_hex_bytes_lenient(text, |b| num::decode_data(b, ty)).and_then(|(v, padded)| {
            if padded {
                odd_hex_digits(el, ctx);
            }
            v
        })
    } else if el.name() == "DefaultString" {
        Some(Value::Text(el.raw_text().into()))
    } else {
        num::parse_value_text(text, ty)
    };
    let v = match v.map(|v| num::fit(v, ty).ok_or(())) {
        Some(Ok(v)) => v,
        Some(Err(())) => {
            ctx.push(
                Diagnostic::error(
                    codes::NUMBER_OUT_OF_RANGE,
                    format!("`{text}` does not fit {}", ty.name()),
                )
                .with_label(el.text_span(), format!("in `{}`", el.name())),
            );
            Value::Invalid(text.into())
        }
        None => {
            let what = if is_data { "little-endian hex bytes" } else { "a value" };
            ctx.push(
                Diagnostic::error(
                    codes::INVALID_DATA,
                    format!("`{}` is not {what} of type {}", text, ty.name()),
                )
                .with_label(el.text_span(), format!("in `{}`", el.name())),
            );
            Value::Invalid(text.into())
        }
    };
    Spanned::new(v, el.text_span())
}

/// Applies an `Info` element (defaults and limits) to a sub-object.
pub(super) fn apply_info(info: Element<'_>, sub: &mut SubObject, ctx: &mut Ctx<'_>) {
    for c in info.children() {
        match c.name() {
            "DefaultData" | "DefaultValue" | "DefaultString" => {
                sub.default = Some(value_of(c, sub.data_type, ctx));
            }
            "MinData" | "MinValue" => {
                sub.low_limit = Some(Box::new(value_of(c, sub.data_type, ctx)))
            }
            "MaxData" | "MaxValue" => {
                sub.high_limit = Some(Box::new(value_of(c, sub.data_type, ctx)))
            }
            _ => {}
        }
    }
}

pub(super) fn unknown_type(name: &str, span: Span, ctx: &mut Ctx<'_>, severe: bool) {
    let msg = format!("unknown data type `{name}`");
    let d = if severe {
        Diagnostic::error(codes::UNKNOWN_DATA_TYPE, msg)
    } else {
        Diagnostic::warning(codes::UNKNOWN_DATA_TYPE, msg)
    };
    ctx.push(d.with_label(span, "neither declared in DataTypes nor a base type"));
}

pub(super) fn lower_objects<'t>(
    dict: Element<'t>,
    ctx: &mut Ctx<'_>,
    types: &Types<'t>,
    flags_out: &mut FlagsOut,
) -> BTreeMap<u16, Object> {
    let mut objects = BTreeMap::new();
    let Some(objs) = dict.child("Objects") else { return objects };
    for o in objs.children_named("Object") {
        let [index_el, type_el, bit_size, flags, info] =
            o.pick(["Index", "Type", "BitSize", "Flags", "Info"]);
        let Some(index_el) = index_el else {
            ctx.missing(o, "Index");
            continue;
        };
        let Some(index) = ctx.el_num::<u16>(index_el, "object index") else { continue };
        let name = first_name(o);
        let type_name = type_el.map(|t| t.text()).unwrap_or("");
        let bit_size = ctx.opt_u32(bit_size, "BitSize");
        let resolved = types.resolve(type_name);
        if resolved.is_none() {
            let span = type_el.map(|t| t.text_span()).unwrap_or(o.span());
            unknown_type(type_name, span, ctx, true);
        }
        let mut object = Object::new(index, name.clone(), ObjectKind::Var, o.span());
        match resolved {
            Some(Resolved::Simple(..)) | None => {
                let (ty, bits) = match resolved {
                    Some(Resolved::Simple(t, b)) => (t, b),
                    _ => (DataType::Domain, None),
                };
                let mut sub = SubObject::new(0, name, ty, Access::Ro);
                sub.bit_size = bit_size.or(bits);
                sub.span = o.span();
                object.subs.reserve_exact(1);
                if let Some(f) = flags {
                    ReadFlags::read(f, ctx.src).apply_once(index, &mut sub, ctx, flags_out);
                }
                if let Some(i) = info {
                    apply_info(i, &mut sub, ctx);
                }
                object.subs.insert(0, sub);
            }
            Some(Resolved::Array(elem, elem_bits, lbound, elements)) => {
                object.kind = ObjectKind::Array;
                object.subs.reserve_exact(elements.min(255) as usize + 1);
                // Arrays of more than 255 elements exist (trace buffers read by complete access);
                // their count needs a wider sub 0 than CoE's usual UNSIGNED8.
                let count_ty =
                    if elements > 255 { DataType::Unsigned16 } else { DataType::Unsigned8 };
                let mut sub0 = SubObject::new(0, "SubIndex 000", count_ty, Access::Ro);
                sub0.default = Some(Spanned::synthetic(Value::Unsigned(u64::from(elements))));
                sub0.span = o.span();
                object.subs.insert(0, sub0);
                let first = lbound.clamp(1, 255);
                for k in 0..elements.min(255) {
                    let si = first + i64::from(k);
                    let Ok(si) = u8::try_from(si) else { break };
                    let mut s = SubObject::new(si, sub_index_name(si), elem, Access::Ro);
                    s.bit_size = elem_bits;
                    s.span = o.span();
                    object.subs.insert(si, s);
                }
                if let Some(f) = flags.map(|f| ReadFlags::read(f, ctx.src)) {
                    for s in object.subs.values_mut() {
                        f.apply(index, s, ctx, flags_out);
                    }
                }
                if let Some(i) = info {
                    if let Some(data) = i.child("DefaultData") {
                        // An array type's own layout (is sub 0 in the bytes?) is not defined
                        // by ETG.2000; say so rather than guess.
                        not_applied(data, "an array type's elements have no bit offsets", ctx);
                    }
                    apply_sub_infos(i, &mut object, ctx);
                }
            }
            Some(Resolved::Struct(dt, _)) => {
                let layout = lower_struct(dt, types, &mut object, flags, ctx, flags_out);
                if let Some(i) = info {
                    if let Some(data) = i.child("DefaultData") {
                        apply_object_data(data, &layout, &mut object, ctx);
                    }
                    apply_sub_infos(i, &mut object, ctx);
                }
            }
        }
        // Types expand: one object of a 255-element array type makes 256 sub-objects, so a
        // few MiB of objects naming such a type would make millions.
        ctx.subs += object.subs.len();
        if ctx.subs > crate::MAX_SUB_OBJECTS {
            ctx.push(
                Diagnostic::error(
                    codes::SUB_OBJECT_LIMIT,
                    format!(
                        "the file's dictionaries have more than {} sub-objects",
                        crate::MAX_SUB_OBJECTS
                    ),
                )
                .with_label(o.span(), "this object and the rest of the dictionary dropped"),
            );
            break;
        }
        if objects.insert(index, object).is_some() {
            ctx.push(
                Diagnostic::warning(
                    codes::DUPLICATE_OBJECT,
                    format!("object 0x{index:04X} defined twice"),
                )
                .with_label(index_el.text_span(), "this definition is used"),
            );
        }
    }
    objects
}

/// Where a sub-object's bits lie in its object's bytes, from the data type's `BitOffs`: how a
/// `DefaultData` of the whole object (complete-access layout) is split.
#[derive(Clone, Copy, Debug)]
pub(super) struct Slot {
    sub: u8,
    offset: u32,
    bits: u32,
}

/// Builds the sub-objects of `object` from a structured data type's `SubItem`s; returns
/// where each lies (those whose `BitOffs` and size are known).
pub(super) fn lower_struct<'t>(
    dt: Element<'t>,
    types: &Types<'t>,
    object: &mut Object,
    obj_flags: Option<Element<'t>>,
    ctx: &mut Ctx<'_>,
    flags_out: &mut FlagsOut,
) -> Vec<Slot> {
    let mut layout = Vec::new();
    let index = object.index;
    let object_span = object.span;
    let mut next: i64 = 0;
    let mut saw_array = false;
    let mut saw_other = false;
    // One sub-object per SubItem, unless one is an array.
    object.subs.reserve_exact(dt.children_named("SubItem").count());
    for si in dt.children_named("SubItem") {
        let [name, type_el, bits, sub_idx, flags, offset] =
            si.pick(["Name", "Type", "BitSize", "SubIdx", "Flags", "BitOffs"]);
        let offset = offset.and_then(|o| u32::try_from(num::parse_int(o.text())?).ok());
        let name = name.map(|n| Name::from(n.text())).unwrap_or_default();
        let type_name = type_el.map(|t| t.text()).unwrap_or("");
        let bits = bits.and_then(|b| num::parse_int(b.text()));
        let bits = bits.and_then(|b| u32::try_from(b).ok());
        let sub_idx = ctx.opt_num::<u8>(sub_idx, "SubIdx");
        let flags = flags.or(obj_flags).map(|f| ReadFlags::read(f, ctx.src));
        let resolved = types.resolve(type_name);
        let mut make =
            |si_no: u8, name: Name, ty: DataType, bits: Option<u32>, ctx: &mut Ctx<'_>| {
                let mut s = SubObject::new(si_no, name, ty, Access::Ro);
                s.bit_size = bits;
                s.span = object_span;
                if let Some(f) = &flags {
                    f.apply(index, &mut s, ctx, flags_out);
                }
                object.subs.insert(si_no, s);
            };
        match resolved {
            Some(Resolved::Array(elem, elem_bits, lbound, elements)) => {
                saw_array = true;
                let first = sub_idx.map(i64::from).unwrap_or(lbound.max(next)).max(0);
                for k in 0..elements.min(256) {
                    let Ok(n) = u8::try_from(first + i64::from(k)) else { break };
                    make(n, sub_index_name(n), elem, elem_bits, ctx);
                    next = i64::from(n) + 1;
                    if let (Some(o), Some(b)) = (offset, elem_bits) {
                        layout.push(Slot { sub: n, offset: o + k * b, bits: b });
                    }
                }
            }
            other => {
                let (ty, tbits) = match other {
                    Some(Resolved::Simple(t, b)) => (t, b),
                    Some(Resolved::Struct(_, b)) => {
                        // CoE sub-objects are not structured; a structure here is usually a
                        // type that contains itself (directly or through another).
                        let span = type_el.map(|t| t.text_span()).unwrap_or(si.span());
                        ctx.push(
                            Diagnostic::warning(
                                codes::STRUCTURED_SUB_ITEM,
                                format!("sub-item of the structured type `{type_name}`"),
                            )
                            .with_label(span, "read as DOMAIN; not expanded"),
                        );
                        (DataType::Domain, b)
                    }
                    _ => {
                        let span = type_el.map(|t| t.text_span()).unwrap_or(si.span());
                        unknown_type(type_name, span, ctx, true);
                        (DataType::Domain, None)
                    }
                };
                let n = sub_idx.map(i64::from).unwrap_or(next);
                let Ok(n) = u8::try_from(n) else { continue };
                if n != 0 {
                    saw_other = true;
                }
                let size = bits.or(tbits);
                make(n, name, ty, size, ctx);
                next = i64::from(n) + 1;
                if let (Some(offset), Some(bits)) = (offset, size) {
                    layout.push(Slot { sub: n, offset, bits });
                }
            }
        }
    }
    object.kind = if saw_array && !saw_other { ObjectKind::Array } else { ObjectKind::Record };
    layout
}

/// F219 for a `*Data` element whose hex digits are odd in number: read with a leading zero.
fn odd_hex_digits(el: Element<'_>, ctx: &mut Ctx<'_>) {
    ctx.push(
        Diagnostic::warning(
            codes::NONSTANDARD_NUMBER,
            format!("`{}` has an odd number of hex digits ({})", el.text(), el.name()),
        )
        .with_label(el.text_span(), "read with a leading zero"),
    );
}

/// Splits an object's own `Info/DefaultData` (ETG.2000: `ObjectInfoType` holds either the
/// whole object's data or `SubItem`s) into its sub-objects' defaults at their `BitOffs`;
/// `SubItem` defaults, applied after, take precedence. Bytes no sub-object covers, and
/// sub-objects the bytes do not reach, are said (F224).
fn apply_object_data(data: Element<'_>, layout: &[Slot], object: &mut Object, ctx: &mut Ctx<'_>) {
    let Some((bytes, padded)) = num::parse_hex_bytes_lenient(data.text()) else {
        ctx.push(
            Diagnostic::error(
                codes::INVALID_DATA,
                format!("`{}` is not little-endian hex bytes", data.text()),
            )
            .with_label(data.text_span(), "in the object's `DefaultData`"),
        );
        return;
    };
    if padded {
        odd_hex_digits(data, ctx);
    }
    if layout.is_empty() {
        return not_applied(data, "its data type gives no `BitOffs`", ctx);
    }
    let have = bytes.len() as u64 * 8;
    let mut short = Vec::new();
    for slot in layout {
        let Some(sub) = object.subs.get_mut(&slot.sub) else { continue };
        let end = u64::from(slot.offset) + u64::from(slot.bits);
        let whole_bytes = slot.offset % 8 == 0 && slot.bits % 8 == 0;
        // A bit field is read into a u64: wider ones that are not whole bytes get no default.
        if end > have || !whole_bytes && slot.bits > 64 {
            short.push(slot.sub);
            continue;
        }
        let value = if whole_bytes {
            let at = slot.offset as usize / 8;
            num::decode_data(&bytes[at..at + slot.bits as usize / 8], sub.data_type)
        } else {
            // A bit field (BOOL, BIT2, …): its bits, as the bytes of an integer.
            let v = (0..slot.bits).fold(0u64, |v, i| {
                let bit = slot.offset + i;
                let set = bytes[bit as usize / 8] >> (bit % 8) & 1;
                v | u64::from(set) << i
            });
            num::decode_data(&v.to_le_bytes()[..slot.bits.div_ceil(8) as usize], sub.data_type)
        };
        match value.and_then(|v| num::fit(v, sub.data_type)) {
            Some(v) => sub.default = Some(Spanned::new(v, data.text_span())),
            None => short.push(slot.sub),
        }
    }
    let used = layout.iter().map(|s| u64::from(s.offset) + u64::from(s.bits)).max().unwrap_or(0);
    let mut said = Vec::new();
    if !short.is_empty() {
        let subs: Vec<String> = short.iter().map(u8::to_string).collect();
        said.push(format!("no default for sub-index {}", subs.join(", ")));
    }
    if used.div_ceil(8) < bytes.len() as u64 {
        said.push(format!(
            "{} byte(s) beyond the last sub-item",
            bytes.len() as u64 - used.div_ceil(8)
        ));
    }
    if !said.is_empty() {
        ctx.push(
            Diagnostic::warning(
                codes::OBJECT_DATA_LAYOUT,
                format!(
                    "object 0x{:04X}'s `DefaultData` ({} bytes) does not match its data type's \
                     sub-items ({} bits)",
                    object.index,
                    bytes.len(),
                    used
                ),
            )
            .with_label(data.text_span(), said.join("; ")),
        );
    }
}

/// An object's own `Info/DefaultData` that odc cannot split into its sub-objects (F224).
fn not_applied(data: Element<'_>, why: &str, ctx: &mut Ctx<'_>) {
    ctx.push(
        Diagnostic::warning(
            codes::OBJECT_DATA_LAYOUT,
            "the object's own `DefaultData` is not applied to its sub-objects",
        )
        .with_label(data.text_span(), why),
    );
}

/// Matches `Info/SubItem`s to the object's sub-objects by name and applies their `Info`.
pub(super) fn apply_sub_infos(info: Element<'_>, object: &mut Object, ctx: &mut Ctx<'_>) {
    // Where each SubItem goes, found first (the lookups borrow the sub-objects' names): by name
    // (the first sub-object of that name), else by position.
    let targets: Vec<(Element<'_>, &str, Option<u8>, Option<u8>)> = {
        // Large objects (arrays of up to 255 elements) get a map; a scan is quicker for few.
        let first_named: Option<HashMap<&str, u8>> = (object.subs.len() > 16)
            .then(|| object.subs.iter().rev().map(|(k, s)| (s.name.as_str(), *k)).collect());
        let subs = &object.subs;
        let by_name = |name: &str| match &first_named {
            Some(m) => m.get(name).copied(),
            None => subs.iter().find(|(_, s)| s.name == name).map(|(k, _)| *k),
        };
        let mut keys = object.subs.keys();
        info.children_named("SubItem")
            .map(|si| {
                let name = si.child("Name").map(|n| n.text()).unwrap_or("");
                (si, name, by_name(name), keys.next().copied())
            })
            .collect()
    };
    for (si, name, by_name, by_pos) in targets {
        let key = match by_name {
            Some(k) => k,
            None => {
                // Names that match nothing (`RxPDO assign Element 1` against `SubIndex 001`,
                // vendor typos): fall back to the position, which is how the list is written.
                // Arrays: element names are ours (`SubIndex nnn`), position is the real key.
                if object.kind != ObjectKind::Array {
                    let span = si.child("Name").map(|n| n.text_span()).unwrap_or(si.span());
                    let applied = match by_pos {
                        Some(k) => format!("applied to sub-index {k} by position"),
                        None => "ignored".to_string(),
                    };
                    ctx.push(
                        Diagnostic::warning(
                            codes::UNMATCHED_SUBITEM,
                            format!("object 0x{:04X} has no sub-item named `{name}`", object.index),
                        )
                        .with_label(
                            span,
                            format!("matches no SubItem of the data type; {applied}"),
                        ),
                    );
                }
                match by_pos {
                    Some(k) => k,
                    None => continue,
                }
            }
        };
        if let Some(sub) = object.subs.get_mut(&key) {
            sub.span = si.span();
            if let Some(i) = si.child("Info") {
                apply_info(i, sub, ctx);
            }
        }
    }
}

/// `SubIndex 001`, the name ESI gives an array element: made inline, with no allocation.
pub(super) fn sub_index_name(n: u8) -> Name {
    let mut b = *b"SubIndex 000";
    b[9] += n / 100;
    b[10] += n / 10 % 10;
    b[11] += n % 10;
    Name::new(std::str::from_utf8(&b).unwrap_or_default())
}

/// A device without a dictionary: objects for its PDO entries, mapping objects and the
/// sync-manager assignment objects, all marked [`Origin::PdoEntry`].
pub(super) fn synthesise(objects: &mut BTreeMap<u16, Object>, pdos: &[Pdo], sms: &[SyncManager]) {
    // Names borrowed until an object or sub-object is made: most entries add a sub-object to
    // an object made already, and sub-object names are inline `Name`s.
    let new_object = |index: u16, name: &str, kind: ObjectKind, span: Span| Object {
        origin: Origin::PdoEntry,
        ..Object::new(index, name, kind, span)
    };
    for pdo in pdos {
        let (access, mapping) = match pdo.direction {
            Direction::Rx => (Access::Rw, PdoMapping::Rx),
            Direction::Tx => (Access::Ro, PdoMapping::Tx),
        };
        for e in &pdo.entries {
            if e.is_gap() {
                continue;
            }
            let name = e.name.as_deref().unwrap_or(&pdo.name);
            let ty = e.data_type.unwrap_or_else(|| type_for_bits(u32::from(e.bits)));
            let object = objects.entry(e.index).or_insert_with(|| {
                let kind = if e.sub == 0 { ObjectKind::Var } else { ObjectKind::Record };
                new_object(e.index, name, kind, e.span)
            });
            if e.sub != 0 && object.kind == ObjectKind::Var {
                object.kind = ObjectKind::Record;
            }
            let synthesised = object.origin == Origin::PdoEntry;
            match object.subs.get_mut(&e.sub) {
                // An entry both an RxPDO and a TxPDO map is written and read by process data.
                Some(s) if synthesised && s.pdo_mapping != mapping => {
                    s.access = Access::Rw;
                    s.pdo_mapping = PdoMapping::Both;
                }
                Some(_) => {}
                None => {
                    let mut s = SubObject::new(e.sub, name, ty, access);
                    s.pdo_mapping = mapping;
                    s.bit_size = Some(u32::from(e.bits));
                    s.span = e.span;
                    object.subs.insert(e.sub, s);
                }
            }
        }
    }
    // Sub-index 0 (highest sub-index) of records made from entries.
    for object in objects.values_mut() {
        if object.kind == ObjectKind::Record && !object.subs.contains_key(&0) {
            let max = object.subs.keys().next_back().copied().unwrap_or(0);
            let mut s0 = SubObject::new(0, "SubIndex 000", DataType::Unsigned8, Access::Ro);
            s0.default = Some(Spanned::synthetic(Value::Unsigned(u64::from(max))));
            object.subs.insert(0, s0);
        }
    }
    for pdo in pdos {
        objects.entry(pdo.mapping_index).or_insert_with(|| mapping_object(pdo, Origin::PdoEntry));
    }
    // The default assignment's PDOs of each direction, in sync manager order: the rule of
    // [`odc_model::ethercat::default_assignment`], so these and the process image agree.
    let assignment = default_assignment(sms, pdos);
    for (index, dir, name) in
        [(0x1C12u16, Direction::Rx, "RxPDO assign"), (0x1C13, Direction::Tx, "TxPDO assign")]
    {
        if objects.contains_key(&index) || !pdos.iter().any(|p| p.direction == dir) {
            continue;
        }
        let assigned: Vec<u16> = assignment
            .values()
            .flatten()
            .copied()
            .filter(|&i| pdos.iter().any(|p| p.mapping_index == i && p.direction == dir))
            .collect();
        let mut o = new_object(index, name, ObjectKind::Array, Span::DUMMY);
        let mut s0 = SubObject::new(0, "SubIndex 000", DataType::Unsigned8, Access::Ro);
        s0.default = Some(Spanned::synthetic(Value::Unsigned(assigned.len() as u64)));
        o.subs.insert(0, s0);
        for (i, pdo_index) in assigned.iter().enumerate().take(254) {
            let n = (i + 1) as u8;
            let mut s = SubObject::new(n, sub_index_name(n), DataType::Unsigned16, Access::Ro);
            s.default = Some(Spanned::synthetic(Value::Unsigned(u64::from(*pdo_index))));
            o.subs.insert(n, s);
        }
        objects.insert(index, o);
    }
}

/// The mapping object of `pdo` (0x16xx, 0x1Axx): a read-only RECORD named as the PDO, its
/// entries' mapping values (`index << 16 | sub << 8 | bits`, gaps index 0) in sub 1.., their
/// count in sub 0.
pub(super) fn mapping_object(pdo: &Pdo, origin: Origin) -> Object {
    let mut o = Object {
        origin,
        ..Object::new(pdo.mapping_index, pdo.name.as_str(), ObjectKind::Record, pdo.span)
    };
    let mut s0 = SubObject::new(0, "SubIndex 000", DataType::Unsigned8, Access::Ro);
    s0.default = Some(Spanned::synthetic(Value::Unsigned(pdo.entries.len().min(254) as u64)));
    s0.span = pdo.span;
    o.subs.insert(0, s0);
    for (i, e) in pdo.entries.iter().enumerate().take(254) {
        let n = (i + 1) as u8;
        let mut s = SubObject::new(n, sub_index_name(n), DataType::Unsigned32, Access::Ro);
        s.default = Some(Spanned::synthetic(Value::Unsigned(u64::from(e.mapping_value()))));
        s.span = e.span;
        o.subs.insert(n, s);
    }
    o
}
