//! The diagnostic codes of the XDD/XDC front-end (`F3xx`) and their `odc explain` texts.

use odc_model::{RuleInfo, Severity};

/// The codes, as constants, so the code and the registry cannot drift apart.
pub mod codes {
    /// `xdd-unsupported-encoding`.
    pub const UNSUPPORTED_ENCODING: &str = "F301";
    /// `xdd-malformed-xml`.
    pub const MALFORMED_XML: &str = "F302";
    /// `xdd-invalid-utf8`.
    pub const INVALID_UTF8: &str = "F303";
    /// `xdd-depth-limit`.
    pub const DEPTH_LIMIT: &str = "F304";
    /// `xdd-size-limit`.
    pub const SIZE_LIMIT: &str = "F305";
    /// `xdd-not-iso15745`.
    pub const NOT_XDD: &str = "F306";
    /// `xdd-invalid-number`.
    pub const INVALID_NUMBER: &str = "F307";
    /// `xdd-invalid-value`.
    pub const INVALID_VALUE: &str = "F308";
    /// `xdd-missing-attribute`.
    pub const MISSING_ATTRIBUTE: &str = "F309";
    /// `xdd-missing-data-type`.
    pub const MISSING_DATA_TYPE: &str = "F310";
    /// `xdd-unknown-access`.
    pub const UNKNOWN_ACCESS: &str = "F311";
    /// `xdd-unknown-pdo-mapping`.
    pub const UNKNOWN_PDO_MAPPING: &str = "F312";
    /// `xdd-duplicate-object`.
    pub const DUPLICATE_OBJECT: &str = "F313";
    /// `xdd-unresolved-reference`.
    pub const UNRESOLVED_REFERENCE: &str = "F314";
    /// `xdd-invalid-object-type`.
    pub const INVALID_OBJECT_TYPE: &str = "F315";
    /// `xdd-unresolved-entity`.
    pub const UNRESOLVED_ENTITY: &str = "F316";
    /// `xdd-doctype-ignored`.
    pub const DOCTYPE_IGNORED: &str = "F317";
    /// `xdd-value-out-of-range`.
    pub const OUT_OF_RANGE: &str = "F318";
    /// `xdd-no-access`.
    pub const NO_ACCESS: &str = "F319";
    /// `xdd-element-limit`.
    pub const ELEMENT_LIMIT: &str = "F320";
    /// `xdd-duplicate-sub-object`.
    pub const DUPLICATE_SUB_OBJECT: &str = "F321";
    /// `xdd-invalid-boolean`.
    pub const INVALID_BOOLEAN: &str = "F322";
    /// `xdd-standard-data-type`.
    pub const STANDARD_DATA_TYPE: &str = "F323";
}

/// The `F3xx` code for a diagnostic of the shared XML reader and decoder (`odc-esi`'s `F2xx`).
pub(crate) fn from_esi(code: &'static str) -> &'static str {
    use odc_esi::codes as e;
    match code {
        c if c == e::UNSUPPORTED_ENCODING => codes::UNSUPPORTED_ENCODING,
        c if c == e::MALFORMED_XML => codes::MALFORMED_XML,
        c if c == e::INVALID_UTF8 => codes::INVALID_UTF8,
        c if c == e::DEPTH_LIMIT => codes::DEPTH_LIMIT,
        c if c == e::SIZE_LIMIT => codes::SIZE_LIMIT,
        c if c == e::UNRESOLVED_ENTITY => codes::UNRESOLVED_ENTITY,
        c if c == e::DOCTYPE_IGNORED => codes::DOCTYPE_IGNORED,
        c if c == e::ELEMENT_LIMIT => codes::ELEMENT_LIMIT,
        // The reader emits no other code; one it might in future stays malformed XML.
        _ => codes::MALFORMED_XML,
    }
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
        "xdd-unsupported-encoding",
        Error,
        "the XDD file's encoding cannot be read",
        "XDD/XDC files are read as UTF-8 (with or without a byte-order mark) or ISO-8859-1 as \
         the XML declaration says. UTF-16 and other encodings are refused. Fix: convert the file \
         to UTF-8."
    ),
    rule!(
        codes::MALFORMED_XML,
        "xdd-malformed-xml",
        Error,
        "the XDD file is not well-formed XML",
        "The XML reader met something that is not well-formed (a mismatched or unclosed tag, a \
         NUL byte, text after the root element). What was read before is still lowered, so later \
         diagnostics may be consequences of this one."
    ),
    rule!(
        codes::INVALID_UTF8,
        "xdd-invalid-utf8",
        Warning,
        "the XDD file is not valid UTF-8",
        "The file declares no encoding (or UTF-8) but holds bytes that are not UTF-8; they are \
         replaced with U+FFFD. Fix: declare the real encoding or convert the file."
    ),
    rule!(
        codes::DEPTH_LIMIT,
        "xdd-depth-limit",
        Error,
        "XML elements nested too deeply",
        "Elements nested deeper than 256 levels are skipped: no XDD needs that depth, and the \
         limit keeps hostile input from exhausting memory or stack."
    ),
    rule!(
        codes::SIZE_LIMIT,
        "xdd-size-limit",
        Error,
        "the XDD file is too large",
        "Files above 64 MiB (`odc_xdd::MAX_FILE_SIZE`) are not read; the largest real XDD files \
         are about 1 MiB."
    ),
    rule!(
        codes::NOT_XDD,
        "xdd-not-iso15745",
        Error,
        "the root element is not ISO15745ProfileContainer",
        "A CiA 311 XDD or XDC file is an ISO 15745 profile container: the root element is \
         ISO15745ProfileContainer with a device profile and a communication network profile. A \
         file with another root describes no device here."
    ),
    rule!(
        codes::INVALID_NUMBER,
        "xdd-invalid-number",
        Error,
        "a number that cannot be read",
        "index, subIndex, dataType and objFlags are hex (CiA 311 hexBinary; a 0x prefix is \
         accepted); objectType, subNumber, nrOfRxPDO and the like are decimal (0x accepted). The \
         element is skipped (index, subIndex) or the attribute taken as absent."
    ),
    rule!(
        codes::INVALID_VALUE,
        "xdd-invalid-value",
        Error,
        "a value that does not read as its data type",
        "defaultValue, lowLimit, highLimit and actualValue are written as in an EDS (CiA 306 \
         numbers, $NODEID+, hex bytes for OCTET_STRING and DOMAIN). A value that does not read is \
         kept as written (so that converting loses nothing) and left out of generated code."
    ),
    rule!(
        codes::MISSING_ATTRIBUTE,
        "xdd-missing-attribute",
        Error,
        "a required attribute is missing",
        "CANopenObject needs index and CANopenSubObject needs subIndex; without them the element \
         is skipped. A missing name or objectType is a warning (VAR is assumed)."
    ),
    rule!(
        codes::MISSING_DATA_TYPE,
        "xdd-missing-data-type",
        Error,
        "an object with no data type",
        "The data type comes from the dataType attribute (a CiA 301 index), else from the \
         referenced parameter's type element (USINT, UDINT, STRING, BITSTRING...), else from the \
         array type it references, else (sub-objects of an ARRAY) from the object. With none of \
         them the object is read as DOMAIN."
    ),
    rule!(
        codes::UNKNOWN_ACCESS,
        "xdd-unknown-access",
        Error,
        "an access type that is not known",
        "accessType is const, ro, wo, rw, rwr or rww; a parameter's access is const, read, \
         write, readWrite, readWriteInput (rwr) or readWriteOutput (rww). Anything else is read \
         as ro."
    ),
    rule!(
        codes::UNKNOWN_PDO_MAPPING,
        "xdd-unknown-pdo-mapping",
        Warning,
        "a PDOmapping value that is not known",
        "PDOmapping is no, default, optional, TPDO or RPDO. Anything else is read as no."
    ),
    rule!(
        codes::DUPLICATE_OBJECT,
        "xdd-duplicate-object",
        Warning,
        "an object index defined twice",
        "Two CANopenObject elements have the same index. The later one is used."
    ),
    rule!(
        codes::UNRESOLVED_REFERENCE,
        "xdd-unresolved-reference",
        Warning,
        "a uniqueIDRef that names no parameter or data type",
        "uniqueIDRef of an object names a parameter of the parameterList, and a parameter's \
         dataTypeIDRef a type of the dataTypeList. A reference to nothing is ignored: the \
         object's own attributes are all there is."
    ),
    rule!(
        codes::INVALID_OBJECT_TYPE,
        "xdd-invalid-object-type",
        Error,
        "objectType is not a CiA 301 object code",
        "objectType is 0 (NULL), 2 (DOMAIN), 5 (DEFTYPE), 6 (DEFSTRUCT), 7 (VAR), 8 (ARRAY) or \
         9 (RECORD). Anything else is read as VAR, or RECORD when the object has sub-objects."
    ),
    rule!(
        codes::UNRESOLVED_ENTITY,
        "xdd-unresolved-entity",
        Warning,
        "an entity reference that is not predefined",
        "Only the five predefined XML entities and character references are resolved; DTD \
         entities are never expanded. Others are kept as written."
    ),
    rule!(
        codes::DOCTYPE_IGNORED,
        "xdd-doctype-ignored",
        Warning,
        "a DOCTYPE declaration was ignored",
        "XDD files are described by an XML schema. A DOCTYPE is not read, and its entities \
         (internal or external) are never resolved."
    ),
    rule!(
        codes::OUT_OF_RANGE,
        "xdd-value-out-of-range",
        Error,
        "a number too large for its field or type",
        "An index must fit 16 bits, a sub-index 8 bits; a value must fit its data type. The \
         value is kept as written."
    ),
    rule!(
        codes::NO_ACCESS,
        "xdd-no-access",
        Warning,
        "a parameter with access noAccess",
        "CiA 311's noAccess has no CiA 306 access type: the object is read as ro."
    ),
    rule!(
        codes::ELEMENT_LIMIT,
        "xdd-element-limit",
        Error,
        "the file has too many XML elements",
        "odc reads at most 2,000,000 elements; reading stops there and what was read before is \
         lowered."
    ),
    rule!(
        codes::DUPLICATE_SUB_OBJECT,
        "xdd-duplicate-sub-object",
        Warning,
        "a sub-index defined twice in one object",
        "Two CANopenSubObject elements of one object have the same subIndex. The later one is \
         used."
    ),
    rule!(
        codes::INVALID_BOOLEAN,
        "xdd-invalid-boolean",
        Error,
        "a boolean that cannot be read",
        "xs:boolean values are true, false, 1 or 0. The attribute is taken as absent."
    ),
    rule!(
        codes::STANDARD_DATA_TYPE,
        "xdd-standard-data-type",
        Warning,
        "an element of a CiA 301 ARRAY with no data type, read as the standard's type",
        "The elements of the ARRAY objects CiA 301 defines have a type the standard fixes: \
         0x1003 pre-defined error field, 0x1010 store parameters, 0x1011 restore default \
         parameters, 0x1016 consumer heartbeat time and 0x1028 emergency consumer are UNSIGNED32, \
         0x1026 OS prompt and 0x1029 error behavior UNSIGNED8, 0x1027 module list UNSIGNED16. \
         Some CANopenEditor versions write these sub-objects with `dataType=\"0000\"` and no type \
         on the object or in the parameters; they are read as the standard's type instead of \
         DOMAIN (F310). Fix: give the object or its sub-objects their dataType."
    ),
];
