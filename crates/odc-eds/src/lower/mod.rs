//! Lowering: raw sections and entries → [`odc_model::Device`], with diagnostics. The section
//! names are classified in `classify`, the known keys of object sections found in `keys`,
//! and values read in `read`; this module walks the sections and builds the device.

use std::collections::BTreeMap;

use odc_model::trim::trim;
use odc_model::{
    Access, Commissioning, DataType, Device, Diagnostic, FileId, Format, Module, Name, Object,
    ObjectKind, ObjectList, PdoMapping, RawEntry, RawSection, Severity, Span, Spanned, SubExtend,
    SubObject, Value, ValueClass,
};

use crate::num;
use crate::raw::{Entry, RawFile, Section};
use crate::rules::codes;

mod classify;
mod keys;
mod read;

use classify::*;
pub(crate) use keys::is_compact_template_key;
use keys::*;

/// The note of a value that does not read: the model keeps its text.
const KEPT_AS_WRITTEN: &str = "the text is kept as written, so `odc convert` writes it back; generated code leaves this value out";

/// The name CiA 306 tools give the implied sub-index 0 of a compact object.
pub(crate) const COMPACT_SUB0_NAME: &str = "NrOfObjects";

pub(crate) struct Lower<'r, 'a> {
    raw: &'r RawFile<'a>,
    file: FileId,
    pub(crate) diags: odc_model::Capped,
    dcf_hint: bool,
    /// Report unreadable header numbers as warnings ([FileInfo]: metadata only).
    soft: bool,
    /// The next sub-object read is that of a NULL object (no AccessType needed).
    null_object: bool,
    /// Sub-objects implied by CompactSubObj so far (see [`crate::MAX_IMPLIED_SUB_OBJECTS`]).
    implied_subs: usize,
    /// The data type indexes (0x0001..=0x025F) the file has an object section for, sorted.
    defined_types: Vec<u16>,
}

fn raw_entry(e: &Entry<'_>, file: FileId) -> RawEntry {
    RawEntry { key: e.key.to_owned(), value: e.value.to_owned(), span: e.line_pos.span(file) }
}

impl<'r, 'a> Lower<'r, 'a> {
    pub(crate) fn new(raw: &'r RawFile<'a>, diags: odc_model::Capped) -> Self {
        Lower {
            raw,
            file: raw.file,
            diags,
            dcf_hint: false,
            soft: false,
            null_object: false,
            implied_subs: 0,
            defined_types: Vec::new(),
        }
    }

    fn sec(&self, i: u32) -> &'r Section<'a> {
        // Indexes come from enumerating `raw.sections`.
        &self.raw.sections[i as usize]
    }

    /// Entries of a section and of its repeats, in file order.
    fn entries(&self, first: u32) -> impl Iterator<Item = &'r Entry<'a>> + 'r {
        let raw = self.raw;
        raw.chain(first).flat_map(move |s| raw.entries_of(s).iter())
    }

    fn keys(&self, first: u32) -> Keys<'r, 'a> {
        let mut keys = Keys { k: [None; N_KEYS], extra: Vec::new(), shadowed: Vec::new() };
        // Plain loops over the section and its repeats (a closure here was not inlined).
        let mut next = Some(first);
        while let Some(i) = next {
            let s = self.sec(i);
            for e in self.raw.entries_of(s) {
                match obj_key(e.key) {
                    Some(k) => {
                        if let Some(old) = keys.k[k as usize].replace(e) {
                            keys.shadowed.push((k, old, e));
                        }
                    }
                    None => keys.extra.push(e),
                }
            }
            next = s.next_same;
        }
        keys
    }

    fn span(&self, p: crate::raw::Pos) -> Span {
        p.span(self.file)
    }

    fn raw_section(&self, first: u32) -> RawSection {
        let s = self.sec(first);
        RawSection {
            name: s.name.to_owned(),
            entries: self.entries(first).map(|e| raw_entry(e, self.file)).collect(),
            span: self.span(s.header_pos),
        }
    }

    // ----- sections --------------------------------------------------------------------------

    pub(crate) fn run(mut self, name: &str) -> (Device, Vec<Diagnostic>) {
        let lname = name.as_bytes();
        self.dcf_hint = lname.len() >= 4 && lname[lname.len() - 4..].eq_ignore_ascii_case(b".dcf");
        let mut dev = Device::default();
        let mut secs: Vec<(u64, u32)> = Vec::with_capacity(self.raw.sections.len());
        let mut objects = 0usize;
        let mut modules: BTreeMap<u16, ModB<'_>> = BTreeMap::new();
        let mut extra: Vec<(u32, RawSection)> = Vec::new();
        let mut has_value_sections = false;

        for (i, s) in self.raw.sections.iter().enumerate() {
            if s.is_duplicate {
                continue;
            }
            let i = i as u32;
            let kind = classify(s.name);
            match kind {
                Kind::FileInfo => self.file_info(i, &mut dev),
                Kind::DeviceInfo => self.device_info(i, &mut dev),
                Kind::DummyUsage => self.dummy_usage(i, &mut dev, &mut extra),
                Kind::Comments => {
                    dev.comments = self.comments(i, &mut extra);
                }
                Kind::ObjList(n) => {
                    let list = self.object_list(i, "SupportedObjects", &mut extra);
                    let slot = match n {
                        0 => &mut dev.object_lists.mandatory,
                        1 => &mut dev.object_lists.optional,
                        _ => &mut dev.object_lists.manufacturer,
                    };
                    *slot = Some(list);
                }
                Kind::Commissioning => self.commissioning(i, &mut dev),
                Kind::SupportedModules => {
                    // The modules are the [MxModuleInfo] sections; NrOfEntries is kept for
                    // odc-check to compare with them.
                    let count = self
                        .entries(i)
                        .filter(|e| e.key.eq_ignore_ascii_case("NrOfEntries"))
                        .last()
                        .and_then(|e| self.uint(e, 0xFFFF).ok().flatten());
                    dev.modules.nr_of_entries = count.map(|v| Spanned::new(v.value as u16, v.span));
                    self.list_section(i, "NrOfEntries", &mut extra);
                }
                Kind::ConnectedModules => {
                    let l = self.list_section(i, "NrOfEntries", &mut extra);
                    dev.modules.connected = l
                        .into_iter()
                        .filter_map(|(e, _)| self.uint(e, 0xFFFF).ok().flatten())
                        .map(|v| Spanned::new(v.value as u16, v.span))
                        .collect();
                }
                Kind::Object(x) => {
                    objects += 1;
                    if x <= 0x025F {
                        self.defined_types.push(x);
                    }
                    secs.push((section_key(0, x, ROLE_MAIN, 0), i));
                }
                Kind::Sub(x, s) => secs.push((section_key(0, x, ROLE_SUB, s), i)),
                Kind::Name(x) => secs.push((section_key(0, x, ROLE_NAME, 0), i)),
                Kind::Value(x) => {
                    has_value_sections = true;
                    secs.push((section_key(0, x, ROLE_VALUE, 0), i));
                }
                Kind::Denotation(x) => secs.push((section_key(0, x, ROLE_DENOTATION, 0), i)),
                Kind::Links(x) => secs.push((section_key(0, x, ROLE_LINKS, 0), i)),
                Kind::ModInfo(m) => modules.entry(m).or_default().info = Some(i),
                Kind::ModFixedObjects(m) => modules.entry(m).or_default().fixed_list = Some(i),
                Kind::ModFixed(m, x) => {
                    modules.entry(m).or_default();
                    secs.push((section_key(u32::from(m) + 1, x, ROLE_MAIN, 0), i));
                }
                Kind::ModFixedSub(m, x, s) => {
                    modules.entry(m).or_default();
                    secs.push((section_key(u32::from(m) + 1, x, ROLE_SUB, s), i));
                }
                Kind::ModSubExtends(m) => modules.entry(m).or_default().sub_ext_list = Some(i),
                Kind::ModSubExt(m, x) => {
                    modules.entry(m).or_default().sub_ext.insert(x, i);
                }
                Kind::ModComments(m) => modules.entry(m).or_default().comments = Some(i),
                Kind::Malformed => {
                    self.warn(
                        codes::MALFORMED_OBJECT_SECTION,
                        format!(
                            "section name [{}] looks like an object but does not parse",
                            s.name
                        ),
                        self.span(s.name_pos),
                        "kept as an unknown section",
                    );
                    extra.push((i, self.raw_section(i)));
                }
                Kind::Unknown => {
                    // `[$NODEID+0x2000]`, `[Obj 2000]`: object keys under a name that is no
                    // object index.
                    let object_like = self.entries(i).any(|e| {
                        e.key.eq_ignore_ascii_case("ParameterName")
                            || e.key.eq_ignore_ascii_case("ObjectType")
                    });
                    if object_like {
                        self.warn(
                            codes::MALFORMED_OBJECT_SECTION,
                            format!(
                                "section [{}] has object keys but its name is not an object index",
                                s.name
                            ),
                            self.span(s.name_pos),
                            "kept as an unknown section",
                        );
                    }
                    extra.push((i, self.raw_section(i)));
                }
            }
        }

        self.defined_types.sort_unstable();
        let mut built: Vec<(u16, Object)> = Vec::with_capacity(objects);
        group_objects(&mut secs, |owner, index, b| {
            if owner > 0 {
                // Module fixed objects are read with their module, below.
                let m = (owner - 1) as u16;
                modules.entry(m).or_default().fixed.insert(index, b);
                return;
            }
            match self.object(index, &b, &mut extra) {
                Some(o) => built.push((index, o)),
                None => {
                    // Orphan companions: kept as unknown sections.
                    let orphans = b
                        .subs
                        .values()
                        .chain(b.name)
                        .chain(b.value)
                        .chain(b.denotation)
                        .chain(b.links);
                    for i in orphans {
                        let s = self.sec(i);
                        self.warn(
                            codes::ORPHAN_SECTION,
                            format!("[{}] has no object section [{:04X}]", s.name, index),
                            self.span(s.name_pos),
                            "kept as an unknown section",
                        );
                        extra.push((i, self.raw_section(i)));
                    }
                }
            }
        });

        // In index order: built in bulk.
        dev.objects = built.into_iter().collect();

        for (number, b) in &modules {
            let m = self.module(*number, b, &mut extra);
            dev.modules.supported.push(m);
        }

        extra.sort_by_key(|(i, _)| *i);
        dev.extra_sections = extra.into_iter().map(|(_, s)| s).collect();

        // ParameterValue, Denotation and [ConnectedModules] exist in DCFs only (the EDS writer
        // leaves them out), in the objects and in the modules' objects.
        let dcf_sub =
            |s: &odc_model::SubObject| s.parameter_value.is_some() || s.rare().denotation.is_some();
        let dcf_object = |o: &Object| o.denotation.is_some() || o.subs.any_ignoring_names(dcf_sub);
        let has_pv = dev.objects.values().any(dcf_object)
            || dev.modules.supported.iter().any(|m| {
                m.fixed_objects.values().any(dcf_object)
                    || m.sub_extends.values().any(|x| dcf_sub(&x.template))
            });
        let dcf_only = !dev.modules.connected.is_empty();
        dev.format = Some(
            if dev.commissioning.is_some()
                || has_pv
                || has_value_sections
                || dcf_only
                || self.dcf_hint
            {
                Format::Dcf
            } else {
                Format::Eds
            },
        );
        dev.device_info.baud_rates.sort_unstable();
        dev.device_info.baud_rates.dedup();
        crate::compact_pdo::synthesise(&mut dev);
        dev.pdos = odc_model::pdo::resolve_canopen_pdos(&dev);
        (dev, self.diags.finish())
    }

    fn file_info(&mut self, first: u32, dev: &mut Device) {
        self.soft = true;
        self.file_info_inner(first, dev);
        self.soft = false;
    }

    fn file_info_inner(&mut self, first: u32, dev: &mut Device) {
        let fi = &mut dev.file_info;
        for e in self.entries(first) {
            let k = e.key;
            let is = |n: &str| k.eq_ignore_ascii_case(n);
            if is("FileName") {
                fi.file_name = Some(self.text(e));
            } else if is("FileVersion") || is("FileRevision") {
                match self.uint(e, 0xFF) {
                    Ok(v) => {
                        let v = v.map(|v| Spanned::new(v.value as u8, v.span));
                        if is("FileVersion") {
                            fi.file_version = v;
                        } else {
                            fi.file_revision = v;
                        }
                    }
                    Err(()) => fi.extra.push(raw_entry(e, self.file)),
                }
            } else if is("EDSVersion") {
                fi.eds_version = Some(self.text(e));
            } else if is("Description") {
                fi.description = Some(self.text(e));
            } else if is("CreationTime") {
                fi.creation_time = Some(self.text(e));
            } else if is("CreationDate") {
                fi.creation_date = Some(self.text(e));
            } else if is("CreatedBy") {
                fi.created_by = Some(self.text(e));
            } else if is("ModificationTime") {
                fi.modification_time = Some(self.text(e));
            } else if is("ModificationDate") {
                fi.modification_date = Some(self.text(e));
            } else if is("ModifiedBy") {
                fi.modified_by = Some(self.text(e));
            } else {
                fi.extra.push(raw_entry(e, self.file));
            }
        }
    }

    fn device_info(&mut self, first: u32, dev: &mut Device) {
        let file = self.file;
        for e in self.entries(first) {
            let k = e.key;
            let is = |n: &str| k.eq_ignore_ascii_case(n);
            let di = &mut dev.device_info;
            macro_rules! num_field {
                ($field:ident, $t:ty) => {
                    match self.uint(e, <$t>::MAX as u64) {
                        Ok(v) => {
                            dev.device_info.$field = v.map(|v| Spanned::new(v.value as $t, v.span))
                        }
                        Err(()) => dev.device_info.extra.push(raw_entry(e, file)),
                    }
                };
            }
            macro_rules! bool_field {
                ($field:ident) => {
                    match self.boolean(e) {
                        Ok(v) => dev.device_info.$field = v,
                        Err(()) => dev.device_info.extra.push(raw_entry(e, file)),
                    }
                };
            }
            if is("VendorName") {
                di.vendor_name = Some(self.text(e));
            } else if is("ProductName") {
                di.product_name = Some(self.text(e));
            } else if is("OrderCode") {
                di.order_code = Some(self.text(e));
            } else if is("VendorNumber") {
                num_field!(vendor_number, u32);
            } else if is("ProductNumber") {
                num_field!(product_number, u32);
            } else if is("RevisionNumber") {
                num_field!(revision_number, u32);
            } else if is("Granularity") {
                num_field!(granularity, u8);
            } else if is("DynamicChannelsSupported") {
                num_field!(dynamic_channels_supported, u8);
            } else if is("NrOfRXPDO") {
                num_field!(nr_of_rx_pdo, u16);
            } else if is("NrOfTXPDO") {
                num_field!(nr_of_tx_pdo, u16);
            } else if is("CompactPDO") {
                num_field!(compact_pdo, u8);
            } else if is("SimpleBootUpMaster") {
                bool_field!(simple_boot_up_master);
            } else if is("SimpleBootUpSlave") {
                bool_field!(simple_boot_up_slave);
            } else if is("GroupMessaging") {
                bool_field!(group_messaging);
            } else if is("LSS_Supported") {
                bool_field!(lss_supported);
            } else if let Some(rate) = strip_prefix_ci(k.as_bytes(), "BaudRate_").and_then(dec_u16)
            {
                match self.boolean(e) {
                    Ok(Some(b)) => {
                        if b.value {
                            dev.device_info.baud_rates.push(u32::from(rate));
                        }
                    }
                    Ok(None) => {}
                    Err(()) => dev.device_info.extra.push(raw_entry(e, file)),
                }
            } else {
                di.extra.push(raw_entry(e, file));
            }
        }
    }

    fn unexpected(&mut self, e: &Entry<'_>, section: &str) {
        self.warn(
            codes::UNEXPECTED_KEY,
            format!("key `{}` does not belong in [{}]", e.key, section),
            self.span(e.key_pos),
            "kept, not interpreted",
        );
    }

    /// Keeps entries a section without an `extra` slot cannot hold, as an unknown section of
    /// the same name.
    fn keep_unexpected(
        &self,
        first: u32,
        kept: Vec<&Entry<'_>>,
        extra: &mut Vec<(u32, RawSection)>,
    ) {
        if kept.is_empty() {
            return;
        }
        let s = self.sec(first);
        extra.push((
            first,
            RawSection {
                name: s.name.to_owned(),
                entries: kept.into_iter().map(|e| raw_entry(e, self.file)).collect(),
                span: self.span(s.header_pos),
            },
        ));
    }

    fn dummy_usage(&mut self, first: u32, dev: &mut Device, extra: &mut Vec<(u32, RawSection)>) {
        let mut kept = Vec::new();
        let name = self.sec(first).name;
        for e in self.entries(first) {
            let idx = strip_prefix_ci(e.key.as_bytes(), "Dummy").and_then(hex4);
            match idx {
                Some(idx) => match self.boolean(e) {
                    Ok(Some(b)) => {
                        dev.dummy_usage.insert(idx, b);
                    }
                    Ok(None) => {}
                    Err(()) => kept.push(e),
                },
                None => {
                    self.unexpected(e, name);
                    kept.push(e);
                }
            }
        }
        self.keep_unexpected(first, kept, extra);
    }

    fn comments(&mut self, first: u32, extra: &mut Vec<(u32, RawSection)>) -> Vec<String> {
        let mut lines: BTreeMap<u16, String> = BTreeMap::new();
        let mut kept = Vec::new();
        let name = self.sec(first).name;
        for e in self.entries(first) {
            if e.key.eq_ignore_ascii_case("Lines") {
                continue; // implied by the LineN keys
            }
            match strip_prefix_ci(e.key.as_bytes(), "Line").and_then(dec_u16) {
                Some(n) => {
                    lines.insert(n, e.value.to_owned());
                }
                None => {
                    self.unexpected(e, name);
                    kept.push(e);
                }
            }
        }
        self.keep_unexpected(first, kept, extra);
        lines.into_values().collect()
    }

    /// A list section: the count key (ignored, implied) and `n=value` entries in order of n.
    fn list_section(
        &mut self,
        first: u32,
        count_key: &str,
        extra: &mut Vec<(u32, RawSection)>,
    ) -> Vec<(&'r Entry<'a>, u16)> {
        let mut items: BTreeMap<u16, &'r Entry<'a>> = BTreeMap::new();
        let mut kept = Vec::new();
        let name = self.sec(first).name;
        for e in self.entries(first) {
            if e.key.eq_ignore_ascii_case(count_key) {
                continue;
            }
            match dec_u16(e.key.as_bytes()) {
                Some(n) => {
                    items.insert(n, e);
                }
                None => {
                    self.unexpected(e, name);
                    kept.push(e);
                }
            }
        }
        self.keep_unexpected(first, kept, extra);
        items.into_iter().map(|(n, e)| (e, n)).collect()
    }

    fn object_list(
        &mut self,
        first: u32,
        count_key: &str,
        extra: &mut Vec<(u32, RawSection)>,
    ) -> ObjectList {
        let mut list =
            ObjectList { span: self.span(self.sec(first).header_pos), ..Default::default() };
        if let Some(e) =
            self.entries(first).filter(|e| e.key.eq_ignore_ascii_case(count_key)).last()
        {
            match self.uint(e, 0xFFFF) {
                Ok(v) => list.supported_objects = v.map(|v| Spanned::new(v.value as u16, v.span)),
                Err(()) => self.keep_unexpected(first, vec![e], extra),
            }
        }
        for (e, _) in self.list_section(first, count_key, extra) {
            match self.uint(e, 0xFFFF) {
                Ok(Some(v)) => list.entries.push(Spanned::new(v.value as u16, v.span)),
                Ok(None) => {}
                Err(()) => self.keep_unexpected(first, vec![e], extra),
            }
        }
        list
    }

    fn commissioning(&mut self, first: u32, dev: &mut Device) {
        let file = self.file;
        let mut c =
            Commissioning { span: self.span(self.sec(first).header_pos), ..Default::default() };
        for e in self.entries(first) {
            let is = |n: &str| e.key.eq_ignore_ascii_case(n);
            macro_rules! num_field {
                ($field:ident, $t:ty) => {
                    match self.uint(e, <$t>::MAX as u64) {
                        Ok(v) => c.$field = v.map(|v| Spanned::new(v.value as $t, v.span)),
                        Err(()) => c.extra.push(raw_entry(e, file)),
                    }
                };
            }
            if is("NodeID") {
                num_field!(node_id, u8);
            } else if is("NodeName") {
                c.node_name = Some(self.text(e));
            } else if is("Baudrate") {
                num_field!(baudrate, u32);
            } else if is("NetNumber") {
                num_field!(net_number, u32);
            } else if is("NetworkName") {
                c.network_name = Some(self.text(e));
            } else if is("CANopenManager") {
                match self.boolean(e) {
                    Ok(v) => c.canopen_manager = v,
                    Err(()) => c.extra.push(raw_entry(e, file)),
                }
            } else if is("LSS_SerialNumber") {
                num_field!(lss_serial_number, u32);
            } else if is("NodeRefd") {
                c.node_refd = Some(self.text(e));
            } else if is("NetRefd") {
                c.net_refd = Some(self.text(e));
            } else {
                c.extra.push(raw_entry(e, file));
            }
        }
        if dev.commissioning.is_none() {
            dev.commissioning = Some(c);
        } else if let Some(old) = dev.commissioning.as_mut() {
            // Both spellings present: merge, later keys win.
            macro_rules! merge {
                ($($f:ident),*) => { $( if c.$f.is_some() { old.$f = c.$f; } )* };
            }
            merge!(
                node_id,
                node_name,
                baudrate,
                net_number,
                network_name,
                canopen_manager,
                lss_serial_number,
                node_refd,
                net_refd
            );
            old.extra.extend(c.extra);
        }
    }

    // ----- objects ---------------------------------------------------------------------------

    /// Fills a sub-object from known keys; leftovers go to `extra`.
    fn sub_from_keys(
        &mut self,
        keys: &mut Keys<'r, 'a>,
        sub_index: u8,
        header: Span,
        default_dt: Option<DataType>,
        what: &dyn std::fmt::Display,
    ) -> SubObject {
        let mut sub = blank_sub(sub_index);
        self.fill_sub(keys, &mut sub, header, default_dt, what);
        sub
    }

    /// Fills `sub` (fresh from [`blank_sub`]) from known keys; leftovers go to its `extra`.
    /// In place: a sub-object is large, and building it elsewhere to move it into its
    /// object's vector was a copy per sub-object.
    fn fill_sub(
        &mut self,
        keys: &mut Keys<'r, 'a>,
        sub: &mut SubObject,
        header: Span,
        default_dt: Option<DataType>,
        what: &dyn std::fmt::Display,
    ) {
        let sub_index = sub.sub_index;
        let what_is_null = std::mem::take(&mut self.null_object);
        let file = self.file;
        sub.name = match keys.take(K::ParameterName) {
            Some(e) => Name::from(e.value),
            None => {
                self.warn(
                    codes::MISSING_NAME,
                    format!("{what} has no ParameterName"),
                    header,
                    "here",
                );
                Name::default()
            }
        };
        let mut extra_entries: Vec<&Entry<'_>> = Vec::new();
        let mut unreadable = None;
        let data_type = match keys.take(K::DataType) {
            Some(e) => match self.data_type(e) {
                Ok(Some(dt)) => {
                    sub.data_type_span = self.span(e.line_pos);
                    Some(dt)
                }
                Ok(None) => None,
                Err(()) => {
                    extra_entries.push(e);
                    unreadable = Some(self.span(e.value_pos));
                    None
                }
            },
            None => None,
        };
        let data_type = match data_type.or(default_dt) {
            Some(dt) => dt,
            None => {
                let d = match unreadable {
                    Some(at) => Diagnostic::error(
                        codes::MISSING_DATA_TYPE,
                        format!("{what} has no readable DataType"),
                    )
                    .with_label(at, "not a DataType"),
                    None => Diagnostic::error(
                        codes::MISSING_DATA_TYPE,
                        format!("{what} has no DataType"),
                    )
                    .with_label(header, "DataType missing"),
                };
                self.diags.push(d.with_note("assumed DOMAIN"));
                DataType::Domain
            }
        };
        let access = match keys.take(K::AccessType) {
            Some(e) => self.access(e).unwrap_or_else(|| {
                if !e.value.is_empty() {
                    extra_entries.push(e);
                }
                Access::Ro
            }),
            None if default_dt == Some(DataType::Domain) && sub_index == 0 && what_is_null => {
                Access::Ro
            }
            None => {
                self.warn(
                    codes::MISSING_ACCESS_TYPE,
                    format!("{what} has no AccessType; assumed ro"),
                    header,
                    "AccessType missing",
                );
                Access::Ro
            }
        };
        let pdo_mapping = match keys.take(K::PdoMapping) {
            Some(e) => match self.boolean(e) {
                Ok(Some(b)) => {
                    if b.value {
                        PdoMapping::Yes
                    } else {
                        PdoMapping::No
                    }
                }
                Ok(None) => PdoMapping::No,
                Err(()) => {
                    extra_entries.push(e);
                    PdoMapping::No
                }
            },
            None => PdoMapping::No,
        };
        sub.data_type = data_type;
        sub.access = access;
        sub.pdo_mapping = pdo_mapping;
        sub.span = header;
        if let Some(e) = keys.take(K::ObjectType) {
            match self.object_kind(e) {
                Some(k) => sub.kind = Some(k),
                None => extra_entries.push(e),
            }
        }
        sub.default = keys.take(K::DefaultValue).and_then(|e| self.value(e, data_type));
        sub.low_limit = keys.take(K::LowLimit).and_then(|e| self.limit(e, data_type));
        sub.high_limit = keys.take(K::HighLimit).and_then(|e| self.limit(e, data_type));
        sub.parameter_value = keys.take(K::ParameterValue).and_then(|e| self.value(e, data_type));
        let denotation = keys.take(K::Denotation).map(|e| self.text(e));
        let mut obj_flags = None;
        if let Some(e) = keys.take(K::ObjFlags) {
            match self.uint(e, u64::from(u32::MAX)) {
                Ok(v) => obj_flags = v.map(|v| Spanned::new(v.value as u32, v.span)),
                Err(()) => extra_entries.push(e),
            }
        }
        let upload_file = keys.take(K::UploadFile).map(|e| self.text(e));
        let download_file = keys.take(K::DownloadFile).map(|e| self.text(e));
        for k in [K::SubNumber, K::CompactSubObj, K::Count, K::ObjExtend] {
            keys.move_to_extra(k);
        }
        if !keys.shadowed.is_empty() {
            self.check_shadowed(keys, Some(data_type));
        }
        let has_extra = !(extra_entries.is_empty() && keys.extra.is_empty());
        let has_rare = denotation.is_some()
            || obj_flags.is_some()
            || upload_file.is_some()
            || download_file.is_some()
            || has_extra;
        // Most sub-objects have none of these: no box is made for them.
        if has_rare || !sub.rare().is_empty() {
            let r = sub.rare_mut();
            r.denotation = denotation;
            r.obj_flags = obj_flags;
            r.upload_file = upload_file;
            r.download_file = download_file;
            if has_extra {
                r.extra = extra_entries
                    .into_iter()
                    .chain(keys.extra.drain(..))
                    .map(|e| raw_entry(e, file))
                    .collect();
            }
        }
    }

    fn object_kind(&mut self, e: &Entry<'_>) -> Option<ObjectKind> {
        let span = self.span(e.value_pos);
        let v = self.uint(e, 0xFF).ok().flatten()?;
        match ObjectKind::from_code(v.value as u8) {
            Some(k) => Some(k),
            None => {
                self.diags.push(
                    Diagnostic::error(
                        codes::INVALID_OBJECT_TYPE,
                        format!("ObjectType `{}` is not a CiA 301 object code", e.value),
                    )
                    .with_label(span, "expected 0x0, 0x2, 0x5, 0x6, 0x7, 0x8 or 0x9"),
                );
                None
            }
        }
    }

    fn object(
        &mut self,
        index: u16,
        b: &ObjB,
        extra: &mut Vec<(u32, RawSection)>,
    ) -> Option<Object> {
        let main = b.main?;
        let file = self.file;
        let header = self.span(self.sec(main).header_pos);
        let mut keys = self.keys(main);
        let mut obj_extra: Vec<&Entry<'_>> = Vec::new();
        let kind = match keys.take(K::ObjectType) {
            Some(e) => self.object_kind(e).unwrap_or_else(|| {
                obj_extra.push(e);
                // Sub-objects, explicit or implied by CompactSubObj, make it a RECORD (the writer
                // may turn explicit ones into implied ones).
                if b.subs.is_empty() && keys.get(K::CompactSubObj).is_none() {
                    ObjectKind::Var
                } else {
                    ObjectKind::Record
                }
            }),
            None => ObjectKind::Var,
        };
        let name = match keys.get(K::ParameterName) {
            Some(e) => e.value.to_owned(),
            // A VAR's sub-object 0 reports the missing name.
            None if !kind.has_subs() => String::new(),
            None => {
                self.warn(
                    codes::MISSING_NAME,
                    format!("object {index:04X} has no ParameterName"),
                    header,
                    "here",
                );
                String::new()
            }
        };
        let mut obj = Object::new(index, name, kind, header);
        if let Some(e) = keys.take(K::SubNumber) {
            match self.uint(e, 0xFFFF) {
                Ok(v) => obj.sub_number = v.map(|v| Spanned::new(v.value as u16, v.span)),
                Err(()) => obj_extra.push(e),
            }
        }
        if let Some(e) = keys.take(K::ObjFlags) {
            match self.uint(e, u64::from(u32::MAX)) {
                Ok(v) => obj.obj_flags = v.map(|v| Spanned::new(v.value as u32, v.span)),
                Err(()) => obj_extra.push(e),
            }
        }
        if kind.has_subs() {
            obj.denotation = keys.take(K::Denotation).map(|e| self.text(e));
            let compact = match keys.take(K::CompactSubObj) {
                Some(e) => match self.uint(e, 0xFF) {
                    Ok(v) => v.map(|v| Spanned::new(v.value as u8, v.span)),
                    Err(()) => {
                        obj_extra.push(e);
                        None
                    }
                },
                None => None,
            };
            obj.compact_sub_obj = compact.clone();
            let compact = compact.filter(|n| {
                self.implied_subs += usize::from(n.value);
                let over = self.implied_subs > crate::MAX_IMPLIED_SUB_OBJECTS;
                // Reported at the first object past the limit.
                if over
                    && self.implied_subs - usize::from(n.value) <= crate::MAX_IMPLIED_SUB_OBJECTS
                {
                    self.diags.push(
                        Diagnostic::error(
                            codes::COMPACT_LIMIT,
                            format!(
                                "more than {} sub-objects implied by CompactSubObj in this file; \
                                 this object and the later ones are not expanded",
                                crate::MAX_IMPLIED_SUB_OBJECTS
                            ),
                        )
                        .with_label(n.span, "the limit is crossed here"),
                    );
                }
                !over
            });
            match compact.filter(|n| n.value > 0) {
                Some(n) => self.compact_subs(&mut obj, &mut keys, n, b),
                None => obj.subs.reserve_exact(b.subs.len()),
            }
            keys.take(K::ParameterName);
            // Keys that only a VAR or a compact object uses are kept as written.
            for k in [
                K::DataType,
                K::AccessType,
                K::PdoMapping,
                K::DefaultValue,
                K::LowLimit,
                K::HighLimit,
                K::ParameterValue,
                K::UploadFile,
                K::DownloadFile,
                K::Count,
                K::ObjExtend,
            ] {
                keys.move_to_extra(k);
            }
            for (s, si) in b.subs.iter() {
                let sheader = self.span(self.sec(si).header_pos);
                let mut skeys = self.keys(si);
                let implied = obj.subs.contains_key(&s);
                let sub = obj.subs.entry(s).or_insert_with(|| blank_sub(s));
                if implied {
                    *sub = blank_sub(s);
                }
                self.fill_sub(
                    &mut skeys,
                    sub,
                    sheader,
                    None,
                    &format_args!("sub-object {index:04X}sub{s:X}"),
                );
                if implied {
                    self.warn(
                        codes::COMPACT_CONFLICT,
                        format!(
                            "[{}] overrides a sub-object implied by CompactSubObj",
                            self.sec(si).name
                        ),
                        self.span(self.sec(si).name_pos),
                        "explicit section wins",
                    );
                }
            }
        } else {
            keys.move_to_extra(K::CompactSubObj);
            self.null_object = kind == ObjectKind::Null;
            let default_dt = match kind {
                ObjectKind::Domain => Some(DataType::Domain),
                ObjectKind::Null => Some(DataType::Domain),
                ObjectKind::DefType => Some(DataType::Unsigned32),
                _ => None,
            };
            obj.subs.reserve_exact(1 + b.subs.len());
            let sub = obj.subs.entry(0).or_insert_with(|| blank_sub(0));
            self.fill_sub(&mut keys, sub, header, default_dt, &format_args!("object {index:04X}"));
            sub.kind = None;
            // Unknown keys of a VAR section belong to the object.
            if !sub.rare().extra.is_empty() {
                obj.extra.append(&mut sub.rare_mut().extra);
            }
            for (s, si) in b.subs.iter() {
                let sec = self.sec(si);
                self.warn(
                    codes::SUBS_ON_VAR,
                    format!("[{}] belongs to a {:?} object", sec.name, kind),
                    self.span(sec.name_pos),
                    "kept as a sub-object",
                );
                if s == 0 {
                    extra.push((si, self.raw_section(si)));
                    continue;
                }
                let sheader = self.span(sec.header_pos);
                let mut skeys = self.keys(si);
                let sub = obj.subs.entry(s).or_insert_with(|| blank_sub(s));
                self.fill_sub(
                    &mut skeys,
                    sub,
                    sheader,
                    None,
                    &format_args!("sub-object {index:04X}sub{s:X}"),
                );
            }
        }
        if let Some(li) = b.links {
            for (e, _) in self.list_section(li, "ObjectLinks", extra) {
                match self.uint(e, 0xFFFF) {
                    Ok(Some(v)) => obj.links.push(Spanned::new(v.value as u16, v.span)),
                    Ok(None) => {}
                    Err(()) => {}
                }
            }
        }
        self.companions(&mut obj, b);
        if !keys.shadowed.is_empty() {
            // A structured object's own keys (a VAR's went through `fill_sub`); values typed
            // by the object's DataType are those of a compact object's sub-objects.
            let dt = obj.sub(1).filter(|_| obj.compact_sub_obj.is_some()).map(|s| s.data_type);
            self.check_shadowed(&mut keys, dt);
        }
        let mut all_extra: Vec<RawEntry> =
            obj_extra.into_iter().chain(keys.extra.drain(..)).map(|e| raw_entry(e, file)).collect();
        all_extra.append(&mut obj.extra);
        obj.extra = all_extra;
        Some(obj)
    }

    fn compact_subs(
        &mut self,
        obj: &mut Object,
        keys: &mut Keys<'r, 'a>,
        n: Spanned<u8>,
        b: &ObjB,
    ) {
        let what = format_args!("compact object {:04X}", obj.index);
        // The template: DataType, AccessType, PDOMapping and values of the object section.
        let mut tkeys = Keys { k: [None; N_KEYS], extra: Vec::new(), shadowed: Vec::new() };
        for k in COMPACT_TEMPLATE {
            tkeys.k[k as usize] = keys.take(k);
        }
        tkeys.k[K::ParameterName as usize] = keys.get(K::ParameterName);
        let mut template = self.sub_from_keys(&mut tkeys, 1, obj.span, None, &what);
        // Every implied sub-object gets its own name: do not clone the template's.
        template.name = Name::default();
        template.span = n.span;
        let mut sub0 = SubObject::new(0, COMPACT_SUB0_NAME, DataType::Unsigned8, Access::Ro);
        sub0.default = Some(Spanned::new(Value::Unsigned(u64::from(n.value)), n.span));
        sub0.span = n.span;
        // Explicit sub sections are read after this, so `obj.subs` is empty here.
        obj.subs.reserve_exact(1 + b.subs.len());
        obj.subs.insert(0, sub0);
        obj.subs.set_implied(template, n.value, &obj.name);
    }

    /// `[IIIIName]`, `[IIIIValue]`, `[IIIIDenotation]`.
    fn companions(&mut self, obj: &mut Object, b: &ObjB) {
        for (sec, which) in [(b.name, 0u8), (b.value, 1), (b.denotation, 2)] {
            let Some(first) = sec else { continue };
            for e in self.entries(first) {
                if e.key.eq_ignore_ascii_case("NrOfEntries") {
                    continue;
                }
                // Companions name and set sub-objects of an ARRAY or RECORD: a VAR's sub-index 0
                // is the object itself, whose name is its own `ParameterName`.
                // `get_mut` makes only this one of a compact object's implied sub-objects.
                let sub = dec_u16(e.key.as_bytes())
                    .and_then(|n| u8::try_from(n).ok())
                    .filter(|_| obj.kind.has_subs())
                    .and_then(|n| obj.subs.get_mut(&n));
                let Some(s) = sub else {
                    self.warn(
                        codes::BAD_COMPACT_ENTRY,
                        format!(
                            "`{}` in [{}] is not a sub-index of object {:04X}",
                            e.key,
                            self.sec(first).name,
                            obj.index
                        ),
                        self.span(e.key_pos),
                        "ignored",
                    );
                    continue;
                };
                match which {
                    0 => s.name = Name::from(e.value),
                    1 => s.parameter_value = self.value(e, s.data_type),
                    _ => s.rare_mut().denotation = Some(self.text(e)),
                }
            }
        }
    }

    fn module(&mut self, number: u16, b: &ModB, extra: &mut Vec<(u32, RawSection)>) -> Module {
        let file = self.file;
        let mut m = Module { number, ..Default::default() };
        if let Some(i) = b.info {
            m.has_info = true;
            m.span = self.span(self.sec(i).header_pos);
            for e in self.entries(i) {
                let is = |n: &str| e.key.eq_ignore_ascii_case(n);
                if is("ProductName") {
                    m.product_name = Some(self.text(e));
                } else if is("OrderCode") {
                    m.order_code = Some(self.text(e));
                } else if is("ProductVersion") || is("ProductRevision") {
                    match self.uint(e, 0xFFFF) {
                        Ok(v) => {
                            let v = v.map(|v| Spanned::new(v.value as u16, v.span));
                            if is("ProductVersion") {
                                m.product_version = v;
                            } else {
                                m.product_revision = v;
                            }
                        }
                        Err(()) => m.extra.push(raw_entry(e, file)),
                    }
                } else {
                    m.extra.push(raw_entry(e, file));
                }
            }
        }
        if let Some(i) = b.fixed_list {
            // The list is implied by the [MxFixedIIII] sections; read it for diagnostics only.
            let _ = self.list_section(i, "NrOfEntries", extra);
        }
        for (&index, ob) in &b.fixed {
            match self.object(index, ob, extra) {
                Some(o) => {
                    std::sync::Arc::make_mut(&mut m.fixed_objects).insert(index, o);
                }
                None => {
                    for i in ob.subs.values() {
                        let s = self.sec(i);
                        self.warn(
                            codes::ORPHAN_SECTION,
                            format!("[{}] has no object section", s.name),
                            self.span(s.name_pos),
                            "kept as an unknown section",
                        );
                        extra.push((i, self.raw_section(i)));
                    }
                }
            }
        }
        if let Some(i) = b.sub_ext_list {
            let _ = self.list_section(i, "NrOfEntries", extra);
        }
        for (&index, &i) in &b.sub_ext {
            let header = self.span(self.sec(i).header_pos);
            let mut keys = self.keys(i);
            let count = keys.take(K::Count).map(|e| self.text(e));
            let obj_extend = keys.take(K::ObjExtend).and_then(|e| match self.uint(e, 0xFFFF) {
                Ok(v) => v.map(|v| Spanned::new(v.value as u16, v.span)),
                Err(()) => None,
            });
            let template = self.sub_from_keys(
                &mut keys,
                0,
                header,
                None,
                &format_args!("module {number} sub-extension {index:04X}"),
            );
            m.sub_extends.insert(index, SubExtend { template, count, obj_extend });
        }
        if let Some(i) = b.comments {
            m.comments = self.comments(i, extra);
        }
        m
    }
}

/// A sub-object with nothing read yet, for [`Lower::fill_sub`].
fn blank_sub(sub_index: u8) -> SubObject {
    SubObject::new(sub_index, String::new(), DataType::Domain, Access::Ro)
}
