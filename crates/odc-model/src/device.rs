//! The device: one object dictionary, whether it was read from an EDS, a DCF or an ESI.

use std::collections::BTreeMap;
use std::sync::Arc;

use serde::Serialize;

use crate::ethercat::EtherCat;
use crate::pdo::Pdo;
use crate::span::{Span, Spanned};
use crate::subs::SubObjects;
use crate::types::{Access, DataType, ObjectKind, PdoMapping};
use crate::value::Value;

/// The file format a device was read from.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize)]
#[serde(rename_all = "lowercase")]
pub enum Format {
    /// CiA 306 electronic data sheet.
    Eds,
    /// CiA 306 device configuration file.
    Dcf,
    /// ETG.2000 EtherCAT slave information.
    Esi,
}

/// A key the front-end does not interpret, kept as written so that it survives a round trip.
#[derive(Clone, Debug, PartialEq, Eq, Serialize)]
pub struct RawEntry {
    /// The key in its original spelling.
    pub key: String,
    /// The value text.
    pub value: String,
    /// Span of the whole `key=value` line.
    pub span: Span,
}

/// A section the front-end does not interpret (e.g. `[Tools]`, vendor sections), kept whole.
#[derive(Clone, Debug, PartialEq, Eq, Serialize)]
pub struct RawSection {
    /// The section name in its original spelling, without brackets.
    pub name: String,
    /// Its entries, in file order.
    pub entries: Vec<RawEntry>,
    /// Span of the header.
    pub span: Span,
}

/// One device: identity, descriptive data and the object dictionary.
#[derive(Clone, Debug, Default, PartialEq, Serialize)]
pub struct Device {
    /// What the file was.
    pub format: Option<Format>,
    /// `[FileInfo]`.
    pub file_info: FileInfo,
    /// `[DeviceInfo]`; for an ESI the identity and names from `<Type>` and `<Name>`.
    pub device_info: DeviceInfo,
    /// `[DummyUsage]`: which data-type indexes may be mapped as PDO gap fillers.
    pub dummy_usage: BTreeMap<u16, Spanned<bool>>,
    /// `[Comments]` lines.
    pub comments: Vec<String>,
    /// The three object lists as declared (checked against `objects`, not used to build it).
    pub object_lists: ObjectLists,
    /// The object dictionary, in index order.
    pub objects: BTreeMap<u16, Object>,
    /// Modular devices: the modules the file describes, and (DCF) the ones connected.
    pub modules: Modules,
    /// DCF `[DeviceComissioning]`.
    pub commissioning: Option<Commissioning>,
    /// PDOs as the file defines them: ESI `RxPdo`/`TxPdo`; for CANopen filled by
    /// [`crate::pdo::resolve_canopen_pdos`] from the 0x14xx–0x1Bxx objects.
    pub pdos: Vec<Pdo>,
    /// EtherCAT-only data (sync managers, mailbox, distributed clocks, ...).
    pub ethercat: Option<Box<EtherCat>>,
    /// Sections the front-end does not interpret, in file order.
    pub extra_sections: Vec<RawSection>,
}

impl Device {
    /// The sub-object at `index`:`sub`.
    pub fn sub(&self, index: u16, sub: u8) -> Option<&SubObject> {
        self.objects.get(&index)?.sub(sub)
    }

    /// The device's display name: product name, else the file name, else "device".
    pub fn name(&self) -> &str {
        self.device_info
            .product_name
            .as_deref()
            .or(self.file_info.file_name.as_deref())
            .map(String::as_str)
            .unwrap_or("device")
    }
}

/// `[FileInfo]`.
#[derive(Clone, Debug, Default, PartialEq, Eq, Serialize)]
#[allow(missing_docs)] // CiA 306 key names
pub struct FileInfo {
    pub file_name: Option<Spanned<String>>,
    pub file_version: Option<Spanned<u8>>,
    pub file_revision: Option<Spanned<u8>>,
    /// Kept as text: real files say `4.0`, `4.04`, `402`, `5`.
    pub eds_version: Option<Spanned<String>>,
    pub description: Option<Spanned<String>>,
    pub creation_time: Option<Spanned<String>>,
    pub creation_date: Option<Spanned<String>>,
    pub created_by: Option<Spanned<String>>,
    pub modification_time: Option<Spanned<String>>,
    pub modification_date: Option<Spanned<String>>,
    pub modified_by: Option<Spanned<String>>,
    /// Keys not named above.
    pub extra: Vec<RawEntry>,
}

/// `[DeviceInfo]`.
#[derive(Clone, Debug, Default, PartialEq, Eq, Serialize)]
#[allow(missing_docs)] // CiA 306 key names
pub struct DeviceInfo {
    pub vendor_name: Option<Spanned<String>>,
    pub vendor_number: Option<Spanned<u32>>,
    pub product_name: Option<Spanned<String>>,
    pub product_number: Option<Spanned<u32>>,
    pub revision_number: Option<Spanned<u32>>,
    pub order_code: Option<Spanned<String>>,
    /// Supported bit rates in kbit/s (`BaudRate_NNN=1`), ascending; unsupported ones are absent.
    pub baud_rates: Vec<u32>,
    pub simple_boot_up_master: Option<Spanned<bool>>,
    pub simple_boot_up_slave: Option<Spanned<bool>>,
    pub granularity: Option<Spanned<u8>>,
    pub dynamic_channels_supported: Option<Spanned<u8>>,
    pub group_messaging: Option<Spanned<bool>>,
    pub nr_of_rx_pdo: Option<Spanned<u16>>,
    pub nr_of_tx_pdo: Option<Spanned<u16>>,
    pub lss_supported: Option<Spanned<bool>>,
    /// CompactPDO bit field (which PDO communication sub-objects are implicit).
    pub compact_pdo: Option<Spanned<u8>>,
    /// Keys not named above.
    pub extra: Vec<RawEntry>,
}

/// The three object lists of an EDS, as written.
#[derive(Clone, Debug, Default, PartialEq, Eq, Serialize)]
pub struct ObjectLists {
    /// `[MandatoryObjects]`.
    pub mandatory: Option<ObjectList>,
    /// `[OptionalObjects]`.
    pub optional: Option<ObjectList>,
    /// `[ManufacturerObjects]`.
    pub manufacturer: Option<ObjectList>,
}

/// One object list section.
#[derive(Clone, Debug, Default, PartialEq, Eq, Serialize)]
pub struct ObjectList {
    /// `SupportedObjects=`.
    pub supported_objects: Option<Spanned<u16>>,
    /// The entries `1=0x1000`, `2=...`, in order.
    pub entries: Vec<Spanned<u16>>,
    /// Span of the section header.
    pub span: Span,
}

/// Where an object came from.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum Origin {
    /// Written out in the file.
    #[default]
    File,
    /// Implied by `CompactPDO` (CiA 306 §4.5.2): the writer does not write it out.
    CompactPdo,
    /// ESI device without a dictionary: synthesised from its PDO entries.
    PdoEntry,
}

/// An object of the dictionary.
///
/// A VAR (and a DOMAIN, DEFTYPE, NULL) has exactly one sub-object, at sub-index 0, that holds
/// its type, access and values; ARRAY, RECORD and DEFSTRUCT hold their sub-objects in order.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Object {
    /// The 16-bit index.
    pub index: u16,
    /// `ParameterName`.
    pub name: String,
    /// `ObjectType`.
    pub kind: ObjectKind,
    /// Sub-objects ordered by sub-index.
    pub subs: SubObjects,
    /// `SubNumber` as declared (a count, gaps allowed).
    pub sub_number: Option<Spanned<u16>>,
    /// `CompactSubObj` as declared; the sub-objects it implies are in `subs`.
    pub compact_sub_obj: Option<Spanned<u8>>,
    /// `ObjFlags` (bit 0: refuse write on download, bit 1: refuse read on scan).
    pub obj_flags: Option<Spanned<u32>>,
    /// DCF `Denotation` of the object.
    pub denotation: Option<Spanned<String>>,
    /// `[xxxxObjectLinks]`: indexes of objects this one is linked to.
    pub links: Vec<Spanned<u16>>,
    /// Where the object came from.
    pub origin: Origin,
    /// Keys not interpreted (of the object section itself).
    pub extra: Vec<RawEntry>,
    /// Span of the section header.
    pub span: Span,
}

impl Object {
    /// An object read from a file, with no sub-objects and nothing optional set yet.
    pub fn new(index: u16, name: impl Into<String>, kind: ObjectKind, span: Span) -> Self {
        Object {
            index,
            name: name.into(),
            kind,
            subs: SubObjects::new(),
            sub_number: None,
            compact_sub_obj: None,
            obj_flags: None,
            denotation: None,
            links: Vec::new(),
            origin: Origin::File,
            extra: Vec::new(),
            span,
        }
    }

    /// The sub-object `sub`.
    pub fn sub(&self, sub: u8) -> Option<&SubObject> {
        self.subs.get(&sub)
    }

    /// For a VAR-like object, its one sub-object (sub-index 0).
    pub fn var(&self) -> Option<&SubObject> {
        if self.kind.has_subs() { None } else { self.subs.get(&0) }
    }
}

/// A sub-object: the unit that has a type, an access and a value.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct SubObject {
    /// The 8-bit sub-index.
    pub sub_index: u8,
    /// `ParameterName` (or the name a `[xxxxName]` section gave it).
    pub name: String,
    /// `ObjectType` of the sub section, when it says one (usually VAR).
    pub kind: Option<ObjectKind>,
    /// `DataType`.
    pub data_type: DataType,
    /// `AccessType`.
    pub access: Access,
    /// `PDOMapping`.
    pub pdo_mapping: PdoMapping,
    /// `DefaultValue`.
    pub default: Option<Spanned<Value>>,
    /// `LowLimit`. Boxed, as `high_limit`: a sub-object is moved and dropped often enough that
    /// its size shows in parse time (a lely master DCF implies ~2,500 per file through
    /// `CompactSubObj`), and limits are absent from most of them, while the default and the
    /// DCF parameter value are present on most (the two limits take 16 bytes boxed, 80 inline;
    /// the extra allocation of a device EDS that states limits costs less than moving the 64
    /// bytes everywhere else).
    pub low_limit: Option<Box<Spanned<Value>>>,
    /// `HighLimit`. Boxed: see `low_limit`.
    pub high_limit: Option<Box<Spanned<Value>>>,
    /// DCF `ParameterValue`.
    pub parameter_value: Option<Spanned<Value>>,
    /// DCF `Denotation`. Boxed, as the two file names below: rare, and a sub-object is moved
    /// and dropped often enough that its size shows in parse time (the three take 24 bytes
    /// boxed, 120 inline).
    pub denotation: Option<Box<Spanned<String>>>,
    /// `ObjFlags` of the sub-object.
    pub obj_flags: Option<Spanned<u32>>,
    /// `UploadFile` (DOMAIN).
    pub upload_file: Option<Box<Spanned<String>>>,
    /// `DownloadFile` (DOMAIN).
    pub download_file: Option<Box<Spanned<String>>>,
    /// Size in bits, when the file states it (ESI `BitSize`); otherwise that of the data type.
    pub bit_size: Option<u32>,
    /// Keys not interpreted.
    pub extra: Vec<RawEntry>,
    /// Span of the section header (or of the line that implied the sub-object).
    pub span: Span,
}

impl SubObject {
    /// A sub-object with the given name and type, read-only, not mappable, no values.
    pub fn new(
        sub_index: u8,
        name: impl Into<String>,
        data_type: DataType,
        access: Access,
    ) -> Self {
        SubObject {
            sub_index,
            name: name.into(),
            kind: None,
            data_type,
            access,
            pdo_mapping: PdoMapping::No,
            default: None,
            low_limit: None,
            high_limit: None,
            parameter_value: None,
            denotation: None,
            obj_flags: None,
            upload_file: None,
            download_file: None,
            bit_size: None,
            extra: Vec::new(),
            span: Span::DUMMY,
        }
    }

    /// The size in bits: stated, else that of the data type.
    pub fn bits(&self) -> Option<u32> {
        self.bit_size.or_else(|| self.data_type.bit_size())
    }

    /// The value the device starts with: ParameterValue (DCF) over DefaultValue.
    pub fn initial_value(&self) -> Option<&Spanned<Value>> {
        self.parameter_value.as_ref().or(self.default.as_ref())
    }
}

/// Modular devices (CiA 306 §4.6: bus couplers with plug-in modules).
#[derive(Clone, Debug, Default, PartialEq, Serialize)]
pub struct Modules {
    /// `[SupportedModules]` with each `[MxModuleInfo]`, `[MxFixedObjects]`, `[MxSubExtends]`.
    pub supported: Vec<Module>,
    /// DCF `[ConnectedModules]`: module numbers in slot order.
    pub connected: Vec<Spanned<u16>>,
    /// `[SupportedModules] NrOfEntries` as written (the writer writes the number of modules),
    /// kept so that a count that disagrees with the `[MxModuleInfo]` sections can be reported.
    /// Left out of the serialised model when absent, as for most devices.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub nr_of_entries: Option<Spanned<u16>>,
}

/// One module a modular device supports.
#[derive(Clone, Debug, Default, PartialEq, Serialize)]
pub struct Module {
    /// The module number `x` of `[MxModuleInfo]`.
    pub number: u16,
    /// Whether the file describes the module itself (EDS `[MxModuleInfo]`, ESI `<Module>`): in
    /// an EDS a module can also be implied by its other `[Mx...]` sections alone, which
    /// CiA 306 §4.6 does not allow.
    pub has_info: bool,
    /// `ProductName`.
    pub product_name: Option<Spanned<String>>,
    /// `ProductVersion`.
    pub product_version: Option<Spanned<u16>>,
    /// `ProductRevision`.
    pub product_revision: Option<Spanned<u16>>,
    /// `OrderCode`.
    pub order_code: Option<Spanned<String>>,
    /// Keys of `[MxModuleInfo]` not named above.
    pub extra: Vec<RawEntry>,
    /// `[MxFixedObjects]` with each `[MxFixedIIII]`: objects the module adds at fixed indexes.
    /// Shared: the modules an ESI file declares once apply to each of its devices, whose
    /// module lists would otherwise each hold a copy of every module's dictionary.
    pub fixed_objects: Arc<BTreeMap<u16, Object>>,
    /// `[MxSubExtends]` with each `[MxSubExtIIII]`: sub-objects the module appends to an object.
    pub sub_extends: BTreeMap<u16, SubExtend>,
    /// `[MxComments]` lines.
    pub comments: Vec<String>,
    /// Span of `[MxModuleInfo]`.
    pub span: Span,
}

/// A `[MxSubExtIIII]`: the template of the sub-objects a module adds to object `IIII`.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct SubExtend {
    /// The sub-object template (name, type, access, limits...).
    pub template: SubObject,
    /// `Count`: how many sub-objects the module adds (CiA 306 allows a list `n;m`, kept as text).
    pub count: Option<Spanned<String>>,
    /// `ObjExtend`: the object index whose sub-objects are extended, when stated.
    pub obj_extend: Option<Spanned<u16>>,
}

/// DCF `[DeviceComissioning]` (CiA 306 spelling; `[DeviceCommissioning]` is read too).
#[derive(Clone, Debug, Default, PartialEq, Eq, Serialize)]
#[allow(missing_docs)] // CiA 306 key names
pub struct Commissioning {
    pub node_id: Option<Spanned<u8>>,
    pub node_name: Option<Spanned<String>>,
    /// kbit/s.
    pub baudrate: Option<Spanned<u32>>,
    pub net_number: Option<Spanned<u32>>,
    pub network_name: Option<Spanned<String>>,
    pub canopen_manager: Option<Spanned<bool>>,
    pub lss_serial_number: Option<Spanned<u32>>,
    pub node_refd: Option<Spanned<String>>,
    pub net_refd: Option<Spanned<String>>,
    /// Keys not named above.
    pub extra: Vec<RawEntry>,
    /// Span of the section header.
    pub span: Span,
}
