//! Lowering: element tree → [`odc_model::Device`]s.

use crate::codes;
use std::cell::RefCell;
use std::collections::{BTreeMap, HashMap};
use std::sync::Arc;

use odc_model::ethercat::{
    ArrayInfo, CoE, Dc, DcOpMode, Eeprom, EnumItem, EsiDataType, EsiModule, EsiSubItem, EtherCat,
    Fmmu, Group, InitCmd, LocalizedText, Mailbox, ObjectFlags, Profile, RawXml, Slot, Slots,
    SmUsage, SoE, SyncManager, XmlAttribute,
};
use odc_model::{
    Access, DataType, Device, DeviceInfo, Diagnostic, Direction, FileId, Format, Module, Name,
    Object, ObjectKind, Origin, Pdo, PdoEntry, PdoMapping, Span, Spanned, SubObject, Value,
};

use crate::num;
use crate::xml::{Attr, Element};
use odc_model::trim::trim;

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

/// A data type name resolved.
#[derive(Clone, Copy, Debug)]
enum Resolved<'t> {
    /// A base type (possibly through `BaseType`), with the declared size if any.
    Simple(DataType, Option<u32>),
    /// A declared type with sub-items.
    Struct(Element<'t>, Option<u32>),
    /// A declared array type: element type, element bits, lower bound, element count.
    Array(DataType, Option<u32>, i64, u32),
}

/// The data types of one dictionary, by name.
#[derive(Default)]
struct Types<'t> {
    by_name: HashMap<&'t str, Element<'t>>,
    /// Names already resolved: a dictionary names the same few types thousands of times, and
    /// resolving walks the type's element and its base types.
    resolved: RefCell<HashMap<&'t str, Option<Resolved<'t>>>>,
}

fn builtin(name: &str) -> Option<DataType> {
    use DataType::*;
    let name = trim(name);
    // Upper-cased on the stack: called for every type name a dictionary mentions.
    let mut buf = [0u8; 32];
    let heap;
    let n = match buf.get_mut(..name.len()) {
        Some(b) => {
            b.copy_from_slice(name.as_bytes());
            b.make_ascii_uppercase();
            std::str::from_utf8(b).unwrap_or("")
        }
        None => {
            heap = name.to_ascii_uppercase();
            heap.as_str()
        }
    };
    Some(match n {
        "BOOL" | "BOOLEAN" => Boolean,
        "BIT" => Bit(1),
        "SINT" | "INT8" | "INTEGER8" => Integer8,
        "INT" | "INT16" | "INTEGER16" => Integer16,
        "INT24" | "INTEGER24" => Integer24,
        "DINT" | "INT32" | "INTEGER32" => Integer32,
        "INT40" | "INTEGER40" => Integer40,
        "INT48" | "INTEGER48" => Integer48,
        "INT56" | "INTEGER56" => Integer56,
        "LINT" | "INT64" | "INTEGER64" => Integer64,
        "USINT" | "BYTE" | "UINT8" | "UNSIGNED8" | "BITARR8" => Unsigned8,
        "UINT" | "WORD" | "UINT16" | "UNSIGNED16" | "BITARR16" => Unsigned16,
        "UINT24" | "UNSIGNED24" => Unsigned24,
        "UDINT" | "DWORD" | "UINT32" | "UNSIGNED32" | "BITARR32" => Unsigned32,
        "UINT40" | "UNSIGNED40" => Unsigned40,
        "UINT48" | "UNSIGNED48" => Unsigned48,
        "UINT56" | "UNSIGNED56" => Unsigned56,
        "ULINT" | "LWORD" | "UINT64" | "UNSIGNED64" => Unsigned64,
        "REAL" | "REAL32" | "FLOAT" => Real32,
        "LREAL" | "REAL64" | "DOUBLE" => Real64,
        "STRING" | "VISIBLE_STRING" => VisibleString,
        "OCTET_STRING" | "GUID" => OctetString,
        "UNICODE_STRING" | "WSTRING" => UnicodeString,
        "TIME_OF_DAY" => TimeOfDay,
        "TIME_DIFFERENCE" => TimeDifference,
        "DOMAIN" => Domain,
        _ => {
            if let Some(bits) = n.strip_prefix("BIT")
                && let Ok(b) = bits.parse::<u8>()
                && (1..=8).contains(&b)
            {
                return Some(Bit(b));
            }
            if n.starts_with("STRING(") || n.starts_with("VISIBLE_STRING(") {
                return Some(VisibleString);
            }
            if n.starts_with("OCTET_STRING(") {
                return Some(OctetString);
            }
            if n.starts_with("UNICODE_STRING(") || n.starts_with("WSTRING(") {
                return Some(UnicodeString);
            }
            if n.starts_with("ARRAY") && (n.ends_with("OF BYTE") || n.ends_with("OF USINT")) {
                return Some(OctetString);
            }
            return None;
        }
    })
}

/// The size in bits a type name says (`STRING(10)` → 80).
fn builtin_bits(name: &str) -> Option<u32> {
    let n = trim(name);
    let open = n.find('(')?;
    let close = n.rfind(')')?;
    let count: u32 = n.get(open + 1..close)?.trim().parse().ok()?;
    Some(count.saturating_mul(8))
}

/// A plausible type for a field of `bits` with no declared type.
fn type_for_bits(bits: u32) -> DataType {
    match bits {
        1 => DataType::Boolean,
        2..=7 => DataType::Bit(bits as u8),
        8 => DataType::Unsigned8,
        16 => DataType::Unsigned16,
        24 => DataType::Unsigned24,
        32 => DataType::Unsigned32,
        64 => DataType::Unsigned64,
        _ => DataType::OctetString,
    }
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
        let mut types = Types { by_name: outer.by_name.clone(), ..Types::default() };
        let mut data_types = Vec::new();
        let dict = m.child("Profile").and_then(|p| p.child("Dictionary"));
        if let Some(dict) = dict {
            collect_types(dict, &mut types, &mut data_types, ctx);
        }
        module.pdos = lower_pdos(m, ctx, &types, refs);
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
    let pdos = lower_pdos(d, ctx, &types, &file.pdo_refs);
    if let Some(mb) = mailbox_el {
        ec.mailbox = Some(mailbox(mb, ctx));
    }
    if let Some(dc) = dc_el {
        ec.dc = Some(lower_dc(dc, ctx));
    }
    if let Some(e) = eeprom_el {
        let mut ee = Eeprom { span: e.span(), ..Eeprom::default() };
        ee.byte_size = ctx.child_u32(e, "ByteSize");
        if let Some(c) = e.child("ConfigData") {
            ee.config_data = ctx.hex(c);
        }
        if let Some(c) = e.child("BootStrap") {
            ee.boot_strap = ctx.hex(c);
        }
        if let Some(c) = e.child("Data") {
            ee.data = ctx.hex(c);
        }
        ee.categories = e.children_named("Category").map(|c| ctx.raw("Eeprom", c)).collect();
        ec.eeprom = Some(ee);
    }
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
        synthesise(&mut objects, &pdos);
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

    Device {
        format: Some(Format::Esi),
        device_info: info,
        objects,
        modules,
        pdos,
        ethercat: Some(Box::new(ec)),
        ..Device::default()
    }
}

fn collect_types<'t>(
    dict: Element<'t>,
    types: &mut Types<'t>,
    out: &mut Vec<EsiDataType>,
    ctx: &mut Ctx<'_>,
) {
    let Some(dts) = dict.child("DataTypes") else { return };
    // New declarations may change what a name resolves to.
    types.resolved.get_mut().clear();
    for dt in dts.children_named("DataType") {
        let [name, index, base_type, bit_size] = dt.pick(["Name", "Index", "BaseType", "BitSize"]);
        let Some(name) = name else {
            ctx.missing(dt, "Name");
            continue;
        };
        let name_text = name.text();
        if types.by_name.insert(name_text, dt).is_some() {
            // Same name declared twice (several profiles declare the base types): the later
            // declaration wins, the model lists each once.
            out.retain(|t| t.name != name_text);
        }
        let mut m = EsiDataType {
            name: name_text.into(),
            index: ctx.opt_u32(index, "Index"),
            base_type: base_type.map(|b| Name::from(b.text())),
            bit_size: ctx.opt_u32(bit_size, "BitSize"),
            span: dt.span(),
            ..EsiDataType::default()
        };
        for a in dt.children_named("ArrayInfo") {
            m.array_info.push(ArrayInfo {
                lbound: ctx.child_num(a, "LBound").unwrap_or(0),
                elements: ctx.child_u32(a, "Elements").unwrap_or(0),
            });
        }
        m.sub_items.reserve_exact(dt.children_named("SubItem").count());
        for s in dt.children_named("SubItem") {
            let [sub_idx, name, type_name, bit_size, bit_offset, flags] =
                s.pick(["SubIdx", "Name", "Type", "BitSize", "BitOffs", "Flags"]);
            let [access, pdo_mapping] =
                flags.map_or([None; 2], |f| f.pick(["Access", "PdoMapping"]));
            let text = |e: Option<Element<'_>>| e.map(|e| Name::from(e.text()));
            m.sub_items.push(EsiSubItem {
                sub_idx: ctx.opt_u32(sub_idx, "SubIdx"),
                name: text(name).unwrap_or_default(),
                type_name: text(type_name).unwrap_or_default(),
                bit_size: ctx.opt_u32(bit_size, "BitSize"),
                bit_offset: ctx.opt_u32(bit_offset, "BitOffs"),
                access: text(access),
                pdo_mapping: text(pdo_mapping),
            });
        }
        for e in dt.children_named("EnumInfo") {
            let text = e.child("Text").map(|t| t.text().to_string()).unwrap_or_default();
            if let Some(value) = e.child("Enum").and_then(|v| ctx.el_num::<i64>(v, "Enum")) {
                m.enum_info.push(EnumItem { text, value });
            }
        }
        out.push(m);
    }
}

impl<'t> Types<'t> {
    /// Resolves a type name; `None` when it is neither declared nor built in.
    fn resolve(&self, name: &'t str) -> Option<Resolved<'t>> {
        if let Some(r) = self.resolved.borrow().get(name) {
            return *r;
        }
        let r = self.resolve_at(name, 0);
        self.resolved.borrow_mut().insert(name, r);
        r
    }

    fn resolve_at(&self, name: &str, depth: u32) -> Option<Resolved<'t>> {
        let name = trim(name);
        if depth > 16 {
            return None;
        }
        if let Some(&dt) = self.by_name.get(name) {
            let bits = dt.child("BitSize").and_then(|b| num::parse_int(b.text()));
            let bits = bits.and_then(|b| u32::try_from(b).ok());
            if dt.child("SubItem").is_some() {
                return Some(Resolved::Struct(dt, bits));
            }
            let base = dt.child("BaseType").map(|b| b.text());
            // `ARRAY [0..1] OF BYTE`, `STRING(10)`: declared with ArrayInfo, but one octet or
            // visible string sub-object, not an array of sub-objects.
            if let Some(b) = builtin(name) {
                return Some(Resolved::Simple(b, bits.or_else(|| builtin_bits(name))));
            }
            if let Some(ai) = dt.child("ArrayInfo") {
                let lbound = ai.child("LBound").and_then(|x| num::parse_int(x.text())).unwrap_or(0);
                let elements =
                    ai.child("Elements").and_then(|x| num::parse_int(x.text())).unwrap_or(0);
                let elements = u32::try_from(elements).unwrap_or(0);
                let (elem_ty, elem_bits) = match base.and_then(|b| self.resolve_at(b, depth + 1)) {
                    Some(Resolved::Simple(t, b)) => (t, b.or_else(|| t.bit_size())),
                    _ => {
                        let eb = bits.and_then(|b| b.checked_div(elements));
                        (eb.map(type_for_bits).unwrap_or(DataType::Unsigned8), eb)
                    }
                };
                return Some(Resolved::Array(elem_ty, elem_bits, lbound as i64, elements));
            }
            if let Some(base) = base
                && trim(base) != name
            {
                return match self.resolve_at(base, depth + 1)? {
                    Resolved::Simple(t, b) => Some(Resolved::Simple(t, bits.or(b))),
                    other => Some(other),
                };
            }
            // Enumerations and opaque types without a base type: guess from the size.
            return Some(Resolved::Simple(type_for_bits(bits.unwrap_or(8)), bits));
        }
        builtin(name).map(|t| Resolved::Simple(t, builtin_bits(name)))
    }
}

fn access_of(text: &str, span: Span, ctx: &mut Ctx<'_>) -> Access {
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

fn pdo_mapping_of(text: &str, span: Span, ctx: &mut Ctx<'_>) -> PdoMapping {
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
type FlagsOut = Vec<ObjectFlags>;

/// The flags sorted by index and sub-index, the last one given for a sub-object winning.
fn flags_by_key(mut flags: FlagsOut) -> Vec<ObjectFlags> {
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
struct ReadFlags {
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
fn value_of(el: Element<'_>, ty: DataType, ctx: &mut Ctx<'_>) -> Spanned<Value> {
    let text = el.text();
    let is_data = el.name().ends_with("Data");
    let v = if is_data {
        num::with_hex_bytes_lenient(text, |b| num::decode_data(b, ty)).and_then(|(v, padded)| {
            if padded {
                ctx.push(
                    Diagnostic::warning(
                        codes::NONSTANDARD_NUMBER,
                        format!("`{text}` has an odd number of hex digits ({})", el.name()),
                    )
                    .with_label(el.text_span(), "read with a leading zero"),
                );
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
fn apply_info(info: Element<'_>, sub: &mut SubObject, ctx: &mut Ctx<'_>) {
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

fn unknown_type(name: &str, span: Span, ctx: &mut Ctx<'_>, severe: bool) {
    let msg = format!("unknown data type `{name}`");
    let d = if severe {
        Diagnostic::error(codes::UNKNOWN_DATA_TYPE, msg)
    } else {
        Diagnostic::warning(codes::UNKNOWN_DATA_TYPE, msg)
    };
    ctx.push(d.with_label(span, "neither declared in DataTypes nor a base type"));
}

fn lower_objects<'t>(
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
                    apply_sub_infos(i, &mut object, ctx);
                }
            }
            Some(Resolved::Struct(dt, _)) => {
                lower_struct(dt, types, &mut object, flags, ctx, flags_out);
                if let Some(i) = info {
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

/// Builds the sub-objects of `object` from a structured data type's `SubItem`s.
fn lower_struct<'t>(
    dt: Element<'t>,
    types: &Types<'t>,
    object: &mut Object,
    obj_flags: Option<Element<'t>>,
    ctx: &mut Ctx<'_>,
    flags_out: &mut FlagsOut,
) {
    let index = object.index;
    let object_span = object.span;
    let mut next: i64 = 0;
    let mut saw_array = false;
    let mut saw_other = false;
    // One sub-object per SubItem, unless one is an array.
    object.subs.reserve_exact(dt.children_named("SubItem").count());
    for si in dt.children_named("SubItem") {
        let [name, type_el, bits, sub_idx, flags] =
            si.pick(["Name", "Type", "BitSize", "SubIdx", "Flags"]);
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
                make(n, name, ty, bits.or(tbits), ctx);
                next = i64::from(n) + 1;
            }
        }
    }
    object.kind = if saw_array && !saw_other { ObjectKind::Array } else { ObjectKind::Record };
}

/// Matches `Info/SubItem`s to the object's sub-objects by name and applies their `Info`.
fn apply_sub_infos(info: Element<'_>, object: &mut Object, ctx: &mut Ctx<'_>) {
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

fn lower_pdos<'t>(
    parent: Element<'t>,
    ctx: &mut Ctx<'_>,
    types: &Types<'t>,
    refs: &PdoRefs<'t>,
) -> Vec<Pdo> {
    let mut pdos = Vec::new();
    for pdo_el in parent.children() {
        let direction = match pdo_el.name() {
            "RxPdo" => Direction::Rx,
            "TxPdo" => Direction::Tx,
            _ => continue,
        };
        // The definition: the element itself, or the `Pdo` its `Ref` names (old files).
        let c = match pdo_el.attr("Ref") {
            Some(r) if pdo_el.child("Index").is_none() => match refs.get(trim(r.value)) {
                Some(def) => *def,
                None => {
                    ctx.push(
                        Diagnostic::error(
                            codes::MISSING_ELEMENT,
                            format!("no `Pdo` with RefName `{}`", r.value),
                        )
                        .with_label(r.span, "referred to here"),
                    );
                    continue;
                }
            },
            _ => pdo_el,
        };
        let Some(index_el) = c.child("Index") else {
            ctx.missing(c, "Index");
            continue;
        };
        let Some(mapping_index) = ctx.el_num::<u16>(index_el, "PDO index") else { continue };
        // Entries are rarely skipped: sized to the elements, no regrowth copies.
        let mut entries = Vec::with_capacity(c.children_named("Entry").count());
        for e in c.children_named("Entry") {
            let [ie, sub, bl, dt_el, name] =
                e.pick(["Index", "SubIndex", "BitLen", "DataType", "Name"]);
            let Some(ie) = ie else {
                ctx.missing(e, "Index");
                continue;
            };
            let Some(index) = ctx.el_num::<u16>(ie, "entry index") else { continue };
            let sub = ctx.opt_num::<u8>(sub, "entry sub-index");
            let Some(bl) = bl else {
                ctx.missing(e, "BitLen");
                continue;
            };
            let Some(bits) = ctx.el_num::<u16>(bl, "BitLen") else { continue };
            let dt_el = dt_el.filter(|t| !t.text().is_empty());
            let data_type = dt_el.and_then(|t| match types.resolve(t.text()) {
                Some(Resolved::Simple(ty, _)) => Some(ty),
                Some(Resolved::Array(..) | Resolved::Struct(..)) => Some(DataType::Domain),
                None => {
                    unknown_type(t.text(), t.text_span(), ctx, false);
                    None
                }
            });
            entries.push(PdoEntry {
                index,
                sub: sub.unwrap_or(0),
                bits,
                name: name.map(|n| n.text().to_string()).filter(|n| !n.is_empty()),
                data_type,
                span: e.span(),
            });
        }
        pdos.push(Pdo {
            direction,
            mapping_index,
            comm_index: None,
            name: first_name(c),
            cob_id: None,
            transmission_type: None,
            inhibit_time: None,
            event_timer: None,
            sync_start: None,
            entries,
            sync_manager: ctx.attr_num(pdo_el, "Sm"),
            fixed: ctx.attr_bool(pdo_el, "Fixed").unwrap_or(false),
            mandatory: ctx.attr_bool(pdo_el, "Mandatory").unwrap_or(false),
            excludes: c
                .children_named("Exclude")
                .filter_map(|x| ctx.el_num::<u16>(x, "Exclude"))
                .collect(),
            span: pdo_el.span(),
        });
    }
    pdos
}

fn init_cmd(c: Element<'_>, ctx: &mut Ctx<'_>) -> InitCmd {
    InitCmd {
        transitions: c.children_named("Transition").map(|t| t.text().to_string()).collect(),
        index: c
            .child("Index")
            .or_else(|| c.child("IDN"))
            .and_then(|i| ctx.el_u32(i, "InitCmd index")),
        sub_index: ctx.child_u32(c, "SubIndex"),
        data: c.child("Data").map(|d| ctx.hex(d)).unwrap_or_default(),
        comment: c.child("Comment").map(|t| t.text().to_string()),
        complete_access: ctx.attr_bool(c, "CompleteAccess").unwrap_or(false),
        fixed: ctx.attr_bool(c, "Fixed").unwrap_or(false),
        span: c.span(),
    }
}

fn mailbox(mb: Element<'_>, ctx: &mut Ctx<'_>) -> Mailbox {
    let mut m = Mailbox {
        data_link_layer: ctx.attr_bool(mb, "DataLinkLayer").unwrap_or(false),
        span: mb.span(),
        ..Mailbox::default()
    };
    if let Some(c) = mb.child("CoE") {
        m.coe = Some(CoE {
            sdo_info: ctx.attr_bool(c, "SdoInfo").unwrap_or(false),
            pdo_assign: ctx.attr_bool(c, "PdoAssign").unwrap_or(false),
            pdo_config: ctx.attr_bool(c, "PdoConfig").unwrap_or(false),
            pdo_upload: ctx.attr_bool(c, "PdoUpload").unwrap_or(false),
            complete_access: ctx.attr_bool(c, "CompleteAccess").unwrap_or(false),
            segmented_sdo: ctx.attr_bool(c, "SegmentedSdo").unwrap_or(false),
            eds_file: c.attr("EdsFile").map(|a| a.value.to_string()),
            init_cmds: c.children_named("InitCmd").map(|i| init_cmd(i, ctx)).collect(),
        });
    }
    if let Some(s) = mb.child("SoE") {
        m.soe = Some(SoE {
            channel_count: ctx.attr_u32(s, "ChannelCount"),
            init_cmds: s.children_named("InitCmd").map(|i| init_cmd(i, ctx)).collect(),
        });
    }
    m.foe = mb.child("FoE").is_some();
    m.eoe = mb.child("EoE").is_some();
    m.aoe = mb.child("AoE").is_some();
    m.voe = mb.child("VoE").is_some();
    m
}

fn lower_dc(dc: Element<'_>, ctx: &mut Ctx<'_>) -> Dc {
    let mut out = Dc { span: dc.span(), ..Dc::default() };
    for o in dc.children_named("OpMode") {
        let factor = |name: &str, ctx: &mut Ctx<'_>| -> Option<i64> {
            o.child(name).and_then(|e| ctx.attr_num::<i64>(e, "Factor"))
        };
        out.op_modes.push(DcOpMode {
            name: o.child("Name").map(|n| n.text().to_string()).unwrap_or_default(),
            desc: o.child("Desc").map(|n| n.text().to_string()),
            assign_activate: ctx.child_u32(o, "AssignActivate"),
            cycle_time_sync0: ctx.child_u32(o, "CycleTimeSync0"),
            cycle_time_sync0_factor: factor("CycleTimeSync0", ctx),
            shift_time_sync0: ctx.child_num(o, "ShiftTimeSync0"),
            shift_time_sync0_factor: factor("ShiftTimeSync0", ctx),
            cycle_time_sync1: ctx.child_u32(o, "CycleTimeSync1"),
            cycle_time_sync1_factor: factor("CycleTimeSync1", ctx),
            shift_time_sync1: ctx.child_num(o, "ShiftTimeSync1"),
            span: o.span(),
        });
    }
    out
}

fn lower_slots(s: Element<'_>, ctx: &mut Ctx<'_>) -> Slots {
    let mut out = Slots {
        slot_index_increment: ctx.attr_u32(s, "SlotIndexIncrement"),
        slot_pdo_increment: ctx.attr_u32(s, "SlotPdoIncrement"),
        max_slot_count: ctx.attr_u32(s, "MaxSlotCount"),
        span: s.span(),
        ..Slots::default()
    };
    for slot in s.children_named("Slot") {
        let mut sl = Slot {
            name: first_name(slot),
            min_instances: ctx.attr_u32(slot, "MinInstances"),
            max_instances: ctx.attr_u32(slot, "MaxInstances"),
            slot_index_increment: ctx.attr_u32(slot, "SlotIndexIncrement"),
            slot_pdo_increment: ctx.attr_u32(slot, "SlotPdoIncrement"),
            span: slot.span(),
            ..Slot::default()
        };
        for mi in slot.children_named("ModuleIdent") {
            if let Some(v) = ctx.el_u32(mi, "ModuleIdent") {
                sl.module_idents.push(v);
                if ctx.attr_bool(mi, "Default") == Some(true) {
                    sl.default_module = Some(v);
                }
            }
        }
        sl.module_classes =
            slot.children_named("ModuleClass").map(|c| c.text().to_string()).collect();
        out.slots.push(sl);
    }
    out
}

/// `SubIndex 001`, the name ESI gives an array element: made inline, with no allocation.
fn sub_index_name(n: u8) -> Name {
    let mut b = *b"SubIndex 000";
    b[9] += n / 100;
    b[10] += n / 10 % 10;
    b[11] += n % 10;
    Name::new(std::str::from_utf8(&b).unwrap_or_default())
}

/// A device without a dictionary: objects for its PDO entries, mapping objects and the
/// sync-manager assignment objects, all marked [`Origin::PdoEntry`].
fn synthesise(objects: &mut BTreeMap<u16, Object>, pdos: &[Pdo]) {
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
            let mut s = SubObject::new(e.sub, name, ty, access);
            s.pdo_mapping = mapping;
            s.bit_size = Some(u32::from(e.bits));
            s.span = e.span;
            object.subs.entry(e.sub).or_insert(s);
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
        if objects.contains_key(&pdo.mapping_index) {
            continue;
        }
        let mut o = new_object(pdo.mapping_index, &pdo.name, ObjectKind::Record, pdo.span);
        let mut s0 = SubObject::new(0, "SubIndex 000", DataType::Unsigned8, Access::Ro);
        s0.default = Some(Spanned::synthetic(Value::Unsigned(pdo.entries.len() as u64)));
        s0.span = pdo.span;
        o.subs.insert(0, s0);
        for (i, e) in pdo.entries.iter().enumerate().take(254) {
            let n = (i + 1) as u8;
            let mut s = SubObject::new(n, sub_index_name(n), DataType::Unsigned32, Access::Ro);
            s.default = Some(Spanned::synthetic(Value::Unsigned(u64::from(e.mapping_value()))));
            s.span = e.span;
            o.subs.insert(n, s);
        }
        objects.insert(pdo.mapping_index, o);
    }
    for (index, dir, name) in
        [(0x1C12u16, Direction::Rx, "RxPDO assign"), (0x1C13, Direction::Tx, "TxPDO assign")]
    {
        if objects.contains_key(&index) || !pdos.iter().any(|p| p.direction == dir) {
            continue;
        }
        let assigned: Vec<u16> = pdos
            .iter()
            .filter(|p| p.direction == dir && (p.sync_manager.is_some() || p.mandatory))
            .map(|p| p.mapping_index)
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
