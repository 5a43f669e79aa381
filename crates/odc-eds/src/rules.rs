//! The diagnostic codes of the EDS/DCF front-end (group `format`, F101..F199).

use odc_model::{RuleInfo, Severity};

/// The codes, as constants, so the code and the registry cannot drift apart.
pub mod codes {
    /// See [`super::RULES`].
    pub const STRAY_LINE: &str = "F101";
    /// See [`super::RULES`].
    pub const KEY_OUTSIDE_SECTION: &str = "F102";
    /// See [`super::RULES`].
    pub const MALFORMED_HEADER: &str = "F103";
    /// See [`super::RULES`].
    pub const TEXT_AFTER_HEADER: &str = "F104";
    /// See [`super::RULES`].
    pub const DUPLICATE_SECTION: &str = "F105";
    /// See [`super::RULES`].
    pub const DUPLICATE_KEY: &str = "F106";
    /// See [`super::RULES`].
    pub const INVALID_VALUE: &str = "F107";
    /// See [`super::RULES`].
    pub const OUT_OF_RANGE: &str = "F108";
    /// See [`super::RULES`].
    pub const OCTAL_NUMBER: &str = "F109";
    /// See [`super::RULES`].
    pub const INTEGER_SUFFIX: &str = "F110";
    /// See [`super::RULES`].
    pub const NODEID_ORDER: &str = "F111";
    /// See [`super::RULES`].
    pub const EMPTY_VALUE: &str = "F112";
    /// See [`super::RULES`].
    pub const INLINE_COMMENT: &str = "F113";
    /// See [`super::RULES`].
    pub const NONSTANDARD_ACCESS: &str = "F114";
    /// See [`super::RULES`].
    pub const UNKNOWN_ACCESS: &str = "F115";
    /// See [`super::RULES`].
    pub const INVALID_OBJECT_TYPE: &str = "F116";
    /// See [`super::RULES`].
    pub const MISSING_DATA_TYPE: &str = "F117";
    /// See [`super::RULES`].
    pub const MISSING_ACCESS_TYPE: &str = "F118";
    /// See [`super::RULES`].
    pub const MISSING_NAME: &str = "F119";
    /// See [`super::RULES`].
    pub const MALFORMED_OBJECT_SECTION: &str = "F120";
    /// See [`super::RULES`].
    pub const ORPHAN_SECTION: &str = "F121";
    /// See [`super::RULES`].
    pub const COMPACT_CONFLICT: &str = "F122";
    /// See [`super::RULES`].
    pub const SUBS_ON_VAR: &str = "F123";
    /// See [`super::RULES`].
    pub const BAD_COMPACT_ENTRY: &str = "F124";
    /// See [`super::RULES`].
    pub const NOT_UTF8: &str = "F125";
    /// See [`super::RULES`].
    pub const UNEXPECTED_KEY: &str = "F126";
    /// See [`super::RULES`].
    pub const SIZE_LIMIT: &str = "F127";
    /// See [`super::RULES`].
    pub const COMPACT_LIMIT: &str = "F128";
    /// See [`super::RULES`].
    pub const NUL_BYTES: &str = "F129";
    /// See [`super::RULES`].
    pub const CR_LINE_ENDS: &str = "F130";
    /// See [`super::RULES`].
    pub const NO_SECTIONS: &str = "F131";
    /// See [`super::RULES`].
    pub const LINE_LIMIT: &str = "F132";
    /// See [`super::RULES`].
    pub const ODD_HEX_DIGITS: &str = "F133";
    /// See [`super::RULES`].
    pub const NOT_A_DATA_TYPE: &str = "F134";
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

/// Every diagnostic code the EDS/DCF front-end emits.
pub static RULES: &[RuleInfo] = &[
    rule!(
        codes::STRAY_LINE,
        "stray-line",
        Warning,
        "a line that is neither `key=value`, a `[section]` header nor a comment",
        "CiA 306 files are INI text: every line is a section header `[name]`, an entry \
         `key=value`, a comment starting with `;`, or blank. A line that is none of these is kept \
         (the writer drops it) and otherwise ignored. Git merge-conflict markers (`<<<<<<<`, \
         `=======`, `>>>>>>>`) are the most common cause in public files; they are reported in \
         one diagnostic per file that labels every marker line: resolve the conflict. \
         Fix: delete the line, or turn it into a `;` comment."
    ),
    rule!(
        codes::KEY_OUTSIDE_SECTION,
        "key-outside-section",
        Warning,
        "an entry before the first section header",
        "Every `key=value` must belong to a section (CiA 306 §4). Entries before the first \
         `[section]` header are kept in the raw layer but not interpreted. Fix: move the entry \
         into the section it belongs to, or delete it."
    ),
    rule!(
        codes::MALFORMED_HEADER,
        "malformed-section-header",
        Warning,
        "a section header without closing bracket or without a name",
        "A section header is `[name]` on a line of its own. A header without `]` is read up to \
         the end of the line; an empty name `[]` opens a section nothing refers to. Fix the \
         brackets."
    ),
    rule!(
        codes::TEXT_AFTER_HEADER,
        "text-after-section-header",
        Warning,
        "text after the `]` of a section header",
        "CiA 306 allows nothing after `]` but blanks. The text is ignored (some kacanopen files \
         put a description there). Fix: move it to a `;` comment line."
    ),
    rule!(
        codes::DUPLICATE_SECTION,
        "duplicate-section",
        Warning,
        "the same section appears twice (names compare case-insensitively)",
        "Section names are case-insensitive and must be unique. odc merges the repeated sections \
         in file order; for a key given in more than one, the later value wins (the behaviour of \
         python's configparser in non-strict mode); a value that does not read is reported even \
         when a later one replaces it. The writer emits one merged section. Fix: \
         merge the sections by hand and decide which values are meant."
    ),
    rule!(
        codes::DUPLICATE_KEY,
        "duplicate-key",
        Warning,
        "the same key appears twice in one section (keys compare case-insensitively)",
        "Keys are case-insensitive and must be unique within a section. The later value wins; \
         an earlier value that does not read is still reported. Fix: delete the line that is not meant."
    ),
    rule!(
        codes::INVALID_VALUE,
        "invalid-value",
        Error,
        "a value that does not read as its type",
        "Numbers are decimal, `0x` hexadecimal or (leading zero) octal, optionally with \
         `$NODEID+`; REAL values are decimal floats or `0x` bit patterns; BOOLEAN is 0/1; \
         OCTET_STRING and DOMAIN values are hex bytes; AccessType, ObjectType and DataType have \
         fixed vocabularies. A value that does not read is kept verbatim (`Value::Invalid`) so \
         that the writer reproduces it, but nothing downstream can use it. Fix the value."
    ),
    rule!(
        codes::OUT_OF_RANGE,
        "value-out-of-range",
        Error,
        "a number that does not fit its data type",
        "An UNSIGNED8 holds 0..=255, an INTEGER16 -32768..=32767, and so on; key values such \
         as FileVersion or NrOfRXPDO have their own widths. For signed types, a hex literal is \
         read as the two's complement bit pattern of the type's width (0xFFFF for an INTEGER16 \
         is -1). A value that does not fit is kept verbatim as invalid. Fix the value or the \
         data type."
    ),
    rule!(
        codes::OCTAL_NUMBER,
        "octal-number",
        Warning,
        "a number with a leading zero, read as octal",
        "CiA 306 follows C (`strtoul` base 0): a leading `0` means octal, so `010` is 8. Many \
         files pad decimal numbers with zeros (`VendorNumber=001`); for values below 8 both \
         readings agree. odc reads octal as the spec says (digits 8 and 9 make it decimal) and \
         warns. Fix: drop the leading zeros, or write `0x` hex."
    ),
    rule!(
        codes::INTEGER_SUFFIX,
        "integer-suffix",
        Warning,
        "a C integer suffix (`U`, `L`, `UL`, `LL`, `ULL`) after a number",
        "Some generators (CANopenSocket) copy C literals such as `0x0LL` into the EDS. CiA 306 \
         has no suffixes; lely and canopen-host reject them. odc ignores the suffix and warns. \
         Fix: delete the suffix."
    ),
    rule!(
        codes::NODEID_ORDER,
        "nodeid-order",
        Warning,
        "`$NODEID` written after the offset (`0x180+$NODEID`)",
        "CiA 306 writes node-ID-relative values as `$NODEID+offset`. CANopenEditor and others \
         write `offset+$NODEID`; odc reads both (and `$NODEID` in any case) and warns about the \
         non-canonical order, which lely and others reject. The writer emits `$NODEID+0x...`."
    ),
    rule!(
        codes::EMPTY_VALUE,
        "empty-value",
        Warning,
        "`Key=` with nothing after the `=` where a number or keyword is expected",
        "An empty value is treated as if the key were absent (python-canopen crashes on it, \
         lely ignores it). For VISIBLE_STRING, OCTET_STRING and DOMAIN values an empty value is \
         the empty string and is not reported; an empty LowLimit or HighLimit is absent and \
         reported whatever the type. Fix: give a value or delete the line."
    ),
    rule!(
        codes::INLINE_COMMENT,
        "inline-comment",
        Warning,
        "a `#` or `;` comment after a value",
        "CiA 306 comments are whole lines starting with `;`. Some files (kacanopen profiles) \
         write `ObjectType=0x07 # VAR`. The raw layer keeps the text; when a number or keyword \
         does not read, the lowering cuts a trailing ` #...` or ` ;...` and tries again, with \
         this warning. Names and strings keep the text: `Motor #1` is a valid name. The writer \
         drops the comment. Fix: move the comment to its own `;` line."
    ),
    rule!(
        codes::NONSTANDARD_ACCESS,
        "nonstandard-access-type",
        Warning,
        "an AccessType spelling that is not CiA 306 but is understood (`r` for `ro`)",
        "CiA 306 AccessType values are ro, wo, rw, rwr, rww and const (any case). `r` is read \
         as `ro`. Fix: write `ro`."
    ),
    rule!(
        codes::UNKNOWN_ACCESS,
        "unknown-access-type",
        Error,
        "an AccessType that is not ro, wo, rw, rwr, rww or const",
        "Values such as `UNKNOWN` say nothing about how the entry may be accessed. odc assumes \
         `ro` so the model stays usable, but code generated from it may be wrong. Fix: write \
         the real access type."
    ),
    rule!(
        codes::INVALID_OBJECT_TYPE,
        "invalid-object-type",
        Error,
        "an ObjectType that is not 0 (NULL), 2 (DOMAIN), 5 (DEFTYPE), 6 (DEFSTRUCT), 7 (VAR), 8 (ARRAY) or 9 (RECORD)",
        "ObjectType codes come from CiA 301 Table 42. An object with another code is read as \
         VAR when it has no sub-object sections and as RECORD when it has. Fix the code."
    ),
    rule!(
        codes::MISSING_DATA_TYPE,
        "missing-data-type",
        Error,
        "a VAR or sub-object without DataType",
        "DataType is mandatory for every VAR and sub-object (CiA 306 §4.6.3): without it values \
         cannot be read and no code can be generated. odc assumes DOMAIN. Fix: add DataType."
    ),
    rule!(
        codes::MISSING_ACCESS_TYPE,
        "missing-access-type",
        Warning,
        "a VAR or sub-object without AccessType",
        "AccessType is mandatory for every VAR and sub-object. odc assumes `ro`. Fix: add \
         AccessType."
    ),
    rule!(
        codes::MISSING_NAME,
        "missing-parameter-name",
        Warning,
        "an object or sub-object without ParameterName",
        "ParameterName is mandatory (CiA 306 §4.6.3). odc uses an empty name; generated code \
         falls back to the index. Fix: add ParameterName."
    ),
    rule!(
        codes::MALFORMED_OBJECT_SECTION,
        "malformed-object-section",
        Warning,
        "a section name that looks like an object or sub-object but does not parse",
        "Object sections are `[IIII]` (4 hex digits), sub-objects `[IIIIsubS]` (S: 1 or 2 hex \
         digits, leading zeros tolerated), and companions `[IIIIName]`, `[IIIIValue]`, \
         `[IIIIDenotation]`, `[IIIIObjectLinks]`. A name such as `[1000sub]` or `[1018sub100]` \
         is kept as an unknown section. Fix the name."
    ),
    rule!(
        codes::ORPHAN_SECTION,
        "orphan-section",
        Warning,
        "a sub-object or companion section whose object section is missing",
        "`[IIIIsubS]`, `[IIIIName]`, `[IIIIValue]`, `[IIIIDenotation]` and `[IIIIObjectLinks]` \
         belong to an `[IIII]` section. Without it the section is kept as an unknown section \
         and not interpreted. Fix: add the object section or delete the orphan."
    ),
    rule!(
        codes::COMPACT_CONFLICT,
        "compact-sub-obj-conflict",
        Warning,
        "an object has both CompactSubObj and explicit sub-object sections",
        "With CompactSubObj=N the sub-objects 0..=N are implied (CiA 306 §4.5.1) and no \
         `[IIIIsubS]` sections are expected. odc builds the implied ones and lets explicit \
         sections override them. Fix: use one form."
    ),
    rule!(
        codes::SUBS_ON_VAR,
        "sub-sections-on-var",
        Warning,
        "a VAR (or DOMAIN, DEFTYPE, NULL) object has sub-object sections",
        "A VAR has one value, described in its own section. Sub-object sections of a VAR are \
         kept as sub-objects other than 0, which most tools ignore. Fix: make the object a \
         RECORD or ARRAY, or delete the sections."
    ),
    rule!(
        codes::BAD_COMPACT_ENTRY,
        "bad-compact-entry",
        Warning,
        "an entry of a `[IIIIName]`, `[IIIIValue]`, `[IIIIDenotation]` or `[IIIIObjectLinks]` section that does not apply",
        "Entries of these sections are `S=text` with S a sub-index (decimal) of an existing \
         sub-object (or `n=0xIIII` for object links), plus the count key (NrOfEntries or \
         ObjectLinks). Other entries are ignored. Fix the key."
    ),
    rule!(
        codes::NOT_UTF8,
        "not-utf8",
        Note,
        "the file is not UTF-8 and was decoded as UTF-16 or Windows-1252",
        "CiA 306 does not name an encoding. Files with a UTF-16 byte-order mark (or ASCII text \
         with every other byte NUL, as Windows \"Unicode\" editors save it) are decoded as \
         UTF-16; other files that are not valid UTF-8 are decoded as Windows-1252 (a superset \
         of Latin-1 for printable characters), which is what Windows-based editors write. Spans \
         refer to the decoded text. The writer emits UTF-8."
    ),
    rule!(
        codes::UNEXPECTED_KEY,
        "unexpected-key",
        Warning,
        "a key that does not belong in its section",
        "Sections such as [DummyUsage], [Comments], the object lists and the module lists have \
         fixed key patterns (`DummyIIII`, `LineN`, `N=0xIIII`). Other keys are kept (the writer \
         writes them back) but not interpreted. Fix the key."
    ),
    rule!(
        codes::SIZE_LIMIT,
        "eds-size-limit",
        Error,
        "the EDS/DCF file is too large",
        "Files above 32 MiB (`odc_eds::MAX_FILE_SIZE`) are not read: the largest real EDS and DCF \
         files are a few hundred KiB, and the limit bounds the memory a hostile file can make \
         odc use. Nothing of the file is interpreted."
    ),
    rule!(
        codes::COMPACT_LIMIT,
        "compact-sub-object-limit",
        Error,
        "CompactSubObj implies more sub-objects than odc expands for one file",
        "Each `CompactSubObj=N` implies N sub-objects that the file does not spell out; a few \
         kilobytes of `CompactSubObj=255` objects would otherwise make millions. odc expands at \
         most 65536 implied sub-objects per file (`odc_eds::MAX_IMPLIED_SUB_OBJECTS`; real files \
         imply a few hundred); objects past the limit keep their CompactSubObj value but get no \
         implied sub-objects."
    ),
    rule!(
        codes::NUL_BYTES,
        "nul-bytes",
        Warning,
        "the text contains NUL bytes",
        "EDS and DCF files are text; a NUL byte means a binary file, a damaged one, or UTF-16 \
         that was not recognised. Keys and section names with a NUL in them are not recognised \
         (an object section becomes an unknown one). Fix: find the first one (the label points \
         at it) and delete or replace them."
    ),
    rule!(
        codes::CR_LINE_ENDS,
        "cr-line-ends",
        Note,
        "lines end with CR alone",
        "Classic Mac OS ended lines with a carriage return alone. A file with CRs and no line \
         feed is read with each CR as a line end; spans and line numbers are those of the file. \
         Fix: convert the line ends to LF or CR LF."
    ),
    rule!(
        codes::NO_SECTIONS,
        "no-sections",
        Warning,
        "the file has no section header",
        "Every EDS or DCF has `[FileInfo]`, `[DeviceInfo]` and one section per object. A file \
         without any `[section]` is empty, not an EDS (a binary file, a file of another \
         format), or lost its headers; the device read from it has no object."
    ),
    rule!(
        codes::LINE_LIMIT,
        "eds-line-limit",
        Error,
        "the file has too many lines",
        "odc reads at most 262,144 lines of an EDS or DCF (`odc_eds::MAX_LINES`; the largest real \
         files have about 15,000): every line costs memory in the lossless raw layer and the \
         model, and the limit bounds what a hostile file can make odc use. Lines past it are \
         not read, as if the file ended there."
    ),
    rule!(
        codes::ODD_HEX_DIGITS,
        "odd-hex-digits",
        Warning,
        "an OCTET_STRING or DOMAIN value with an odd number of hex digits",
        "OCTET_STRING and DOMAIN values are hex bytes, two digits each, contiguous or \
         blank-separated (`0102AB`, `01 02 AB`). A group of odd length cannot be split into \
         bytes: odc reads it with a zero nibble in front (`ABC` is `0A BC`), other tools may \
         read it otherwise, and the warning says which bytes odc read. Fix: write the leading zero (`0ABC`) or the \
         missing digit."
    ),
    rule!(
        codes::NOT_A_DATA_TYPE,
        "not-a-data-type",
        Warning,
        "a DataType that is no data type CiA 301 defines and that the file does not define",
        "DataType is the index of a data type object: CiA 301 defines 0x0001-0x001B (BOOLEAN \
         .. UNSIGNED64, with gaps at 0x000E and 0x0017) and 0x0020-0x0023 (PDO and SDO \
         parameter records, IDENTITY), ETG.1000 BIT1..BIT8 are 0x0030-0x0037; \
         0x0040-0x025F are for manufacturer and profile types, which the file defines with a \
         DEFTYPE or DEFSTRUCT object at that index. Any other \
         index (a reserved one, or a profile index with no object describing it) gives values \
         no size or type: odc keeps the number and reads values as text or plain numbers. \
         Fix: use the index of the intended type (`0x0007` for UNSIGNED32), or define the type."
    ),
];
