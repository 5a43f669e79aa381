//! The EtherCAT ESI (ETG.2000 `EtherCATInfo` XML) front-end of odc.
//!
//! [`parse`] decodes the bytes (UTF-8 with or without BOM, ISO-8859-1 in any spelling the XML
//! declaration uses; UTF-16 is refused with a diagnostic), reads them into a small span-keeping
//! element tree (see the `xml` module for why not serde), and lowers every `<Device>` (each
//! revision is its own device) into an [`odc_model::Device`]: identity, object dictionary,
//! PDOs and the EtherCAT-only part ([`odc_model::ethercat::EtherCat`]).
//!
//! Policies:
//! - numbers are `#x` hex (the schema's form), `0x` hex (common in real files) or decimal, with
//!   an optional sign; booleans are `1`/`0`/`true`/`false`;
//! - `DefaultData`/`MinData`/`MaxData` are little-endian hex bytes, decoded with the object's
//!   data type; `DefaultValue`/`MinValue`/`MaxValue` (CODESYS-style files) are read as text;
//! - an object's `Type` names a `DataType`; its `SubItem`s give the sub-objects, and the
//!   object's `Info/SubItem`s are matched to them **by name**; array types expand into one
//!   sub-object per element, named `SubIndex nnn` as Beckhoff's files do;
//! - access `ro`/`rw`/`wo` maps to [`odc_model::Access`]; `ReadRestrictions`/`WriteRestrictions`
//!   (per EtherCAT state), category, backup and setting flags are kept in
//!   [`odc_model::ethercat::EtherCat::object_flags`];
//! - a device without a dictionary gets objects synthesised from its PDO entries, the mapping
//!   objects 0x16xx/0x1Axx and 0x1C12/0x1C13, all marked [`odc_model::Origin::PdoEntry`];
//! - a device with CoE and sync managers gets what ETG.1000.6 gives every such device and its
//!   dictionary leaves out: 0x1C00 (sync manager types), 0x1C10 + n (the PDO assignment of each
//!   process data sync manager, [`odc_model::ethercat::default_assignment`]) and each PDO's
//!   mapping object, marked [`odc_model::Origin::CoeImplied`]: read-only, but the assignment
//!   objects writable (with room for every PDO a master may assign to the sync manager) where
//!   `CoE@PdoAssign`, a non-`Fixed` PDO's mapping object where `CoE@PdoConfig`;
//! - the file's own assignment and mapping objects without a default start with what the PDO
//!   elements say (note `F231`; the file's sub 0 kept in
//!   [`odc_model::ethercat::EtherCat::esi_defaults`], the values without a span);
//! - elements the front-end does not interpret are kept as raw XML with their spans;
//! - every problem is a [`Diagnostic`] with a stable code (see [`RULES`]); reading never stops
//!   at the first one, except at XML that is not well-formed, where what was read before the
//!   error is still lowered.
// Bad input is a diagnostic, never a panic: no unwrap, expect or panic outside tests. A
// proven invariant may opt out with an `#[allow]` and a comment saying why.
#![cfg_attr(not(test), deny(clippy::unwrap_used, clippy::expect_used, clippy::panic))]

mod decode;
mod lower;
pub mod num;
pub mod xml;

use std::borrow::Cow;

use odc_model::{Device, Diagnostic, FileId, RuleInfo, Severity, Sources, Span};

/// What [`parse`] produced for one file.
pub struct Parsed {
    /// One device per `<Device>` element, in file order.
    pub devices: Vec<Device>,
    /// Every problem found, sorted by position.
    pub diagnostics: Vec<Diagnostic>,
    /// The file's id in the [`Sources`] it was added to.
    pub file: FileId,
}

/// Largest file read (bytes); larger ones get error `F205` and no device. The largest real
/// ESI files are about 4 MiB.
pub const MAX_FILE_SIZE: usize = 64 * 1024 * 1024;

/// Deepest element nesting read (`F204` past it).
pub const MAX_DEPTH: usize = xml::MAX_DEPTH;

/// Most elements read (`F221` past it).
pub const MAX_ELEMENTS: usize = xml::MAX_ELEMENTS;

/// Most sub-objects the dictionaries of one file make, data types expanded (`F220` past it).
/// The largest real file makes about 16,000.
pub const MAX_SUB_OBJECTS: usize = 262_144;

/// An XML device file read up to its element tree, for a front-end to lower.
pub struct XmlFile<'s> {
    /// The file's id in the [`Sources`] it was added to.
    pub file: FileId,
    /// Its decoded text.
    pub text: &'s str,
    /// Its elements.
    pub doc: xml::Document<'s>,
    /// The problems met so far (decoding, a NUL byte, the reader's), capped per code.
    pub diagnostics: odc_model::Capped,
}

/// Reads an XML device file into `sources` under `name`: the size limit ([`MAX_FILE_SIZE`]),
/// decoding (BOM, UTF-8, ISO-8859-1 by the XML declaration; UTF-16 refused), a NUL byte (XML
/// 1.0 §2.2 allows none) and the element tree with the reader's limits. Shared with the XDD
/// front-end (`odc-xdd`), which reads the same XML with the same limits; `kind` names the
/// files in messages (`"ESI files"`), and the codes are this crate's (`F2xx`), which the
/// caller maps to its own.
///
/// # Errors
///
/// A file that cannot be read at all (too large, an unsupported encoding): its diagnostic,
/// labelled at the start of an empty source added under `name`.
pub fn read_xml_file<'s>(
    sources: &'s mut Sources,
    name: &str,
    bytes: Cow<'_, [u8]>,
    kind: &str,
) -> Result<XmlFile<'s>, (FileId, Diagnostic)> {
    let refuse = |sources: &mut Sources, d: Diagnostic| {
        let file = sources.add(name, String::new());
        (file, d.with_label(Span::new(file, 0, 0), "not read"))
    };
    if bytes.len() > MAX_FILE_SIZE {
        let size = format!("the file is larger than {MAX_FILE_SIZE} bytes, the limit");
        return Err(refuse(sources, Diagnostic::error(codes::SIZE_LIMIT, size)));
    }
    let decoded = match decode::decode(bytes) {
        Ok(d) => d,
        Err(e) => {
            let d = match e {
                decode::DecodeError::Utf16 => Diagnostic::error(
                    codes::UNSUPPORTED_ENCODING,
                    format!("the file is UTF-16; {kind} are read as UTF-8 or ISO-8859-1"),
                )
                .with_note("convert it, e.g. `iconv -f UTF-16 -t UTF-8`"),
                decode::DecodeError::Unsupported(label) => Diagnostic::error(
                    codes::UNSUPPORTED_ENCODING,
                    format!("unsupported encoding `{label}` in the XML declaration"),
                )
                .with_note(format!("{kind} are read as UTF-8 or ISO-8859-1")),
            };
            return Err(refuse(sources, d));
        }
    };
    let file = sources.add(name, decoded.text);
    let mut diagnostics = decoded.diagnostics;
    for d in &mut diagnostics {
        if d.labels.is_empty() {
            d.labels.push(odc_model::Label {
                span: Span::new(file, 0, 0),
                message: String::new(),
                primary: true,
            });
        }
    }
    let text = sources.text(file).unwrap_or("");
    // memchr's vector search: the whole file is scanned, and `str::find` is several times slower.
    if let Some(at) = memchr::memchr(0, text.as_bytes()) {
        // quick-xml reads NUL as a name character; XML 1.0 §2.2 allows it nowhere.
        let at = at as u32;
        diagnostics.push(
            Diagnostic::error(
                codes::MALFORMED_XML,
                "the file contains a NUL byte, which XML does not allow",
            )
            .with_label(Span::new(file, at, at + 1), "the first one"),
        );
    }
    let mut doc = xml::read(text, file);
    // One capped list from reading through lowering (at most MAX_PER_CODE per code).
    let mut capped = std::mem::take(&mut doc.diagnostics);
    capped.extend(diagnostics);
    Ok(XmlFile { file, text, doc, diagnostics: capped })
}

/// Decodes `bytes`, adds the text to `sources` under `name`, reads and lowers it.
/// Never panics; every problem is a diagnostic.
pub fn parse(sources: &mut Sources, name: &str, bytes: &[u8]) -> Parsed {
    parse_input(sources, name, Cow::Borrowed(bytes))
}

/// [`parse`] for bytes the caller no longer needs (a file just read): UTF-8 and ASCII files
/// become the source text in place instead of being copied, so that the file is held in memory
/// once rather than twice while it is read.
pub fn parse_vec(sources: &mut Sources, name: &str, bytes: Vec<u8>) -> Parsed {
    parse_input(sources, name, Cow::Owned(bytes))
}

fn parse_input(sources: &mut Sources, name: &str, bytes: Cow<'_, [u8]>) -> Parsed {
    let XmlFile { file, text, doc, diagnostics: mut capped } =
        match read_xml_file(sources, name, bytes, "ESI files") {
            Ok(x) => x,
            Err((file, d)) => return Parsed { devices: Vec::new(), diagnostics: vec![d], file },
        };
    let devices = lower::lower(text, file, &doc, &mut capped);
    let mut diagnostics = capped.finish();
    odc_model::diag::sort(&mut diagnostics);
    Parsed { devices, diagnostics, file }
}

/// The codes, as constants, so the code and the registry cannot drift apart.
pub mod codes {
    /// See [`super::RULES`]: `esi-unsupported-encoding`.
    pub const UNSUPPORTED_ENCODING: &str = "F201";
    /// See [`super::RULES`]: `esi-malformed-xml`.
    pub const MALFORMED_XML: &str = "F202";
    /// See [`super::RULES`]: `esi-invalid-utf8`.
    pub const INVALID_UTF8: &str = "F203";
    /// See [`super::RULES`]: `esi-depth-limit`.
    pub const DEPTH_LIMIT: &str = "F204";
    /// See [`super::RULES`]: `esi-size-limit`.
    pub const SIZE_LIMIT: &str = "F205";
    /// See [`super::RULES`]: `esi-not-ethercatinfo`.
    pub const NOT_ETHERCATINFO: &str = "F206";
    /// See [`super::RULES`]: `esi-invalid-number`.
    pub const INVALID_NUMBER: &str = "F207";
    /// See [`super::RULES`]: `esi-invalid-boolean`.
    pub const INVALID_BOOLEAN: &str = "F208";
    /// See [`super::RULES`]: `esi-missing-element`.
    pub const MISSING_ELEMENT: &str = "F209";
    /// See [`super::RULES`]: `esi-unknown-data-type`.
    pub const UNKNOWN_DATA_TYPE: &str = "F210";
    /// See [`super::RULES`]: `esi-invalid-data`.
    pub const INVALID_DATA: &str = "F211";
    /// See [`super::RULES`]: `esi-unknown-access`.
    pub const UNKNOWN_ACCESS: &str = "F212";
    /// See [`super::RULES`]: `esi-unknown-pdo-mapping`.
    pub const UNKNOWN_PDO_MAPPING: &str = "F213";
    /// See [`super::RULES`]: `esi-duplicate-object`.
    pub const DUPLICATE_OBJECT: &str = "F214";
    /// See [`super::RULES`]: `esi-unmatched-subitem`.
    pub const UNMATCHED_SUBITEM: &str = "F215";
    /// See [`super::RULES`]: `esi-unresolved-entity`.
    pub const UNRESOLVED_ENTITY: &str = "F216";
    /// See [`super::RULES`]: `esi-doctype-ignored`.
    pub const DOCTYPE_IGNORED: &str = "F217";
    /// See [`super::RULES`]: `esi-number-out-of-range`.
    pub const NUMBER_OUT_OF_RANGE: &str = "F218";
    /// See [`super::RULES`]: `esi-nonstandard-number`.
    pub const NONSTANDARD_NUMBER: &str = "F219";
    /// See [`super::RULES`]: `esi-sub-object-limit`.
    pub const SUB_OBJECT_LIMIT: &str = "F220";
    /// See [`super::RULES`]: `esi-element-limit`.
    pub const ELEMENT_LIMIT: &str = "F221";
    /// See [`super::RULES`]: `esi-structured-sub-item`.
    pub const STRUCTURED_SUB_ITEM: &str = "F222";
    /// See [`super::RULES`]: `esi-duplicate-module`.
    pub const DUPLICATE_MODULE: &str = "F223";
    /// See [`super::RULES`]: `esi-object-data-layout`.
    pub const OBJECT_DATA_LAYOUT: &str = "F224";
    /// See [`super::RULES`]: `esi-unknown-transition`.
    pub const UNKNOWN_TRANSITION: &str = "F230";
    /// See [`super::RULES`]: `esi-default-from-pdos`.
    pub const ESI_DEFAULT: &str = "F231";
}

macro_rules! rule {
    ($code:expr, $name:literal, $sev:ident, $summary:literal, $expl:literal) => {
        RuleInfo {
            code: $code,
            name: $name,
            group: "format",
            default: Severity::$sev,
            summary: $summary,
            explanation: $expl,
        }
    };
}

/// Every diagnostic code this crate emits.
pub static RULES: &[RuleInfo] = &[
    rule!(
        codes::UNSUPPORTED_ENCODING,
        "esi-unsupported-encoding",
        Error,
        "the ESI file's encoding cannot be read",
        "ESI files are read as UTF-8 (with or without a byte-order mark) or ISO-8859-1 (any \
         spelling of the label in the XML declaration: ISO-8859-1, ISO8859-1, latin1). UTF-16 \
         files and other encodings are refused. Fix: convert the file to UTF-8."
    ),
    rule!(
        codes::MALFORMED_XML,
        "esi-malformed-xml",
        Error,
        "the ESI file is not well-formed XML",
        "The XML reader met something that is not well-formed: a mismatched or unclosed tag, an \
         invalid token, text or a second element after the root element, a malformed attribute. \
         The diagnostic points at the line and column where reading stopped; what was read before \
         is still lowered, so later diagnostics may be consequences of this one. Fix the file."
    ),
    rule!(
        codes::INVALID_UTF8,
        "esi-invalid-utf8",
        Warning,
        "the ESI file is not valid UTF-8",
        "The file declares no encoding (or UTF-8) but contains bytes that are not UTF-8. They are \
         replaced with U+FFFD. Fix: declare the real encoding (encoding=\"ISO-8859-1\") or \
         convert the file."
    ),
    rule!(
        codes::DEPTH_LIMIT,
        "esi-depth-limit",
        Error,
        "XML elements nested too deeply",
        "Elements nested deeper than 256 levels are skipped: no ESI file needs that depth, and a \
         limit keeps hostile input from exhausting memory or stack."
    ),
    rule!(
        codes::SIZE_LIMIT,
        "esi-size-limit",
        Error,
        "the ESI file is too large",
        "Files above 64 MiB (`odc_esi::MAX_FILE_SIZE`) are not read: the largest real ESI files \
         are about 4 MiB, and the limit bounds the memory a hostile file can make odc use."
    ),
    rule!(
        codes::NOT_ETHERCATINFO,
        "esi-not-ethercatinfo",
        Error,
        "the root element is not EtherCATInfo",
        "An ESI file has the root element EtherCATInfo (ETG.2000). Module files \
         (EtherCATModule), dictionary files (EtherCATDict) and diagnosis files (EtherCATDiag) \
         describe no device on their own and are reported with a warning; anything else is an \
         error."
    ),
    rule!(
        codes::INVALID_NUMBER,
        "esi-invalid-number",
        Error,
        "a number that cannot be read",
        "ETG.2000 numbers (HexDecValue) are decimal or #x-prefixed hex, optionally signed; 0x hex \
         is accepted too. The value is dropped (or kept as invalid text) and the rest of the file \
         is read."
    ),
    rule!(
        codes::INVALID_BOOLEAN,
        "esi-invalid-boolean",
        Error,
        "a boolean that cannot be read",
        "xs:boolean values are 1, 0, true or false. The attribute is taken as absent."
    ),
    rule!(
        codes::MISSING_ELEMENT,
        "esi-missing-element",
        Error,
        "a required element or attribute is missing",
        "An element the model cannot do without is absent: an object's Index, a PDO's Index, a \
         PDO entry's Index or BitLen, a device's Type. The enclosing element is skipped (or, for \
         a device's Type, its identity stays empty)."
    ),
    rule!(
        codes::UNKNOWN_DATA_TYPE,
        "esi-unknown-data-type",
        Error,
        "a data type name that is neither built in nor declared",
        "An object's Type (or a sub-item's) must name a DataType of the dictionary or a base type \
         (BOOL, BITn, SINT, INT, DINT, LINT, USINT, UINT, UDINT, ULINT, REAL, LREAL, STRING(n), \
         OCTET_STRING(n), ...). The object is kept as a DOMAIN. For a PDO entry's DataType this is \
         a warning: the entry's BitLen still gives its size."
    ),
    rule!(
        codes::INVALID_DATA,
        "esi-invalid-data",
        Error,
        "DefaultData/MinData/MaxData or a value that does not fit its type",
        "DefaultData, MinData and MaxData are little-endian hex bytes (xs:hexBinary) decoded with \
         the object's data type; DefaultValue/MinValue/MaxValue are text. A value that is not \
         valid hex, or does not fit the type, is kept as invalid text."
    ),
    rule!(
        codes::UNKNOWN_ACCESS,
        "esi-unknown-access",
        Warning,
        "an access value that is not ro, rw or wo",
        "Flags/Access is conventionally ro, rw or wo (const, rwr and rww are accepted). Anything \
         else is read as ro."
    ),
    rule!(
        codes::UNKNOWN_PDO_MAPPING,
        "esi-unknown-pdo-mapping",
        Warning,
        "a PdoMapping flag that is not R, T, RT or TR",
        "Flags/PdoMapping says in which PDO direction an object may be mapped: R (RxPDO), T \
         (TxPDO), RT/TR (both), any case. Anything else is read as not mappable."
    ),
    rule!(
        codes::DUPLICATE_OBJECT,
        "esi-duplicate-object",
        Warning,
        "an object index defined twice",
        "Two Object elements of one dictionary have the same Index. The later one is used."
    ),
    rule!(
        codes::UNMATCHED_SUBITEM,
        "esi-unmatched-subitem",
        Warning,
        "an object's Info/SubItem matches no sub-item of its data type",
        "Object/Info/SubItem elements are matched to the SubItems of the object's DataType by \
         Name (the schema's key). A name that matches none is applied to the sub-object at the \
         same position (for arrays, whose element names the front-end makes up, silently), or \
         ignored when there is none."
    ),
    rule!(
        codes::UNRESOLVED_ENTITY,
        "esi-unresolved-entity",
        Warning,
        "an entity reference that is not predefined",
        "Only the five predefined XML entities and character references are resolved; DTD \
         entities are never expanded. Others are kept as written."
    ),
    rule!(
        codes::DOCTYPE_IGNORED,
        "esi-doctype-ignored",
        Warning,
        "a DOCTYPE declaration was ignored",
        "ESI files are described by an XML schema. A DOCTYPE is not read, and its entities \
         (internal or external) are never resolved."
    ),
    rule!(
        codes::NUMBER_OUT_OF_RANGE,
        "esi-number-out-of-range",
        Error,
        "a number too large or too small for its field",
        "An object index must fit 16 bits, a sub-index 8 bits, a bit length 16 bits, a product \
         code or revision 32 bits (negative 32-bit values are taken as their two's complement). \
         A default, minimum or maximum must fit its data type: an INTEGERn written as an \
         unsigned bit pattern (`#xFFFD` for an INT) is taken as two's complement; anything \
         wider is an error and the text is kept as written."
    ),
    rule!(
        codes::NONSTANDARD_NUMBER,
        "esi-nonstandard-number",
        Warning,
        "a number or hex string in a broken but readable form",
        "Real files contain `#x0x6041` (two hex prefixes) and hexBinary with an odd number of \
         digits (`2` for `02`). They are read (the second with a leading zero) and reported so \
         that the file can be fixed."
    ),
    rule!(
        codes::SUB_OBJECT_LIMIT,
        "esi-sub-object-limit",
        Error,
        "the file's dictionaries make too many sub-objects",
        "Data types expand: every object of a 255-element array type, or of a structure with \
         255 SubItems, gets 256 sub-objects, so a few MiB of objects naming such types would \
         make millions. odc makes at most 262,144 sub-objects per file \
         (`odc_esi::MAX_SUB_OBJECTS`; the largest real files make about 16,000); the object \
         that crosses the limit and the rest of its dictionary are dropped."
    ),
    rule!(
        codes::ELEMENT_LIMIT,
        "esi-element-limit",
        Error,
        "the file has too many XML elements",
        "odc reads at most 2,000,000 elements (`odc_esi::MAX_ELEMENTS`; the largest real ESI \
         files have about 100,000). Reading stops at the limit and what was read before is \
         lowered, as after a well-formedness error."
    ),
    rule!(
        codes::STRUCTURED_SUB_ITEM,
        "esi-structured-sub-item",
        Warning,
        "a sub-item whose type is itself structured",
        "CoE sub-objects hold simple values or arrays; a SubItem of a structured DataType is read \
         as a DOMAIN and not expanded. Usually the type contains itself, directly or through \
         another type (which odc never follows). Fix the SubItem's Type."
    ),
    rule!(
        codes::DUPLICATE_MODULE,
        "esi-duplicate-module",
        Warning,
        "two modules with the same ModuleIdent",
        "Slots name the modules they accept by ModuleIdent, so each Module's ident must be unique \
         in the file. Both modules are kept; a configuration tool cannot tell them apart. Fix \
         the ident of one of them."
    ),
    rule!(
        codes::OBJECT_DATA_LAYOUT,
        "esi-object-data-layout",
        Warning,
        "an object's own DefaultData does not match its data type's sub-items",
        "An object's Info holds either SubItems or one DefaultData for the whole object \
         (ETG.2000 ObjectInfoType), laid out as complete access reads it: each sub-item at its \
         data type's BitOffs. odc splits the bytes into the sub-objects' defaults (a SubItem's \
         own default wins). Reported when bytes are left over, when a sub-item lies beyond the \
         bytes or its value does not fit its type (it then gets no default), or when the \
         data type gives no BitOffs (array types: the bytes are then not applied). Write the \
         bytes for every sub-item, or SubItem defaults instead."
    ),
    rule!(
        codes::UNKNOWN_TRANSITION,
        "esi-unknown-transition",
        Warning,
        "an init command names no state transition, or one ETG.2000 does not know",
        "An InitCmd (CoE, SoE, EoE, AoE) says when the master sends it with one or more \
         Transition elements: IP, PS, SO, SP, OS, OP, PI, SI, OI, PO, IB, BI, II, PP or SS \
         (ETG.2000 TransitionType). Another text is kept as written, but a master runs the \
         command at no transition; an InitCmd without Transition is reported as missing it."
    ),
    rule!(
        codes::ESI_DEFAULT,
        "esi-default-from-pdos",
        Note,
        "an assignment or mapping object without a default starts with the ESI's PDOs",
        "A PDO assignment object 0x1C10 + n whose sub 0 has no default (or 0), or a mapping \
         object (0x1600-0x17FF, 0x1A00-0x1BFF) whose sub 0 has none, while the ESI's PDO \
         elements assign PDOs to that sync manager (Sm attributes) or list that PDO's entries: \
         the device starts with what the PDO elements say, as its SII's PDO categories tell a \
         master. A device that started empty maps nothing, and SOEM's default bring-up meets \
         AL status 0x001D at SAFE-OP. The values are odc's, not the file's: checks compare the \
         file's own (the model keeps sub 0 as written in EtherCat::esi_defaults). Fix: give the \
         object the DefaultData the PDO elements imply."
    ),
];

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn rules_are_well_formed() {
        for (i, r) in RULES.iter().enumerate() {
            assert!(r.code.starts_with("F2") && r.code.len() == 4, "{}", r.code);
            assert_eq!(r.group, "format");
            assert!(
                r.name.chars().all(|c| c.is_ascii_lowercase() || c.is_ascii_digit() || c == '-')
            );
            assert!(RULES[..i].iter().all(|o| o.code != r.code), "dup {}", r.code);
        }
    }

    #[test]
    fn garbage_never_panics() {
        let mut s = Sources::new();
        for input in [&b""[..], b"\xFF\xFE", b"<", b"<EtherCATInfo>", b"\x00\x01\x02", b"<a/>"] {
            let p = parse(&mut s, "x.xml", input);
            assert!(p.devices.is_empty());
            let p = parse_vec(&mut s, "x.xml", input.to_vec());
            assert!(p.devices.is_empty());
        }
    }
}
