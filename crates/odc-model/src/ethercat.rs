//! EtherCAT-only parts of a device (ETG.2000): sync managers, FMMUs, mailbox, distributed clocks,
//! EEPROM, modules and slots, and the ESI data that has no CANopen counterpart.
//!
//! The object dictionary and the PDOs of an ESI device live in the common model
//! ([`crate::Device::objects`], [`crate::Device::pdos`]); this holds what only EtherCAT has.
//! Elements the ESI front-end does not interpret (vendor `Info` blocks, `VendorSpecific`, `Sci`,
//! images, ...) are kept as raw XML text ([`RawXml`]) with their spans, so nothing is lost.

use std::collections::BTreeMap;
use std::sync::Arc;

use serde::Serialize;

use crate::Name;
use crate::device::Object;
use crate::pdo::Pdo;
use crate::span::{Span, Spanned};

/// The EtherCAT description of one device (revision) of an ESI file.
#[derive(Clone, Debug, Default, PartialEq, Serialize)]
pub struct EtherCat {
    /// Vendor `Id`.
    pub vendor_id: Option<u32>,
    /// `Type ProductCode`.
    pub product_code: Option<u32>,
    /// `Type RevisionNo`.
    pub revision: Option<u32>,
    /// `Type SerialNo`.
    pub serial_no: Option<u32>,
    /// The other attributes of `Type` (`CheckProductCode`, `CheckRevisionNo`, `TcSmClass`, ...).
    pub type_attributes: Vec<XmlAttribute>,
    /// `Device@Physics` (e.g. `YY`: two EBUS/MII ports).
    pub physics: Option<String>,
    /// Vendor `Name` in every language.
    pub vendor_names: Vec<LocalizedText>,
    /// Device `Name` in every language, in file order.
    pub names: Vec<LocalizedText>,
    /// `GroupType` and the group it names (from `Descriptions/Groups`).
    pub group: Option<Group>,
    /// `Profile` elements (without the dictionary, which is lowered into the objects).
    pub profiles: Vec<Profile>,
    /// The dictionary's data types, as declared (the objects refer to them by name).
    pub data_types: Vec<EsiDataType>,
    /// ESI-only flags of sub-objects: access restrictions per state, category, backup, setting.
    /// Only sub-objects that have any of them are listed, in (index, sub-index) order.
    pub object_flags: Vec<ObjectFlags>,
    /// `Fmmu` elements in order (FMMU 0, 1, ...).
    pub fmmus: Vec<Fmmu>,
    /// `Sm` elements in order (SM 0, 1, ...).
    pub sync_managers: Vec<SyncManager>,
    /// The ESI-only attributes of the device's PDOs (`Virtual`, oversampling), for the PDOs
    /// that have any, in file order; the common ones (`Sm`, `Fixed`, `Mandatory`, `Exclude`)
    /// are on [`Pdo`].
    #[serde(skip_serializing_if = "Vec::is_empty")]
    pub pdo_attributes: Vec<PdoAttributes>,
    /// Beckhoff's alternative sync-manager assignments
    /// (`Info/VendorSpecific/TwinCAT/AlternativeSmMapping`), in file order.
    #[serde(skip_serializing_if = "Vec::is_empty")]
    pub alternative_sm_mappings: Vec<AlternativeSmMapping>,
    /// `Mailbox`, when the device has one.
    pub mailbox: Option<Mailbox>,
    /// `Dc`, when the device supports distributed clocks.
    pub dc: Option<Dc>,
    /// `Eeprom`.
    pub eeprom: Option<Eeprom>,
    /// `Slots` of a modular device.
    pub slots: Option<Slots>,
    /// The modules of the file (`Descriptions/Modules`, or `Modules` inside the device).
    pub modules: Vec<EsiModule>,
    /// Whether the dictionary was synthesised from the PDOs (the file has none).
    pub dictionary_synthesised: bool,
    /// The file's own assignment (0x1C10 + n) and mapping objects whose defaults the ESI
    /// front-end filled from the ESI's `Sm` attributes and PDO entries, because the file gives
    /// them none (or an empty assignment): a device starts with those (#31). The filled values
    /// carry no span ([`Spanned::synthetic`]); each entry keeps what the file's sub 0 said, so
    /// checks compare the file's own words, not odc's.
    #[serde(skip_serializing_if = "Vec::is_empty")]
    pub esi_defaults: Vec<EsiDefault>,
    /// Elements of the device (and of the file's `Vendor`/`Descriptions`) that the front-end does
    /// not interpret, kept as raw XML.
    pub raw: Vec<RawXml>,
}

/// Serialises bytes as one hex string (`0a1b`), as ESI files write them.
fn hex<S: serde::Serializer>(bytes: &[u8], s: S) -> Result<S::Ok, S::Error> {
    let text: String = bytes.iter().map(|b| format!("{b:02x}")).collect();
    s.serialize_str(&text)
}

/// A text with its language (`LcId`, e.g. 1033 English, 1031 German).
#[derive(Clone, Debug, PartialEq, Eq, Serialize)]
pub struct LocalizedText {
    /// The Windows locale id, when given.
    pub lc_id: Option<u32>,
    /// The text.
    pub text: String,
    /// Where it is written.
    pub span: Span,
}

/// An XML attribute kept as written.
#[derive(Clone, Debug, PartialEq, Eq, Serialize)]
pub struct XmlAttribute {
    /// Name.
    pub name: String,
    /// Value (entities resolved).
    pub value: String,
    /// Span of the value.
    pub span: Span,
}

/// An object of the file whose default the ESI front-end filled (see
/// [`EtherCat::esi_defaults`]).
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct EsiDefault {
    /// The object's index.
    #[serde(serialize_with = "crate::hex::index")]
    pub index: u16,
    /// Sub 0's default as the file wrote it (`None`: the file gives none).
    pub file_count: Option<Spanned<crate::value::Value>>,
}

/// An XML element the front-end does not interpret, kept as its source text.
#[derive(Clone, Debug, PartialEq, Eq, Serialize)]
pub struct RawXml {
    /// The element's name, with its parent's (e.g. `Device/Info`).
    pub path: String,
    /// The element's source text, from `<` to the end of its end tag.
    pub xml: String,
    /// Where it is.
    pub span: Span,
}

/// A device group (`Descriptions/Groups/Group`).
#[derive(Clone, Debug, PartialEq, Eq, Serialize)]
pub struct Group {
    /// `Type`, the key `GroupType` refers to.
    pub type_name: String,
    /// `Name` in every language (empty when the group is not declared).
    pub names: Vec<LocalizedText>,
    /// Span of `GroupType`.
    pub span: Span,
}

/// A `Profile` element.
#[derive(Clone, Debug, Default, PartialEq, Eq, Serialize)]
pub struct Profile {
    /// `@Channel`.
    pub channel: Option<u32>,
    /// `ProfileNo` (e.g. 402, 5001).
    pub profile_no: Option<u32>,
    /// `AddInfo`.
    pub add_info: Option<u32>,
    /// `ChannelCount`.
    pub channel_count: Option<u32>,
    /// `ChannelInfo/ProfileNo` of each channel, in order (a device whose channels follow
    /// different profiles lists them instead of `ChannelCount`); `None` where a `ChannelInfo`
    /// has no readable `ProfileNo`.
    #[serde(skip_serializing_if = "Vec::is_empty")]
    pub channel_profiles: Vec<Option<u32>>,
    /// `DictionaryFile`: the dictionary is in another file.
    pub dictionary_file: Option<String>,
    /// Whether the profile has an inline `Dictionary`.
    pub has_dictionary: bool,
    /// Span of the element.
    pub span: Span,
}

/// A dictionary `DataType`.
///
/// Its texts, and those of [`EsiSubItem`] and [`ObjectFlags`], are [`Name`]s: short (type names,
/// `ro`, `m`), made by the thousand per file, and kept inline up to 24 bytes where a `String`
/// would cost an allocation each.
#[derive(Clone, Debug, Default, PartialEq, Eq, Serialize)]
pub struct EsiDataType {
    /// `Name`, the key objects and sub-items refer to.
    pub name: Name,
    /// `Index`, when given.
    pub index: Option<u32>,
    /// `BaseType`.
    pub base_type: Option<Name>,
    /// `BitSize`.
    pub bit_size: Option<u32>,
    /// `ArrayInfo` (one per dimension).
    pub array_info: Vec<ArrayInfo>,
    /// `SubItem`s of a structured type.
    pub sub_items: Vec<EsiSubItem>,
    /// `EnumInfo` of an enumeration type.
    pub enum_info: Vec<EnumItem>,
    /// Span of the element.
    pub span: Span,
}

/// `ArrayInfo`.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize)]
pub struct ArrayInfo {
    /// `LBound`.
    pub lbound: i64,
    /// `Elements`.
    pub elements: u32,
}

/// A `DataType/SubItem`.
#[derive(Clone, Debug, Default, PartialEq, Eq, Serialize)]
pub struct EsiSubItem {
    /// `SubIdx`.
    pub sub_idx: Option<u32>,
    /// `Name`.
    pub name: Name,
    /// `Type`.
    pub type_name: Name,
    /// `BitSize`.
    pub bit_size: Option<u32>,
    /// `BitOffs`.
    pub bit_offset: Option<u32>,
    /// `Flags/Access` text.
    pub access: Option<Name>,
    /// `Flags/PdoMapping` text.
    pub pdo_mapping: Option<Name>,
}

/// One `EnumInfo`.
#[derive(Clone, Debug, PartialEq, Eq, Serialize)]
pub struct EnumItem {
    /// `Text` (the first one; other languages are dropped).
    pub text: String,
    /// `Enum`.
    pub value: i64,
}

/// ESI-only flags of one sub-object.
#[derive(Clone, Debug, Default, PartialEq, Eq, Serialize)]
pub struct ObjectFlags {
    /// Object index.
    pub index: u16,
    /// Sub-index.
    pub sub: u8,
    /// `Access@ReadRestrictions` (PreOP, PreOP_SafeOP, PreOP_OP, SafeOP, SafeOP_OP, OP).
    pub read_restrictions: Option<Name>,
    /// `Access@WriteRestrictions`.
    pub write_restrictions: Option<Name>,
    /// `Category`: m (mandatory), o (optional), c (conditional).
    pub category: Option<Name>,
    /// `Backup`.
    pub backup: Option<bool>,
    /// `Setting`.
    pub setting: Option<bool>,
    /// `Transition` (IP, PS, SO).
    pub transition: Option<Name>,
}

/// What a sync manager or FMMU is used for.
#[derive(Clone, Debug, PartialEq, Eq, Serialize)]
#[serde(rename_all = "PascalCase")]
pub enum SmUsage {
    /// `MBoxOut`: mailbox master → device.
    MBoxOut,
    /// `MBoxIn`: mailbox device → master.
    MBoxIn,
    /// `Outputs`: process data master → device.
    Outputs,
    /// `Inputs`: process data device → master.
    Inputs,
    /// `MBoxState` (FMMU only).
    MBoxState,
    /// Any other text (empty when the element had none).
    Other(String),
}

impl SmUsage {
    /// The ESI's spelling (`MBoxOut`, `Outputs`, …; another text as written).
    pub fn as_str(&self) -> &str {
        match self {
            SmUsage::MBoxOut => "MBoxOut",
            SmUsage::MBoxIn => "MBoxIn",
            SmUsage::Outputs => "Outputs",
            SmUsage::Inputs => "Inputs",
            SmUsage::MBoxState => "MBoxState",
            SmUsage::Other(t) => t,
        }
    }

    /// Reads the element text.
    pub fn parse(text: &str) -> SmUsage {
        match text.trim() {
            "MBoxOut" => SmUsage::MBoxOut,
            "MBoxIn" => SmUsage::MBoxIn,
            "Outputs" => SmUsage::Outputs,
            "Inputs" => SmUsage::Inputs,
            "MBoxState" => SmUsage::MBoxState,
            other => SmUsage::Other(other.to_string()),
        }
    }

    /// The sync manager communication type of 0x1C00 (ETG.1000.6 §5.6.7.4.5): 1 mailbox out,
    /// 2 mailbox in, 3 outputs, 4 inputs, 0 unused (any other usage).
    pub fn communication_type(&self) -> u8 {
        match self {
            SmUsage::MBoxOut => 1,
            SmUsage::MBoxIn => 2,
            SmUsage::Outputs => 3,
            SmUsage::Inputs => 4,
            SmUsage::MBoxState | SmUsage::Other(_) => 0,
        }
    }
}

/// The default PDO assignment of an ESI device, sync manager → PDO mapping indexes in order:
/// each PDO with an `Sm` attribute on that sync manager, and each `Mandatory` PDO without one
/// on the first sync manager of its direction's usage (`Outputs` for RxPDOs, `Inputs` for
/// TxPDOs); in file order. A PDO's `Fixed` says only that its mapping cannot change, not that
/// it is assigned. A PDO that excludes, or is excluded by, a PDO assigned before it
/// (`Exclude`) is left out, as TwinCAT does. Sync managers marked `Virtual` are left out: they
/// are no sync manager of the ESC but ESC registers (0x0981 DC activation, 0x0990 SYNC0 start
/// time, ...) that TwinCAT maps with an FMMU of their own; a master that configures sync
/// managers from the SII (ethercrab, SOEM) has no such segment.
///
/// The one rule for it: the ESI front-end's assignment objects (0x1C1n it synthesises) and
/// the analysis layer's process image both come from here.
pub fn default_assignment(sms: &[SyncManager], pdos: &[Pdo]) -> BTreeMap<u8, Vec<u16>> {
    use crate::types::Direction;
    let first =
        |usage: SmUsage| sms.iter().find(|s| s.usage == usage && !s.virtual_sm).map(|s| s.number);
    let is_virtual = |n: u8| sms.iter().any(|s| s.number == n && s.virtual_sm);
    let mut out: BTreeMap<u8, Vec<u16>> = BTreeMap::new();
    for pdo in pdos {
        let sm = pdo.sync_manager.or_else(|| {
            pdo.mandatory.then_some(()).and_then(|()| match pdo.direction {
                Direction::Rx => first(SmUsage::Outputs),
                Direction::Tx => first(SmUsage::Inputs),
            })
        });
        let Some(sm) = sm.filter(|&n| !is_virtual(n)) else { continue };
        let clash = out.values().flatten().any(|&other| {
            pdo.excludes.contains(&other)
                || pdos
                    .iter()
                    .any(|p| p.mapping_index == other && p.excludes.contains(&pdo.mapping_index))
        });
        if !clash {
            out.entry(sm).or_default().push(pdo.mapping_index);
        }
    }
    out
}

/// An `Fmmu` element.
#[derive(Clone, Debug, PartialEq, Eq, Serialize)]
pub struct Fmmu {
    /// What it maps.
    pub usage: SmUsage,
    /// `@Sm`: the sync manager it is tied to.
    pub sm: Option<u8>,
    /// `@Su`: the sync unit.
    pub su: Option<u8>,
    /// Span of the element.
    pub span: Span,
}

/// An `Sm` element.
#[derive(Clone, Debug, PartialEq, Eq, Serialize)]
pub struct SyncManager {
    /// The sync manager's number (position among the `Sm` elements).
    pub number: u8,
    /// What it carries.
    pub usage: SmUsage,
    /// `@MinSize`.
    pub min_size: Option<u32>,
    /// `@MaxSize`.
    pub max_size: Option<u32>,
    /// `@DefaultSize`.
    pub default_size: Option<u32>,
    /// `@StartAddress`.
    pub start_address: Option<Spanned<u16>>,
    /// `@ControlByte`.
    pub control_byte: Option<Spanned<u8>>,
    /// `@Enable`.
    pub enable: bool,
    /// `@Virtual`.
    pub virtual_sm: bool,
    /// `@OpOnly`.
    pub op_only: bool,
    /// Span of the element.
    pub span: Span,
}

/// ESI attributes of one `RxPdo`/`TxPdo` that the common [`Pdo`] does not carry.
#[derive(Clone, Debug, Default, PartialEq, Eq, Serialize)]
pub struct PdoAttributes {
    /// The PDO's mapping index.
    pub index: u16,
    /// Whether it is an RxPDO (else a TxPDO).
    pub rx: bool,
    /// `@Virtual`: the PDO maps ESC registers through a virtual sync manager, not objects of a
    /// real one.
    pub virtual_pdo: bool,
    /// `@OSFac`: the default oversampling factor.
    pub os_fac: Option<u32>,
    /// `@OSMin`.
    pub os_min: Option<u32>,
    /// `@OSMax`.
    pub os_max: Option<u32>,
    /// `@OSIndexInc`: how far the entries' index moves per oversampled copy.
    pub os_index_inc: Option<u32>,
    /// Span of the element.
    pub span: Span,
}

/// PDOs assigned to one sync manager (`Sm No=` with `Pdo` children, in a DC op-mode or an
/// alternative mapping).
#[derive(Clone, Debug, Default, PartialEq, Eq, Serialize)]
pub struct SmAssignment {
    /// `@No`: the sync manager.
    pub number: u8,
    /// `SyncType` (DC op-modes only).
    pub sync_type: Option<u32>,
    /// The PDO indexes, in order, each with its `@OSFac` when given.
    pub pdos: Vec<(u16, Option<u32>)>,
    /// Span of the element.
    pub span: Span,
}

/// A Beckhoff `AlternativeSmMapping`: a named assignment of PDOs to sync managers the user
/// may pick instead of the `Sm` attributes.
#[derive(Clone, Debug, Default, PartialEq, Eq, Serialize)]
pub struct AlternativeSmMapping {
    /// `Name` (may be empty).
    pub name: String,
    /// `@Default`: the assignment TwinCAT starts with.
    pub default: bool,
    /// The sync managers it assigns.
    pub sms: Vec<SmAssignment>,
    /// Span of the element.
    pub span: Span,
}

/// The `Mailbox` element: which protocols the device speaks.
#[derive(Clone, Debug, Default, PartialEq, Eq, Serialize)]
pub struct Mailbox {
    /// `@DataLinkLayer`.
    pub data_link_layer: bool,
    /// CAN application protocol over EtherCAT.
    pub coe: Option<CoE>,
    /// File access over EtherCAT.
    pub foe: bool,
    /// Ethernet over EtherCAT.
    pub eoe: bool,
    /// `EoE/InitCmd`s (their `Type` in [`InitCmd::index`]).
    #[serde(skip_serializing_if = "Vec::is_empty")]
    pub eoe_init_cmds: Vec<InitCmd>,
    /// Servo drive profile over EtherCAT.
    pub soe: Option<SoE>,
    /// ADS over EtherCAT.
    pub aoe: bool,
    /// `AoE/InitCmd`s (data only).
    #[serde(skip_serializing_if = "Vec::is_empty")]
    pub aoe_init_cmds: Vec<InitCmd>,
    /// Vendor-specific protocol over EtherCAT.
    pub voe: bool,
    /// Span of the element.
    pub span: Span,
}

/// `Mailbox/CoE`.
#[derive(Clone, Debug, Default, PartialEq, Eq, Serialize)]
pub struct CoE {
    /// `@SdoInfo`: the device answers SDO information requests.
    pub sdo_info: bool,
    /// `@PdoAssign`: 0x1C1x may be written.
    pub pdo_assign: bool,
    /// `@PdoConfig`: 0x16xx/0x1Axx may be written.
    pub pdo_config: bool,
    /// `@PdoUpload`: the master reads the PDO configuration from the device.
    pub pdo_upload: bool,
    /// `@CompleteAccess`.
    pub complete_access: bool,
    /// `@SegmentedSdo`.
    pub segmented_sdo: bool,
    /// `@EdsFile`.
    pub eds_file: Option<String>,
    /// `InitCmd`s: SDO writes the master does on state transitions.
    pub init_cmds: Vec<InitCmd>,
}

/// `Mailbox/SoE`.
#[derive(Clone, Debug, Default, PartialEq, Eq, Serialize)]
pub struct SoE {
    /// `@ChannelCount`.
    pub channel_count: Option<u32>,
    /// `InitCmd`s (with an IDN instead of an index).
    pub init_cmds: Vec<InitCmd>,
}

/// An `InitCmd`.
#[derive(Clone, Debug, Default, PartialEq, Eq, Serialize)]
pub struct InitCmd {
    /// `Transition` elements (IP, PS, SO, SP, OP, OS, ...; ETG.2000 `TransitionType`).
    pub transitions: Vec<String>,
    /// `Index` (CoE), `IDN` (SoE) or `Type` (EoE).
    pub index: Option<u32>,
    /// `SubIndex`.
    pub sub_index: Option<u32>,
    /// `Data` as bytes (hexBinary).
    #[serde(serialize_with = "hex")]
    pub data: Vec<u8>,
    /// `Comment`.
    pub comment: Option<String>,
    /// `@CompleteAccess`.
    pub complete_access: bool,
    /// `@Fixed`.
    pub fixed: bool,
    /// Span of the element.
    pub span: Span,
}

/// The `Dc` element.
#[derive(Clone, Debug, Default, PartialEq, Eq, Serialize)]
pub struct Dc {
    /// `OpMode`s (free run, SM-synchronous, DC-synchronous...).
    pub op_modes: Vec<DcOpMode>,
    /// Span of the element.
    pub span: Span,
}

/// A `Dc/OpMode`.
#[derive(Clone, Debug, Default, PartialEq, Eq, Serialize)]
pub struct DcOpMode {
    /// `Name`.
    pub name: String,
    /// `Desc`.
    pub desc: Option<String>,
    /// `AssignActivate`: value of ESC registers 0x0980/0x0981 (e.g. 0x300 = SYNC0 on).
    pub assign_activate: Option<u32>,
    /// `CycleTimeSync0`.
    pub cycle_time_sync0: Option<u32>,
    /// `CycleTimeSync0@Factor`.
    pub cycle_time_sync0_factor: Option<i64>,
    /// `ShiftTimeSync0`.
    pub shift_time_sync0: Option<i64>,
    /// `ShiftTimeSync0@Factor`.
    pub shift_time_sync0_factor: Option<i64>,
    /// `CycleTimeSync1`.
    pub cycle_time_sync1: Option<u32>,
    /// `CycleTimeSync1@Factor`.
    pub cycle_time_sync1_factor: Option<i64>,
    /// `ShiftTimeSync1`.
    pub shift_time_sync1: Option<i64>,
    /// `ShiftTimeSync1@Factor`.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub shift_time_sync1_factor: Option<i64>,
    /// `Sm` elements: the PDO assignment this mode uses instead of the `Sm` attributes.
    #[serde(skip_serializing_if = "Vec::is_empty")]
    pub sms: Vec<SmAssignment>,
    /// Span of the element.
    pub span: Span,
}

/// The `Eeprom` element: what the device's SII EEPROM holds (ETG.2000 §5.3.4, ETG.2010).
#[derive(Clone, Debug, Default, PartialEq, Eq, Serialize)]
pub struct Eeprom {
    /// `ByteSize`: the EEPROM's size in bytes.
    pub byte_size: Option<u32>,
    /// `ConfigData` bytes: the SII's first words (PDI control, PDI configuration, sync impulse
    /// length, extended PDI configuration, station alias), in EEPROM byte order.
    #[serde(serialize_with = "hex")]
    pub config_data: Vec<u8>,
    /// `BootStrap` bytes: SII words 0x14..0x17 (bootstrap mailbox offsets and sizes).
    #[serde(serialize_with = "hex")]
    pub boot_strap: Vec<u8>,
    /// `Data`: the whole EEPROM image, when given instead.
    #[serde(serialize_with = "hex")]
    pub data: Vec<u8>,
    /// `Category` elements: vendor categories to put into the SII as they are.
    pub categories: Vec<EepromCategory>,
    /// `@AssignToPdi`: the EEPROM is handed to the PDI after start-up.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub assign_to_pdi: Option<bool>,
    /// Span of the `ByteSize`, `ConfigData`, `BootStrap` and `Data` texts, when given (for
    /// diagnostics about the SII image built from them).
    #[serde(skip_serializing_if = "EepromSpans::is_empty")]
    pub spans: EepromSpans,
    /// Span of the element.
    pub span: Span,
}

/// Where the parts of an [`Eeprom`] are written.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize)]
pub struct EepromSpans {
    /// `ByteSize` text.
    pub byte_size: Option<Span>,
    /// `ConfigData` text.
    pub config_data: Option<Span>,
    /// `BootStrap` text.
    pub boot_strap: Option<Span>,
    /// `Data` text.
    pub data: Option<Span>,
}

impl EepromSpans {
    /// Whether no part is given (nothing to serialise).
    pub fn is_empty(&self) -> bool {
        *self == EepromSpans::default()
    }
}

/// An `Eeprom/Category`: a category the vendor wants in the SII (e.g. Beckhoff's category 1).
#[derive(Clone, Debug, Default, PartialEq, Eq, Serialize)]
pub struct EepromCategory {
    /// `CatNo`: the category type word.
    pub cat_no: u16,
    /// The category's bytes: `Data` as written, `DataString` as its text's bytes, `DataUINT` and
    /// `DataUDINT` as 2 and 4 little-endian bytes.
    #[serde(serialize_with = "hex")]
    pub data: Vec<u8>,
    /// `@PreserveOnlineData`: a tool writing the EEPROM keeps the device's own category.
    pub preserve_online_data: bool,
    /// Span of the element.
    pub span: Span,
}

/// The `Slots` element of a modular device.
#[derive(Clone, Debug, Default, PartialEq, Eq, Serialize)]
pub struct Slots {
    /// `@SlotIndexIncrement`: object index distance between slots.
    pub slot_index_increment: Option<u32>,
    /// `@SlotPdoIncrement`: PDO index distance between slots.
    pub slot_pdo_increment: Option<u32>,
    /// `@MaxSlotCount`.
    pub max_slot_count: Option<u32>,
    /// The slots.
    pub slots: Vec<Slot>,
    /// Span of the element.
    pub span: Span,
}

/// One `Slot`.
#[derive(Clone, Debug, Default, PartialEq, Eq, Serialize)]
pub struct Slot {
    /// `Name`.
    pub name: String,
    /// `@MinInstances`.
    pub min_instances: Option<u32>,
    /// `@MaxInstances`.
    pub max_instances: Option<u32>,
    /// `@SlotIndexIncrement` of this slot.
    pub slot_index_increment: Option<u32>,
    /// `@SlotPdoIncrement` of this slot.
    pub slot_pdo_increment: Option<u32>,
    /// `ModuleIdent`s that fit.
    pub module_idents: Vec<u32>,
    /// The `ModuleIdent` marked `Default="1"`.
    pub default_module: Option<u32>,
    /// `ModuleClass`es that fit.
    pub module_classes: Vec<String>,
    /// Span of the element.
    pub span: Span,
}

/// A `Modules/Module`.
#[derive(Clone, Debug, Default, PartialEq, Serialize)]
pub struct EsiModule {
    /// `Type` text.
    pub type_name: String,
    /// `Type@ModuleIdent`.
    pub module_ident: Option<u32>,
    /// `Type@ModuleClass`.
    pub module_class: Option<String>,
    /// `Name` in every language.
    pub names: Vec<LocalizedText>,
    /// The module's PDOs.
    pub pdos: Vec<Pdo>,
    /// ESI-only attributes of the module's PDOs (as [`EtherCat::pdo_attributes`]).
    #[serde(skip_serializing_if = "Vec::is_empty")]
    pub pdo_attributes: Vec<PdoAttributes>,
    /// The module's own dictionary objects (`Profile/Dictionary/Objects`). Shared with
    /// [`crate::Module::fixed_objects`] and with every device of the file the module applies to.
    pub objects: Arc<BTreeMap<u16, Object>>,
    /// `Mailbox/CoE/InitCmd`s.
    pub init_cmds: Vec<InitCmd>,
    /// Indexes (of PDOs, PDO entries, objects) marked `DependOnSlot`: shifted by the slot's
    /// `SlotIndexIncrement`/`SlotPdoIncrement` when the module is plugged in. Sorted, unique.
    pub depend_on_slot: Vec<u16>,
    /// Span of the element.
    pub span: Span,
}

impl SyncManager {
    /// One line for a person: `MBoxOut, start 0x1000, 128 bytes, control 0x26` (what the ESI
    /// gives of it).
    pub fn summary(&self) -> String {
        let mut parts = vec![self.usage.as_str().to_owned()];
        if let Some(a) = &self.start_address {
            parts.push(format!("start 0x{:04X}", a.value));
        }
        if let Some(n) = self.default_size {
            parts.push(format!("{n} bytes"));
        }
        if let Some(c) = &self.control_byte {
            parts.push(format!("control 0x{:02X}", c.value));
        }
        if !self.enable {
            parts.push("disabled".into());
        }
        parts.join(", ")
    }
}

impl Mailbox {
    /// The protocols it offers, CoE with its services: `CoE (SDO info, PDO assign)`, `FoE`, …
    pub fn protocols(&self) -> Vec<String> {
        let mut out = Vec::new();
        if let Some(coe) = &self.coe {
            let services: Vec<&str> = [
                (coe.sdo_info, "SDO info"),
                (coe.pdo_assign, "PDO assign"),
                (coe.pdo_config, "PDO config"),
                (coe.pdo_upload, "PDO upload"),
                (coe.complete_access, "complete access"),
                (coe.segmented_sdo, "segmented SDO"),
            ]
            .into_iter()
            .filter_map(|(on, name)| on.then_some(name))
            .collect();
            out.push(if services.is_empty() {
                "CoE".to_owned()
            } else {
                format!("CoE ({})", services.join(", "))
            });
        }
        for (on, name) in [
            (self.foe, "FoE"),
            (self.eoe, "EoE"),
            (self.soe.is_some(), "SoE"),
            (self.aoe, "AoE"),
            (self.voe, "VoE"),
        ] {
            if on {
                out.push(name.to_owned());
            }
        }
        out
    }
}
