//! CiA 306 EDS/DCF front-end for odc: a lossless raw layer ([`raw`]), the lowering to the
//! [`odc_model::Device`] IR with coded diagnostics ([`parse`]), and the writer ([`write`]).
//!
//! ```
//! let mut sources = odc_model::Sources::new();
//! let parsed = odc_eds::parse(&mut sources, "dev.eds", b"[1000]\nParameterName=Device type\nDataType=0x0007\nAccessType=ro\n");
//! assert!(parsed.diagnostics.is_empty());
//! let text = odc_eds::write(&parsed.device, odc_model::Format::Eds);
//! assert!(text.contains("[1000]"));
//! ```
//!
//! # Policies
//!
//! Real files disagree with CiA 306 and with each other; these are the decisions, each tested.
//!
//! - **Tolerant by default.** Every problem is a [`Diagnostic`] with a stable code (`F101`..,
//!   see [`RULES`]) and a label on the exact key or value; parsing never panics and never stops
//!   at the first problem. Real-file mess is a warning; errors are for what makes the model
//!   wrong (a value that does not read, an unknown access or object type, a missing DataType).
//! - **Encoding.** UTF-8 (a BOM is stripped); otherwise Windows-1252 (note `F125`).
//! - **Keys and sections are case-insensitive**; the original spelling is kept in the raw
//!   layer and in the `extra` entries the writer writes back. Sub-object sections may be
//!   `[1018sub1]`, `[1018Sub1]`, `[1a00sub01]`.
//! - **Duplicates.** Repeated sections are merged, repeated keys are kept; the **last** value
//!   wins (as python's `configparser` in non-strict mode); both are warnings (`F105`, `F106`).
//! - **Comments.** Whole lines starting with `;` or `#` are comments. A trailing ` # ...` or
//!   ` ; ...` is cut only from values that must be a number or keyword and do not read with it
//!   (`ObjectType=0x07 # VAR`, `AccessType=rw # ...`), with warning `F113`; names and strings
//!   keep it.
//! - **`$NODEID`** stays symbolic ([`odc_model::Value::NodeIdPlus`]); it is read in any case and
//!   in either order (`$NODEID+0x180`, `0x180+$NODEID`, also `$NODEID-n` and `$NODEID` alone);
//!   the non-canonical order is warning `F111`; the writer emits `$NODEID+0x180`.
//! - **Numbers**: decimal, `0x` hex, leading-zero octal as CiA 306 says (`010` is 8; warning
//!   `F109` unless the value is below 8; `08`/`09` read as decimal), optional sign. For signed
//!   types a hex literal is a two's complement bit pattern (`0xFFFF` as INTEGER16 is -1). C
//!   suffixes `U`, `L`, `UL`, `LL`, `ULL` are ignored with warning `F110`. A value that does not
//!   read or does not fit is kept as [`odc_model::Value::Invalid`] (errors `F107`, `F108`).
//! - **REAL32/REAL64**: a `0x` literal is the IEEE bit pattern, anything else a decimal float;
//!   the writer emits Rust's shortest round-trip decimal (NaN as its bit pattern).
//! - **Empty values** (`Key=`) are absent, with warning `F112`, except for VISIBLE_STRING,
//!   OCTET_STRING, DOMAIN and UNICODE_STRING values, where they are the empty string.
//! - **OCTET_STRING/DOMAIN** values are hex bytes, contiguous or blank-separated.
//! - **`SubNumber`** is kept as declared: a count of sub-objects (gaps allowed), not the highest
//!   sub-index; comparing it with the sub-objects is the checker's job, as is **0x1003 sub 0**
//!   being a count of errors. Object lists are kept as declared and not used to build
//!   `objects`: every `[IIII]` section present is an object.
//! - **`rwr`/`rww`** stay distinct; `r` is read as `ro` (warning `F114`); other spellings are
//!   error `F115` and read as `ro`.
//! - **VAR by default** when ObjectType is absent. For VAR, DOMAIN, DEFTYPE and NULL the one
//!   sub-object 0 holds type, access and values; a missing DataType is DOMAIN for DOMAIN and
//!   NULL objects and UNSIGNED32 for DEFTYPE; `ObjFlags` of such an object is the object's.
//! - **CompactSubObj=N** implies sub 0 (`NrOfObjects`, UNSIGNED8 ro, default N) and subs
//!   1..=N with the object's DataType, AccessType, PDOMapping and values, named
//!   `<ParameterName><n>` unless `[IIIIName]` names them; `[IIIIValue]` gives ParameterValues,
//!   `[IIIIDenotation]` denotations. Explicit sub sections override (warning `F122`).
//! - **CompactPDO** (see [`compact_pdo`](crate#compactpdo)): objects are synthesised with
//!   [`odc_model::Origin::CompactPdo`] only when `CompactPDO` is non-zero; the writer leaves them
//!   out and keeps the `CompactPDO` key.
//! - **DCF**: `[DeviceComissioning]` (CiA 306 spelling) and `[DeviceCommissioning]` are both
//!   read (merged if both appear); the writer uses the CiA 306 spelling. `Device.format` is
//!   `Dcf` when the file has a commissioning section, a `ParameterValue`, a `Denotation`, a
//!   `[IIIIValue]` section, a `[ConnectedModules]` entry, or its name ends in `.dcf`;
//!   otherwise `Eds`.
//! - **Unknown keys and sections are preserved**: keys go to the `extra` of their node, sections
//!   to `Device.extra_sections` (also orphan sub-sections and malformed object section names),
//!   and the writer writes them back. Keys that do not fit a fixed-pattern section
//!   (`[DummyUsage]`, `[Comments]`, object lists) are kept as an extra section of that name.
//! - Modular devices: the modules are the `[MxModuleInfo]` sections present, each collecting
//!   its `[Mx...]` sections; `[SupportedModules] NrOfEntries` is kept as written
//!   (`Modules::nr_of_entries`, compared with the modules by odc-check C509) and the writer
//!   writes the number of modules.
//!
//! # CompactPDO
//!
//! See the `compact_pdo` module source: for each of `NrOfRXPDO`/`NrOfTXPDO` PDOs whose
//! communication or mapping object is absent, one is synthesised; the bits of `CompactPDO` say
//! which communication sub-objects exist (bit 0 COB-ID, 1 transmission type, 2 inhibit time,
//! 3 reserved, 4 event timer, 5 SYNC start value); the first four PDOs get the predefined
//! COB-IDs `$NODEID+0x200`.. (RPDO) and `$NODEID+0x180`.. (TPDO).

mod compact_pdo;
mod lower;
mod num;
pub mod raw;
mod rules;
mod write;

pub use odc_model::Diagnostic;
pub use rules::{RULES, codes};

/// The result of [`parse`].
#[derive(Debug)]
pub struct Parsed {
    /// The device.
    pub device: odc_model::Device,
    /// Problems found, sorted by position.
    pub diagnostics: Vec<odc_model::Diagnostic>,
    /// The file's id in the [`odc_model::Sources`] it was added to.
    pub file: odc_model::FileId,
}

/// Decodes bytes: UTF-8 (BOM stripped), else Windows-1252. Returns whether the fallback was
/// used.
pub fn decode(bytes: &[u8]) -> (String, bool) {
    let bytes = bytes.strip_prefix(b"\xEF\xBB\xBF").unwrap_or(bytes);
    match std::str::from_utf8(bytes) {
        Ok(s) => (s.to_owned(), false),
        Err(_) => {
            let (text, _, _) = encoding_rs::WINDOWS_1252.decode(bytes);
            (text.into_owned(), true)
        }
    }
}

/// Decodes (UTF-8, else Windows-1252; BOM stripped), adds the text to `sources`, scans and
/// lowers. Never panics, never stops at the first problem.
pub fn parse(sources: &mut odc_model::Sources, name: &str, bytes: &[u8]) -> Parsed {
    let (text, fallback) = decode(bytes);
    let file = sources.add(name, text);
    let text = sources.text(file).unwrap_or("");
    let mut diagnostics = Vec::new();
    if fallback {
        diagnostics.push(
            Diagnostic::new(
                odc_model::Severity::Note,
                codes::NOT_UTF8,
                "file is not UTF-8; decoded as Windows-1252",
            )
            .with_label(odc_model::Span::new(file, 0, 0), ""),
        );
    }
    let raw = raw::scan(text, file, &mut diagnostics);
    let lower = lower::Lower::new(&raw, diagnostics);
    let (device, mut diagnostics) = lower.run(name);
    odc_model::diag::sort(&mut diagnostics);
    Parsed { device, diagnostics, file }
}

/// Parses text that is already decoded (for callers that have a `&str`); see [`parse`].
pub fn parse_str(sources: &mut odc_model::Sources, name: &str, text: &str) -> Parsed {
    parse(sources, name, text.as_bytes())
}

/// Writes the model as EDS or DCF text (`Format::Esi` writes EDS). Deterministic.
pub fn write(device: &odc_model::Device, format: odc_model::Format) -> String {
    write::write(device, format)
}
