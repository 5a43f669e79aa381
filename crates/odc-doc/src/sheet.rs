//! What a data sheet says, gathered once from the model: both renderers draw from a [`Sheet`],
//! so the HTML page and the Markdown file cannot tell different stories.

use odc_analysis::image::{Image, default_images};
use odc_model::{
    Device, Diagnostic, Direction, Format, Object, Severity, Sources, SubObject, Value,
};

/// What the sheet is made from.
pub struct Input<'a> {
    /// The device.
    pub device: &'a Device,
    /// The device file's name as the sheet shows it.
    pub file: &'a str,
    /// The sources, for the lines and columns of the diagnostics.
    pub sources: Option<&'a Sources>,
    /// What `odc check` says about the device.
    pub diagnostics: &'a [Diagnostic],
    /// The vendor parameter schemes of the overlay.
    pub schemes: &'a [odc_analysis::Scheme],
}

/// A device's data sheet.
#[derive(Clone, Debug)]
pub struct Sheet {
    /// The product's name.
    pub title: String,
    /// The device file.
    pub file: String,
    /// Identity and file information, label and value.
    pub identity: Vec<(String, String)>,
    /// Capabilities: bit rates, PDO counts, LSS, granularity; for EtherCAT the sync managers,
    /// FMMUs, mailbox protocols and DC modes.
    pub capabilities: Vec<(String, String)>,
    /// CiA 402 modes of operation the device supports: value of 0x6060, name.
    pub modes: Vec<(i8, String)>,
    /// One row per object and per sub-object, in index order.
    pub objects: Vec<ObjectRow>,
    /// Every PDO the file defines, and for EtherCAT the default process image.
    pub diagrams: Vec<Diagram>,
    /// The overlay's parameter schemes.
    pub schemes: Vec<SchemeDoc>,
    /// The diagnostics of `odc check`.
    pub findings: Vec<Finding>,
}

/// A row of the object table.
#[derive(Clone, Debug)]
pub struct ObjectRow {
    /// The HTML id (`o1018` for an object, `o1018-01` for a sub-object).
    pub anchor: String,
    /// Object index.
    pub index: u16,
    /// Sub-index; `None` on the row that heads a RECORD or ARRAY.
    pub sub: Option<u8>,
    /// Name.
    pub name: String,
    /// Object code (VAR, ARRAY, RECORD, …) on an object's row; empty on a sub-object's.
    pub kind: String,
    /// Data type.
    pub data_type: String,
    /// Access.
    pub access: String,
    /// Whether and how it maps into PDOs (`RPDO`, `TPDO`, `RPDO/TPDO`), empty when not.
    pub pdo: String,
    /// Default value.
    pub default: String,
    /// The configured value (DCF/XDC `ParameterValue`/`actualValue`), if any.
    pub value: String,
    /// Lowest value.
    pub low: String,
    /// Highest value.
    pub high: String,
    /// Denotation (DCF/XDC).
    pub denotation: String,
    /// Whether the row is the file's, or odc's.
    pub made: Made,
}

/// Where a row of the object table comes from: a sheet must not present odc's objects or
/// values as the file's.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Made {
    /// The file.
    File,
    /// odc made the object ([`odc_model::Origin::is_esi_synthesised`]): an ESI's objects
    /// ETG.1000.6 gives a CoE device (0x1C00, 0x1C1n, mapping objects), or a dictionary made
    /// from the PDO entries of an ESI without one.
    Synthesised,
    /// The file's object, with the defaults odc took from the ESI's PDO elements because the
    /// file gives none ([`odc_model::ethercat::EtherCat::esi_defaults`]).
    DefaultFromEsi,
}

impl Made {
    /// The mark beside the index (empty for the file's rows).
    pub fn marker(self) -> &'static str {
        match self {
            Made::File => "",
            Made::Synthesised => "†",
            Made::DefaultFromEsi => "‡",
        }
    }

    /// What the mark means, for the legend under the table.
    pub fn legend(self) -> &'static str {
        match self {
            Made::File => "",
            Made::Synthesised => {
                "not in the file: odc synthesised it from the ESI's sync managers and PDOs \
                 (an object ETG.1000.6 gives a CoE device, or one made from the PDO entries of \
                 an ESI without a dictionary)"
            }
            Made::DefaultFromEsi => {
                "the file gives no default: the device starts with what the ESI's PDO elements \
                 say (Sm attributes, entries)"
            }
        }
    }
}

/// The marks the rows of `rows` use, each once, in order, with their meaning.
pub fn legend(rows: &[ObjectRow]) -> Vec<(&'static str, &'static str)> {
    [Made::Synthesised, Made::DefaultFromEsi]
        .into_iter()
        .filter(|m| rows.iter().any(|r| r.made == *m))
        .map(|m| (m.marker(), m.legend()))
        .collect()
}

/// A bit diagram: a PDO or one direction of a process image.
#[derive(Clone, Debug)]
pub struct Diagram {
    /// The HTML id.
    pub anchor: String,
    /// Its heading.
    pub title: String,
    /// What else to say about it (COB-ID, transmission type, sync manager).
    pub detail: String,
    /// Length in bits (fields and gaps).
    pub bits: u32,
    /// The fields, in wire order.
    pub fields: Vec<Field>,
}

/// One field of a diagram.
#[derive(Clone, Debug)]
pub struct Field {
    /// First bit, from the start of the diagram (bit 0 of byte 0).
    pub offset: u32,
    /// Width in bits.
    pub bits: u32,
    /// The mapped object (`0x6041:00`), empty for a gap.
    pub address: String,
    /// The object's name, or `gap`.
    pub name: String,
    /// Its data type, if known.
    pub data_type: String,
    /// The anchor of its row in the object table, if the device has the object.
    pub anchor: Option<String>,
}

impl Field {
    /// Whether the field only fills space (CANopen dummy entry, EtherCAT gap).
    pub fn is_gap(&self) -> bool {
        self.address.is_empty()
    }
}

/// A vendor parameter scheme.
#[derive(Clone, Debug)]
pub struct SchemeDoc {
    /// The generated module.
    pub module: String,
    /// What it is (the overlay's `doc`).
    pub doc: String,
    /// The rule: `index = …` with the arguments' ranges.
    pub rule: String,
    /// The entries it names: alias, object anchor, address, what.
    pub entries: Vec<(String, String, String, String)>,
    /// Why the entries could not be listed.
    pub error: Option<String>,
}

/// A diagnostic of `odc check`.
#[derive(Clone, Debug)]
pub struct Finding {
    /// `error`, `warning`, …
    pub severity: String,
    /// The rule's code.
    pub code: String,
    /// The message.
    pub message: String,
    /// `line L, column C` of its primary label.
    pub at: String,
    /// The object row it concerns.
    pub anchor: Option<String>,
}

/// The anchor of an object's row.
pub fn object_anchor(index: u16) -> String {
    format!("o{index:04X}")
}

/// The anchor of a sub-object's row (the object's for a VAR).
fn sub_anchor(object: &Object, sub: u8) -> String {
    if object.kind.has_subs() {
        format!("o{:04X}-{sub:02X}", object.index)
    } else {
        object_anchor(object.index)
    }
}

/// Gathers the sheet.
pub fn sheet(input: &Input<'_>) -> Sheet {
    let dev = input.device;
    Sheet {
        title: dev.name().to_owned(),
        file: input.file.to_owned(),
        identity: identity(dev),
        capabilities: capabilities(dev),
        modes: if odc_analysis::is_cia402(dev) {
            odc_analysis::supported_modes(dev)
                .into_iter()
                .map(|m| (m.value, m.text.to_owned()))
                .collect()
        } else {
            Vec::new()
        },
        objects: objects(dev),
        diagrams: diagrams(dev),
        schemes: input.schemes.iter().map(|s| scheme(dev, s)).collect(),
        findings: input.diagnostics.iter().map(|d| finding(dev, input.sources, d)).collect(),
    }
}

fn hex32(v: u32) -> String {
    format!("0x{v:08X}")
}

fn yes_no(b: bool) -> String {
    if b { "yes" } else { "no" }.to_owned()
}

fn identity(dev: &Device) -> Vec<(String, String)> {
    let info = &dev.device_info;
    let fi = &dev.file_info;
    let mut rows = Vec::new();
    let mut text = |label: &str, v: Option<String>| {
        if let Some(v) = v.filter(|v| !v.is_empty()) {
            rows.push((label.to_owned(), v));
        }
    };
    text("Vendor", info.vendor_name.as_ref().map(|v| v.value.clone()));
    text("Vendor ID", info.vendor_number.as_ref().map(|v| hex32(v.value)));
    text("Product", info.product_name.as_ref().map(|v| v.value.clone()));
    text("Product code", info.product_number.as_ref().map(|v| hex32(v.value)));
    text("Revision", info.revision_number.as_ref().map(|v| hex32(v.value)));
    text("Order code", info.order_code.as_ref().map(|v| v.value.clone()));
    text("Format", dev.format.map(|f| format_name(f).to_owned()));
    text("File name", fi.file_name.as_ref().map(|v| v.value.clone()));
    text(
        "File version",
        match (&fi.file_version, &fi.file_revision) {
            (Some(v), Some(r)) => Some(format!("{}.{}", v.value, r.value)),
            (Some(v), None) => Some(v.value.to_string()),
            _ => None,
        },
    );
    text("Description", fi.description.as_ref().map(|v| v.value.clone()));
    let when = |date: &Option<odc_model::Spanned<String>>,
                time: &Option<odc_model::Spanned<String>>| {
        let parts: Vec<&str> =
            [date, time].into_iter().flatten().map(|s| s.value.as_str()).collect();
        (!parts.is_empty()).then(|| parts.join(" "))
    };
    text("Created", when(&fi.creation_date, &fi.creation_time));
    text("Created by", fi.created_by.as_ref().map(|v| v.value.clone()));
    text("Modified", when(&fi.modification_date, &fi.modification_time));
    text("Modified by", fi.modified_by.as_ref().map(|v| v.value.clone()));
    rows
}

fn format_name(f: Format) -> &'static str {
    match f {
        Format::Eds => "EDS (CiA 306)",
        Format::Dcf => "DCF (CiA 306)",
        Format::Xdd => "XDD (CiA 311)",
        Format::Xdc => "XDC (CiA 311)",
        Format::Esi => "ESI (ETG.2000)",
    }
}

fn capabilities(dev: &Device) -> Vec<(String, String)> {
    let info = &dev.device_info;
    let mut rows: Vec<(String, String)> = Vec::new();
    if !info.baud_rates.is_empty() {
        let rates: Vec<String> = info.baud_rates.iter().map(u32::to_string).collect();
        rows.push(("Bit rates (kbit/s)".into(), rates.join(", ")));
    }
    let flags = [
        ("Simple boot-up master", &info.simple_boot_up_master),
        ("Simple boot-up slave", &info.simple_boot_up_slave),
        ("Group messaging", &info.group_messaging),
        ("LSS", &info.lss_supported),
    ];
    for (label, v) in flags {
        if let Some(v) = v {
            rows.push((label.into(), yes_no(v.value)));
        }
    }
    let numbers = [
        ("Granularity (bits)", info.granularity.as_ref().map(|v| u32::from(v.value))),
        ("Dynamic channels", info.dynamic_channels_supported.as_ref().map(|v| u32::from(v.value))),
        ("Receive PDOs", info.nr_of_rx_pdo.as_ref().map(|v| u32::from(v.value))),
        ("Transmit PDOs", info.nr_of_tx_pdo.as_ref().map(|v| u32::from(v.value))),
        ("CompactPDO", info.compact_pdo.as_ref().map(|v| u32::from(v.value))),
    ];
    for (label, v) in numbers {
        if let Some(v) = v {
            rows.push((label.into(), v.to_string()));
        }
    }
    let Some(ec) = dev.ethercat.as_deref() else { return rows };
    for sm in &ec.sync_managers {
        rows.push((format!("SM{}", sm.number), sm.summary()));
    }
    for (i, f) in ec.fmmus.iter().enumerate() {
        let sm = f.sm.map_or(String::new(), |s| format!(", SM{s}"));
        rows.push((format!("FMMU{i}"), format!("{}{sm}", f.usage.as_str())));
    }
    if let Some(mb) = &ec.mailbox {
        rows.push(("Mailbox".into(), mb.protocols().join(", ")));
    }
    if let Some(dc) = &ec.dc {
        for m in &dc.op_modes {
            let desc = m.desc.as_deref().filter(|d| !d.is_empty() && *d != m.name);
            let text = desc.map_or(m.name.clone(), |d| format!("{} ({d})", m.name));
            rows.push(("DC mode".into(), text));
        }
    }
    rows
}

/// A value of the table (empty when absent), in the one spelling (`odc_analysis::value_text`).
fn cell(v: Option<&odc_model::Spanned<Value>>) -> String {
    v.map_or(String::new(), |v| odc_analysis::value_text(&v.value))
}

fn objects(dev: &Device) -> Vec<ObjectRow> {
    let mut rows = Vec::new();
    for object in dev.objects.values() {
        let made = if object.origin.is_esi_synthesised() {
            Made::Synthesised
        } else if dev.esi_default(object.index).is_some() {
            Made::DefaultFromEsi
        } else {
            Made::File
        };
        let start = rows.len();
        if object.kind.has_subs() {
            rows.push(ObjectRow {
                anchor: object_anchor(object.index),
                index: object.index,
                sub: None,
                name: object.name.clone(),
                kind: object.kind.name().to_owned(),
                data_type: String::new(),
                access: String::new(),
                pdo: String::new(),
                default: String::new(),
                value: String::new(),
                low: String::new(),
                high: String::new(),
                denotation: object.denotation.as_ref().map_or(String::new(), |d| d.value.clone()),
                made: Made::File,
            });
            for sub in object.subs.values() {
                rows.push(sub_row(object, sub, String::new()));
            }
        } else if let Some(sub) = object.var() {
            let mut row = sub_row(object, sub, object.kind.name().to_owned());
            row.name = object.name.clone();
            rows.push(row);
        }
        rows[start..].iter_mut().for_each(|r| r.made = made);
    }
    rows
}

fn sub_row(object: &Object, sub: &SubObject, kind: String) -> ObjectRow {
    let has_subs = object.kind.has_subs();
    ObjectRow {
        anchor: sub_anchor(object, sub.sub_index),
        index: object.index,
        sub: has_subs.then_some(sub.sub_index),
        name: sub.name.to_string(),
        kind,
        data_type: sub.data_type.name().into_owned(),
        access: sub.access.as_str().to_owned(),
        pdo: sub.pdo_mapping.directions(sub.access).to_owned(),
        default: cell(sub.default.as_ref()),
        value: cell(sub.parameter_value.as_ref()),
        low: cell(sub.low_limit.as_deref()),
        high: cell(sub.high_limit.as_deref()),
        denotation: sub.rare().denotation.as_ref().map_or(String::new(), |d| d.value.clone()),
        made: Made::File,
    }
}

/// A field of a PDO entry of `dev`.
fn field(dev: &Device, entry: &odc_model::PdoEntry, offset: u32) -> Field {
    let bits = u32::from(entry.bits);
    if entry.is_gap() {
        return Field {
            offset,
            bits,
            address: String::new(),
            name: "gap".into(),
            data_type: String::new(),
            anchor: None,
        };
    }
    let object = dev.objects.get(&entry.index);
    let sub = object.and_then(|o| o.sub(entry.sub));
    let name = match (object, sub) {
        (Some(o), Some(s)) if o.kind.has_subs() => format!("{} / {}", o.name, s.name),
        (Some(o), _) => o.name.clone(),
        _ => entry.name.clone().unwrap_or_default(),
    };
    let data_type = sub
        .map(|s| s.data_type)
        .or(entry.data_type)
        .map_or(String::new(), |t| t.name().into_owned());
    Field {
        offset,
        bits,
        address: format!("0x{:04X}:{:02X}", entry.index, entry.sub),
        name,
        data_type,
        anchor: match (object, sub) {
            (Some(o), Some(_)) => Some(sub_anchor(o, entry.sub)),
            (Some(o), None) => Some(object_anchor(o.index)),
            _ => None,
        },
    }
}

fn diagrams(dev: &Device) -> Vec<Diagram> {
    let mut out = Vec::new();
    for pdo in &dev.pdos {
        let kind = match pdo.direction {
            Direction::Rx => "RPDO",
            Direction::Tx => "TPDO",
        };
        let mut offset = 0;
        let mut fields = Vec::new();
        for e in &pdo.entries {
            fields.push(field(dev, e, offset));
            offset += u32::from(e.bits);
        }
        let mut detail = Vec::new();
        match &pdo.cob_id {
            Some(Value::NodeIdPlus(n)) => detail.push(format!("COB-ID $NODEID+0x{n:X}")),
            Some(Value::Unsigned(n)) => detail.push(format!("COB-ID 0x{n:X}")),
            _ => {}
        }
        if let Some(t) = pdo.transmission_type {
            detail.push(format!("transmission type {t}"));
        }
        if let Some(sm) = pdo.sync_manager {
            detail.push(format!("SM{sm} by default"));
        }
        if pdo.fixed {
            detail.push("fixed".into());
        }
        detail.push(format!("{offset} bits"));
        let name = if pdo.name.is_empty() { String::new() } else { format!(" {}", pdo.name) };
        out.push(Diagram {
            anchor: format!("pdo-{:04X}", pdo.mapping_index),
            title: format!("{kind} 0x{:04X}{name}", pdo.mapping_index),
            detail: detail.join(", "),
            bits: offset,
            fields,
        });
    }
    if dev.ethercat.is_some()
        && let Ok((outputs, inputs)) = default_images(dev)
    {
        for (image, name, anchor) in [
            (&outputs, "Outputs (master → device)", "image-out"),
            (&inputs, "Inputs (device → master)", "image-in"),
        ] {
            if !image.is_empty() {
                out.push(image_diagram(dev, image, name, anchor));
            }
        }
    }
    out
}

fn image_diagram(dev: &Device, image: &Image, name: &str, anchor: &str) -> Diagram {
    let mut fields = Vec::new();
    let mut sms = Vec::new();
    for seg in &image.segments {
        sms.push(format!("SM{} at byte {}, {} bytes", seg.sm, seg.byte_offset, seg.bytes));
        for placed in &seg.entries {
            let entry = dev.pdos.get(placed.pdo).and_then(|p| p.entries.get(placed.entry));
            if let Some(e) = entry {
                fields.push(field(dev, e, placed.range.offset));
            }
        }
    }
    Diagram {
        anchor: anchor.to_owned(),
        title: format!("Process image: {name}"),
        detail: format!("{} bytes; {}", image.len(), sms.join("; ")),
        bits: u32::try_from(image.len() * 8).unwrap_or(u32::MAX),
        fields,
    }
}

fn scheme(dev: &Device, s: &odc_analysis::Scheme) -> SchemeDoc {
    let args: Vec<String> = s.args.iter().map(|a| format!("{} in {}", a.name, a.range)).collect();
    let mut rule = format!("index = {} ({})", s.index, args.join(", "));
    if let Some(e) = &s.element {
        let offset = match e.offset {
            0 => String::new(),
            o if o > 0 => format!(" + {o}"),
            o => format!(" - {}", o.unsigned_abs()),
        };
        rule.push_str(&format!("; sub-index = {}{offset} ({} in {})", e.name, e.name, e.range));
    }
    let (entries, error) = match odc_analysis::scheme_entries(dev, s) {
        Ok(list) => (
            list.into_iter()
                .map(|e| {
                    let anchor = dev
                        .objects
                        .get(&e.index)
                        .map_or_else(|| object_anchor(e.index), |o| sub_anchor(o, e.sub));
                    (e.name, anchor, format!("0x{:04X}:{:02X}", e.index, e.sub), e.what)
                })
                .collect(),
            None,
        ),
        Err(e) => (Vec::new(), Some(e)),
    };
    SchemeDoc { module: s.module.clone(), doc: s.doc.clone(), rule, entries, error }
}

fn finding(dev: &Device, sources: Option<&Sources>, d: &Diagnostic) -> Finding {
    let span = d.primary_span();
    let at = span
        .and_then(|s| sources.and_then(|src| src.line_col(s)))
        .map_or(String::new(), |lc| format!("line {}, column {}", lc.line, lc.column));
    // The object the rule names, else the sub-object whose text holds the primary label.
    let anchor = match d.object {
        Some((index, sub)) => dev.objects.get(&index).map(|o| match sub {
            Some(s) => sub_anchor(o, s),
            None => object_anchor(index),
        }),
        None => span.and_then(|span| {
            dev.objects.values().find_map(|o| {
                let inside = |s: odc_model::Span| {
                    s.file == span.file
                        && s.start <= span.start
                        && span.end <= s.end
                        && s.end > s.start
                };
                let sub = o.subs.values().find(|s| inside(s.span));
                match sub {
                    Some(s) => Some(sub_anchor(o, s.sub_index)),
                    None => inside(o.span).then(|| object_anchor(o.index)),
                }
            })
        }),
    };
    Finding {
        severity: severity(d.severity).to_owned(),
        code: d.code.to_owned(),
        message: d.message.clone(),
        at,
        anchor,
    }
}

fn severity(s: Severity) -> &'static str {
    s.as_str()
}
