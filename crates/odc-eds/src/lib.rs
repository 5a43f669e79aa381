//! CiA 306 EDS/DCF front-end for odc: a lossless raw layer ([`raw`]), the lowering to the
//! [`odc_model::Device`] IR with coded diagnostics ([`parse`]), and the writer ([`write()`]).
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
//! - **Encoding.** UTF-8 (a BOM is stripped); UTF-16 with a byte-order mark or recognisably
//!   ASCII-in-UTF-16; otherwise Windows-1252 (both with note `F125`).
//! - **Keys and sections are case-insensitive**; the original spelling is kept in the raw
//!   layer and in the `extra` entries the writer writes back. Sub-object sections may be
//!   `[1018sub1]`, `[1018Sub1]`, `[1a00sub01]`.
//! - **Duplicates.** Repeated sections are merged, repeated keys are kept; the **last** value
//!   wins (as python's `configparser` in non-strict mode); both are warnings (`F105`, `F106`).
//!   The values a later one replaces are still read for their diagnostics, so an error in
//!   either of two merged sections is reported.
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
//!   OCTET_STRING, DOMAIN and UNICODE_STRING values (`DefaultValue`, `ParameterValue`), where
//!   they are the empty string. An empty `LowLimit`/`HighLimit` is absent whatever the type.
//! - **OCTET_STRING/DOMAIN** values are hex bytes, contiguous or blank-separated; a group of
//!   an odd number of digits is read with a zero nibble in front (`ABC` is `0A BC`), with
//!   warning `F133`.
//! - **DataType** is an index: a name (`UNSIGNED16`) is error `F107` with the index it names;
//!   an index that is neither a CiA 301 type nor defined by an object of the file (`0x0099`)
//!   is warning `F134` and kept.
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
//!   `[IIIIDenotation]` denotations. Explicit sub sections override (warning `F122`). The
//!   implied sub-objects are kept as the template and the count and made when first read
//!   ([`odc_model::SubObjects::set_implied`]): a master's DCF implies thousands.
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
//! As lely-core reads it (the `compact_pdo` module source has the details): PDOs the file
//! writes out (communication or mapping object present) count towards
//! `NrOfRXPDO`/`NrOfTXPDO` and get the object of the pair they lack; the rest of the count
//! goes to the lowest PDO numbers not written out, which get both objects. The bits of
//! `CompactPDO` say which communication sub-objects exist (bit 0 COB-ID, 1 transmission type,
//! 2 inhibit time, 3 reserved, 4 event timer, 5 SYNC start value); the first four PDOs get the
//! predefined COB-IDs `$NODEID+0x200`.. (RPDO) and `$NODEID+0x180`.. (TPDO), the other values
//! are 0 (transmission type included); an implied mapping object has 0x40 empty entries.
// Bad input is a diagnostic, never a panic: no unwrap, expect or panic outside tests. A
// proven invariant may opt out with an `#[allow]` and a comment saying why.
#![cfg_attr(not(test), deny(clippy::unwrap_used, clippy::expect_used, clippy::panic))]

mod compact_pdo;
mod lower;
mod mandatory;
mod num;
pub mod raw;
mod rules;
mod write;

pub use mandatory::{add_mandatory_objects, as_canopen, pdo_directions_by_index};
pub use odc_model::Diagnostic;
pub use rules::{RULES, codes};
pub use write::{DcfOnly, dcf_only};

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

/// Decodes bytes: UTF-8 (BOM stripped), UTF-16 (by its byte-order mark, or ASCII text with
/// every other byte NUL), else Windows-1252. Returns whether it was not UTF-8.
pub fn decode(bytes: &[u8]) -> (String, bool) {
    let (text, encoding) = decode_as(bytes);
    (text, encoding.is_some())
}

/// [`decode`], naming the encoding used when it was not UTF-8.
fn decode_as(bytes: &[u8]) -> (String, Option<&'static str>) {
    let bytes = bytes.strip_prefix(b"\xEF\xBB\xBF").unwrap_or(bytes);
    if let Some(utf16) = utf16(bytes) {
        let (text, _, _) = utf16.decode(bytes);
        return (text.into_owned(), Some(utf16.name()));
    }
    match std::str::from_utf8(bytes) {
        Ok(s) => (s.to_owned(), None),
        Err(_) => {
            let (text, _, _) = encoding_rs::WINDOWS_1252.decode(bytes);
            (text.into_owned(), Some("Windows-1252"))
        }
    }
}

/// UTF-16 by its byte-order mark, or by its look: the first (up to) 64 bytes are ASCII
/// characters each followed (LE) or preceded (BE) by a NUL byte.
fn utf16(bytes: &[u8]) -> Option<&'static encoding_rs::Encoding> {
    if bytes.starts_with(b"\xFF\xFE") {
        return Some(encoding_rs::UTF_16LE);
    }
    if bytes.starts_with(b"\xFE\xFF") {
        return Some(encoding_rs::UTF_16BE);
    }
    let head = &bytes[..bytes.len().min(64) & !1];
    let looks = |text: usize, nul: usize| {
        head.len() >= 4
            && head.chunks_exact(2).all(|p| p[nul] == 0 && p[text] != 0 && p[text].is_ascii())
    };
    if looks(0, 1) {
        Some(encoding_rs::UTF_16LE)
    } else if looks(1, 0) {
        Some(encoding_rs::UTF_16BE)
    } else {
        None
    }
}

/// Largest file read (bytes); larger ones get error `F127` and an empty device.
pub const MAX_FILE_SIZE: usize = 32 * 1024 * 1024;

/// Most lines read (error `F132` past it); the largest real files have about 15,000.
pub const MAX_LINES: usize = 262_144;

/// Most sub-objects `CompactSubObj` implies in one file (error `F128` past it).
pub const MAX_IMPLIED_SUB_OBJECTS: usize = 65_536;

/// Decodes (UTF-8, else Windows-1252; BOM stripped), adds the text to `sources`, scans and
/// lowers. Never panics, never stops at the first problem.
///
/// Resource use is bounded: files above [`MAX_FILE_SIZE`] are not read, lines past
/// [`MAX_LINES`] are not read, `CompactSubObj` expands to at most [`MAX_IMPLIED_SUB_OBJECTS`]
/// sub-objects, and at most [`odc_model::diag::MAX_PER_CODE`] diagnostics of one code are kept.
pub fn parse(sources: &mut odc_model::Sources, name: &str, bytes: &[u8]) -> Parsed {
    if bytes.len() > MAX_FILE_SIZE {
        let file = sources.add(name, String::new());
        let d = Diagnostic::error(
            codes::SIZE_LIMIT,
            format!("the file is larger than {MAX_FILE_SIZE} bytes, the limit"),
        )
        .with_label(odc_model::Span::new(file, 0, 0), "not read");
        return Parsed { device: odc_model::Device::default(), diagnostics: vec![d], file };
    }
    let (text, encoding) = decode_as(bytes);
    // Classic Mac OS line ends (CR alone) are read as line ends: one byte for one byte, so
    // the spans stay those of the file.
    let cr_only = !text.contains('\n') && text.contains('\r');
    let text = if cr_only { text.replace('\r', "\n") } else { text };
    let file = sources.add(name, text);
    let text = sources.text(file).unwrap_or("");
    let span = |at: usize| odc_model::Span::new(file, at as u32, at as u32 + 1);
    let mut diagnostics = odc_model::Capped::new();
    if cr_only {
        diagnostics.push(
            Diagnostic::new(
                odc_model::Severity::Note,
                codes::CR_LINE_ENDS,
                "lines end with CR alone (classic Mac OS); read as line ends",
            )
            .with_label(span(text.find('\n').unwrap_or(0)), "the first one"),
        );
    }
    // `memchr`, not `str::find`: every file is searched to its end, and the crate's vector
    // search is several times faster than the standard library's word-at-a-time one.
    if let Some(at) = memchr::memchr(0, text.as_bytes()) {
        let n = memchr::memchr_iter(0, text.as_bytes()).count();
        diagnostics.push(
            Diagnostic::warning(
                codes::NUL_BYTES,
                format!("the file contains {n} NUL byte(s): a binary file, or damaged"),
            )
            .with_label(span(at), "the first one"),
        );
    }
    if let Some(encoding) = encoding {
        diagnostics.push(
            Diagnostic::new(
                odc_model::Severity::Note,
                codes::NOT_UTF8,
                format!("file is not UTF-8; decoded as {encoding}"),
            )
            .with_label(odc_model::Span::new(file, 0, 0), ""),
        );
    }
    // Memory grows with the number of lines (a few hundred bytes each, raw layer and model):
    // lines past MAX_LINES are not read. Only a text of more than MAX_LINES bytes can have
    // that many.
    let text = match text.len() > MAX_LINES {
        true => match memchr::memchr_iter(b'\n', text.as_bytes()).nth(MAX_LINES - 1) {
            Some(at) => {
                diagnostics.push(
                    Diagnostic::error(
                        codes::LINE_LIMIT,
                        format!("the file has more than {MAX_LINES} lines; the rest is not read"),
                    )
                    .with_label(span(at + 1), "reading stopped here"),
                );
                &text[..=at]
            }
            None => text,
        },
        false => text,
    };
    let raw = raw::scan(text, file, &mut diagnostics);
    if raw.sections.iter().all(|s| s.name.is_empty()) {
        diagnostics.push(
            Diagnostic::warning(codes::NO_SECTIONS, "the file has no `[section]`")
                .with_label(odc_model::Span::new(file, 0, 0), "")
                .with_note(
                    "an EDS or DCF file is made of sections such as [DeviceInfo] and [1000]",
                ),
        );
    }
    let lower = lower::Lower::new(&raw, diagnostics);
    let (device, mut diagnostics) = lower.run(name);
    odc_model::diag::sort(&mut diagnostics);
    Parsed { device, diagnostics, file }
}

/// Parses text that is already decoded (for callers that have a `&str`); see [`parse`].
pub fn parse_str(sources: &mut odc_model::Sources, name: &str, text: &str) -> Parsed {
    parse(sources, name, text.as_bytes())
}

/// Why [`read_value`] could not read a value.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum ValueError {
    /// The text is not a value of the type (`F107` in an EDS).
    Invalid,
    /// A number that does not fit the type (`F108` in an EDS).
    OutOfRange,
}

/// Reads `text` as the EDS front-end reads a `DefaultValue` of type `dt` (numbers in any
/// CiA 306 form, `$NODEID+`, REAL bit patterns, hex bytes), for front-ends whose files write
/// values in CiA 306 syntax: CiA 311 XDD files do, and sharing the reader makes an XDD value
/// lower to exactly what the same value in an EDS does. An empty text is not read here (the
/// caller decides what an empty value means).
///
/// # Errors
///
/// [`ValueError`] when the text does not read as a value of `dt`.
pub fn read_value(text: &str, dt: odc_model::DataType) -> Result<odc_model::Value, ValueError> {
    let mut problem = lower::Problem::Invalid;
    match lower::read_value(text, dt, &mut problem) {
        Some((v, _)) => Ok(v),
        None if problem == lower::Problem::Range => Err(ValueError::OutOfRange),
        None => Err(ValueError::Invalid),
    }
}

/// Writes the model as EDS or DCF text (`Format::Esi` writes EDS). Deterministic.
pub fn write(device: &odc_model::Device, format: odc_model::Format) -> String {
    write::write(device, format)
}
