//! Lowering: raw sections and entries → [`odc_model::Device`], with diagnostics. The section
//! names are classified in `classify`, the known keys of object sections found in `keys`,
//! values read in `read`; `sections` lowers the sections that are not objects and `objects`
//! the object, companion and module sections; this module walks the sections and builds the
//! device.

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
mod objects;
mod read;
pub(crate) use read::{Problem, read_value};
mod sections;

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
                    secs.push((section_key(0, x, Role::Main, 0), i));
                }
                Kind::Sub(x, s) => secs.push((section_key(0, x, Role::Sub, s), i)),
                Kind::Name(x) => secs.push((section_key(0, x, Role::Name, 0), i)),
                Kind::Value(x) => {
                    has_value_sections = true;
                    secs.push((section_key(0, x, Role::Value, 0), i));
                }
                Kind::Denotation(x) => secs.push((section_key(0, x, Role::Denotation, 0), i)),
                Kind::Links(x) => secs.push((section_key(0, x, Role::Links, 0), i)),
                Kind::ModInfo(m) => modules.entry(m).or_default().info = Some(i),
                Kind::ModFixedObjects(m) => modules.entry(m).or_default().fixed_list = Some(i),
                Kind::ModFixed(m, x) => {
                    modules.entry(m).or_default();
                    secs.push((section_key(u32::from(m) + 1, x, Role::Main, 0), i));
                }
                Kind::ModFixedSub(m, x, s) => {
                    modules.entry(m).or_default();
                    secs.push((section_key(u32::from(m) + 1, x, Role::Sub, s), i));
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
}
