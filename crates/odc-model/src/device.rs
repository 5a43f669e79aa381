//! The device: one object dictionary, whether it was read from an EDS, a DCF or an ESI.

use std::collections::BTreeMap;
use std::sync::Arc;

use serde::Serialize;

use crate::Name;
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
    /// CiA 311 XML device description.
    Xdd,
    /// CiA 311 XML device configuration.
    Xdc,
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
    #[serde(serialize_with = "crate::hex::index_map")]
    pub dummy_usage: BTreeMap<u16, Spanned<bool>>,
    /// `[Comments]` lines.
    pub comments: Vec<String>,
    /// The three object lists as declared (checked against `objects`, not used to build it).
    pub object_lists: ObjectLists,
    /// The object dictionary, in index order.
    #[serde(serialize_with = "crate::hex::index_map")]
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
    /// XDD/XDC elements the front-end does not interpret, kept as written for the XDD writer
    /// (an EDS has no place for them: converting to EDS says so). Not serialised when empty.
    #[serde(skip_serializing_if = "Vec::is_empty")]
    pub xml_extra: Vec<XmlExtra>,
}

/// An XML element kept as written: where it was, and its text.
#[derive(Clone, Debug, PartialEq, Eq, Serialize)]
pub struct XmlExtra {
    /// The element it was a child of (`DeviceProfile`, `ApplicationProcess`,
    /// `ApplicationLayers`, `TransportLayers`, `NetworkManagement`, `CommunicationProfile`).
    pub parent: String,
    /// The element's source text, from `<` to the end of its end tag.
    pub xml: String,
    /// Where it was.
    pub span: Span,
}

impl Device {
    /// The entry of [`crate::ethercat::EtherCat::esi_defaults`] for object `index`, when its
    /// defaults are odc's, taken from the ESI's PDO elements.
    pub fn esi_default(&self, index: u16) -> Option<&crate::ethercat::EsiDefault> {
        self.ethercat.as_deref()?.esi_defaults.iter().find(|d| d.index == index)
    }

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
    #[serde(serialize_with = "crate::hex::ident")]
    pub vendor_number: Option<Spanned<u32>>,
    pub product_name: Option<Spanned<String>>,
    #[serde(serialize_with = "crate::hex::ident")]
    pub product_number: Option<Spanned<u32>>,
    #[serde(serialize_with = "crate::hex::ident")]
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
    #[serde(serialize_with = "crate::hex::index_list")]
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
    /// ESI device with CoE whose dictionary leaves out an object ETG.1000.6 gives every such
    /// device (0x1C00 the sync manager types, 0x1C10 + n the PDO assignment of a process data
    /// sync manager, a PDO's mapping object 0x16xx/0x1Axx), which masters read over CoE:
    /// synthesised from its `Sm` elements and PDOs (ETG.2000 lets the ESI leave them out).
    CoeImplied,
}

impl Origin {
    /// Whether the ESI front-end made the object rather than read it from the file
    /// ([`Origin::PdoEntry`], [`Origin::CoeImplied`]): its values are odc's, not the file's.
    pub fn is_esi_synthesised(self) -> bool {
        matches!(self, Origin::PdoEntry | Origin::CoeImplied)
    }
}

/// An object of the dictionary.
///
/// A VAR (and a DOMAIN, DEFTYPE, NULL) has exactly one sub-object, at sub-index 0, that holds
/// its type, access and values; ARRAY, RECORD and DEFSTRUCT hold their sub-objects in order.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Object {
    #[serde(serialize_with = "crate::hex::index")]
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
    /// `CompactSubObj` as declared; the sub-objects it implies are in `subs` (made when first
    /// read, see [`SubObjects::set_implied`]).
    pub compact_sub_obj: Option<Spanned<u8>>,
    /// `ObjFlags` (bit 0: refuse write on download, bit 1: refuse read on scan).
    pub obj_flags: Option<Spanned<u32>>,
    /// DCF `Denotation` of the object.
    pub denotation: Option<Spanned<String>>,
    /// `[xxxxObjectLinks]`: indexes of objects this one is linked to.
    #[serde(serialize_with = "crate::hex::index_list")]
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
///
/// Its layout is chosen for parse time: a lely master DCF implies up to ~2,000 sub-objects
/// through `CompactSubObj`, each a copy of a template, and an ESI device has thousands, so a
/// sub-object is moved, cloned and dropped often enough that its size shows. What most
/// sub-objects have (name, type, access, default, DCF parameter value) is inline; the limits
/// are boxed one by one (present on many device EDS sub-objects, absent from most others);
/// what only a few have (denotation, `ObjFlags`, DOMAIN file names, keys kept as written) is in
/// one [`SubRare`] behind one box, [`SubObject::rare`] and [`SubObject::rare_mut`]. `Debug`,
/// `Serialize` and `PartialEq` see those fields as the sub-object's own, in their place, and an
/// empty box as no box: the layout does not show.
pub struct SubObject {
    /// The 8-bit sub-index.
    pub sub_index: u8,
    /// `ParameterName` (or the name a `[xxxxName]` section gave it).
    pub name: Name,
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
    /// `LowLimit` (boxed: 8 bytes instead of 40 where absent).
    pub low_limit: Option<Box<Spanned<Value>>>,
    /// `HighLimit` (boxed: see `low_limit`).
    pub high_limit: Option<Box<Spanned<Value>>>,
    /// DCF `ParameterValue`.
    pub parameter_value: Option<Spanned<Value>>,
    /// Size in bits, when the file states it (ESI `BitSize`); otherwise that of the data type.
    pub bit_size: Option<u32>,
    /// Span of the section header (or of the line that implied the sub-object).
    pub span: Span,
    /// Span of the `DataType=` line, when the file states one (for diagnostics about the
    /// type; not serialised, as the other spans of keys that have no value of their own).
    pub data_type_span: Span,
    /// The fields few sub-objects have; `None` when all are absent.
    rare: Option<Box<SubRare>>,
}

/// The fields of a [`SubObject`] that few sub-objects have, kept together behind one box.
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub struct SubRare {
    /// DCF `Denotation`.
    pub denotation: Option<Spanned<String>>,
    /// `ObjFlags` of the sub-object.
    pub obj_flags: Option<Spanned<u32>>,
    /// `UploadFile` (DOMAIN).
    pub upload_file: Option<Spanned<String>>,
    /// `DownloadFile` (DOMAIN).
    pub download_file: Option<Spanned<String>>,
    /// The names the file gives values (XDD `allowedValues/value` with a `label`), in file
    /// order: what a monitor or a data sheet shows beside a raw value.
    pub value_names: Vec<ValueName>,
    /// Keys not interpreted.
    pub extra: Vec<RawEntry>,
}

/// A value the file names, such as `1` = `Profile position` (XDD `allowedValues/value`).
#[derive(Clone, Debug, PartialEq, Eq, Serialize)]
pub struct ValueName {
    /// The value, of the sub-object's type.
    pub value: Spanned<Value>,
    /// Its name (the label).
    pub name: String,
}

impl SubRare {
    /// Whether all are absent (field by field: comparing with an empty one compared every
    /// field through `PartialEq`, and the EDS reader asks this of every sub-object).
    pub fn is_empty(&self) -> bool {
        let SubRare { denotation, obj_flags, upload_file, download_file, value_names, extra } =
            self;
        denotation.is_none()
            && obj_flags.is_none()
            && upload_file.is_none()
            && download_file.is_none()
            && value_names.is_empty()
            && extra.is_empty()
    }
}

impl SubObject {
    /// A sub-object with the given name and type, read-only, not mappable, no values.
    pub fn new(sub_index: u8, name: impl Into<Name>, data_type: DataType, access: Access) -> Self {
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
            bit_size: None,
            span: Span::DUMMY,
            data_type_span: Span::DUMMY,
            rare: None,
        }
    }

    /// Denotation, `ObjFlags`, file names and keys kept as written (all absent for most).
    pub fn rare(&self) -> &SubRare {
        // All absent: what a sub-object without the box shows.
        static EMPTY: SubRare = SubRare {
            denotation: None,
            obj_flags: None,
            upload_file: None,
            download_file: None,
            value_names: Vec::new(),
            extra: Vec::new(),
        };
        self.rare.as_deref().unwrap_or(&EMPTY)
    }

    /// The name the file gives `value` (XDD `allowedValues`), if any.
    pub fn value_name(&self, value: &Value) -> Option<&str> {
        let names = &self.rare.as_deref()?.value_names;
        names.iter().find(|n| n.value.value == *value).map(|n| n.name.as_str())
    }

    /// [`SubObject::rare`], to set: makes the box on first use.
    pub fn rare_mut(&mut self) -> &mut SubRare {
        self.rare.get_or_insert_with(Box::default)
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

/// By hand only to be inlined where it is called: a compact object's implied sub-objects are
/// clones of one template, thousands in a master's DCF, and a clone that is a call returns the
/// whole sub-object through a stack copy before it reaches its vector. Field for field what
/// `#[derive(Clone)]` does (the struct literal names every field, so none can be missed).
impl Clone for SubObject {
    #[inline(always)]
    fn clone(&self) -> Self {
        SubObject {
            sub_index: self.sub_index,
            name: self.name.clone(),
            kind: self.kind,
            data_type: self.data_type,
            access: self.access,
            pdo_mapping: self.pdo_mapping,
            default: self.default.clone(),
            low_limit: self.low_limit.clone(),
            high_limit: self.high_limit.clone(),
            parameter_value: self.parameter_value.clone(),
            bit_size: self.bit_size,
            span: self.span,
            data_type_span: self.data_type_span,
            rare: self.rare.clone(),
        }
    }
}

// Debug, Serialize and PartialEq by hand, so that the fields of `SubRare` show as the
// sub-object's own, in the order they had as fields of it (snapshots and JSON output).
impl std::fmt::Debug for SubObject {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        let r = self.rare();
        f.debug_struct("SubObject")
            .field("sub_index", &self.sub_index)
            .field("name", &self.name)
            .field("kind", &self.kind)
            .field("data_type", &self.data_type)
            .field("access", &self.access)
            .field("pdo_mapping", &self.pdo_mapping)
            .field("default", &self.default)
            .field("low_limit", &self.low_limit)
            .field("high_limit", &self.high_limit)
            .field("parameter_value", &self.parameter_value)
            .field("denotation", &r.denotation)
            .field("obj_flags", &r.obj_flags)
            .field("upload_file", &r.upload_file)
            .field("download_file", &r.download_file)
            .field("bit_size", &self.bit_size)
            .field("extra", &r.extra)
            .field("span", &self.span)
            .field("data_type_span", &self.data_type_span)
            .finish()
    }
}

impl Serialize for SubObject {
    fn serialize<S: serde::Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
        use serde::ser::SerializeStruct;
        let r = self.rare();
        let mut st = s.serialize_struct("SubObject", 18)?;
        st.serialize_field("sub_index", &format_args!("0x{:02X}", self.sub_index))?;
        st.serialize_field("name", &self.name)?;
        st.serialize_field("kind", &self.kind)?;
        st.serialize_field("data_type", &self.data_type)?;
        st.serialize_field("access", &self.access)?;
        st.serialize_field("pdo_mapping", &self.pdo_mapping)?;
        st.serialize_field("default", &self.default)?;
        st.serialize_field("low_limit", &self.low_limit)?;
        st.serialize_field("high_limit", &self.high_limit)?;
        st.serialize_field("parameter_value", &self.parameter_value)?;
        st.serialize_field("denotation", &r.denotation)?;
        st.serialize_field("obj_flags", &r.obj_flags)?;
        st.serialize_field("upload_file", &r.upload_file)?;
        st.serialize_field("download_file", &r.download_file)?;
        if r.value_names.is_empty() {
            st.skip_field("value_names")?;
        } else {
            st.serialize_field("value_names", &r.value_names)?;
        }
        st.serialize_field("bit_size", &self.bit_size)?;
        st.serialize_field("extra", &r.extra)?;
        st.serialize_field("span", &self.span)?;
        st.end()
    }
}

impl PartialEq for SubObject {
    fn eq(&self, o: &SubObject) -> bool {
        self.sub_index == o.sub_index
            && self.name == o.name
            && self.kind == o.kind
            && self.data_type == o.data_type
            && self.access == o.access
            && self.pdo_mapping == o.pdo_mapping
            && self.default == o.default
            && self.low_limit == o.low_limit
            && self.high_limit == o.high_limit
            && self.parameter_value == o.parameter_value
            && self.bit_size == o.bit_size
            && self.span == o.span
            && self.rare() == o.rare()
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
    #[serde(serialize_with = "crate::hex::index_map")]
    pub fixed_objects: Arc<BTreeMap<u16, Object>>,
    /// `[MxSubExtends]` with each `[MxSubExtIIII]`: sub-objects the module appends to an object.
    #[serde(serialize_with = "crate::hex::index_map")]
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
    #[serde(serialize_with = "crate::hex::ident")]
    pub lss_serial_number: Option<Spanned<u32>>,
    pub node_refd: Option<Spanned<String>>,
    pub net_refd: Option<Spanned<String>>,
    /// Keys not named above.
    pub extra: Vec<RawEntry>,
    /// Span of the section header.
    pub span: Span,
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The layout of `SubObject` is chosen for parse time (see its docs): a field added inline
    /// shows in every DCF's thousands of implied sub-objects, so growing it is a decision, not
    /// an accident.
    #[test]
    #[cfg(target_pointer_width = "64")]
    fn sub_object_stays_small() {
        assert_eq!(std::mem::size_of::<Value>(), 24);
        // 168 since the span of `DataType` (diagnostics point at the key, issue 14).
        assert_eq!(std::mem::size_of::<SubObject>(), 168);
        // Empty rare fields compare, print and serialise as absent ones.
        let a = SubObject::new(1, "x", DataType::Unsigned8, Access::Ro);
        let mut b = a.clone();
        b.rare_mut().denotation = None;
        assert_eq!(a, b);
        assert_eq!(format!("{a:?}"), format!("{b:?}"));
        assert!(format!("{a:?}").contains("denotation: None, obj_flags: None"));
    }
}
