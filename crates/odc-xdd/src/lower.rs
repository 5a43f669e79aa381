//! The XML tree of an ISO 15745 container to the model: identity, object list (with the
//! parameters its `uniqueIDRef`s name), dummy usage, bit rates, network management and
//! commissioning. See the crate documentation for the policies.

use rustc_hash::{FxHashMap, FxHashSet};

use odc_esi::xml::{Attr, Document, Element};
use odc_model::{
    Access, Capped, Commissioning, DataType, Device, Diagnostic, FileId, Format, Object,
    ObjectKind, PdoMapping, RawEntry, Span, Spanned, SubObject, Value, ValueClass, ValueName,
    XmlExtra,
};

use crate::codes;

mod objects;

pub(crate) use objects::iec_name;

/// An attribute's value as a text, with its span.
fn text(a: Attr<'_>) -> Spanned<String> {
    Spanned::new(a.value.to_owned(), a.span)
}

/// The key under which a parameter's description is kept in `extra`.
pub(crate) const DESCRIPTION_KEY: &str = "Description";

struct L<'d> {
    diags: &'d mut Capped,
    // Keyed by `uniqueID`: FxHash, as std's SipHash cost a seventh of the lowering here.
    params: FxHashMap<&'d str, Element<'d>>,
    types: FxHashMap<&'d str, Element<'d>>,
    used: FxHashSet<&'d str>,
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
        params: FxHashMap::default(),
        types: FxHashMap::default(),
        used: FxHashSet::default(),
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
                // Sized once: a file has thousands of parameters.
                into.reserve(list.children().count());
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
        e.source_text()
    }

    fn err(&mut self, code: &'static str, msg: String, span: Span, label: &str) {
        self.diags.push(Diagnostic::error(code, msg).with_label(span, label));
    }

    fn warn(&mut self, code: &'static str, msg: String, span: Span, label: &str) {
        self.diags.push(Diagnostic::warning(code, msg).with_label(span, label));
    }

    /// A decimal (or CiA 306 form) unsigned number attribute of at most `max`.
    fn uint(&mut self, e: Element<'_>, name: &str, max: u64) -> Option<Spanned<u64>> {
        self.uint_of(e.attr(name), name, max)
    }

    /// [`Self::uint`] of an attribute already looked up.
    fn uint_of(&mut self, a: Option<Attr<'_>>, name: &str, max: u64) -> Option<Spanned<u64>> {
        let a = a?;
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

    /// A hex attribute (CiA 311 hexBinary, `0x` accepted) of at most `max`, of an attribute
    /// already looked up (`name` is for the diagnostics).
    fn hex(&mut self, a: Option<Attr<'_>>, name: &str, max: u64) -> Option<Spanned<u64>> {
        let a = a?;
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
        e.attr(name).map(text)
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
}
