//! The XML tree of an ISO 15745 container to the model: identity, object list (with the
//! parameters its `uniqueIDRef`s name), dummy usage, bit rates, network management and
//! commissioning. See the crate documentation for the policies.

use std::collections::{HashMap, HashSet};

use odc_esi::xml::{Document, Element};
use odc_model::{
    Access, Capped, Commissioning, DataType, Device, Diagnostic, FileId, Format, Object,
    ObjectKind, PdoMapping, RawEntry, Span, Spanned, SubObject, Value, ValueClass, XmlExtra,
};

use crate::codes;

/// The attributes of `CANopenObject`/`CANopenSubObject` this module reads; others are kept.
const KNOWN_ATTRS: &[&str] = &[
    "index",
    "subIndex",
    "name",
    "objectType",
    "dataType",
    "accessType",
    "PDOmapping",
    "defaultValue",
    "lowLimit",
    "highLimit",
    "actualValue",
    "denotation",
    "objFlags",
    "uniqueIDRef",
    "subNumber",
];

/// The key under which a parameter's description is kept in `extra`.
pub(crate) const DESCRIPTION_KEY: &str = "Description";

struct L<'d> {
    diags: &'d mut Capped,
    params: HashMap<&'d str, Element<'d>>,
    types: HashMap<&'d str, Element<'d>>,
    used: HashSet<&'d str>,
    dev: Device,
    /// An actualValue or denotation was read: the file is an XDC.
    xdc_values: bool,
}

/// Lowers the document; `None` when it is not an ISO 15745 container.
pub(crate) fn lower(
    doc: &Document<'_>,
    file: FileId,
    xdc_name: bool,
    diags: &mut Capped,
) -> Option<Device> {
    let Some(root) = doc.roots().next() else {
        diags.push(
            Diagnostic::error(codes::NOT_XDD, "the file has no XML element")
                .with_label(Span::new(file, 0, 0), ""),
        );
        return None;
    };
    if !root.is("ISO15745ProfileContainer") {
        diags.push(
            Diagnostic::error(
                codes::NOT_XDD,
                format!("the root element is `{}`, not ISO15745ProfileContainer", root.name()),
            )
            .with_label(root.span(), "")
            .with_note("a CiA 311 XDD or XDC file is an ISO 15745 profile container"),
        );
        return None;
    }
    let mut l = L {
        diags,
        params: HashMap::new(),
        types: HashMap::new(),
        used: HashSet::new(),
        dev: Device::default(),
        xdc_values: false,
    };
    let mut bodies = Vec::new();
    for prof in root.children() {
        if !prof.is("ISO15745Profile") {
            l.keep("ISO15745ProfileContainer", prof);
            continue;
        }
        for c in prof.children() {
            match c.name() {
                "ProfileBody" => bodies.push(c),
                "ProfileHeader" => {}
                _ => l.keep("ISO15745Profile", c),
            }
        }
    }
    // Parameters and types first: objects of the communication profile refer to them.
    for body in &bodies {
        for ap in body.children_named("ApplicationProcess") {
            for list in ap.children() {
                let (into, item_id) = match list.name() {
                    "parameterList" => (&mut l.params, "uniqueID"),
                    "dataTypeList" => (&mut l.types, "uniqueID"),
                    _ => continue,
                };
                for item in list.children() {
                    if let Some(id) = item.attr(item_id) {
                        into.insert(id.value, item);
                    }
                }
            }
        }
    }
    let mut first = true;
    for body in bodies {
        if first {
            l.file_info(body);
            first = false;
        }
        let device_profile = body.child("ApplicationLayers").is_none();
        let here = if device_profile { "DeviceProfile" } else { "CommunicationProfile" };
        for c in body.children() {
            match c.name() {
                "DeviceIdentity" => l.identity(c),
                "ApplicationProcess" => l.application_process(c),
                "ApplicationLayers" => l.application_layers(c),
                "TransportLayers" => l.transport_layers(c),
                "NetworkManagement" => l.network_management(c),
                _ => l.keep(here, c),
            }
        }
    }
    let mut dev = l.dev;
    dev.format = Some(if xdc_name || l.xdc_values { Format::Xdc } else { Format::Xdd });
    dev.device_info.baud_rates.sort_unstable();
    dev.device_info.baud_rates.dedup();
    dev.pdos = odc_model::pdo::resolve_canopen_pdos(&dev);
    Some(dev)
}

impl<'d> L<'d> {
    fn keep(&mut self, parent: &str, e: Element<'_>) {
        let span = e.span();
        let xml = self.text_of(e).to_owned();
        self.dev.xml_extra.push(XmlExtra { parent: parent.to_owned(), xml, span });
    }

    fn text_of<'t>(&self, e: Element<'t>) -> &'t str {
        e_src(e)
    }

    fn err(&mut self, code: &'static str, msg: String, span: Span, label: &str) {
        self.diags.push(Diagnostic::error(code, msg).with_label(span, label));
    }

    fn warn(&mut self, code: &'static str, msg: String, span: Span, label: &str) {
        self.diags.push(Diagnostic::warning(code, msg).with_label(span, label));
    }

    /// A decimal (or CiA 306 form) unsigned number attribute of at most `max`.
    fn uint(&mut self, e: Element<'_>, name: &str, max: u64) -> Option<Spanned<u64>> {
        let a = e.attr(name)?;
        let v = a.value.trim();
        if v.is_empty() {
            return None;
        }
        match odc_eds::read_value(v, DataType::Unsigned64) {
            Ok(Value::Unsigned(n)) if n <= max => Some(Spanned::new(n, a.span)),
            Ok(Value::Unsigned(_)) | Err(odc_eds::ValueError::OutOfRange) => {
                self.err(
                    codes::OUT_OF_RANGE,
                    format!("{name} `{v}` is out of range"),
                    a.span,
                    &format!("at most {max}"),
                );
                None
            }
            _ => {
                self.err(
                    codes::INVALID_NUMBER,
                    format!("{name} `{v}` is not a number"),
                    a.span,
                    "expected a number",
                );
                None
            }
        }
    }

    /// A hex attribute (CiA 311 hexBinary, `0x` accepted) of at most `max`.
    fn hex(&mut self, e: Element<'_>, name: &str, max: u64) -> Option<Spanned<u64>> {
        let a = e.attr(name)?;
        let v = a.value.trim();
        let digits = v.strip_prefix("0x").or_else(|| v.strip_prefix("0X")).unwrap_or(v);
        match u64::from_str_radix(digits, 16) {
            Ok(n) if n <= max => Some(Spanned::new(n, a.span)),
            Ok(_) => {
                self.err(
                    codes::OUT_OF_RANGE,
                    format!("{name} `{v}` is out of range"),
                    a.span,
                    &format!("at most 0x{max:X}"),
                );
                None
            }
            Err(_) => {
                self.err(
                    codes::INVALID_NUMBER,
                    format!("{name} `{v}` is not a hex number"),
                    a.span,
                    "expected hex digits",
                );
                None
            }
        }
    }

    fn boolean(&mut self, e: Element<'_>, name: &str) -> Option<Spanned<bool>> {
        let a = e.attr(name)?;
        match a.value.trim() {
            "true" | "1" => Some(Spanned::new(true, a.span)),
            "false" | "0" => Some(Spanned::new(false, a.span)),
            v => {
                self.err(
                    codes::INVALID_BOOLEAN,
                    format!("{name} `{v}` is not a boolean"),
                    a.span,
                    "expected true or false",
                );
                None
            }
        }
    }

    fn text_attr(e: Element<'_>, name: &str) -> Option<Spanned<String>> {
        // Empty is kept (`fileModifiedBy=""`), as an EDS's `ModifiedBy=` is an empty text.
        e.attr(name).map(|a| Spanned::new(a.value.to_owned(), a.span))
    }

    fn file_info(&mut self, body: Element<'_>) {
        let fi = &mut self.dev.file_info;
        fi.file_name = Self::text_attr(body, "fileName");
        fi.created_by = Self::text_attr(body, "fileCreator");
        fi.creation_date = Self::text_attr(body, "fileCreationDate");
        fi.creation_time = Self::text_attr(body, "fileCreationTime");
        fi.modified_by = Self::text_attr(body, "fileModifiedBy");
        fi.modification_date = Self::text_attr(body, "fileModificationDate");
        fi.modification_time = Self::text_attr(body, "fileModificationTime");
        if let Some(a) = body.attr("fileVersion").filter(|a| !a.value.is_empty()) {
            match a.value.trim().parse::<u8>() {
                Ok(v) => self.dev.file_info.file_version = Some(Spanned::new(v, a.span)),
                // `1.0`, `2.3`: no CiA 306 FileVersion, kept as written.
                Err(_) => self.dev.file_info.extra.push(RawEntry {
                    key: "fileVersion".into(),
                    value: a.value.to_owned(),
                    span: a.span,
                }),
            }
        }
    }

    fn identity(&mut self, id: Element<'_>) {
        for c in id.children() {
            let text = || Some(Spanned::new(c.text().to_owned(), c.text_span()));
            match c.name() {
                "vendorName" => self.dev.device_info.vendor_name = text(),
                "productName" => self.dev.device_info.product_name = text(),
                "orderNumber" => self.dev.device_info.order_code = text(),
                "vendorID" | "productID" => {
                    let t = c.text();
                    if t.is_empty() {
                        continue;
                    }
                    let v = match odc_eds::read_value(t, DataType::Unsigned32) {
                        Ok(Value::Unsigned(n)) => Some(Spanned::new(n as u32, c.text_span())),
                        _ => {
                            self.err(
                                codes::INVALID_NUMBER,
                                format!("{} `{t}` is not a 32-bit number", c.name()),
                                c.text_span(),
                                "expected a number",
                            );
                            None
                        }
                    };
                    if c.is("vendorID") {
                        self.dev.device_info.vendor_number = v;
                    } else {
                        self.dev.device_info.product_number = v;
                    }
                }
                "productText" => match c.child("description") {
                    Some(d) if c.children().count() == 1 => {
                        self.dev.file_info.description =
                            Some(Spanned::new(d.text().to_owned(), d.text_span()));
                    }
                    _ => self.keep("DeviceIdentity", c),
                },
                _ => self.keep("DeviceIdentity", c),
            }
        }
    }

    fn application_process(&mut self, ap: Element<'_>) {
        for c in ap.children() {
            match c.name() {
                // Read with the objects that refer to them; the unreferenced ones are kept
                // when the object list has been read (see `application_layers`).
                "parameterList" => {}
                _ => self.keep("ApplicationProcess", c),
            }
        }
    }

    fn application_layers(&mut self, al: Element<'d>) {
        for c in al.children() {
            match c.name() {
                "CANopenObjectList" => {
                    for o in c.children() {
                        if o.is("CANopenObject") {
                            self.object(o);
                        } else {
                            self.keep("CANopenObjectList", o);
                        }
                    }
                }
                "dummyUsage" => self.dummy_usage(c),
                _ => self.keep("ApplicationLayers", c),
            }
        }
        // Parameters no object referred to (after the objects, so that `used` is complete).
        let mut unused: Vec<Element<'_>> = self
            .params
            .iter()
            .filter(|(id, _)| !self.used.contains(*id))
            .map(|(_, e)| *e)
            .collect();
        unused.sort_by_key(|e| e.span().start);
        for p in unused {
            self.keep("parameterList", p);
        }
        self.used.extend(self.params.keys().copied());
    }

    fn dummy_usage(&mut self, du: Element<'_>) {
        for d in du.children() {
            let entry = d.attr("entry").filter(|_| d.is("dummy"));
            let parsed = entry.and_then(|a| {
                let (k, v) = a.value.split_once('=')?;
                let k = k.trim();
                k.get(..5).filter(|p| p.eq_ignore_ascii_case("dummy"))?;
                let index = u16::from_str_radix(k.get(5..)?, 16).ok()?;
                let on = match v.trim() {
                    "1" => true,
                    "0" => false,
                    _ => return None,
                };
                Some((index, Spanned::new(on, a.span)))
            });
            match parsed {
                Some((i, on)) => {
                    self.dev.dummy_usage.insert(i, on);
                }
                None => {
                    let span = entry.map_or(d.span(), |a| a.span);
                    self.err(
                        codes::INVALID_NUMBER,
                        "a dummy entry that is not `DummyNNNN=0|1`".into(),
                        span,
                        "expected DummyNNNN=0 or DummyNNNN=1",
                    );
                }
            }
        }
    }

    fn transport_layers(&mut self, tl: Element<'_>) {
        for c in tl.children() {
            let Some(br) = c.child("baudRate").filter(|_| {
                c.is("PhysicalLayer") && c.children().count() == 1 && c.attrs().next().is_none()
            }) else {
                self.keep("TransportLayers", c);
                continue;
            };
            for a in br.attrs() {
                self.dev.device_info.extra.push(RawEntry {
                    key: format!("baudRate.{}", a.name),
                    value: a.value.to_owned(),
                    span: a.span,
                });
            }
            for s in br.children() {
                let Some(v) = s.attr("value").filter(|_| s.is("supportedBaudRate")) else {
                    self.keep("TransportLayers", c);
                    continue;
                };
                let kbps =
                    v.value.trim().strip_suffix("Kbps").and_then(|n| n.trim().parse::<u32>().ok());
                match kbps {
                    Some(k) => self.dev.device_info.baud_rates.push(k),
                    // `auto-baudRate`: no CiA 306 key; kept as written.
                    None => self.dev.device_info.extra.push(RawEntry {
                        key: "supportedBaudRate".into(),
                        value: v.value.to_owned(),
                        span: v.span,
                    }),
                }
            }
        }
    }

    fn network_management(&mut self, nm: Element<'_>) {
        for c in nm.children() {
            match c.name() {
                "CANopenGeneralFeatures" => {
                    for a in c.attrs() {
                        match a.name {
                            "granularity" => {
                                self.dev.device_info.granularity = self
                                    .uint(c, a.name, 64)
                                    .map(|v| Spanned::new(v.value as u8, v.span))
                            }
                            "nrOfRxPDO" => {
                                self.dev.device_info.nr_of_rx_pdo = self
                                    .uint(c, a.name, 512)
                                    .map(|v| Spanned::new(v.value as u16, v.span))
                            }
                            "nrOfTxPDO" => {
                                self.dev.device_info.nr_of_tx_pdo = self
                                    .uint(c, a.name, 512)
                                    .map(|v| Spanned::new(v.value as u16, v.span))
                            }
                            "dynamicChannels" => {
                                self.dev.device_info.dynamic_channels_supported = self
                                    .uint(c, a.name, 255)
                                    .map(|v| Spanned::new(v.value as u8, v.span))
                            }
                            "layerSettingServiceSlave" => {
                                self.dev.device_info.lss_supported = self.boolean(c, a.name)
                            }
                            "groupMessaging" => {
                                self.dev.device_info.group_messaging = self.boolean(c, a.name)
                            }
                            "bootUpSlave" => {
                                self.dev.device_info.simple_boot_up_slave = self.boolean(c, a.name)
                            }
                            _ => self.dev.device_info.extra.push(RawEntry {
                                key: a.name.to_owned(),
                                value: a.value.to_owned(),
                                span: a.span,
                            }),
                        }
                    }
                    if c.children().next().is_some() {
                        self.keep("NetworkManagement", c);
                    }
                }
                "CANopenMasterFeatures" => {
                    for a in c.attrs() {
                        match a.name {
                            "bootUpMaster" => {
                                self.dev.device_info.simple_boot_up_master = self.boolean(c, a.name)
                            }
                            _ => self.dev.device_info.extra.push(RawEntry {
                                key: format!("master.{}", a.name),
                                value: a.value.to_owned(),
                                span: a.span,
                            }),
                        }
                    }
                }
                "deviceCommissioning" => self.commissioning(c),
                _ => self.keep("NetworkManagement", c),
            }
        }
    }

    fn commissioning(&mut self, c: Element<'_>) {
        let mut dc = Commissioning { span: c.span(), ..Commissioning::default() };
        for a in c.attrs() {
            match a.name {
                "nodeID" => {
                    dc.node_id =
                        self.uint(c, a.name, 255).map(|v| Spanned::new(v.value as u8, v.span))
                }
                "nodeName" => dc.node_name = Self::text_attr(c, a.name),
                "actualBaudRate" => {
                    dc.baudrate = self
                        .uint(c, a.name, u64::from(u32::MAX))
                        .map(|v| Spanned::new(v.value as u32, v.span))
                }
                "networkNumber" => {
                    dc.net_number = self
                        .uint(c, a.name, u64::from(u32::MAX))
                        .map(|v| Spanned::new(v.value as u32, v.span))
                }
                "networkName" => dc.network_name = Self::text_attr(c, a.name),
                "CANopenManager" => dc.canopen_manager = self.boolean(c, a.name),
                _ => dc.extra.push(RawEntry {
                    key: a.name.to_owned(),
                    value: a.value.to_owned(),
                    span: a.span,
                }),
            }
        }
        self.dev.commissioning = Some(dc);
    }

    fn object(&mut self, o: Element<'d>) {
        let Some(index) = o.attr("index").map(|_| self.hex(o, "index", 0xFFFF)) else {
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
        let param = self.param(o);
        let has_children = o.children().next().is_some();
        let kind = match self.uint(o, "objectType", 255) {
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
        let name = match (o.attr("name"), param.and_then(label)) {
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
        obj.sub_number =
            self.uint(o, "subNumber", 0xFFFF).map(|v| Spanned::new(v.value as u16, v.span));
        obj.obj_flags = self.hex_opt(o, "objFlags");
        let object_type = o.attr("dataType").and_then(|_| self.data_type_attr(o));
        if kind.has_subs() {
            obj.denotation = Self::text_attr(o, "denotation").filter(|d| !d.value.is_empty());
            if obj.denotation.is_some() {
                self.xdc_values = true;
            }
            obj.extra = self.extras(o, param);
            for s in o.children() {
                if !s.is("CANopenSubObject") {
                    self.keep_in_object(&mut obj, s);
                    continue;
                }
                let Some(si) = s.attr("subIndex").map(|_| self.hex(s, "subIndex", 0xFF)) else {
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
                let inherit = if kind == ObjectKind::Array && si > 0 { object_type } else { None };
                let sparam = self.param(s);
                let mut sub =
                    self.sub(s, sparam, si, inherit, &format!("sub-object {index:04X}sub{si:X}"));
                sub.name = s
                    .attr("name")
                    .map(|a| a.value)
                    .or_else(|| sparam.and_then(label))
                    .unwrap_or_default()
                    .into();
                let kind_attr = s
                    .attr("objectType")
                    .and_then(|a| a.value.trim().parse::<u8>().ok())
                    .and_then(ObjectKind::from_code);
                sub.kind = kind_attr;
                let extra = self.extras(s, sparam);
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
            let mut sub = self.sub(o, param, 0, default_dt, &format!("object {index:04X}"));
            sub.name = name.into();
            obj.extra = self.extras(o, param);
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

    fn hex_opt(&mut self, e: Element<'_>, name: &str) -> Option<Spanned<u32>> {
        e.attr(name).filter(|a| !a.value.trim().is_empty())?;
        self.hex(e, name, u64::from(u32::MAX)).map(|v| Spanned::new(v.value as u32, v.span))
    }

    /// The parameter an element's `uniqueIDRef` names, marked as used.
    fn param(&mut self, e: Element<'_>) -> Option<Element<'d>> {
        let r = e.attr("uniqueIDRef")?;
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
    fn data_type_attr(&mut self, e: Element<'_>) -> Option<DataType> {
        let v = self.hex(e, "dataType", 0xFFFF)?;
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
        param: Option<Element<'d>>,
        si: u8,
        inherit: Option<DataType>,
        what: &str,
    ) -> SubObject {
        let dt = match e.attr("dataType") {
            Some(_) => self.data_type_attr(e),
            None => None,
        };
        let dt = dt.or_else(|| param.and_then(|p| self.param_type(p))).or(inherit);
        let dt = dt.unwrap_or_else(|| {
            self.err(
                codes::MISSING_DATA_TYPE,
                format!("{what} has no data type; read as DOMAIN"),
                e.span(),
                "no dataType, and no type in its parameter",
            );
            DataType::Domain
        });
        let access = self.access(e, param, what);
        let mut sub = SubObject::new(si, "", dt, access);
        sub.span = e.span();
        sub.pdo_mapping = match e.attr("PDOmapping") {
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
        let pick = |attr: &str, from_param: Option<odc_esi::xml::Attr<'d>>| {
            e.attr(attr)
                .filter(|a| !a.value.is_empty())
                .or(from_param.filter(|a| !a.value.is_empty()))
        };
        let string_like =
            matches!(dt.class(), ValueClass::Text | ValueClass::Bytes | ValueClass::Unicode);
        sub.default = match (e.attr("defaultValue").or(pv("defaultValue")), string_like) {
            (Some(a), true) if a.value.is_empty() => Some(Spanned::new(empty_of(dt), a.span)),
            _ => pick("defaultValue", pv("defaultValue")).and_then(|a| self.value(a, dt)),
        };
        sub.low_limit =
            pick("lowLimit", rv("minValue")).and_then(|a| self.value(a, dt)).map(Box::new);
        sub.high_limit =
            pick("highLimit", rv("maxValue")).and_then(|a| self.value(a, dt)).map(Box::new);
        sub.parameter_value =
            pick("actualValue", pv("actualValue")).and_then(|a| self.value(a, dt));
        if sub.parameter_value.is_some() {
            self.xdc_values = true;
        }
        let denotation = e
            .attr("denotation")
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
        // A VAR's objFlags are the object's (as in an EDS).
        if e.is("CANopenSubObject")
            && let Some(f) = self.hex_opt(e, "objFlags")
        {
            sub.rare_mut().obj_flags = Some(f);
        }
        sub
    }

    fn value(&mut self, a: odc_esi::xml::Attr<'_>, dt: DataType) -> Option<Spanned<Value>> {
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

    fn access(&mut self, e: Element<'_>, param: Option<Element<'_>>, what: &str) -> Access {
        if let Some(a) = e.attr("accessType").filter(|a| !a.value.is_empty()) {
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
    fn extras(&mut self, e: Element<'_>, param: Option<Element<'_>>) -> Vec<RawEntry> {
        let mut out = Vec::new();
        for a in e.attrs() {
            if !KNOWN_ATTRS.contains(&a.name) {
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
