//! Objects and sub-objects: `CANopenObject`/`CANopenSubObject` with the parameters their
//! `uniqueIDRef`s name, lowered as the EDS front-end lowers the same object.

use super::*;

/// What a diagnostic about a sub-object names: "object 1000" or "sub-object 1018sub1".
/// Formatted only when a diagnostic is made (a `String` per sub-object cost more than its
/// lowering's other allocations together).
#[derive(Clone, Copy)]
struct What {
    index: u16,
    sub: Option<u8>,
}

impl std::fmt::Display for What {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self.sub {
            Some(si) => write!(f, "sub-object {:04X}sub{si:X}", self.index),
            None => write!(f, "object {:04X}", self.index),
        }
    }
}

/// The attributes of a `CANopenObject`/`CANopenSubObject` this module reads, found in one
/// pass over the element's attributes (the first of a name, as [`Element::attr`] finds it):
/// the lowering reads a dozen of them on every object and sub-object.
#[derive(Clone, Copy, Default)]
struct ObjAttrs<'d> {
    index: Option<Attr<'d>>,
    sub_index: Option<Attr<'d>>,
    name: Option<Attr<'d>>,
    object_type: Option<Attr<'d>>,
    data_type: Option<Attr<'d>>,
    access_type: Option<Attr<'d>>,
    pdo_mapping: Option<Attr<'d>>,
    default_value: Option<Attr<'d>>,
    low_limit: Option<Attr<'d>>,
    high_limit: Option<Attr<'d>>,
    actual_value: Option<Attr<'d>>,
    denotation: Option<Attr<'d>>,
    obj_flags: Option<Attr<'d>>,
    unique_id_ref: Option<Attr<'d>>,
    sub_number: Option<Attr<'d>>,
    /// An attribute of another name was met: [`L::extras`] keeps those.
    unknown: bool,
}

impl<'d> ObjAttrs<'d> {
    fn of(e: Element<'d>) -> Self {
        let mut a = ObjAttrs::default();
        for x in e.attrs() {
            let Some(slot) = a.slot(x.name) else {
                a.unknown = true;
                continue;
            };
            if slot.is_none() {
                *slot = Some(x);
            }
        }
        a
    }

    /// Whether the lowering reads an attribute of this name (others are kept as they are).
    fn reads(name: &str) -> bool {
        ObjAttrs::default().slot(name).is_some()
    }

    /// Where an attribute of this name goes; `None` for the ones kept as they are.
    fn slot(&mut self, name: &str) -> Option<&mut Option<Attr<'d>>> {
        Some(match name {
            "index" => &mut self.index,
            "subIndex" => &mut self.sub_index,
            "name" => &mut self.name,
            "objectType" => &mut self.object_type,
            "dataType" => &mut self.data_type,
            "accessType" => &mut self.access_type,
            "PDOmapping" => &mut self.pdo_mapping,
            "defaultValue" => &mut self.default_value,
            "lowLimit" => &mut self.low_limit,
            "highLimit" => &mut self.high_limit,
            "actualValue" => &mut self.actual_value,
            "denotation" => &mut self.denotation,
            "objFlags" => &mut self.obj_flags,
            "uniqueIDRef" => &mut self.unique_id_ref,
            "subNumber" => &mut self.sub_number,
            _ => return None,
        })
    }
}

impl<'d> L<'d> {
    pub(super) fn object(&mut self, o: Element<'d>) {
        let oa = ObjAttrs::of(o);
        let Some(index) = oa.index.map(|a| self.hex(Some(a), "index", 0xFFFF)) else {
            self.err(
                codes::MISSING_ATTRIBUTE,
                "CANopenObject has no index".into(),
                o.span(),
                "skipped",
            );
            return;
        };
        let Some(index) = index else { return };
        let index = index.value as u16;
        let param = self.param(oa.unique_id_ref);
        let has_children = o.children().next().is_some();
        let kind = match self.uint_of(oa.object_type, "objectType", 255) {
            Some(v) => match ObjectKind::from_code(v.value as u8) {
                Some(k) => k,
                None => {
                    self.err(
                        codes::INVALID_OBJECT_TYPE,
                        format!("objectType {} is not a CiA 301 object code", v.value),
                        v.span,
                        "expected 0, 2, 5, 6, 7, 8 or 9",
                    );
                    if has_children { ObjectKind::Record } else { ObjectKind::Var }
                }
            },
            None => {
                self.warn(
                    codes::MISSING_ATTRIBUTE,
                    format!("object {index:04X} has no objectType; VAR assumed"),
                    o.span(),
                    "here",
                );
                if has_children { ObjectKind::Record } else { ObjectKind::Var }
            }
        };
        let name = match (oa.name, param.and_then(label)) {
            (Some(a), _) => a.value.to_owned(),
            (None, Some(l)) => l.to_owned(),
            (None, None) => {
                self.warn(
                    codes::MISSING_ATTRIBUTE,
                    format!("object {index:04X} has no name"),
                    o.span(),
                    "here",
                );
                String::new()
            }
        };
        let mut obj = Object::new(index, name.clone(), kind, o.span());
        obj.sub_number = self
            .uint_of(oa.sub_number, "subNumber", 0xFFFF)
            .map(|v| Spanned::new(v.value as u16, v.span));
        obj.obj_flags = self.hex_opt(oa.obj_flags, "objFlags");
        let object_type = self.data_type_attr(oa.data_type);
        if kind.has_subs() {
            obj.denotation = oa.denotation.map(text).filter(|d| !d.value.is_empty());
            if obj.denotation.is_some() {
                self.xdc_values = true;
            }
            obj.extra = self.extras(o, oa, param);
            for s in o.children() {
                if !s.is("CANopenSubObject") {
                    self.keep_in_object(&mut obj, s);
                    continue;
                }
                let sa = ObjAttrs::of(s);
                let Some(si) = sa.sub_index.map(|a| self.hex(Some(a), "subIndex", 0xFF)) else {
                    self.err(
                        codes::MISSING_ATTRIBUTE,
                        format!("a sub-object of {index:04X} has no subIndex"),
                        s.span(),
                        "skipped",
                    );
                    continue;
                };
                let Some(si) = si else { continue };
                let si = si.value as u8;
                let element = kind == ObjectKind::Array && si > 0;
                let fallback = match (element, object_type) {
                    (true, Some(dt)) => Fallback::Object(dt),
                    (true, None) => Fallback::Standard(cia301_element_type(index)),
                    (false, _) => Fallback::Standard(None),
                };
                let sparam = self.param(sa.unique_id_ref);
                let what = What { index, sub: Some(si) };
                let mut sub = self.sub(s, sa, sparam, si, fallback, what);
                sub.name = sa
                    .name
                    .map(|a| a.value)
                    .or_else(|| sparam.and_then(label))
                    .unwrap_or_default()
                    .into();
                let kind_attr = sa
                    .object_type
                    .and_then(|a| a.value.trim().parse::<u8>().ok())
                    .and_then(ObjectKind::from_code);
                sub.kind = kind_attr;
                let extra = self.extras(s, sa, sparam);
                if !extra.is_empty() {
                    sub.rare_mut().extra = extra;
                }
                if obj.subs.insert(si, sub).is_some() {
                    self.warn(
                        codes::DUPLICATE_SUB_OBJECT,
                        format!("sub-index {si:X} of object {index:04X} defined twice"),
                        s.span(),
                        "this one is used",
                    );
                }
            }
        } else {
            let default_dt = match kind {
                ObjectKind::Domain | ObjectKind::Null => Some(DataType::Domain),
                ObjectKind::DefType => Some(DataType::Unsigned32),
                _ => None,
            };
            let fallback = default_dt.map_or(Fallback::Standard(None), Fallback::Object);
            let mut sub = self.sub(o, oa, param, 0, fallback, What { index, sub: None });
            sub.name = name.into();
            obj.extra = self.extras(o, oa, param);
            obj.subs.insert(0, sub);
            for s in o.children() {
                self.keep_in_object(&mut obj, s);
            }
        }
        if self.dev.objects.insert(index, obj).is_some() {
            self.warn(
                codes::DUPLICATE_OBJECT,
                format!("object {index:04X} defined twice"),
                o.span(),
                "this one is used",
            );
        }
    }

    /// A child of an object the model has no place for: kept in the object's `extra` as
    /// written (key `<` + its name), so the XDD writer writes it back.
    fn keep_in_object(&mut self, obj: &mut Object, e: Element<'_>) {
        obj.extra.push(RawEntry {
            key: format!("<{}", e.name()),
            value: e_src(e).to_owned(),
            span: e.span(),
        });
    }

    fn hex_opt(&mut self, a: Option<Attr<'_>>, name: &str) -> Option<Spanned<u32>> {
        let a = a.filter(|a| !a.value.trim().is_empty());
        self.hex(a, name, u64::from(u32::MAX)).map(|v| Spanned::new(v.value as u32, v.span))
    }

    /// The parameter an element's `uniqueIDRef` names, marked as used.
    fn param(&mut self, r: Option<Attr<'_>>) -> Option<Element<'d>> {
        let r = r?;
        match self.params.get_key_value(r.value) {
            Some((k, p)) => {
                self.used.insert(k);
                Some(*p)
            }
            None => {
                self.warn(
                    codes::UNRESOLVED_REFERENCE,
                    format!("uniqueIDRef `{}` names no parameter", r.value),
                    r.span,
                    "not in the parameterList",
                );
                None
            }
        }
    }

    /// `dataType="NNNN"`; `0000` (old CANopenEditor) is absent.
    fn data_type_attr(&mut self, a: Option<Attr<'_>>) -> Option<DataType> {
        let v = self.hex(a, "dataType", 0xFFFF)?;
        (v.value != 0).then(|| DataType::from_code(v.value as u16))
    }

    /// The IEC type of a parameter, or the element type of the array it refers to.
    fn param_type(&mut self, p: Element<'_>) -> Option<DataType> {
        for c in p.children() {
            if let Some(dt) = iec_type(c.name()) {
                return Some(dt);
            }
            if c.is("dataTypeIDRef") {
                let r = c.attr("uniqueIDRef")?;
                let Some(t) = self.types.get(r.value).copied() else {
                    self.warn(
                        codes::UNRESOLVED_REFERENCE,
                        format!("dataTypeIDRef `{}` names no data type", r.value),
                        r.span,
                        "not in the dataTypeList",
                    );
                    return None;
                };
                return t.children().find_map(|c| iec_type(c.name()));
            }
        }
        None
    }

    fn sub(
        &mut self,
        e: Element<'d>,
        ea: ObjAttrs<'d>,
        param: Option<Element<'d>>,
        si: u8,
        fallback: Fallback,
        what: What,
    ) -> SubObject {
        let dt = self.data_type_attr(ea.data_type);
        let dt = dt.or_else(|| param.and_then(|p| self.param_type(p))).or(match fallback {
            Fallback::Object(dt) => Some(dt),
            Fallback::Standard(_) => None,
        });
        let label = "no dataType, and no type in its parameter";
        let dt = match (dt, fallback) {
            (Some(dt), _) => dt,
            (None, Fallback::Standard(Some(standard))) => {
                self.warn(
                    codes::STANDARD_DATA_TYPE,
                    format!(
                        "{what} has no data type; read as {}, as CiA 301 defines it",
                        standard.name()
                    ),
                    e.span(),
                    label,
                );
                standard
            }
            (None, _) => {
                self.err(
                    codes::MISSING_DATA_TYPE,
                    format!("{what} has no data type; read as DOMAIN"),
                    e.span(),
                    label,
                );
                DataType::Domain
            }
        };
        let access = self.access(e, ea.access_type, param, what);
        let mut sub = SubObject::new(si, "", dt, access);
        sub.span = e.span();
        sub.pdo_mapping = match ea.pdo_mapping {
            None => PdoMapping::No,
            Some(a) => match a.value.trim() {
                "no" | "" => PdoMapping::No,
                "default" | "optional" => PdoMapping::Yes,
                "TPDO" => PdoMapping::Tx,
                "RPDO" => PdoMapping::Rx,
                v => {
                    self.warn(
                        codes::UNKNOWN_PDO_MAPPING,
                        format!("PDOmapping `{v}` is not no, default, optional, TPDO or RPDO"),
                        a.span,
                        "read as no",
                    );
                    PdoMapping::No
                }
            },
        };
        (sub.access, sub.pdo_mapping) = as_eds(sub.access, sub.pdo_mapping);
        let pv = |name: &str| param.and_then(|p| p.child(name)).and_then(|c| c.attr("value"));
        let range = param.and_then(|p| p.child("allowedValues")).and_then(|a| a.child("range"));
        let rv = |name: &str| range.and_then(|r| r.child(name)).and_then(|c| c.attr("value"));
        let pick = |own: Option<Attr<'d>>, from_param: Option<Attr<'d>>| {
            own.filter(|a| !a.value.is_empty()).or(from_param.filter(|a| !a.value.is_empty()))
        };
        let string_like =
            matches!(dt.class(), ValueClass::Text | ValueClass::Bytes | ValueClass::Unicode);
        let param_default = pv("defaultValue");
        sub.default = match (ea.default_value.or(param_default), string_like) {
            (Some(a), true) if a.value.is_empty() => Some(Spanned::new(empty_of(dt), a.span)),
            _ => pick(ea.default_value, param_default).and_then(|a| self.value(a, dt)),
        };
        sub.low_limit =
            pick(ea.low_limit, rv("minValue")).and_then(|a| self.value(a, dt)).map(Box::new);
        sub.high_limit =
            pick(ea.high_limit, rv("maxValue")).and_then(|a| self.value(a, dt)).map(Box::new);
        sub.parameter_value =
            pick(ea.actual_value, pv("actualValue")).and_then(|a| self.value(a, dt));
        if sub.parameter_value.is_some() {
            self.xdc_values = true;
        }
        let denotation = ea
            .denotation
            .filter(|a| !a.value.is_empty())
            .map(|a| Spanned::new(a.value.to_owned(), a.span))
            .or_else(|| {
                let d = param?.child("denotation")?;
                let l = d.child("label")?;
                Some(Spanned::new(l.text().to_owned(), l.text_span()))
                    .filter(|t| !t.value.is_empty())
            });
        if denotation.is_some() {
            self.xdc_values = true;
            sub.rare_mut().denotation = denotation;
        }
        let value_names = self.value_names(param, dt);
        if !value_names.is_empty() {
            sub.rare_mut().value_names = value_names;
        }
        // A VAR's objFlags are the object's (as in an EDS).
        if e.is("CANopenSubObject")
            && let Some(f) = self.hex_opt(ea.obj_flags, "objFlags")
        {
            sub.rare_mut().obj_flags = Some(f);
        }
        sub
    }

    /// The names `allowedValues` gives values (`<value value="1"><label>Profile position`),
    /// in file order. A `value` without a label only allows a value: it names nothing. The
    /// element itself stays in `extra` (the XDD writer writes it back as read).
    fn value_names(&mut self, param: Option<Element<'_>>, dt: DataType) -> Vec<ValueName> {
        let Some(allowed) = param.and_then(|p| p.child("allowedValues")) else {
            return Vec::new();
        };
        allowed
            .children()
            .filter(|v| v.is("value"))
            .filter_map(|v| {
                let name = label(v)?.trim();
                let value = self.value(v.attr("value")?, dt)?;
                Some(ValueName { value, name: name.to_owned() })
            })
            .collect()
    }

    fn value(&mut self, a: Attr<'_>, dt: DataType) -> Option<Spanned<Value>> {
        match odc_eds::read_value(a.value, dt) {
            Ok(v) => Some(Spanned::new(v, a.span)),
            Err(e) => {
                let (code, what) = match e {
                    odc_eds::ValueError::OutOfRange => (codes::OUT_OF_RANGE, "does not fit"),
                    odc_eds::ValueError::Invalid => {
                        (codes::INVALID_VALUE, "is not a valid value of")
                    }
                };
                let d = Diagnostic::error(code, format!("`{}` {what} {}", a.value, dt.name()))
                    .with_label(a.span, "kept as written");
                self.diags.push(d);
                Some(Spanned::new(Value::Invalid(a.value.into()), a.span))
            }
        }
    }

    fn access(
        &mut self,
        e: Element<'_>,
        access_type: Option<Attr<'_>>,
        param: Option<Element<'_>>,
        what: What,
    ) -> Access {
        if let Some(a) = access_type.filter(|a| !a.value.is_empty()) {
            return Access::parse(a.value).unwrap_or_else(|| {
                self.err(
                    codes::UNKNOWN_ACCESS,
                    format!("accessType `{}` is not const, ro, wo, rw, rwr or rww", a.value),
                    a.span,
                    "read as ro",
                );
                Access::Ro
            });
        }
        let Some(p) = param else {
            self.warn(
                codes::UNKNOWN_ACCESS,
                format!("{what} has no accessType and no parameter; ro assumed"),
                e.span(),
                "here",
            );
            return Access::Ro;
        };
        let Some(a) = p.attr("access") else { return Access::Ro }; // CiA 311 default: read
        match a.value.trim() {
            "const" => Access::Const,
            "read" => Access::Ro,
            "write" => Access::Wo,
            "readWrite" => Access::Rw,
            "readWriteInput" => Access::Rwr,
            "readWriteOutput" => Access::Rww,
            "noAccess" => {
                self.warn(
                    codes::NO_ACCESS,
                    format!("{what}: access noAccess has no CiA 306 access type"),
                    a.span,
                    "read as ro",
                );
                Access::Ro
            }
            v => {
                self.err(
                    codes::UNKNOWN_ACCESS,
                    format!("access `{v}` is not a CiA 311 access"),
                    a.span,
                    "read as ro",
                );
                Access::Ro
            }
        }
    }

    /// Unknown attributes, the parameter's description, properties and unknown children.
    fn extras(
        &mut self,
        e: Element<'_>,
        ea: ObjAttrs<'_>,
        param: Option<Element<'_>>,
    ) -> Vec<RawEntry> {
        let mut out = Vec::new();
        if ea.unknown {
            for a in e.attrs().filter(|a| !ObjAttrs::reads(a.name)) {
                out.push(RawEntry {
                    key: a.name.to_owned(),
                    value: a.value.to_owned(),
                    span: a.span,
                });
            }
        }
        let Some(p) = param else { return out };
        for c in p.children() {
            match c.name() {
                "description" => out.push(RawEntry {
                    key: DESCRIPTION_KEY.into(),
                    value: escape_lines(c.text()),
                    span: c.text_span(),
                }),
                "property" => {
                    if let (Some(n), Some(v)) = (c.attr("name"), c.attr("value")) {
                        out.push(RawEntry {
                            key: n.value.to_owned(),
                            value: v.value.to_owned(),
                            span: c.span(),
                        });
                    }
                }
                "label" | "defaultValue" | "actualValue" | "denotation" | "dataTypeIDRef" => {}
                "allowedValues" if c.children().all(|r| r.is("range")) => {}
                n if iec_type(n).is_some() => {}
                n => out.push(RawEntry {
                    key: format!("<{n}"),
                    value: e_src(c).to_owned(),
                    span: c.span(),
                }),
            }
        }
        out
    }
}

/// The source text of an element (its span's slice).
fn e_src<'t>(e: Element<'t>) -> &'t str {
    e.source_text()
}

/// An access and a one-direction PDO mapping as an EDS says them, where it can: CiA 306 gives
/// a PDO's direction by the access alone (`rwr`/`ro`/`const` transmit, `rww`/`wo` receive), so
/// `readWrite` with `TPDO` is `rwr` and with `RPDO` is `rww`, mappable. A direction the access
/// forbids (`read` with `RPDO`) stays as the file says it (the EDS writer then picks the access
/// that allows it).
fn as_eds(access: Access, mapping: PdoMapping) -> (Access, PdoMapping) {
    match (mapping, access) {
        (PdoMapping::Tx, Access::Rw) => (Access::Rwr, PdoMapping::Yes),
        (PdoMapping::Rx, Access::Rw) => (Access::Rww, PdoMapping::Yes),
        (PdoMapping::Tx, Access::Ro | Access::Const | Access::Rwr) => (access, PdoMapping::Yes),
        (PdoMapping::Rx, Access::Wo | Access::Rww) => (access, PdoMapping::Yes),
        _ => (access, mapping),
    }
}

/// The first `label` of a parameter.
fn label<'t>(p: Element<'t>) -> Option<&'t str> {
    p.child("label").map(|l| l.text())
}

/// Line ends of a description as `\n`, so that it fits one EDS line.
pub(crate) fn escape_lines(s: &str) -> String {
    // Most descriptions are one line: one copy, no searches of the replacing kind.
    if !s.contains('\n') {
        return s.to_owned();
    }
    s.replace("\r\n", "\n").replace('\n', "\\n")
}

fn empty_of(dt: DataType) -> Value {
    match dt.class() {
        ValueClass::Bytes => Value::Bytes(Box::default()),
        ValueClass::Unicode => Value::Unicode(Box::default()),
        _ => Value::Text(Box::default()),
    }
}

/// The CANopen data type of an IEC 61131 type element (CiA 311 table 1).
pub(crate) fn iec_type(name: &str) -> Option<DataType> {
    Some(match name {
        "BOOL" => DataType::Boolean,
        "SINT" => DataType::Integer8,
        "INT" => DataType::Integer16,
        "DINT" => DataType::Integer32,
        "LINT" => DataType::Integer64,
        "USINT" | "BYTE" => DataType::Unsigned8,
        "UINT" | "WORD" => DataType::Unsigned16,
        "UDINT" | "DWORD" => DataType::Unsigned32,
        "ULINT" | "LWORD" => DataType::Unsigned64,
        "REAL" => DataType::Real32,
        "LREAL" => DataType::Real64,
        "STRING" | "CHAR" => DataType::VisibleString,
        "WSTRING" => DataType::UnicodeString,
        "BITSTRING" => DataType::OctetString,
        _ => return None,
    })
}

/// The IEC type element for a CANopen data type, where CiA 311 has one.
pub(crate) fn iec_name(dt: DataType) -> Option<&'static str> {
    Some(match dt {
        DataType::Boolean => "BOOL",
        DataType::Integer8 => "SINT",
        DataType::Integer16 => "INT",
        DataType::Integer32 => "DINT",
        DataType::Integer64 => "LINT",
        DataType::Unsigned8 => "USINT",
        DataType::Unsigned16 => "UINT",
        DataType::Unsigned32 => "UDINT",
        DataType::Unsigned64 => "ULINT",
        DataType::Real32 => "REAL",
        DataType::Real64 => "LREAL",
        DataType::VisibleString => "STRING",
        DataType::UnicodeString => "WSTRING",
        DataType::OctetString | DataType::Domain => "BITSTRING",
        _ => return None,
    })
}

/// The data type of a sub-object that says none: the object's (an ARRAY's elements, a DEFTYPE),
/// else the type CiA 301 gives it, read with a warning (F323), else none (F310, DOMAIN).
#[derive(Clone, Copy)]
enum Fallback {
    Object(DataType),
    Standard(Option<DataType>),
}

/// The element type CiA 301 §7.5.2 gives the sub-objects 1.. of its ARRAY objects, for files
/// that leave it out (F323).
fn cia301_element_type(index: u16) -> Option<DataType> {
    match index {
        0x1003 | 0x1010 | 0x1011 | 0x1016 | 0x1028 => Some(DataType::Unsigned32),
        0x1026 | 0x1029 => Some(DataType::Unsigned8),
        0x1027 => Some(DataType::Unsigned16),
        _ => None,
    }
}
