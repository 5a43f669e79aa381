//! The writer: model → EDS/DCF text with CiA 306 spellings and canonical values.

use odc_model::subs::implied_name;
use odc_model::{
    Access, Device, Direction, Format, Module, Object, Origin, PdoMapping, RawEntry, Spanned,
    SubObject, Value,
};

use odc_analysis::value_text;

use crate::lower::{COMPACT_SUB0_NAME, is_compact_template_key};

/// The access to write for a sub-object. An EDS says in which PDOs an object may be mapped
/// through its access alone (CiA 306 §4.6.3: `ro`/`rwr` transmit, `wo`/`rww` receive, `rw`
/// both); an ESI says it apart (`PdoMapping` R, T, RT). Where the access forbids a direction
/// the ESI allows, it becomes the access that allows it: an ESI `ro` object mappable into
/// RxPDOs becomes `rww` (readable, written by the PDO), since no EDS access is read-only by SDO
/// yet RPDO-mappable. Every other access is written as read.
fn eds_access(s: &SubObject) -> Access {
    let a = s.access;
    let (rx, tx) = match s.pdo_mapping {
        PdoMapping::No | PdoMapping::Yes => return a,
        PdoMapping::Rx => (true, false),
        PdoMapping::Tx => (false, true),
        PdoMapping::Both => (true, true),
    };
    let yes = |dir| PdoMapping::Yes.allows(a, dir);
    if (!rx || yes(Direction::Rx)) && (!tx || yes(Direction::Tx)) {
        return a;
    }
    match (rx, tx) {
        (true, true) => Access::Rw,
        (true, false) => Access::Rww,
        _ => Access::Rwr,
    }
}

struct W {
    out: String,
    dcf: bool,
    /// The model was read from an EDS, DCF, XDD or XDC: what it lacks, the file lacked.
    from_eds: bool,
}

impl W {
    fn header(&mut self, name: &str) {
        if !self.out.is_empty() {
            self.out.push('\n');
        }
        self.out.push('[');
        self.out.push_str(name);
        self.out.push_str("]\n");
    }
    fn kv(&mut self, k: &str, v: &str) {
        self.out.push_str(k);
        self.out.push('=');
        self.out.push_str(v);
        self.out.push('\n');
    }
    fn opt_text(&mut self, k: &str, v: &Option<Spanned<String>>) {
        self.opt_text_ref(k, v.as_ref());
    }
    fn opt_text_ref(&mut self, k: &str, v: Option<&Spanned<String>>) {
        if let Some(v) = v {
            self.kv(k, &v.value);
        }
    }
    fn opt_hex<T: Copy + Into<u64>>(&mut self, k: &str, v: &Option<Spanned<T>>) {
        if let Some(v) = v {
            self.kv(k, &format!("0x{:X}", v.value.into()));
        }
    }
    fn opt_dec<T: Copy + Into<u64>>(&mut self, k: &str, v: &Option<Spanned<T>>) {
        if let Some(v) = v {
            self.kv(k, &v.value.into().to_string());
        }
    }
    fn opt_bool(&mut self, k: &str, v: &Option<Spanned<bool>>) {
        if let Some(v) = v {
            self.kv(k, if v.value { "1" } else { "0" });
        }
    }
    fn opt_value(&mut self, k: &str, v: Option<&Spanned<Value>>) {
        if let Some(v) = v {
            self.kv(k, &value_text(&v.value));
        }
    }
    /// A limit: an empty one reads back as absent, so a limit of zero bytes (read from `0x`)
    /// is written `0x`.
    fn opt_limit(&mut self, k: &str, v: Option<&Spanned<Value>>) {
        match v.map(|v| &v.value) {
            Some(Value::Bytes(b)) if b.is_empty() => self.kv(k, "0x"),
            _ => self.opt_value(k, v),
        }
    }
    fn extra(&mut self, extra: &[RawEntry]) {
        for e in extra {
            self.kv(&e.key, &e.value);
        }
    }
    fn lines(&mut self, name: &str, lines: &[String]) {
        if lines.is_empty() {
            return;
        }
        self.header(name);
        self.kv("Lines", &lines.len().to_string());
        for (i, l) in lines.iter().enumerate() {
            self.kv(&format!("Line{}", i + 1), l);
        }
    }
    fn index_list(&mut self, name: &str, count_key: &str, items: &[u16]) {
        self.header(name);
        self.kv(count_key, &items.len().to_string());
        for (i, x) in items.iter().enumerate() {
            self.kv(&(i + 1).to_string(), &format!("0x{x:04X}"));
        }
    }

    /// The keys of a sub-object (or of a VAR's section), without ParameterName.
    fn sub_keys(&mut self, s: &SubObject, obj_flags: Option<&Spanned<u32>>) {
        if let Some(k) = s.kind {
            self.kv("ObjectType", &format!("0x{:X}", k.code()));
        }
        self.kv("DataType", &format!("0x{:04X}", s.data_type.code()));
        self.kv("AccessType", eds_access(s).as_str());
        self.opt_value("DefaultValue", s.default.as_ref());
        self.opt_limit("LowLimit", s.low_limit.as_deref());
        self.opt_limit("HighLimit", s.high_limit.as_deref());
        if self.dcf {
            self.opt_value("ParameterValue", s.parameter_value.as_ref());
            self.opt_text_ref("Denotation", s.rare().denotation.as_ref());
        }
        self.kv("PDOMapping", if s.pdo_mapping == PdoMapping::No { "0" } else { "1" });
        if let Some(f) = obj_flags {
            self.kv("ObjFlags", &format!("0x{:X}", f.value));
        }
        self.opt_text_ref("UploadFile", s.rare().upload_file.as_ref());
        self.opt_text_ref("DownloadFile", s.rare().download_file.as_ref());
    }

    fn sub_section(&mut self, name: &str, s: &SubObject) {
        self.header(name);
        self.kv("ParameterName", &s.name);
        self.sub_keys(s, s.rare().obj_flags.as_ref());
        self.extra(&s.rare().extra);
    }

    fn object(&mut self, prefix: &str, o: &Object) {
        let name = format!("{prefix}{:04X}", o.index);
        self.header(&name);
        self.kv("ParameterName", &o.name);
        self.kv("ObjectType", &format!("0x{:X}", o.kind.code()));
        if !o.kind.has_subs() {
            // A SubNumber on a VAR is wrong (warned about) but kept, so it is written back.
            self.opt_dec("SubNumber", &o.sub_number);
            if let Some(s0) = o.subs.get(&0) {
                self.sub_keys(s0, o.obj_flags.as_ref().or(s0.rare().obj_flags.as_ref()));
                self.extra(&s0.rare().extra);
            } else if let Some(f) = &o.obj_flags {
                self.kv("ObjFlags", &format!("0x{:X}", f.value));
            }
            self.extra(&o.extra);
            for (i, s) in o.subs.range(1..) {
                self.sub_section(&format!("{name}sub{i:X}"), s);
            }
            self.links(&name, o);
            return;
        }
        match &o.sub_number {
            Some(n) => self.kv("SubNumber", &n.value.to_string()),
            // A model that was not read from an EDS/DCF (an ESI device, a model built in code)
            // has no SubNumber: CiA 306 §4.5.2 wants it on every ARRAY/RECORD not written
            // compactly (C115), so it is the count of the sub-objects written. A model read
            // from an EDS without one is written as it was read, so that it reads back equal.
            None if o.compact_sub_obj.is_none() && !self.from_eds && !o.subs.is_empty() => {
                self.kv("SubNumber", &o.subs.len().to_string());
            }
            None => {}
        }
        if let Some(f) = &o.obj_flags {
            self.kv("ObjFlags", &format!("0x{:X}", f.value));
        }
        if self.dcf {
            self.opt_text("Denotation", &o.denotation);
        }
        let n = o.compact_sub_obj.as_ref().map_or(0, |c| c.value);
        if let Some(c) = &o.compact_sub_obj {
            self.kv("CompactSubObj", &c.value.to_string());
        }
        // The template of the implied sub-objects: sub 1 without what is per sub-object. Of
        // its kept-as-written keys only those of the template (a DataType that did not read)
        // are the object's; a sub 1 with other unknown keys is an explicit section.
        let template = if n > 0 {
            o.subs.get(&1).map(|t| {
                let mut t = t.clone();
                t.kind = None;
                t.parameter_value = None;
                let r = t.rare_mut();
                r.denotation = None;
                // `ObjFlags` in the object's section is the object's: a sub 1 with its own is
                // an explicit section.
                r.obj_flags = None;
                r.extra.retain(|e| is_compact_template_key(&e.key));
                t
            })
        } else {
            None
        };
        let template = template.as_ref();
        if let Some(t) = template {
            self.sub_keys(t, None);
            // Keys kept as written (a DataType that did not read) belong to every implied
            // sub-object, so they go back into the object's section.
            self.extra(&t.rare().extra);
        }
        self.extra(&o.extra);
        let implied = |s: &SubObject| -> bool {
            let Some(t) = template else { return false };
            if s.sub_index == 0 {
                let mut e = SubObject::new(
                    0,
                    COMPACT_SUB0_NAME,
                    odc_model::DataType::Unsigned8,
                    odc_model::Access::Ro,
                );
                e.default = Some(Spanned::synthetic(Value::Unsigned(u64::from(n))));
                e.parameter_value = s.parameter_value.clone();
                e.rare_mut().denotation = s.rare().denotation.clone();
                return *s == e;
            }
            if s.sub_index > n {
                return false;
            }
            let mut c = s.clone();
            c.sub_index = t.sub_index;
            c.name = t.name.clone();
            c.parameter_value = t.parameter_value.clone();
            c.rare_mut().denotation = t.rare().denotation.clone();
            c == *t
        };
        for (i, s) in &o.subs {
            if !implied(s) {
                self.sub_section(&format!("{name}sub{i:X}"), s);
            }
        }
        if n > 0 {
            let names: Vec<(u8, &str)> = o
                .subs
                .range(1..=n)
                .filter(|(i, s)| implied(s) && s.name != implied_name(&o.name, **i))
                .map(|(i, s)| (*i, s.name.as_str()))
                .collect();
            if !names.is_empty() {
                self.header(&format!("{name}Name"));
                self.kv("NrOfEntries", &names.len().to_string());
                for (i, s) in names {
                    self.kv(&i.to_string(), s);
                }
            }
            if self.dcf {
                let values: Vec<(u8, String)> = o
                    .subs
                    .range(..=n)
                    .filter(|(_, s)| implied(s))
                    .filter_map(|(i, s)| Some((*i, value_text(&s.parameter_value.as_ref()?.value))))
                    .collect();
                if !values.is_empty() {
                    self.header(&format!("{name}Value"));
                    self.kv("NrOfEntries", &values.len().to_string());
                    for (i, v) in values {
                        self.kv(&i.to_string(), &v);
                    }
                }
                let dens: Vec<(u8, &str)> = o
                    .subs
                    .range(..=n)
                    .filter(|(_, s)| implied(s))
                    .filter_map(|(i, s)| Some((*i, s.rare().denotation.as_ref()?.value.as_str())))
                    .collect();
                if !dens.is_empty() {
                    self.header(&format!("{name}Denotation"));
                    self.kv("NrOfEntries", &dens.len().to_string());
                    for (i, v) in dens {
                        self.kv(&i.to_string(), v);
                    }
                }
            }
        }
        self.links(&name, o);
    }

    fn links(&mut self, name: &str, o: &Object) {
        if o.links.is_empty() {
            return;
        }
        let items: Vec<u16> = o.links.iter().map(|l| l.value).collect();
        self.index_list(&format!("{name}ObjectLinks"), "ObjectLinks", &items);
    }

    fn module(&mut self, m: &Module) {
        let p = format!("M{}", m.number);
        self.header(&format!("{p}ModuleInfo"));
        self.opt_text("ProductName", &m.product_name);
        self.opt_dec("ProductVersion", &m.product_version);
        self.opt_dec("ProductRevision", &m.product_revision);
        self.opt_text("OrderCode", &m.order_code);
        self.extra(&m.extra);
        if !m.fixed_objects.is_empty() {
            let items: Vec<u16> = m.fixed_objects.keys().copied().collect();
            self.index_list(&format!("{p}FixedObjects"), "NrOfEntries", &items);
            for o in m.fixed_objects.values() {
                self.object(&format!("{p}Fixed"), o);
            }
        }
        if !m.sub_extends.is_empty() {
            let items: Vec<u16> = m.sub_extends.keys().copied().collect();
            self.index_list(&format!("{p}SubExtends"), "NrOfEntries", &items);
            for (i, x) in &m.sub_extends {
                self.header(&format!("{p}SubExt{i:04X}"));
                self.kv("ParameterName", &x.template.name);
                self.sub_keys(&x.template, x.template.rare().obj_flags.as_ref());
                self.opt_text("Count", &x.count);
                self.opt_hex("ObjExtend", &x.obj_extend);
                self.extra(&x.template.rare().extra);
            }
        }
        self.lines(&format!("{p}Comments"), &m.comments);
    }
}

pub(crate) fn write(dev: &Device, format: Format) -> String {
    let mut w = W {
        out: String::with_capacity(64 * 1024),
        dcf: format == Format::Dcf,
        // An XDD/XDC states SubNumber as an EDS does: a model read from one lacks it only
        // where the file did.
        from_eds: matches!(dev.format, Some(Format::Eds | Format::Dcf | Format::Xdd | Format::Xdc)),
    };
    let fi = &dev.file_info;
    if *fi != odc_model::FileInfo::default() {
        w.header("FileInfo");
        w.opt_text("FileName", &fi.file_name);
        w.opt_dec("FileVersion", &fi.file_version);
        w.opt_dec("FileRevision", &fi.file_revision);
        w.opt_text("EDSVersion", &fi.eds_version);
        w.opt_text("Description", &fi.description);
        w.opt_text("CreationTime", &fi.creation_time);
        w.opt_text("CreationDate", &fi.creation_date);
        w.opt_text("CreatedBy", &fi.created_by);
        w.opt_text("ModificationTime", &fi.modification_time);
        w.opt_text("ModificationDate", &fi.modification_date);
        w.opt_text("ModifiedBy", &fi.modified_by);
        w.extra(&fi.extra);
    }
    let di = &dev.device_info;
    if *di != odc_model::DeviceInfo::default() {
        w.header("DeviceInfo");
        w.opt_text("VendorName", &di.vendor_name);
        w.opt_hex("VendorNumber", &di.vendor_number);
        w.opt_text("ProductName", &di.product_name);
        w.opt_hex("ProductNumber", &di.product_number);
        w.opt_hex("RevisionNumber", &di.revision_number);
        w.opt_text("OrderCode", &di.order_code);
        let mut rates: Vec<u32> = vec![10, 20, 50, 125, 250, 500, 800, 1000];
        rates.extend(di.baud_rates.iter().copied());
        rates.sort_unstable();
        rates.dedup();
        for r in rates {
            w.kv(&format!("BaudRate_{r}"), if di.baud_rates.contains(&r) { "1" } else { "0" });
        }
        w.opt_bool("SimpleBootUpMaster", &di.simple_boot_up_master);
        w.opt_bool("SimpleBootUpSlave", &di.simple_boot_up_slave);
        w.opt_dec("Granularity", &di.granularity);
        w.opt_dec("DynamicChannelsSupported", &di.dynamic_channels_supported);
        w.opt_bool("GroupMessaging", &di.group_messaging);
        w.opt_dec("NrOfRXPDO", &di.nr_of_rx_pdo);
        w.opt_dec("NrOfTXPDO", &di.nr_of_tx_pdo);
        w.opt_bool("LSS_Supported", &di.lss_supported);
        w.opt_hex("CompactPDO", &di.compact_pdo);
        w.extra(&di.extra);
    }
    if w.dcf
        && let Some(c) = &dev.commissioning
    {
        w.header("DeviceComissioning");
        w.opt_dec("NodeID", &c.node_id);
        w.opt_text("NodeName", &c.node_name);
        w.opt_dec("Baudrate", &c.baudrate);
        w.opt_dec("NetNumber", &c.net_number);
        w.opt_text("NetworkName", &c.network_name);
        w.opt_bool("CANopenManager", &c.canopen_manager);
        w.opt_hex("LSS_SerialNumber", &c.lss_serial_number);
        w.opt_text("NodeRefd", &c.node_refd);
        w.opt_text("NetRefd", &c.net_refd);
        w.extra(&c.extra);
    }
    if !dev.dummy_usage.is_empty() {
        w.header("DummyUsage");
        for (i, b) in &dev.dummy_usage {
            w.kv(&format!("Dummy{i:04X}"), if b.value { "1" } else { "0" });
        }
    }
    w.lines("Comments", &dev.comments);
    for (name, list) in [
        ("MandatoryObjects", &dev.object_lists.mandatory),
        ("OptionalObjects", &dev.object_lists.optional),
        ("ManufacturerObjects", &dev.object_lists.manufacturer),
    ] {
        if let Some(l) = list {
            // The count is written only when the file had one, so that a list without it
            // reads back as the same model (found by the `eds_roundtrip` fuzz target).
            w.header(name);
            if let Some(count) = &l.supported_objects {
                w.kv("SupportedObjects", &count.value.to_string());
            }
            // Entries kept as written (a value that did not read) keep their numbers; the
            // list is numbered around them, else a re-read would let them replace an entry.
            let taken: Vec<u32> = dev
                .extra_sections
                .iter()
                .filter(|s| s.name.eq_ignore_ascii_case(name))
                .flat_map(|s| s.entries.iter().filter_map(|e| e.key.trim().parse().ok()))
                .collect();
            let mut n = 0u32;
            for x in &l.entries {
                n += 1;
                while taken.contains(&n) {
                    n += 1;
                }
                w.kv(&n.to_string(), &format!("0x{:04X}", x.value));
            }
        }
    }
    for o in dev.objects.values() {
        if o.origin == Origin::CompactPdo {
            continue;
        }
        w.object("", o);
    }
    if !dev.modules.supported.is_empty() {
        w.header("SupportedModules");
        w.kv("NrOfEntries", &dev.modules.supported.len().to_string());
        for m in &dev.modules.supported {
            w.module(m);
        }
    }
    if w.dcf && !dev.modules.connected.is_empty() {
        w.header("ConnectedModules");
        w.kv("NrOfEntries", &dev.modules.connected.len().to_string());
        for (i, m) in dev.modules.connected.iter().enumerate() {
            w.kv(&(i + 1).to_string(), &m.value.to_string());
        }
    }
    for s in &dev.extra_sections {
        w.header(&s.name);
        w.extra(&s.entries);
    }
    w.out
}

/// What a DCF holds that an EDS has no place for (CiA 306 §5): the values a device written as
/// EDS leaves out. See [`dcf_only`].
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct DcfOnly {
    /// `ParameterValue` of sub-objects (also those of `[xxxxValue]` sections).
    pub parameter_values: usize,
    /// `Denotation` of objects and sub-objects (also those of `[xxxxDenotation]` sections).
    pub denotations: usize,
    /// Keys of `[DeviceComissioning]`.
    pub commissioning: usize,
    /// Entries of `[ConnectedModules]`.
    pub connected_modules: usize,
}

impl DcfOnly {
    /// The number of values in all.
    pub fn total(&self) -> usize {
        self.parameter_values + self.denotations + self.commissioning + self.connected_modules
    }

    /// Whether the device has nothing an EDS cannot hold.
    pub fn is_empty(&self) -> bool {
        self.total() == 0
    }

    fn sub(&mut self, s: &SubObject) {
        self.parameter_values += usize::from(s.parameter_value.is_some());
        self.denotations += usize::from(s.rare().denotation.is_some());
    }

    fn object(&mut self, o: &Object) {
        self.denotations += usize::from(o.denotation.is_some());
        for s in o.subs.values() {
            self.sub(s);
        }
    }
}

/// Lists the parts, `12 ParameterValue, 1 Denotation, 3 [DeviceComissioning] keys`; empty parts
/// are left out.
impl std::fmt::Display for DcfOnly {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        let parts = [
            (self.parameter_values, "ParameterValue"),
            (self.denotations, "Denotation"),
            (self.commissioning, "[DeviceComissioning] keys"),
            (self.connected_modules, "[ConnectedModules] entries"),
        ];
        let mut first = true;
        for (n, what) in parts.into_iter().filter(|(n, _)| *n > 0) {
            if !first {
                f.write_str(", ")?;
            }
            first = false;
            write!(f, "{n} {what}")?;
        }
        Ok(())
    }
}

/// Counts the DCF-only values of a device: what [`write`](crate::write) leaves out when it
/// writes the device as EDS (it writes them all as DCF).
pub fn dcf_only(dev: &Device) -> DcfOnly {
    let mut n = DcfOnly::default();
    for o in dev.objects.values().filter(|o| o.origin != Origin::CompactPdo) {
        n.object(o);
    }
    for m in &dev.modules.supported {
        for o in m.fixed_objects.values() {
            n.object(o);
        }
        for x in m.sub_extends.values() {
            n.sub(&x.template);
        }
    }
    if let Some(c) = &dev.commissioning {
        let named = [
            c.node_id.is_some(),
            c.node_name.is_some(),
            c.baudrate.is_some(),
            c.net_number.is_some(),
            c.network_name.is_some(),
            c.canopen_manager.is_some(),
            c.lss_serial_number.is_some(),
            c.node_refd.is_some(),
            c.net_refd.is_some(),
        ];
        n.commissioning = named.iter().filter(|b| **b).count() + c.extra.len();
    }
    n.connected_modules = dev.modules.connected.len();
    n
}

#[cfg(test)]
mod tests {
    #![allow(clippy::unwrap_used, clippy::expect_used, clippy::panic)]

    use odc_model::{Format, Sources};

    use super::{DcfOnly, dcf_only};

    const DCF: &str = "\
[DeviceInfo]
ProductName=p

[DeviceComissioning]
NodeID=5
NodeName=drive
Baudrate=500

[MandatoryObjects]
SupportedObjects=2
1=0x1000
2=0x1018

[1000]
ParameterName=Device type
ObjectType=0x7
DataType=0x0007
AccessType=ro
DefaultValue=0x20192
ParameterValue=0x20192
Denotation=axis 1
PDOMapping=0

[1018]
ParameterName=Identity
ObjectType=0x9
SubNumber=2

[1018sub0]
ParameterName=n
ObjectType=0x7
DataType=0x0005
AccessType=ro
DefaultValue=1
PDOMapping=0

[1018sub1]
ParameterName=Vendor-ID
ObjectType=0x7
DataType=0x0007
AccessType=ro
DefaultValue=0
ParameterValue=0x1234
PDOMapping=0
";

    #[test]
    fn dcf_only_counts_what_an_eds_leaves_out() {
        let mut sources = Sources::new();
        let dev = crate::parse_str(&mut sources, "x.dcf", DCF).device;
        let n = dcf_only(&dev);
        let want =
            DcfOnly { parameter_values: 2, denotations: 1, commissioning: 3, connected_modules: 0 };
        assert_eq!(n, want);
        assert_eq!(n.total(), 6);
        assert_eq!(n.to_string(), "2 ParameterValue, 1 Denotation, 3 [DeviceComissioning] keys");
        // A DCF keeps them all; an EDS none.
        let dcf = crate::parse_str(&mut sources, "y.dcf", &crate::write(&dev, Format::Dcf)).device;
        assert_eq!(dcf_only(&dcf), want);
        let eds = crate::parse_str(&mut sources, "y.eds", &crate::write(&dev, Format::Eds)).device;
        assert!(dcf_only(&eds).is_empty(), "{}", dcf_only(&eds));
    }

    /// A model that did not come from an EDS (here: one whose format is ESI) gets the SubNumber
    /// CiA 306 requires; one read from an EDS without it is written as read.
    #[test]
    fn sub_number_is_written_for_a_model_that_has_none() {
        let mut sources = Sources::new();
        let text = DCF.replace("SubNumber=2\n", "");
        let mut dev = crate::parse_str(&mut sources, "x.eds", &text).device;
        assert!(dev.objects[&0x1018].sub_number.is_none());
        assert!(!crate::write(&dev, Format::Eds).contains("SubNumber"));
        dev.format = Some(Format::Esi);
        let eds = crate::write(&dev, Format::Eds);
        assert!(
            eds.contains("[1018]\nParameterName=Identity\nObjectType=0x9\nSubNumber=2\n"),
            "{eds}"
        );
        let back = crate::parse_str(&mut sources, "y.eds", &eds);
        assert_eq!(back.device.objects[&0x1018].sub_number.as_ref().map(|n| n.value), Some(2));
    }
}
