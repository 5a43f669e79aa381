//! Lowering: element tree → [`odc_model::Device`]s.

use crate::codes;
use std::cell::RefCell;
use std::collections::{BTreeMap, HashMap};
use std::sync::Arc;

use odc_model::ethercat::{
    AlternativeSmMapping, ArrayInfo, CoE, Dc, DcOpMode, Eeprom, EnumItem, EsiDataType, EsiModule,
    EsiSubItem, EtherCat, Fmmu, Group, InitCmd, LocalizedText, Mailbox, ObjectFlags, PdoAttributes,
    Profile, RawXml, Slot, Slots, SmAssignment, SmUsage, SoE, SyncManager, XmlAttribute,
    default_assignment,
};
use odc_model::{
    Access, DataType, Device, DeviceInfo, Diagnostic, Direction, FileId, Format, Module, Name,
    Object, ObjectKind, Origin, Pdo, PdoEntry, PdoMapping, Span, Spanned, SubObject, Value,
};

use crate::num;
use crate::xml::{Attr, Element};
use odc_model::trim::trim;

mod coe;
mod eeprom;
mod ethercat;
mod objects;
mod types;

use coe::*;
use eeprom::*;
use ethercat::*;
use objects::*;
use types::*;

/// Device children the lowering interprets; the others are kept raw.
const DEVICE_KNOWN: &[&str] = &[
    "Type",
    "Name",
    "GroupType",
    "Profile",
    "Fmmu",
    "Sm",
    "RxPdo",
    "TxPdo",
    "Mailbox",
    "Dc",
    "Eeprom",
    "Slots",
    "Modules",
];

struct Ctx<'a> {
    src: &'a str,
    diags: &'a mut odc_model::Capped,
    /// Sub-objects made so far in this file (see [`crate::MAX_SUB_OBJECTS`]).
    subs: usize,
}

impl<'a> Ctx<'a> {
    fn push(&mut self, d: Diagnostic) {
        self.diags.push(d);
    }

    fn number(&mut self, text: &str, span: Span, what: &str) -> Option<i128> {
        let v = num::parse_int_lenient(text).map(|(v, broken)| {
            if broken {
                self.push(
                    Diagnostic::warning(
                        codes::NONSTANDARD_NUMBER,
                        format!("`{}` is not a well-formed number ({what})", text.trim()),
                    )
                    .with_label(span, format!("read as {v:#x}")),
                );
            }
            v
        });
        if v.is_none() {
            self.push(
                Diagnostic::error(
                    codes::INVALID_NUMBER,
                    format!("`{}` is not a number ({what})", text.trim()),
                )
                .with_label(span, "expected decimal or #x hex")
                .with_note("ETG.2000 HexDecValue: [+-]?[0-9]+ or #x[0-9a-fA-F]+"),
            );
        }
        v
    }

    fn ranged<T: TryFrom<i128>>(&mut self, v: i128, span: Span, what: &str) -> Option<T> {
        let r = T::try_from(v).ok();
        if r.is_none() {
            self.push(
                Diagnostic::error(
                    codes::NUMBER_OUT_OF_RANGE,
                    format!("{v} is out of range for {what}"),
                )
                .with_label(span, "out of range"),
            );
        }
        r
    }

    /// An element's text as a number of type `T`.
    fn el_num<T: TryFrom<i128>>(&mut self, el: Element<'_>, what: &str) -> Option<T> {
        let span = el.text_span();
        let v = self.number(el.text(), span, what)?;
        self.ranged(v, span, what)
    }

    /// An element's text as a u32; negative values in i32 range wrap (two's complement).
    fn el_u32(&mut self, el: Element<'_>, what: &str) -> Option<u32> {
        let span = el.text_span();
        let v = self.number(el.text(), span, what)?;
        self.wrap_u32(v, span, what)
    }

    fn wrap_u32(&mut self, v: i128, span: Span, what: &str) -> Option<u32> {
        if (i128::from(i32::MIN)..0).contains(&v) {
            return Some(v as i32 as u32);
        }
        self.ranged(v, span, what)
    }

    fn child_num<T: TryFrom<i128>>(&mut self, el: Element<'_>, name: &str) -> Option<T> {
        self.opt_num(el.child(name), name)
    }

    fn child_u32(&mut self, el: Element<'_>, name: &str) -> Option<u32> {
        self.opt_u32(el.child(name), name)
    }

    /// [`Self::el_num`] of a child found already (see [`Element::pick`]).
    fn opt_num<T: TryFrom<i128>>(&mut self, el: Option<Element<'_>>, what: &str) -> Option<T> {
        self.el_num(el?, what)
    }

    /// [`Self::el_u32`] of a child found already (see [`Element::pick`]).
    fn opt_u32(&mut self, el: Option<Element<'_>>, what: &str) -> Option<u32> {
        self.el_u32(el?, what)
    }

    fn attr_num<T: TryFrom<i128>>(&mut self, el: Element<'_>, name: &str) -> Option<T> {
        let a = el.attr(name)?;
        let v = self.number(a.value, a.span, name)?;
        self.ranged(v, a.span, name)
    }

    fn attr_u32(&mut self, el: Element<'_>, name: &str) -> Option<u32> {
        let a = el.attr(name)?;
        let v = self.number(a.value, a.span, name)?;
        self.wrap_u32(v, a.span, name)
    }

    fn attr_bool(&mut self, el: Element<'_>, name: &str) -> Option<bool> {
        let a: Attr = el.attr(name)?;
        let v = num::parse_bool(a.value);
        if v.is_none() {
            self.push(
                Diagnostic::error(
                    codes::INVALID_BOOLEAN,
                    format!("`{}` is not a boolean ({name})", a.value),
                )
                .with_label(a.span, "expected 1, 0, true or false"),
            );
        }
        v
    }

    fn el_bool(&mut self, el: Element<'_>) -> Option<bool> {
        let v = num::parse_bool(el.text());
        if v.is_none() {
            self.push(
                Diagnostic::error(
                    codes::INVALID_BOOLEAN,
                    format!("`{}` is not a boolean ({})", el.text(), el.name()),
                )
                .with_label(el.text_span(), "expected 1, 0, true or false"),
            );
        }
        v
    }

    fn hex(&mut self, el: Element<'_>) -> Vec<u8> {
        match num::parse_hex_bytes(el.text()) {
            Some(b) => b,
            None => {
                self.push(
                    Diagnostic::error(
                        codes::INVALID_DATA,
                        format!("`{}` is not hex bytes", el.name()),
                    )
                    .with_label(el.text_span(), "expected pairs of hex digits"),
                );
                Vec::new()
            }
        }
    }

    fn missing(&mut self, parent: Element<'_>, what: &str) {
        self.push(
            Diagnostic::error(
                codes::MISSING_ELEMENT,
                format!("`{}` has no `{what}`", parent.name()),
            )
            .with_label(parent.span(), format!("`{what}` missing")),
        );
    }

    fn raw(&self, parent: &str, el: Element<'_>) -> RawXml {
        RawXml {
            path: format!("{parent}/{}", el.name()),
            xml: self.src.get(el.span().range()).unwrap_or("").to_string(),
            span: el.span(),
        }
    }
}

fn names(el: Element<'_>, ctx: &mut Ctx<'_>) -> Vec<LocalizedText> {
    el.children_named("Name")
        .map(|n| LocalizedText {
            lc_id: ctx.attr_u32(n, "LcId"),
            text: n.text().to_string(),
            span: n.text_span(),
        })
        .collect()
}

/// English (1033) if there is one, else the first.
fn preferred(names: &[LocalizedText]) -> Option<&LocalizedText> {
    names.iter().find(|n| n.lc_id == Some(1033)).or_else(|| names.first())
}

fn first_name(el: Element<'_>) -> String {
    let mut best: Option<Element<'_>> = None;
    for n in el.children_named("Name") {
        let english = n.attr("LcId").is_some_and(|a| trim(a.value) == "1033");
        if english {
            best = Some(n);
            break;
        }
        if best.is_none() {
            best = Some(n);
        }
    }
    best.map(|n| n.text().to_string()).unwrap_or_default()
}

/// PDO definitions of old (ETG.2000 v1.2) files: `Descriptions/Pdos/Pdo@RefName`, referred to
/// by `RxPdo@Ref`/`TxPdo@Ref`.
type PdoRefs<'t> = HashMap<&'t str, Element<'t>>;

/// The file-level data shared by all devices.
struct FileData<'t> {
    pdo_refs: PdoRefs<'t>,
    /// Uninterpreted elements of the root, `Vendor` and `Descriptions`.
    raw: Vec<RawXml>,
    vendor_id: Option<Spanned<u32>>,
    vendor_names: Vec<LocalizedText>,
    groups: HashMap<String, Vec<LocalizedText>>,
    modules: Vec<EsiModule>,
}

/// Lowers the document.
pub(crate) fn lower(
    src: &str,
    _file: FileId,
    doc: &crate::xml::Document<'_>,
    diags: &mut odc_model::Capped,
) -> Vec<Device> {
    let mut ctx = Ctx { src, diags, subs: 0 };
    let Some(root) = doc.roots().next() else {
        if !ctx.diags.iter().any(|d| d.is_error()) {
            ctx.push(Diagnostic::error(codes::MALFORMED_XML, "the file has no root element"));
        }
        return Vec::new();
    };
    match root.name() {
        "EtherCATInfo" => {}
        "EtherCATModule" | "EtherCATDict" | "EtherCATDiag" => {
            ctx.push(
                Diagnostic::warning(
                    codes::NOT_ETHERCATINFO,
                    format!("`{}` file: it describes no device on its own", root.name()),
                )
                .with_label(root.span(), "root element"),
            );
            return Vec::new();
        }
        other => {
            ctx.push(
                Diagnostic::error(
                    codes::NOT_ETHERCATINFO,
                    format!("root element is `{other}`, not `EtherCATInfo`"),
                )
                .with_label(root.span(), "not an ESI file"),
            );
            return Vec::new();
        }
    }
    let vendor = root.child("Vendor");
    let vendor_id = vendor.and_then(|v| v.child("Id")).and_then(|id| {
        let v = ctx.el_u32(id, "Vendor Id")?;
        Some(Spanned::new(v, id.text_span()))
    });
    let vendor_names = vendor.map(|v| names(v, &mut ctx)).unwrap_or_default();
    let Some(descriptions) = root.child("Descriptions") else {
        // After a well-formedness error the rest of the file is unread: no second error for it.
        if !ctx.diags.iter().any(|d| d.code == codes::MALFORMED_XML) {
            ctx.missing(root, "Descriptions");
        }
        return Vec::new();
    };
    let mut groups = HashMap::new();
    if let Some(gs) = descriptions.child("Groups") {
        for g in gs.children_named("Group") {
            if let Some(t) = g.child("Type") {
                let n = names(g, &mut ctx);
                groups.insert(t.text().to_string(), n);
            }
        }
    }
    let mut pdo_refs = HashMap::new();
    if let Some(pdos) = descriptions.child("Pdos") {
        for p in pdos.children_named("Pdo") {
            if let Some(r) = p.attr("RefName") {
                pdo_refs.insert(trim(r.value), p);
            }
        }
    }
    let modules = descriptions
        .child("Modules")
        .map(|m| lower_modules(m, &mut ctx, &Types::default(), &pdo_refs))
        .unwrap_or_default();
    let mut raw = Vec::new();
    for c in root.children() {
        if !matches!(c.name(), "Vendor" | "Descriptions") {
            raw.push(ctx.raw("EtherCATInfo", c));
        }
    }
    for c in vendor.into_iter().flat_map(|v| v.children()) {
        if !matches!(c.name(), "Id" | "Name") {
            raw.push(ctx.raw("Vendor", c));
        }
    }
    for c in descriptions.children() {
        if !matches!(c.name(), "Groups" | "Devices" | "Modules" | "Pdos") {
            raw.push(ctx.raw("Descriptions", c));
        }
    }
    let data = FileData { pdo_refs, raw, vendor_id, vendor_names, groups, modules };
    let mut devices = Vec::new();
    if let Some(devs) = descriptions.child("Devices") {
        devices.reserve_exact(devs.children_named("Device").count());
        for d in devs.children_named("Device") {
            devices.push(lower_device(d, &data, &mut ctx));
        }
    }
    devices
}

fn lower_modules<'t>(
    el: Element<'t>,
    ctx: &mut Ctx<'_>,
    outer: &Types<'t>,
    refs: &PdoRefs<'t>,
) -> Vec<EsiModule> {
    let mut out = Vec::new();
    for m in el.children_named("Module") {
        let mut module = EsiModule { span: m.span(), ..EsiModule::default() };
        if let Some(t) = m.child("Type") {
            module.type_name = t.text().to_string();
            module.module_ident = ctx.attr_u32(t, "ModuleIdent");
            module.module_class = t.attr("ModuleClass").map(|a| a.value.to_string());
        }
        module.names = names(m, ctx);
        let mut types = Types::inherit(outer);
        let mut data_types = Vec::new();
        let dict = m.child("Profile").and_then(|p| p.child("Dictionary"));
        if let Some(dict) = dict {
            collect_types(dict, &mut types, &mut data_types, ctx);
        }
        module.pdos = lower_pdos(m, ctx, &types, refs, &mut module.pdo_attributes);
        if let Some(dict) = dict {
            let mut flags = FlagsOut::new();
            module.objects = Arc::new(lower_objects(dict, ctx, &types, &mut flags));
        }
        slot_dependent(m, &mut module.depend_on_slot, 0);
        module.depend_on_slot.sort_unstable();
        module.depend_on_slot.dedup();
        if let Some(coe) = m.child("Mailbox").and_then(|mb| mb.child("CoE")) {
            module.init_cmds = coe.children_named("InitCmd").map(|c| init_cmd(c, ctx)).collect();
        }
        // A slot names its modules by ident: two modules with one ident are ambiguous.
        if let Some(ident) = module.module_ident
            && let Some(first) = out.iter().find(|o: &&EsiModule| o.module_ident == Some(ident))
        {
            ctx.push(
                Diagnostic::warning(
                    codes::DUPLICATE_MODULE,
                    format!("module ident 0x{ident:X} used twice"),
                )
                .with_label(module.span, "this module")
                .with_secondary(first.span, "the first module with it"),
            );
        }
        out.push(module);
    }
    out
}

/// Collects the values of `Index` elements marked `DependOnSlot` below `el`.
fn slot_dependent(el: Element<'_>, out: &mut Vec<u16>, depth: u32) {
    for c in el.children() {
        if c.name() == "Index" {
            let marked = c.attr("DependOnSlot").and_then(|a| num::parse_bool(a.value));
            if marked == Some(true)
                && let Some(v) = num::parse_int(c.text()).and_then(|v| u16::try_from(v).ok())
            {
                out.push(v);
            }
        } else if depth < 8 {
            slot_dependent(c, out, depth + 1);
        }
    }
}

fn lower_device(d: Element<'_>, file: &FileData<'_>, ctx: &mut Ctx<'_>) -> Device {
    let mut ec = EtherCat {
        vendor_id: file.vendor_id.as_ref().map(|v| v.value),
        physics: d.attr("Physics").map(|a| a.value.to_string()),
        vendor_names: file.vendor_names.clone(),
        ..EtherCat::default()
    };
    let mut info = DeviceInfo {
        vendor_number: file.vendor_id.clone(),
        vendor_name: preferred(&file.vendor_names).map(|n| Spanned::new(n.text.clone(), n.span)),
        ..DeviceInfo::default()
    };
    // A device has many children (every PDO is one): the single ones found in one pass.
    let [type_el, group_type, mailbox_el, dc_el, eeprom_el, slots_el, modules_el] =
        d.pick(["Type", "GroupType", "Mailbox", "Dc", "Eeprom", "Slots", "Modules"]);
    match type_el {
        Some(t) => {
            for a in t.attrs() {
                match a.name {
                    "ProductCode" => {
                        let v = ctx.number(a.value, a.span, "ProductCode");
                        let v = v.and_then(|v| ctx.wrap_u32(v, a.span, "ProductCode"));
                        ec.product_code = v;
                        info.product_number = v.map(|v| Spanned::new(v, a.span));
                    }
                    "RevisionNo" => {
                        let v = ctx.number(a.value, a.span, "RevisionNo");
                        let v = v.and_then(|v| ctx.wrap_u32(v, a.span, "RevisionNo"));
                        ec.revision = v;
                        info.revision_number = v.map(|v| Spanned::new(v, a.span));
                    }
                    "SerialNo" => {
                        let v = ctx.number(a.value, a.span, "SerialNo");
                        ec.serial_no = v.and_then(|v| ctx.wrap_u32(v, a.span, "SerialNo"));
                    }
                    _ => ec.type_attributes.push(XmlAttribute {
                        name: a.name.to_string(),
                        value: a.value.to_string(),
                        span: a.span,
                    }),
                }
            }
            if !t.text().is_empty() {
                info.order_code = Some(Spanned::new(t.text().to_string(), t.text_span()));
            }
        }
        None => ctx.missing(d, "Type"),
    }
    ec.names = names(d, ctx);
    info.product_name = preferred(&ec.names).map(|n| Spanned::new(n.text.clone(), n.span));
    if let Some(g) = group_type {
        let type_name = g.text().to_string();
        let names = file.groups.get(&type_name).cloned().unwrap_or_default();
        ec.group = Some(Group { type_name, names, span: g.text_span() });
    }

    // Dictionary: data types first (all profiles), then objects.
    let mut types = Types::default();
    let mut objects = BTreeMap::new();
    let profiles: Vec<(Element<'_>, Option<Element<'_>>)> =
        d.children_named("Profile").map(|p| (p, p.child("Dictionary"))).collect();
    for &(_, dict) in &profiles {
        if let Some(dict) = dict {
            collect_types(dict, &mut types, &mut ec.data_types, ctx);
        }
    }
    let mut flags = FlagsOut::new();
    for &(p, dict) in &profiles {
        ec.profiles.push(Profile {
            channel: ctx.attr_u32(p, "Channel"),
            profile_no: ctx.child_u32(p, "ProfileNo"),
            add_info: ctx.child_u32(p, "AddInfo"),
            channel_count: ctx.child_u32(p, "ChannelCount"),
            channel_profiles: p
                .children_named("ChannelInfo")
                .map(|c| ctx.child_u32(c, "ProfileNo"))
                .collect(),
            dictionary_file: p.child("DictionaryFile").map(|f| f.text().to_string()),
            has_dictionary: dict.is_some(),
            span: p.span(),
        });
        if let Some(dict) = dict {
            let objs = lower_objects(dict, ctx, &types, &mut flags);
            objects.extend(objs);
        }
    }
    ec.object_flags = flags_by_key(flags);

    for f in d.children_named("Fmmu") {
        ec.fmmus.push(Fmmu {
            usage: SmUsage::parse(f.text()),
            sm: ctx.attr_num(f, "Sm"),
            su: ctx.attr_num(f, "Su"),
            span: f.span(),
        });
    }
    for (i, s) in d.children_named("Sm").enumerate() {
        let start_address = s.attr("StartAddress").and_then(|a| {
            let v = ctx.number(a.value, a.span, "StartAddress")?;
            Some(Spanned::new(ctx.ranged(v, a.span, "StartAddress")?, a.span))
        });
        let control_byte = s.attr("ControlByte").and_then(|a| {
            let v = ctx.number(a.value, a.span, "ControlByte")?;
            Some(Spanned::new(ctx.ranged(v, a.span, "ControlByte")?, a.span))
        });
        ec.sync_managers.push(SyncManager {
            number: i.min(255) as u8,
            usage: SmUsage::parse(s.text()),
            min_size: ctx.attr_num::<u16>(s, "MinSize").map(u32::from),
            max_size: ctx.attr_num::<u16>(s, "MaxSize").map(u32::from),
            // A sync manager's length register is 16 bits.
            default_size: ctx.attr_num::<u16>(s, "DefaultSize").map(u32::from),
            start_address,
            control_byte,
            enable: ctx.attr_bool(s, "Enable").unwrap_or(false),
            virtual_sm: ctx.attr_bool(s, "Virtual").unwrap_or(false),
            op_only: ctx.attr_bool(s, "OpOnly").unwrap_or(false),
            span: s.span(),
        });
    }
    let pdos = lower_pdos(d, ctx, &types, &file.pdo_refs, &mut ec.pdo_attributes);
    if let Some(info) = d.child("Info") {
        ec.alternative_sm_mappings = alternative_sm_mappings(info, ctx);
    }
    if let Some(mb) = mailbox_el {
        ec.mailbox = Some(mailbox(mb, ctx));
    }
    if let Some(dc) = dc_el {
        ec.dc = Some(lower_dc(dc, ctx));
    }
    ec.eeprom = eeprom_el.map(|e| lower_eeprom(e, ctx));
    if let Some(s) = slots_el {
        ec.slots = Some(lower_slots(s, ctx));
    }
    ec.modules = file.modules.clone();
    if let Some(m) = modules_el {
        ec.modules.extend(lower_modules(m, ctx, &types, &file.pdo_refs));
    }
    ec.raw.extend(file.raw.iter().cloned());
    for c in d.children() {
        if !DEVICE_KNOWN.contains(&c.name()) {
            ec.raw.push(ctx.raw("Device", c));
        }
    }

    if objects.is_empty() && !pdos.is_empty() {
        synthesise(&mut objects, &pdos, &ec.sync_managers);
        ec.dictionary_synthesised = true;
    }

    let modules = odc_model::Modules {
        supported: ec
            .modules
            .iter()
            .enumerate()
            .map(|(i, m)| Module {
                number: (i + 1).min(usize::from(u16::MAX)) as u16,
                has_info: true,
                product_name: preferred(&m.names).map(|n| Spanned::new(n.text.clone(), n.span)),
                order_code: (!m.type_name.is_empty())
                    .then(|| Spanned::new(m.type_name.clone(), m.span)),
                fixed_objects: m.objects.clone(),
                span: m.span,
                ..Module::default()
            })
            .collect(),
        connected: Vec::new(),
        nr_of_entries: None,
    };

    let mut device = Device {
        format: Some(Format::Esi),
        device_info: info,
        objects,
        modules,
        pdos,
        ethercat: Some(Box::new(ec)),
        ..Device::default()
    };
    complete_coe(&mut device, ctx);
    device
}
