//! The writer: model → CiA 311 XDD or XDC text. Deterministic: the same model gives the same
//! bytes.
//!
//! Objects are written in the attribute form of CiA 311 (`dataType`, `accessType`,
//! `defaultValue`, ... on `CANopenObject`), which every XDD reader understands and which holds
//! all the model has; a parameter is written only for an object with data the attributes have
//! no place for (its description, kept properties and elements), and holds those in order.
//! What the model holds and an XDD cannot (an EDS's `[Comments]`, object lists, modules,
//! `CompactPDO`, ...) is left out and named in [`Written::lost`].

use std::fmt::Write as _;

use odc_model::{Device, Format, Object, Origin, PdoMapping, RawEntry, SubObject, Value, XmlExtra};

use crate::lower::{DESCRIPTION_KEY, iec_name};

/// What [`write()`] produced.
#[derive(Debug)]
pub struct Written {
    /// The XDD/XDC text.
    pub text: String,
    /// What the model holds that the file has no place for, one line each (for a warning).
    pub lost: Vec<String>,
}

struct W<'a> {
    out: String,
    dev: &'a Device,
    xdc: bool,
    lost: Vec<String>,
}

/// Writes `dev` as XDD (`Format::Xdc` for XDC: actual values, denotations and commissioning;
/// any other format writes XDD).
pub fn write(dev: &Device, format: Format) -> Written {
    let mut w = W {
        out: String::with_capacity(256 * 1024),
        dev,
        xdc: format == Format::Xdc,
        lost: Vec::new(),
    };
    w.document();
    w.report_lost();
    Written { text: w.out, lost: w.lost }
}

/// XML-escaped attribute or text content (line ends and tabs as character references, so
/// that attribute-value normalisation keeps them).
fn esc(s: &str) -> String {
    let mut o = String::with_capacity(s.len());
    for c in s.chars() {
        match c {
            '&' => o.push_str("&amp;"),
            '<' => o.push_str("&lt;"),
            '>' => o.push_str("&gt;"),
            '"' => o.push_str("&quot;"),
            '\'' => o.push_str("&apos;"),
            '\n' => o.push_str("&#10;"),
            '\r' => o.push_str("&#13;"),
            '\t' => o.push_str("&#9;"),
            c => o.push(c),
        }
    }
    o
}

fn value(v: &Value) -> String {
    esc(&odc_analysis::value_text(v))
}

impl W<'_> {
    fn line(&mut self, depth: usize, s: &str) {
        for _ in 0..depth {
            self.out.push_str("  ");
        }
        self.out.push_str(s);
        self.out.push('\n');
    }

    fn kept(&mut self, depth: usize, parent: &str) {
        let items: Vec<&XmlExtra> =
            self.dev.xml_extra.iter().filter(|x| x.parent == parent).collect();
        for x in items {
            self.line(depth, &x.xml);
        }
    }

    fn attr(s: &mut String, name: &str, v: &str) {
        let _ = write!(s, " {name}=\"{}\"", esc(v));
    }

    fn file_attrs(&self) -> String {
        let fi = &self.dev.file_info;
        let mut s = String::new();
        let opt = |s: &mut String, n: &str, v: &Option<odc_model::Spanned<String>>| {
            if let Some(v) = v {
                Self::attr(s, n, &v.value);
            }
        };
        opt(&mut s, "fileName", &fi.file_name);
        opt(&mut s, "fileCreator", &fi.created_by);
        opt(&mut s, "fileCreationDate", &fi.creation_date);
        opt(&mut s, "fileCreationTime", &fi.creation_time);
        opt(&mut s, "fileModifiedBy", &fi.modified_by);
        opt(&mut s, "fileModificationDate", &fi.modification_date);
        opt(&mut s, "fileModificationTime", &fi.modification_time);
        if let Some(v) = &fi.file_version {
            Self::attr(&mut s, "fileVersion", &v.value.to_string());
        } else if let Some(e) = fi.extra.iter().find(|e| e.key == "fileVersion") {
            Self::attr(&mut s, "fileVersion", &e.value);
        }
        s
    }

    fn header(&mut self, what: &str, class: &str) {
        self.line(2, "<ProfileHeader>");
        self.line(3, &format!("<ProfileIdentification>{what}</ProfileIdentification>"));
        self.line(3, "<ProfileRevision>1.1</ProfileRevision>");
        self.line(3, "<ProfileName />");
        self.line(3, "<ProfileSource />");
        self.line(3, &format!("<ProfileClassID>{class}</ProfileClassID>"));
        self.line(3, "<ISO15745Reference>");
        self.line(4, "<ISO15745Part>1</ISO15745Part>");
        self.line(4, "<ISO15745Edition>1</ISO15745Edition>");
        self.line(4, "<ProfileTechnology>CANopen</ProfileTechnology>");
        self.line(3, "</ISO15745Reference>");
        self.line(2, "</ProfileHeader>");
    }

    fn document(&mut self) {
        self.line(0, "<?xml version=\"1.0\" encoding=\"utf-8\"?>");
        self.line(0, "<!--written by odc-->");
        self.line(0, "<ISO15745ProfileContainer xmlns=\"http://www.canopen.org/xml/1.1\" xmlns:xsi=\"http://www.w3.org/2001/XMLSchema-instance\">");
        self.line(1, "<ISO15745Profile>");
        self.header("CANopen device profile", "Device");
        let fa = self.file_attrs();
        self.line(2, &format!("<ProfileBody xsi:type=\"ProfileBody_Device_CANopen\" formatName=\"CANopen\" formatVersion=\"1.0\"{fa} supportedLanguages=\"en\">"));
        self.identity();
        self.kept(3, "DeviceProfile");
        self.line(3, "<ApplicationProcess>");
        self.kept(4, "ApplicationProcess");
        self.line(4, "<parameterList>");
        self.parameters();
        self.kept(5, "parameterList");
        self.line(4, "</parameterList>");
        self.line(3, "</ApplicationProcess>");
        self.line(2, "</ProfileBody>");
        self.kept(2, "ISO15745Profile");
        self.line(1, "</ISO15745Profile>");
        self.line(1, "<ISO15745Profile>");
        self.header("CANopen communication network profile", "CommunicationNetwork");
        self.line(2, &format!("<ProfileBody xsi:type=\"ProfileBody_CommunicationNetwork_CANopen\" formatName=\"CANopen\" formatVersion=\"1.0\"{fa} supportedLanguages=\"en\">"));
        self.line(3, "<ApplicationLayers>");
        self.line(4, "<CANopenObjectList>");
        let dev = self.dev;
        for o in dev.objects.values() {
            self.object(o);
        }
        self.kept(5, "CANopenObjectList");
        self.line(4, "</CANopenObjectList>");
        self.line(4, "<dummyUsage>");
        for (i, on) in &dev.dummy_usage {
            self.line(5, &format!("<dummy entry=\"Dummy{i:04X}={}\" />", u8::from(on.value)));
        }
        self.line(4, "</dummyUsage>");
        self.kept(4, "ApplicationLayers");
        self.line(3, "</ApplicationLayers>");
        self.transport();
        self.network_management();
        self.kept(3, "CommunicationProfile");
        self.line(2, "</ProfileBody>");
        self.line(1, "</ISO15745Profile>");
        self.kept(1, "ISO15745ProfileContainer");
        self.line(0, "</ISO15745ProfileContainer>");
    }

    fn identity(&mut self) {
        let di = &self.dev.device_info;
        self.line(3, "<DeviceIdentity>");
        if let Some(v) = &di.vendor_name {
            self.line(4, &format!("<vendorName>{}</vendorName>", esc(&v.value)));
        }
        if let Some(v) = &di.vendor_number {
            self.line(4, &format!("<vendorID>0x{:08X}</vendorID>", v.value));
        }
        if let Some(v) = &di.product_name {
            self.line(4, &format!("<productName>{}</productName>", esc(&v.value)));
        }
        if let Some(v) = &di.product_number {
            self.line(4, &format!("<productID>0x{:08X}</productID>", v.value));
        }
        if let Some(v) = &di.order_code {
            self.line(4, &format!("<orderNumber>{}</orderNumber>", esc(&v.value)));
        }
        if let Some(d) = &self.dev.file_info.description {
            self.line(
                4,
                &format!(
                    "<productText><description lang=\"en\">{}</description></productText>",
                    esc(&d.value)
                ),
            );
        }
        self.kept(4, "DeviceIdentity");
        self.line(3, "</DeviceIdentity>");
    }

    fn transport(&mut self) {
        let di = &self.dev.device_info;
        self.line(3, "<TransportLayers>");
        self.line(4, "<PhysicalLayer>");
        let mut attrs = String::new();
        for e in &di.extra {
            if let Some(n) = e.key.strip_prefix("baudRate.") {
                Self::attr(&mut attrs, n, &e.value);
            }
        }
        self.line(5, &format!("<baudRate{attrs}>"));
        for b in &di.baud_rates {
            self.line(6, &format!("<supportedBaudRate value=\"{b} Kbps\" />"));
        }
        for e in di.extra.iter().filter(|e| e.key == "supportedBaudRate") {
            self.line(6, &format!("<supportedBaudRate value=\"{}\" />", esc(&e.value)));
        }
        self.line(5, "</baudRate>");
        self.line(4, "</PhysicalLayer>");
        self.kept(4, "TransportLayers");
        self.line(3, "</TransportLayers>");
    }

    fn network_management(&mut self) {
        let di = &self.dev.device_info;
        self.line(3, "<NetworkManagement>");
        let mut g = String::new();
        let b = |v: bool| if v { "true" } else { "false" };
        if let Some(v) = &di.group_messaging {
            Self::attr(&mut g, "groupMessaging", b(v.value));
        }
        if let Some(v) = &di.dynamic_channels_supported {
            Self::attr(&mut g, "dynamicChannels", &v.value.to_string());
        }
        if let Some(v) = &di.granularity {
            Self::attr(&mut g, "granularity", &v.value.to_string());
        }
        if let Some(v) = &di.nr_of_rx_pdo {
            Self::attr(&mut g, "nrOfRxPDO", &v.value.to_string());
        }
        if let Some(v) = &di.nr_of_tx_pdo {
            Self::attr(&mut g, "nrOfTxPDO", &v.value.to_string());
        }
        if let Some(v) = &di.simple_boot_up_slave {
            Self::attr(&mut g, "bootUpSlave", b(v.value));
        }
        if let Some(v) = &di.lss_supported {
            Self::attr(&mut g, "layerSettingServiceSlave", b(v.value));
        }
        let mut m = String::new();
        if let Some(v) = &di.simple_boot_up_master {
            Self::attr(&mut m, "bootUpMaster", b(v.value));
        }
        for e in &di.extra {
            if e.key == "supportedBaudRate" || e.key.starts_with("baudRate.") {
                continue;
            }
            match e.key.strip_prefix("master.") {
                Some(n) if is_name(n) => Self::attr(&mut m, n, &e.value),
                None if is_name(&e.key) => Self::attr(&mut g, &e.key, &e.value),
                _ => self.lost.push(format!("[DeviceInfo] {}={}", e.key, e.value)),
            }
        }
        self.line(4, &format!("<CANopenGeneralFeatures{g} />"));
        self.line(4, &format!("<CANopenMasterFeatures{m} />"));
        // Written in an XDD too when the model has it: CANopenEditor's XDD files carry one.
        if let Some(dc) = &self.dev.commissioning {
            {
                let mut a = String::new();
                if let Some(v) = &dc.node_id {
                    Self::attr(&mut a, "nodeID", &v.value.to_string());
                }
                if let Some(v) = &dc.node_name {
                    Self::attr(&mut a, "nodeName", &v.value);
                }
                if let Some(v) = &dc.baudrate {
                    Self::attr(&mut a, "actualBaudRate", &v.value.to_string());
                }
                if let Some(v) = &dc.net_number {
                    Self::attr(&mut a, "networkNumber", &v.value.to_string());
                }
                if let Some(v) = &dc.network_name {
                    Self::attr(&mut a, "networkName", &v.value);
                }
                if let Some(v) = &dc.canopen_manager {
                    Self::attr(&mut a, "CANopenManager", b(v.value));
                }
                for e in &dc.extra {
                    if is_name(&e.key) {
                        Self::attr(&mut a, &e.key, &e.value);
                    } else {
                        self.lost.push(format!("[DeviceComissioning] {}={}", e.key, e.value));
                    }
                }
                for (what, v) in [
                    (
                        "LSS_SerialNumber",
                        dc.lss_serial_number.as_ref().map(|v| format!("0x{:X}", v.value)),
                    ),
                    ("NodeRefd", dc.node_refd.as_ref().map(|v| v.value.clone())),
                    ("NetRefd", dc.net_refd.as_ref().map(|v| v.value.clone())),
                ] {
                    if let Some(v) = v {
                        self.lost.push(format!("[DeviceComissioning] {what}={v}"));
                    }
                }
                self.line(4, &format!("<deviceCommissioning{a} />"));
            }
        }
        self.kept(4, "NetworkManagement");
        self.line(3, "</NetworkManagement>");
    }

    /// The attributes a sub-object (or a VAR's sub-object 0) is written with.
    fn sub_attrs(&mut self, s: &SubObject, at: &str) -> String {
        let mut a = String::new();
        let _ = write!(a, " dataType=\"{:04X}\"", s.data_type.code());
        let _ = write!(a, " accessType=\"{}\"", access_text(s.access));
        let pdo = match s.pdo_mapping {
            PdoMapping::No => "no",
            PdoMapping::Yes => "optional",
            PdoMapping::Tx => "TPDO",
            PdoMapping::Rx => "RPDO",
            PdoMapping::Both => {
                self.lost
                    .push(format!("{at}: PDO mapping in both directions (written as optional)"));
                "optional"
            }
        };
        let _ = write!(a, " PDOmapping=\"{pdo}\"");
        if let Some(v) = &s.default {
            let _ = write!(a, " defaultValue=\"{}\"", value(&v.value));
        }
        if let Some(v) = &s.low_limit {
            let _ = write!(a, " lowLimit=\"{}\"", value(&v.value));
        }
        if let Some(v) = &s.high_limit {
            let _ = write!(a, " highLimit=\"{}\"", value(&v.value));
        }
        let r = s.rare();
        if self.xdc {
            if let Some(v) = &s.parameter_value {
                let _ = write!(a, " actualValue=\"{}\"", value(&v.value));
            }
            if let Some(v) = &r.denotation {
                let _ = write!(a, " denotation=\"{}\"", esc(&v.value));
            }
        } else if s.parameter_value.is_some() || r.denotation.is_some() {
            self.lost
                .push(format!("{at}: actual value or denotation (an XDD has none; write an XDC)"));
        }
        if let Some(f) = &r.obj_flags {
            let _ = write!(a, " objFlags=\"{:04X}\"", f.value);
        }
        for (what, v) in [("UploadFile", &r.upload_file), ("DownloadFile", &r.download_file)] {
            if let Some(v) = v {
                self.lost.push(format!("{at}: {what}={}", v.value));
            }
        }
        if s.bit_size.is_some_and(|b| Some(b) != s.data_type.bit_size()) {
            self.lost.push(format!("{at}: bit size {:?}", s.bit_size));
        }
        a
    }

    fn object(&mut self, o: &Object) {
        let at = format!("object {:04X}", o.index);
        if o.origin == Origin::CompactPdo {
            self.lost.push(format!(
                "{at}: implied by CompactPDO, written out (an XDD has no CompactPDO)"
            ));
        }
        let mut head = format!(
            "<CANopenObject index=\"{:04X}\" name=\"{}\" objectType=\"{}\"",
            o.index,
            esc(&o.name),
            o.kind.code()
        );
        if o.compact_sub_obj.is_some() {
            self.lost.push(format!("{at}: CompactSubObj (its sub-objects are written out)"));
        }
        if !o.links.is_empty() {
            self.lost.push(format!("{at}: ObjectLinks"));
        }
        let extra: &[RawEntry] = &o.extra;
        if !o.kind.has_subs() {
            if let Some(s) = o.subs.get(&0) {
                if s.name != o.name.as_str() {
                    self.lost.push(format!("{at}: sub-object 0 name `{}`", s.name));
                }
                let a = self.sub_attrs(s, &at);
                head.push_str(&a);
            }
            for s in o.subs.values().filter(|s| s.sub_index != 0) {
                self.lost.push(format!("{at}: sub-object {} of a {:?}", s.sub_index, o.kind));
            }
        } else {
            if let Some(n) = &o.sub_number {
                let _ = write!(head, " subNumber=\"{}\"", n.value);
            }
            if let Some(f) = &o.obj_flags {
                let _ = write!(head, " objFlags=\"{:04X}\"", f.value);
            }
            if let Some(d) = &o.denotation {
                if self.xdc {
                    let _ = write!(head, " denotation=\"{}\"", esc(&d.value));
                } else {
                    self.lost.push(format!("{at}: denotation (an XDD has none; write an XDC)"));
                }
            }
        }
        if !o.kind.has_subs() {
            if let Some(f) = &o.obj_flags {
                let _ = write!(head, " objFlags=\"{:04X}\"", f.value);
            }
            if let Some(d) = &o.denotation {
                self.lost.push(format!("{at}: object denotation `{}` of a VAR", d.value));
            }
        }
        if !extra.is_empty() {
            let _ = write!(head, " uniqueIDRef=\"UID_OBJ_{:04X}\"", o.index);
        }
        if !o.kind.has_subs() {
            self.line(5, &format!("{head} />"));
            return;
        }
        self.line(5, &format!("{head}>"));
        for s in o.subs.values() {
            let sat = format!("{at} sub {}", s.sub_index);
            let mut line = format!(
                "<CANopenSubObject subIndex=\"{:02X}\" name=\"{}\"",
                s.sub_index,
                esc(&s.name)
            );
            if let Some(k) = s.kind {
                let _ = write!(line, " objectType=\"{}\"", k.code());
            }
            let a = self.sub_attrs(s, &sat);
            line.push_str(&a);
            if !s.rare().extra.is_empty() {
                let _ = write!(line, " uniqueIDRef=\"UID_SUB_{:04X}{:02X}\"", o.index, s.sub_index);
            }
            self.line(6, &format!("{line} />"));
        }
        self.line(5, "</CANopenObject>");
    }

    /// The parameters of the objects and sub-objects that have kept entries.
    fn parameters(&mut self) {
        let dev = self.dev;
        for o in dev.objects.values() {
            if !o.extra.is_empty() {
                let dt = o.var().map(|s| s.data_type);
                self.parameter(&format!("UID_OBJ_{:04X}", o.index), &o.name, dt, &o.extra);
            }
            if o.kind.has_subs() {
                for s in o.subs.values().filter(|s| !s.rare().extra.is_empty()) {
                    self.parameter(
                        &format!("UID_SUB_{:04X}{:02X}", o.index, s.sub_index),
                        &s.name,
                        Some(s.data_type),
                        &s.rare().extra,
                    );
                }
            }
        }
    }

    fn parameter(
        &mut self,
        id: &str,
        name: &str,
        dt: Option<odc_model::DataType>,
        extra: &[RawEntry],
    ) {
        self.line(5, &format!("<parameter uniqueID=\"{id}\">"));
        self.line(6, &format!("<label lang=\"en\">{}</label>", esc(name)));
        if let Some(t) = dt.and_then(iec_name) {
            self.line(6, &format!("<{t} />"));
        }
        // In the order kept: the reader keeps them in document order.
        for e in extra {
            if e.key == DESCRIPTION_KEY {
                let text = esc(&e.value.replace("\\n", "\n"));
                self.line(6, &format!("<description lang=\"en\">{text}</description>"));
            } else if e.key.starts_with('<') {
                self.line(6, &e.value);
            } else {
                let (k, v) = (esc(&e.key), esc(&e.value));
                self.line(6, &format!("<property name=\"{k}\" value=\"{v}\" />"));
            }
        }
        self.line(5, "</parameter>");
    }

    fn report_lost(&mut self) {
        let d = self.dev;
        let fi = &d.file_info;
        if let Some(v) = &fi.file_revision {
            self.lost.push(format!("[FileInfo] FileRevision={}", v.value));
        }
        if let Some(v) = &fi.eds_version {
            self.lost.push(format!("[FileInfo] EDSVersion={}", v.value));
        }
        for e in fi.extra.iter().filter(|e| e.key != "fileVersion") {
            self.lost.push(format!("[FileInfo] {}={}", e.key, e.value));
        }
        if let Some(v) = &d.device_info.revision_number {
            self.lost.push(format!(
                "[DeviceInfo] RevisionNumber=0x{:X} (0x1018 sub 3 holds it)",
                v.value
            ));
        }
        if let Some(v) = &d.device_info.compact_pdo {
            self.lost.push(format!("[DeviceInfo] CompactPDO=0x{:X}", v.value));
        }
        if !d.comments.is_empty() {
            self.lost.push(format!("[Comments]: {} line(s)", d.comments.len()));
        }
        let l = &d.object_lists;
        if l.mandatory.is_some() || l.optional.is_some() || l.manufacturer.is_some() {
            self.lost.push(
                "the object lists ([MandatoryObjects], ...): an XDD lists the objects themselves"
                    .into(),
            );
        }
        if !d.modules.supported.is_empty() || !d.modules.connected.is_empty() {
            self.lost.push(format!("{} module(s)", d.modules.supported.len()));
        }
        for s in &d.extra_sections {
            self.lost.push(format!("[{}]", s.name));
        }
        if d.ethercat.is_some() {
            self.lost.push("the EtherCAT data (sync managers, mailbox, ...)".into());
        }
    }
}

fn access_text(a: odc_model::Access) -> &'static str {
    use odc_model::Access::*;
    match a {
        Ro => "ro",
        Wo => "wo",
        Rw => "rw",
        Rwr => "rwr",
        Rww => "rww",
        Const => "const",
    }
}

/// Whether `s` can be an XML attribute name (ASCII letters, digits, `_`, `-`, `.`, not first
/// a digit, `-` or `.`).
fn is_name(s: &str) -> bool {
    let mut b = s.bytes();
    b.next().is_some_and(|c| c.is_ascii_alphabetic() || c == b'_')
        && b.all(|c| c.is_ascii_alphanumeric() || matches!(c, b'_' | b'-' | b'.'))
}
