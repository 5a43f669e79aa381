//! [`ModelDictionary`]: the object dictionary of a device file, built at run time from the
//! model into the runtime's own table ([`odc::slave::RuntimeTable`]), so that its semantics
//! are those of the `slave::Dictionary` odc generates for the same file: the same code.

use core::fmt;
use odc::cob::NodeId;
use std::collections::BTreeMap;

use odc::cia402::{Controlword, DriveObjects, ModeOfOperation, Statusword};
use odc::slave::{ObjectDictionary, RuntimeDictionary, Storage, TableBuilder, WriteHook};
use odc::{Access, DataType, ObjValue, ObjectAddr, SdoAbort};
use odc_analysis::RustTy;
use odc_model::Device;

/// The object dictionary of a device, built from its model when the program runs: what
/// `odc simulate` serves.
///
/// Its entries are those of the generated `slave::Dictionary` of the same file
/// ([`odc_analysis::slave_entries`]), and so are their semantics but for DOMAIN entries (the
/// simulated application keeps their data, [`ModelDictionary::domain`], where firmware's
/// `WriteHook::write_domain` takes it): the values stored in their SDO encoding, initial
/// values from the default with `$NODEID` applied (else zero moved into the limits), SDO reads and writes with the same access, length and limit checks and the
/// same abort codes. The crate's tests compare the two entry by entry for every CANopen file
/// of `eds/`.
///
/// ```
/// use odc::slave::ObjectDictionary;
/// use odc_model::{Access, DataType, Device, Object, ObjectKind, Span, Spanned, SubObject, Value};
///
/// // 0x1017 producer heartbeat time, UNSIGNED16 rw, default 1000 (as a device file says).
/// let mut device = Device::default();
/// let mut sub = SubObject::new(0, "Producer heartbeat time", DataType::Unsigned16, Access::Rw);
/// sub.default = Some(Spanned::new(Value::Unsigned(1000), Span::DUMMY));
/// let mut object = Object::new(0x1017, "Producer heartbeat time", ObjectKind::Var, Span::DUMMY);
/// object.subs.insert(0, sub);
/// device.objects.insert(0x1017, object);
///
/// let mut od = odc_sim::ModelDictionary::new(&device, odc::node_id!(5));
/// let mut buf = [0u8; 2];
/// assert_eq!(od.read(0x1017, 0, &mut buf), Ok(2));
/// assert_eq!(u16::from_le_bytes(buf), 1000);
/// od.write(0x1017, 0, &500u16.to_le_bytes())?;
/// assert_eq!(od.read(0x1018, 0, &mut buf), Err(odc::SdoAbort::NoSuchObject));
/// # Ok::<(), odc::SdoAbort>(())
/// ```
pub struct ModelDictionary {
    od: RuntimeDictionary,
    /// The data last downloaded into each DOMAIN entry (the table stores none): the
    /// simulated application keeps it, as firmware would in its `WriteHook::write_domain`,
    /// and a read answers it. At most the SDO server's buffer long
    /// ([`SDO_BUFFER`](crate::SDO_BUFFER)).
    domains: BTreeMap<ObjectAddr, Vec<u8>>,
    /// The file's default of each DOMAIN entry that has one (CiA 306 hex bytes): its data
    /// after a reset.
    domain_defaults: BTreeMap<ObjectAddr, Vec<u8>>,
    drive: bool,
}

impl ModelDictionary {
    /// The dictionary of `device` on node `node_id`, every entry at its initial value.
    pub fn new(device: &Device, node_id: impl Into<Option<NodeId>>) -> Self {
        let mut table = TableBuilder::new();
        let mut domain_defaults = BTreeMap::new();
        let mut drive = (false, false);
        for e in odc_analysis::slave_entries(device) {
            match (e.index, e.ty) {
                (0x6040, RustTy::Controlword) => drive.0 = true,
                (0x6041, RustTy::Statusword) => drive.1 = true,
                _ => {}
            }
            let addr = ObjectAddr::new(e.index, e.sub.sub_index);
            if e.ty == RustTy::Domain
                && let Some(d) = e.sub.initial_value()
                && let Some(bytes) = odc_model::wire::encode(&d.value, odc_model::DataType::Domain)
            {
                domain_defaults.insert(addr, bytes);
            }
            crate::value::push(&mut table, addr, access(e.sub.access), e.sub, e.ty);
        }
        let od = RuntimeDictionary::new(table.build(), node_id.into());
        let domains = domain_defaults.clone();
        ModelDictionary { od, domains, domain_defaults, drive: drive.0 && drive.1 }
    }

    /// Every entry back to its initial value on node `node_id` (NMT reset node).
    pub fn reset(&mut self, node_id: Option<NodeId>) {
        self.reset_where(node_id, |_| true);
    }

    /// The communication profile area 0x1000–0x1FFF back to its initial values (NMT reset
    /// communication, CiA 301 §7.3.2.2.1); the application's values stay.
    pub fn reset_communication(&mut self, node_id: Option<NodeId>) {
        self.reset_where(node_id, |index| (0x1000..=0x1FFF).contains(&index));
    }

    fn reset_where(&mut self, node_id: Option<NodeId>, which: impl Fn(u16) -> bool) {
        self.domains.retain(|addr, _| !which(addr.index));
        for (addr, data) in self.domain_defaults.iter().filter(|(a, _)| which(a.index)) {
            self.domains.insert(*addr, data.clone());
        }
        self.od.reset_where(node_id, which);
    }

    /// The number of entries.
    pub fn len(&self) -> usize {
        self.od.table().len()
    }

    /// Whether it has no entry.
    pub fn is_empty(&self) -> bool {
        self.od.table().is_empty()
    }

    /// The entries' addresses, access rights and data types, in address order.
    pub fn entries(&self) -> impl Iterator<Item = (ObjectAddr, Access, DataType)> + '_ {
        self.od.table().entries().map(|e| (e.addr, e.access, e.data_type))
    }

    /// Whether the device is a CiA 402 drive this dictionary can run: it has the controlword
    /// 0x6040 and statusword 0x6041 typed as the profile types them (as the generated code
    /// implements [`DriveObjects`] only then).
    pub fn is_drive(&self) -> bool {
        self.drive
    }

    /// The value at `index:sub` as `T`, for the firmware side: no access check.
    ///
    /// # Errors
    ///
    /// No such object or sub-index, or [`SdoAbort::LengthMismatch`] when the entry has
    /// another type.
    pub fn get<T: ObjValue>(&self, index: u16, sub: u8) -> Result<T, SdoAbort> {
        self.od.get(index, sub)
    }

    /// Stores `value` at `index:sub`, for the firmware side: no access or limit check.
    ///
    /// # Errors
    ///
    /// As for [`ModelDictionary::get`], or the encoding error of a time out of range.
    pub fn set<T: ObjValue>(&mut self, index: u16, sub: u8, value: T) -> Result<(), SdoAbort> {
        self.od.set(index, sub, value)
    }

    /// The bytes the entry's value takes in storage (its type's size; a string's capacity).
    pub fn entry_len(&self, index: u16, sub: u8) -> Option<usize> {
        self.od.raw(index, sub).map(<[u8]>::len)
    }

    /// The data last downloaded into the DOMAIN entry `index:sub` (a program image for
    /// 0x1F50), for the simulated application; `None` before any.
    pub fn domain(&self, index: u16, sub: u8) -> Option<&[u8]> {
        self.domains.get(&ObjectAddr::new(index, sub)).map(Vec::as_slice)
    }

    /// The stored bytes of `index:sub`, for the firmware side (process data): no access
    /// check.
    pub fn raw(&self, index: u16, sub: u8) -> Option<&[u8]> {
        self.od.raw(index, sub)
    }

    /// The stored bytes of `index:sub`, to change in place (process data): no access or
    /// limit check.
    pub fn raw_mut(&mut self, index: u16, sub: u8) -> Option<&mut [u8]> {
        self.od.raw_mut(index, sub)
    }
}

fn access(a: odc_model::Access) -> Access {
    match a {
        odc_model::Access::Ro => Access::Ro,
        odc_model::Access::Wo => Access::Wo,
        odc_model::Access::Rw => Access::Rw,
        odc_model::Access::Rwr => Access::Rwr,
        odc_model::Access::Rww => Access::Rww,
        odc_model::Access::Const => Access::Const,
    }
}

impl ObjectDictionary for ModelDictionary {
    fn read(&self, index: u16, sub: u8, buf: &mut [u8]) -> Result<usize, SdoAbort> {
        match self.od.read(index, sub, buf) {
            // A DOMAIN (the table keeps no data of one, the shared path answers `NoData`):
            // what was last downloaded, empty until a download.
            Err(SdoAbort::NoData) => {
                let data =
                    self.domains.get(&ObjectAddr::new(index, sub)).map_or(&[][..], Vec::as_slice);
                let dst = buf.get_mut(..data.len()).ok_or(SdoAbort::TooShort)?;
                dst.copy_from_slice(data);
                Ok(data.len())
            }
            other => other,
        }
    }

    fn write(&mut self, index: u16, sub: u8, data: &[u8]) -> Result<(), SdoAbort> {
        self.od.write_with(index, sub, data, &mut KeepDomains(&mut self.domains))
    }

    fn access(&self, index: u16, sub: u8) -> Option<odc::Access> {
        self.od.access(index, sub)
    }

    /// As the generated table answers: the file's flag and the access's direction.
    fn pdo_mappable(&self, index: u16, sub: u8, tx: bool) -> Result<u32, SdoAbort> {
        self.od.pdo_mappable(index, sub, tx)
    }
}

/// The simulated application's [`WriteHook`]: keeps the data of DOMAIN downloads.
struct KeepDomains<'a>(&'a mut BTreeMap<ObjectAddr, Vec<u8>>);

impl WriteHook for KeepDomains<'_> {
    fn write_domain(&mut self, addr: ObjectAddr, data: &[u8]) -> Result<(), SdoAbort> {
        self.0.insert(addr, data.to_vec());
        Ok(())
    }
}

impl Storage for ModelDictionary {
    fn raw(&self, index: u16, sub: u8) -> Option<&[u8]> {
        self.od.raw(index, sub)
    }
    fn raw_mut(&mut self, index: u16, sub: u8) -> Option<&mut [u8]> {
        self.od.raw_mut(index, sub)
    }
    fn entry_at(&self, pos: usize) -> Option<odc::slave::EntryMeta> {
        self.od.entry_at(pos)
    }
    fn position(&self, index: u16, sub: u8) -> usize {
        self.od.position(index, sub)
    }
}

/// The 402 objects by their profile addresses and types; an object the file lacks, or types
/// otherwise, reads as absent and is not set (as the generated implementation leaves it out).
impl DriveObjects for ModelDictionary {
    fn controlword(&self) -> Controlword {
        Controlword(self.get(0x6040, 0).unwrap_or_default())
    }
    fn set_statusword(&mut self, statusword: Statusword) {
        let _ = self.set(0x6041, 0, statusword.bits());
    }
    fn modes_of_operation(&self) -> Option<ModeOfOperation> {
        self.get::<i8>(0x6060, 0).ok().map(ModeOfOperation::from_i8)
    }
    fn set_modes_of_operation_display(&mut self, mode: ModeOfOperation) {
        let _ = self.set(0x6061, 0, mode.to_i8());
    }
    fn target_position(&self) -> Option<i32> {
        self.get(0x607A, 0).ok()
    }
    fn target_velocity(&self) -> Option<i32> {
        self.get(0x60FF, 0).ok()
    }
    fn profile_velocity(&self) -> Option<u32> {
        self.get(0x6081, 0).ok()
    }
    fn set_position_actual_value(&mut self, position: i32) {
        let _ = self.set(0x6064, 0, position);
    }
    fn set_velocity_actual_value(&mut self, velocity: i32) {
        let _ = self.set(0x606C, 0, velocity);
    }
    fn homing_method(&self) -> Option<i8> {
        self.get(0x6098, 0).ok()
    }
    fn homing_speed(&self) -> Option<u32> {
        self.get(0x6099, 1).ok()
    }
    fn home_offset(&self) -> Option<i32> {
        self.get(0x607C, 0).ok()
    }
    fn target_torque(&self) -> Option<i16> {
        self.get(0x6071, 0).ok()
    }
    fn set_torque_actual_value(&mut self, torque: i16) {
        let _ = self.set(0x6077, 0, torque);
    }
}

impl fmt::Debug for ModelDictionary {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        fmt::Debug::fmt(&self.od, f)
    }
}
