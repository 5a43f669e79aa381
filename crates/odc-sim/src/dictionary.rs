//! [`ModelDictionary`]: the object dictionary of a device file, built at run time from the
//! model, with the semantics of the `slave::Dictionary` odc generates for the same file.

use core::fmt;
use odc::cob::NodeId;

use odc::cia402::{Controlword, DriveObjects, ModeOfOperation, Statusword};
use odc::slave::ObjectDictionary;
use odc::{Access, DataType, ObjValue, ObjectAddr, SdoAbort};
use odc_analysis::RustTy;
use odc_model::Device;

use crate::value::{Slot, slot};

/// One entry: address, access, the typed work of its value, where the value is stored.
struct Row {
    addr: ObjectAddr,
    access: Access,
    /// The file's PDO mapping flag.
    mapping: odc_model::PdoMapping,
    slot: Box<dyn Slot>,
    at: usize,
}

impl Row {
    fn key(&self) -> u32 {
        u32::from(self.addr.index) << 8 | u32::from(self.addr.sub)
    }
}

/// The object dictionary of a device, built from its model when the program runs: what
/// `odc simulate` serves.
///
/// Its entries are those of the generated `slave::Dictionary` of the same file
/// ([`odc_analysis::slave_entries`]), and so are their semantics but for DOMAIN entries (the
/// simulated application keeps their data, [`ModelDictionary::domain`], where firmware's
/// `WriteHook::write_domain` takes it): the values stored in their SDO encoding, initial values from the default with `$NODEID` applied (else zero moved into
/// the limits), SDO reads and writes with the same access, length and limit checks and the
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
    rows: Vec<Row>,
    values: Vec<u8>,
    /// The data last downloaded into each DOMAIN entry (none stored in `values`): the
    /// simulated application keeps it, as firmware would in its `WriteHook::write_domain`,
    /// and a read answers it. At most the SDO server's buffer long
    /// ([`SDO_BUFFER`](crate::SDO_BUFFER)).
    domains: std::collections::BTreeMap<ObjectAddr, Vec<u8>>,
    drive: bool,
}

impl ModelDictionary {
    /// The dictionary of `device` on node `node_id`, every entry at its initial value.
    pub fn new(device: &Device, node_id: impl Into<Option<NodeId>>) -> Self {
        let node_id = node_id.into();
        let mut rows = Vec::new();
        let mut at = 0;
        let mut drive = (false, false);
        for e in odc_analysis::slave_entries(device) {
            let slot = slot(e.sub, e.ty);
            let len = slot.len();
            match (e.index, e.ty) {
                (0x6040, RustTy::Controlword) => drive.0 = true,
                (0x6041, RustTy::Statusword) => drive.1 = true,
                _ => {}
            }
            let addr = ObjectAddr::new(e.index, e.sub.sub_index);
            rows.push(Row {
                addr,
                access: access(e.sub.access),
                mapping: e.sub.pdo_mapping,
                slot,
                at,
            });
            at += len;
        }
        let mut od = ModelDictionary {
            rows,
            values: vec![0; at],
            domains: std::collections::BTreeMap::new(),
            drive: drive.0 && drive.1,
        };
        od.reset(node_id);
        od
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
        for row in self.rows.iter().filter(|r| which(r.addr.index)) {
            if let Some(d) = row.slot.domain_default() {
                self.domains.insert(row.addr, d.to_vec());
            }
            if let Some(stored) = self.values.get_mut(row.at..row.at + row.slot.len()) {
                stored.fill(0);
                row.slot.init(stored, node_id);
            }
        }
    }

    /// The number of entries.
    pub fn len(&self) -> usize {
        self.rows.len()
    }

    /// Whether it has no entry.
    pub fn is_empty(&self) -> bool {
        self.rows.is_empty()
    }

    /// The entries' addresses, access rights and data types, in address order.
    pub fn entries(&self) -> impl Iterator<Item = (ObjectAddr, Access, DataType)> + '_ {
        self.rows.iter().map(|r| (r.addr, r.access, r.slot.data_type()))
    }

    /// Whether the device is a CiA 402 drive this dictionary can run: it has the controlword
    /// 0x6040 and statusword 0x6041 typed as the profile types them (as the generated code
    /// implements [`DriveObjects`] only then).
    pub fn is_drive(&self) -> bool {
        self.drive
    }

    fn row(&self, index: u16, sub: u8) -> Result<&Row, SdoAbort> {
        let key = u32::from(index) << 8 | u32::from(sub);
        match self.rows.binary_search_by_key(&key, Row::key) {
            Ok(pos) => self.rows.get(pos).ok_or(SdoAbort::NoSuchObject),
            Err(pos) => {
                let same = |p: usize| self.rows.get(p).is_some_and(|r| r.addr.index == index);
                if same(pos) || pos.checked_sub(1).is_some_and(same) {
                    Err(SdoAbort::NoSuchSub)
                } else {
                    Err(SdoAbort::NoSuchObject)
                }
            }
        }
    }

    fn stored(&self, row: &Row) -> Result<&[u8], SdoAbort> {
        self.values.get(row.at..row.at + row.slot.len()).ok_or(SdoAbort::General)
    }

    /// The value at `index:sub` as `T`, for the firmware side: no access check.
    ///
    /// # Errors
    ///
    /// No such object or sub-index, or [`SdoAbort::LengthMismatch`] when the entry has
    /// another type.
    pub fn get<T: ObjValue>(&self, index: u16, sub: u8) -> Result<T, SdoAbort> {
        let row = self.typed::<T>(index, sub)?;
        Ok(T::decode(self.stored(row)?)?)
    }

    /// Stores `value` at `index:sub`, for the firmware side: no access or limit check.
    ///
    /// # Errors
    ///
    /// As for [`ModelDictionary::get`], or the encoding error of a time out of range.
    pub fn set<T: ObjValue>(&mut self, index: u16, sub: u8, value: T) -> Result<(), SdoAbort> {
        let row = self.typed::<T>(index, sub)?;
        let (at, len) = (row.at, row.slot.len());
        let stored = self.values.get_mut(at..at + len).ok_or(SdoAbort::General)?;
        stored.fill(0);
        value.encode(stored)?;
        Ok(())
    }

    /// The bytes the entry's value takes in storage (its type's size; a string's capacity).
    pub fn entry_len(&self, index: u16, sub: u8) -> Option<usize> {
        self.row(index, sub).ok().map(|r| r.slot.len())
    }

    /// The data last downloaded into the DOMAIN entry `index:sub` (a program image for
    /// 0x1F50), for the simulated application; `None` before any.
    pub fn domain(&self, index: u16, sub: u8) -> Option<&[u8]> {
        self.domains.get(&ObjectAddr::new(index, sub)).map(Vec::as_slice)
    }

    /// The stored bytes of `index:sub`, for the firmware side (process data): no access
    /// check.
    pub fn raw(&self, index: u16, sub: u8) -> Option<&[u8]> {
        let row = self.row(index, sub).ok()?;
        self.stored(row).ok()
    }

    /// The stored bytes of `index:sub`, to change in place (process data): no access or
    /// limit check.
    pub fn raw_mut(&mut self, index: u16, sub: u8) -> Option<&mut [u8]> {
        let row = self.row(index, sub).ok()?;
        let (at, len) = (row.at, row.slot.len());
        self.values.get_mut(at..at + len)
    }

    fn typed<T: ObjValue>(&self, index: u16, sub: u8) -> Result<&Row, SdoAbort> {
        let row = self.row(index, sub)?;
        if row.slot.data_type() != T::DATA_TYPE || row.slot.len() != T::MAX_LEN {
            return Err(SdoAbort::LengthMismatch);
        }
        Ok(row)
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

/// Copies checked download `data` into the `stored` bytes of its entry, as the generated
/// table does: zero-padded to the capacity, a time without the 4 reserved bits.
fn store(data_type: DataType, data: &[u8], stored: &mut [u8]) {
    let mut src = data.iter().copied();
    for d in stored.iter_mut() {
        *d = src.next().unwrap_or(0);
    }
    if matches!(data_type, DataType::TimeOfDay | DataType::TimeDifference)
        && let Some(ms_high) = stored.get_mut(3)
    {
        *ms_high &= 0x0F;
    }
}

impl ObjectDictionary for ModelDictionary {
    fn read(&self, index: u16, sub: u8, buf: &mut [u8]) -> Result<usize, SdoAbort> {
        let row = self.row(index, sub)?;
        if !row.access.readable() {
            return Err(SdoAbort::ReadOfWriteOnly);
        }
        let stored = match row.slot.data_type() {
            // Empty until a download.
            DataType::Domain => self.domains.get(&row.addr).map_or(&[][..], Vec::as_slice),
            _ => self.stored(row)?,
        };
        let len = match row.slot.data_type() {
            DataType::VisibleString => stored.iter().rposition(|&b| b != 0).map_or(0, |p| p + 1),
            DataType::UnicodeString => {
                let mut end = stored.len() & !1;
                while end >= 2 && stored.get(end - 2..end) == Some(&[0, 0]) {
                    end -= 2;
                }
                end
            }
            _ => stored.len(),
        };
        let (Some(src), Some(dst)) = (stored.get(..len), buf.get_mut(..len)) else {
            return Err(SdoAbort::TooShort);
        };
        dst.copy_from_slice(src);
        Ok(len)
    }

    fn write(&mut self, index: u16, sub: u8, data: &[u8]) -> Result<(), SdoAbort> {
        let row = self.row(index, sub)?;
        if !row.access.writable() {
            return Err(SdoAbort::WriteOfReadOnly);
        }
        row.slot.check(data)?;
        if row.slot.data_type() == DataType::Domain {
            self.domains.insert(row.addr, data.to_vec());
            return Ok(());
        }
        let (at, len, data_type) = (row.at, row.slot.len(), row.slot.data_type());
        let stored = self.values.get_mut(at..at + len).ok_or(SdoAbort::General)?;
        store(data_type, data, stored);
        Ok(())
    }

    fn access(&self, index: u16, sub: u8) -> Option<odc::Access> {
        self.row(index, sub).ok().map(|row| row.access)
    }

    /// As the generated table answers: the file's flag and the access's direction.
    fn pdo_mappable(&self, index: u16, sub: u8, tx: bool) -> Result<u32, SdoAbort> {
        let row = self.row(index, sub)?;
        let allowed = if tx { row.access.tpdo_allowed() } else { row.access.rpdo_allowed() };
        if !row.mapping.is_mappable() || !allowed {
            return Err(SdoAbort::NotMappable);
        }
        Ok(u32::try_from(row.slot.len() * 8).unwrap_or(u32::MAX))
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
        f.debug_map()
            .entries(self.rows.iter().map(|r| {
                let bytes = self.stored(r).unwrap_or(&[]);
                (r.addr.to_string(), bytes)
            }))
            .finish()
    }
}
