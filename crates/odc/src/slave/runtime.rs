//! A dictionary table built when the program runs (feature `alloc`): the same rows, checks and
//! storage layout as the `const` [`Table`](super::Table) of generated code, made from a device
//! file loaded at run time (the simulator serves any file this way, without a build step).
//!
//! The rows own their typed work ([`Spec<T>`] of any fixed-size type, or a string or octet
//! string whose size is known only at run time); reads, writes and initial values go through
//! the one path the generated tables use.

use alloc::boxed::Box;
use alloc::vec;
use alloc::vec::Vec;
use core::fmt;

use super::key as row_key;
use super::table::{MAPPABLE, RowLike, Rows, Slot};
use super::{EntryMeta, ObjectDictionary, Storage, WriteHook};
use crate::cob::NodeId;
use crate::{Access, DataType, Entry, ObjValue, ObjectAddr, SdoAbort, ValueError};

/// A row that owns its slot.
struct OwnedRow {
    slot: Box<dyn Slot + Send>,
    key: u32,
    at: usize,
}

impl RowLike for OwnedRow {
    fn packed(&self) -> u32 {
        self.key
    }
    fn at(&self) -> usize {
        self.at
    }
    fn slot(&self) -> &dyn Slot {
        &*self.slot
    }
}

/// Collects the entries of a [`RuntimeTable`] in any order.
#[derive(Default)]
pub struct TableBuilder {
    rows: Vec<OwnedRow>,
}

impl fmt::Debug for TableBuilder {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.debug_struct("TableBuilder").field("rows", &self.rows.len()).finish()
    }
}

fn packed(addr: ObjectAddr, access: Access, mappable: bool) -> u32 {
    let flag = if mappable { MAPPABLE } else { 0 };
    row_key(addr.index, addr.sub) | (access as u32) << 24 | flag
}

/// `v` zero-padded to `capacity` bytes, when it fits (a string's stored form).
fn padded(v: Option<&[u8]>, capacity: usize) -> Option<Vec<u8>> {
    v.filter(|v| v.len() <= capacity).map(|v| {
        let mut padded = v.to_vec();
        padded.resize(capacity, 0);
        padded
    })
}

impl TableBuilder {
    /// An empty table.
    pub fn new() -> Self {
        Self::default()
    }

    /// Adds the entry `entry` (its address, access, limits and default); a later entry at the
    /// same address replaces it.
    pub fn push<T>(&mut self, entry: &Entry<T>) -> &mut Self
    where
        T: ObjValue + PartialOrd + Send + Sync + 'static,
    {
        self.push_slot(entry.addr, entry.access, entry.pdo_mappable, entry.spec())
    }

    /// Adds a row of `slot` at `addr`; its place among the values is laid out by `build`.
    fn push_slot(
        &mut self,
        addr: ObjectAddr,
        access: Access,
        mappable: bool,
        slot: impl Slot + Send + 'static,
    ) -> &mut Self {
        let key = packed(addr, access, mappable);
        self.rows.push(OwnedRow { slot: Box::new(slot), key, at: 0 });
        self
    }

    /// Adds a VISIBLE_STRING of at most `capacity` bytes (as `VisibleString<capacity>`):
    /// `default`, `low` and `high` are its default and limits, each at most `capacity` bytes
    /// (longer ones are not used); `mappable` when the file allows mapping it into PDOs.
    #[allow(clippy::too_many_arguments)]
    pub fn push_text(
        &mut self,
        addr: ObjectAddr,
        access: Access,
        mappable: bool,
        capacity: usize,
        default: Option<&[u8]>,
        limits: (Option<&[u8]>, Option<&[u8]>),
    ) -> &mut Self {
        let fit = |v: Option<&[u8]>| padded(v, capacity);
        let slot = Bytes {
            kind: Kind::Text,
            len: capacity,
            default: fit(default),
            low: fit(limits.0),
            high: fit(limits.1),
        };
        self.push_slot(addr, access, mappable, slot)
    }

    /// Adds an OCTET_STRING of exactly `len` bytes (as `OctetString<len>`), with its default
    /// and limits (those of another length are not used); `mappable` as for
    /// [`TableBuilder::push_text`].
    #[allow(clippy::too_many_arguments)]
    pub fn push_octets(
        &mut self,
        addr: ObjectAddr,
        access: Access,
        mappable: bool,
        len: usize,
        default: Option<&[u8]>,
        limits: (Option<&[u8]>, Option<&[u8]>),
    ) -> &mut Self {
        let fit = |v: Option<&[u8]>| v.filter(|v| v.len() == len).map(<[u8]>::to_vec);
        let slot = Bytes {
            kind: Kind::Octets,
            len,
            default: fit(default),
            low: fit(limits.0),
            high: fit(limits.1),
        };
        self.push_slot(addr, access, mappable, slot)
    }

    /// Adds a UNICODE_STRING of at most `capacity` bytes (as `UnicodeString<N>` with
    /// `capacity / 2` code units) with its default, the UTF-16LE bytes (a longer one is not
    /// used); `mappable` as for [`TableBuilder::push_text`].
    pub fn push_unicode(
        &mut self,
        addr: ObjectAddr,
        access: Access,
        mappable: bool,
        capacity: usize,
        default: Option<&[u8]>,
    ) -> &mut Self {
        let default = padded(default, capacity);
        let slot = Bytes { kind: Kind::Unicode, len: capacity, default, low: None, high: None };
        self.push_slot(addr, access, mappable, slot)
    }

    /// Adds a DOMAIN: any bytes, none stored (the shared path hands a download to
    /// [`WriteHook::write_domain`] and answers an upload [`SdoAbort::NoData`], as a generated
    /// table does).
    pub fn push_domain(&mut self, addr: ObjectAddr, access: Access, mappable: bool) -> &mut Self {
        let slot = Bytes { kind: Kind::Domain, len: 0, default: None, low: None, high: None };
        self.push_slot(addr, access, mappable, slot)
    }

    /// The table: rows sorted by address (the last of equal addresses kept), values laid out
    /// one after the other in that order.
    pub fn build(mut self) -> RuntimeTable {
        self.rows.sort_by_key(|r| r.key & 0xFF_FFFF);
        // Of rows with equal addresses, the last pushed (stable sort keeps push order).
        let mut rows: Vec<OwnedRow> = Vec::with_capacity(self.rows.len());
        for row in self.rows {
            match rows.last_mut() {
                Some(last) if last.key & 0xFF_FFFF == row.key & 0xFF_FFFF => *last = row,
                _ => rows.push(row),
            }
        }
        let mut at = 0;
        for row in &mut rows {
            row.at = at;
            at += row.slot.len();
        }
        RuntimeTable { rows, size: at }
    }
}

/// The types of [`Bytes`].
#[derive(Clone, Copy, PartialEq, Eq)]
enum Kind {
    Text,
    Octets,
    Unicode,
    Domain,
}

/// A VISIBLE_STRING, OCTET_STRING, UNICODE_STRING or DOMAIN whose size is known at run time;
/// limits compare as the runtime's `VisibleString<N>` and `OctetString<N>` order: the bytes, a
/// string zero-padded to its capacity.
struct Bytes {
    kind: Kind,
    len: usize,
    default: Option<Vec<u8>>,
    low: Option<Vec<u8>>,
    high: Option<Vec<u8>>,
}

impl Slot for Bytes {
    fn check(&self, data: &[u8]) -> Result<(), SdoAbort> {
        match self.kind {
            Kind::Domain => return Ok(()),
            Kind::Unicode => {
                // As `UnicodeString::<N>::decode`: whole code units, zero units at the end pad.
                if data.len() & 1 != 0 {
                    return Err(ValueError::Invalid.into());
                }
                if crate::value::unicode_len(data) > self.len {
                    return Err(ValueError::TooLong.into());
                }
                return Ok(());
            }
            Kind::Text | Kind::Octets => {}
        }
        if self.kind == Kind::Octets {
            return match data.len() {
                n if n < self.len => Err(ValueError::TooShort.into()),
                n if n > self.len => Err(ValueError::TooLong.into()),
                _ => crate::check_range(
                    &data,
                    self.low.as_deref().as_ref(),
                    self.high.as_deref().as_ref(),
                ),
            };
        }
        // As `VisibleString::<N>::decode`: zeros at the end pad, the rest is visible ASCII.
        let end = data.iter().rposition(|&b| b != 0).map_or(0, |p| p + 1);
        let text = data.get(..end).unwrap_or(&[]);
        if text.len() > self.len {
            return Err(ValueError::TooLong.into());
        }
        if !text.iter().all(|b| (0x20..=0x7E).contains(b)) {
            return Err(ValueError::Invalid.into());
        }
        let mut padded = text.to_vec();
        padded.resize(self.len, 0);
        crate::check_range(&padded, self.low.as_ref(), self.high.as_ref())
    }

    fn init(&self, stored: &mut [u8], _: Option<NodeId>) {
        if let Some(d) = &self.default {
            for (s, d) in stored.iter_mut().zip(d) {
                *s = *d;
            }
        }
    }

    fn len(&self) -> usize {
        self.len
    }

    fn data_type(&self) -> DataType {
        match self.kind {
            Kind::Text => DataType::VisibleString,
            Kind::Octets => DataType::OctetString,
            Kind::Unicode => DataType::UnicodeString,
            Kind::Domain => DataType::Domain,
        }
    }
}

/// A table built at run time: what [`Table`](super::Table) is for generated code, with the
/// same methods.
pub struct RuntimeTable {
    rows: Vec<OwnedRow>,
    size: usize,
}

impl fmt::Debug for RuntimeTable {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.debug_struct("RuntimeTable")
            .field("rows", &self.rows.len())
            .field("size", &self.size)
            .finish()
    }
}

impl RuntimeTable {
    /// The size of the storage in bytes.
    pub fn size(&self) -> usize {
        self.size
    }

    /// The number of entries.
    pub fn len(&self) -> usize {
        self.rows.len()
    }

    /// Whether the table has no entry.
    pub fn is_empty(&self) -> bool {
        self.rows.is_empty()
    }

    /// The entries in address order.
    pub fn entries(&self) -> impl Iterator<Item = EntryMeta> + '_ {
        (0..self.rows.len()).filter_map(|p| Rows(self.rows.as_slice()).entry_at(p))
    }

    /// As [`Table::init`](super::Table::init).
    pub fn init(&self, values: &mut [u8], node_id: Option<NodeId>) {
        Rows(self.rows.as_slice()).init(values, node_id);
    }
}

/// A [`RuntimeTable`] with its values: the run-time counterpart of a generated `Dictionary`.
pub struct RuntimeDictionary {
    table: RuntimeTable,
    values: Vec<u8>,
}

impl RuntimeDictionary {
    /// The dictionary of `table` on node `node_id`, every entry at its initial value.
    pub fn new(table: RuntimeTable, node_id: Option<NodeId>) -> Self {
        let mut values = vec![0; table.size];
        table.init(&mut values, node_id);
        Self { table, values }
    }

    /// The table.
    pub fn table(&self) -> &RuntimeTable {
        &self.table
    }

    /// The entries whose index `which` accepts back to their initial values on node
    /// `node_id` (all of them: NMT reset node; 0x1000–0x1FFF: reset communication).
    pub fn reset_where(&mut self, node_id: Option<NodeId>, which: impl Fn(u16) -> bool) {
        for row in self.table.rows.iter().filter(|r| which(r.addr().index)) {
            if let Ok(stored) = row.of_mut(&mut self.values) {
                stored.fill(0);
                row.slot().init(stored, node_id);
            }
        }
    }

    /// The value at `index:sub` as `T`, for the firmware side: no access check.
    ///
    /// # Errors
    ///
    /// No such object or sub-index, or [`SdoAbort::LengthMismatch`] for another type.
    pub fn get<T: ObjValue>(&self, index: u16, sub: u8) -> Result<T, SdoAbort> {
        Rows(self.table.rows.as_slice()).get(&self.values, index, sub)
    }

    /// Stores `value` at `index:sub`, for the firmware side: no access or limit check.
    ///
    /// # Errors
    ///
    /// As for [`RuntimeDictionary::get`], or the encoding error of a time out of range.
    pub fn set<T: ObjValue>(&mut self, index: u16, sub: u8, value: T) -> Result<(), SdoAbort> {
        Rows(self.table.rows.as_slice()).set(&mut self.values, index, sub, value)
    }

    /// SDO download of `data` into `index:sub`, telling `hook` before and after.
    ///
    /// # Errors
    ///
    /// As [`Table::write`](super::Table::write).
    pub fn write_with(
        &mut self,
        index: u16,
        sub: u8,
        data: &[u8],
        hook: &mut dyn WriteHook,
    ) -> Result<(), SdoAbort> {
        Rows(self.table.rows.as_slice()).write(&mut self.values, index, sub, data, hook)
    }
}

impl ObjectDictionary for RuntimeDictionary {
    fn read(&self, index: u16, sub: u8, buf: &mut [u8]) -> Result<usize, SdoAbort> {
        Rows(self.table.rows.as_slice()).read(&self.values, index, sub, buf)
    }
    fn write(&mut self, index: u16, sub: u8, data: &[u8]) -> Result<(), SdoAbort> {
        self.write_with(index, sub, data, &mut ())
    }
    fn access(&self, index: u16, sub: u8) -> Option<Access> {
        Rows(self.table.rows.as_slice()).access(index, sub)
    }
    fn pdo_mappable(&self, index: u16, sub: u8, tx: bool) -> Result<u32, SdoAbort> {
        Rows(self.table.rows.as_slice()).pdo_mappable(index, sub, tx)
    }
}

impl Storage for RuntimeDictionary {
    fn raw(&self, index: u16, sub: u8) -> Option<&[u8]> {
        Rows(self.table.rows.as_slice()).raw(&self.values, index, sub)
    }
    fn raw_mut(&mut self, index: u16, sub: u8) -> Option<&mut [u8]> {
        Rows(self.table.rows.as_slice()).raw_mut(&mut self.values, index, sub)
    }
    fn entry_at(&self, pos: usize) -> Option<EntryMeta> {
        Rows(self.table.rows.as_slice()).entry_at(pos)
    }
    fn position(&self, index: u16, sub: u8) -> usize {
        Rows(self.table.rows.as_slice()).position(index, sub)
    }
}

impl fmt::Debug for RuntimeDictionary {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        Rows(self.table.rows.as_slice()).fmt_values(&self.values, f)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::VisibleString;

    /// The run-time table answers as the `const` one does for the same entries.
    #[test]
    fn same_answers_as_a_const_table() {
        const HB: Entry<u16> = Entry::new(0x1017, 0, "Producer heartbeat", Access::Rw, false)
            .with_limits(Some(10), Some(1000));
        const TYPE: Entry<u32> = Entry::new(0x1000, 0, "Device type", Access::Ro, false)
            .with_default(crate::DefaultValue::Value(0x0402_0192));
        const NAME: Entry<VisibleString<8>> = Entry::new(0x1008, 0, "Name", Access::Ro, false);
        static TABLE: super::super::Table<3> = super::super::Table::new([
            crate::slave::row!(TYPE),
            crate::slave::row!(NAME),
            crate::slave::row!(HB),
        ]);
        let mut b = TableBuilder::new();
        b.push(&HB).push(&TYPE);
        b.push_text(ObjectAddr::new(0x1008, 0), Access::Ro, false, 8, Some(b"odc"), (None, None));
        let mut rt = RuntimeDictionary::new(b.build(), None);
        let mut values = [0u8; 14];
        assert_eq!(TABLE.size(), 14);
        assert_eq!(rt.table().size(), 14);
        TABLE.init(&mut values, None);
        let (mut a, mut c) = ([0u8; 8], [0u8; 8]);
        for (i, s) in [(0x1000, 0), (0x1008, 0), (0x1017, 0), (0x1017, 1), (0x1018, 0)] {
            let ours = rt.read(i, s, &mut a).map(|n| a[..n].to_vec());
            let theirs = TABLE.read(&values, i, s, &mut c).map(|n| c[..n].to_vec());
            if (i, s) != (0x1008, 0) {
                assert_eq!(ours, theirs, "{i:04X}:{s}");
            }
        }
        assert_eq!(rt.read(0x1008, 0, &mut a), Ok(3));
        assert_eq!(&a[..3], b"odc");
        assert_eq!(rt.read(0x1000, 0, &mut a), Ok(4));
        assert_eq!(a[..4], [0x92, 0x01, 0x02, 0x04]);
        assert_eq!(rt.write(0x1017, 0, &5u16.to_le_bytes()), Err(SdoAbort::ValueTooLow));
        assert_eq!(rt.write(0x1017, 1, &5u16.to_le_bytes()), Err(SdoAbort::NoSuchSub));
        assert_eq!(rt.write(0x1000, 0, &5u32.to_le_bytes()), Err(SdoAbort::WriteOfReadOnly));
        assert_eq!(rt.write(0x1017, 0, &500u16.to_le_bytes()), Ok(()));
        assert_eq!(rt.get::<u16>(0x1017, 0), Ok(500));
        assert_eq!(rt.get::<u32>(0x1017, 0), Err(SdoAbort::LengthMismatch));
        assert_eq!(rt.raw(0x1017, 0), Some(&[0xF4, 0x01][..]));
        assert_eq!(rt.position(0x1008, 1), 2);
        assert_eq!(rt.entry_at(1).map(|e| (e.addr, e.len)), Some((ObjectAddr::new(0x1008, 0), 8)));
    }

    #[test]
    fn strings_of_run_time_size() {
        let mut b = TableBuilder::new();
        let addr = ObjectAddr::new(0x2000, 0);
        b.push_text(addr, Access::Rw, false, 4, None, (Some(b"B"), Some(b"M")));
        b.push_octets(
            ObjectAddr::new(0x2001, 0),
            Access::Rw,
            false,
            2,
            Some(&[1, 2]),
            (None, None),
        );
        let mut d = RuntimeDictionary::new(b.build(), None);
        assert_eq!(d.write(0x2000, 0, b"A"), Err(SdoAbort::ValueTooLow));
        assert_eq!(d.write(0x2000, 0, b"Z"), Err(SdoAbort::ValueTooHigh));
        assert_eq!(d.write(0x2000, 0, b"ABCDE"), Err(SdoAbort::TooLong));
        assert_eq!(d.write(0x2000, 0, b"C"), Ok(()));
        assert_eq!(d.raw(0x2001, 0), Some(&[1, 2][..]));
        assert_eq!(d.write(0x2001, 0, &[1]), Err(SdoAbort::TooShort));
    }

    /// The file's mapping flag and the access's direction, as `Table::pdo_mappable` answers.
    #[test]
    fn mapping_flag_from_the_entry() {
        let cw: Entry<u16> = Entry::new(0x6040, 0, "Controlword", Access::Rww, true);
        let sw: Entry<u16> = Entry::new(0x6041, 0, "Statusword", Access::Ro, true);
        let hb: Entry<u16> = Entry::new(0x1017, 0, "Producer heartbeat", Access::Rw, false);
        let mut b = TableBuilder::new();
        b.push(&cw).push(&sw).push(&hb);
        b.push_octets(ObjectAddr::new(0x2001, 0), Access::Rw, true, 3, None, (None, None));
        let d = RuntimeDictionary::new(b.build(), None);
        assert_eq!(d.pdo_mappable(0x6040, 0, false), Ok(16));
        assert_eq!(d.pdo_mappable(0x6040, 0, true), Err(SdoAbort::NotMappable));
        assert_eq!(d.pdo_mappable(0x6041, 0, true), Ok(16));
        assert_eq!(d.pdo_mappable(0x6041, 0, false), Err(SdoAbort::NotMappable));
        assert_eq!(d.pdo_mappable(0x1017, 0, true), Err(SdoAbort::NotMappable));
        assert_eq!(d.pdo_mappable(0x2001, 0, false), Ok(24));
        assert_eq!(d.pdo_mappable(0x6042, 0, true), Err(SdoAbort::NoSuchObject));
        // The flag in bit 31 leaves the access code (bits 24-26) as it was.
        assert_eq!(d.access(0x6040, 0), Some(Access::Rww));
        assert_eq!(d.access(0x6041, 0), Some(Access::Ro));
    }

    /// UNICODE_STRING reads without its zero padding; a DOMAIN stores nothing, hands a
    /// download to the hook and answers an upload `NoData`, as a generated table does.
    #[test]
    fn unicode_and_domain() {
        struct Keep(Vec<u8>);
        impl WriteHook for Keep {
            fn write_domain(&mut self, _: ObjectAddr, data: &[u8]) -> Result<(), SdoAbort> {
                self.0 = data.to_vec();
                Ok(())
            }
        }
        let mut b = TableBuilder::new();
        b.push_unicode(ObjectAddr::new(0x2000, 0), Access::Rw, false, 6, Some(&[0x41, 0]));
        b.push_domain(ObjectAddr::new(0x1F50, 1), Access::Rw, false);
        let mut d = RuntimeDictionary::new(b.build(), None);
        assert_eq!(d.table().size(), 6);
        let mut buf = [0u8; 8];
        assert_eq!(d.read(0x2000, 0, &mut buf), Ok(2));
        assert_eq!(buf[..2], [0x41, 0]);
        assert_eq!(d.write(0x2000, 0, &[0x41, 0, 0x62]), Err(SdoAbort::InvalidValue));
        assert_eq!(d.write(0x2000, 0, &[1, 0, 2, 0, 3, 0, 4, 0]), Err(SdoAbort::TooLong));
        assert_eq!(d.write(0x2000, 0, &[0x62, 0, 0x63, 0, 0, 0]), Ok(()));
        assert_eq!(d.read(0x2000, 0, &mut buf), Ok(4));
        assert_eq!(buf[..4], [0x62, 0, 0x63, 0]);
        assert_eq!(d.read(0x1F50, 1, &mut buf), Err(SdoAbort::NoData));
        assert_eq!(d.write(0x1F50, 1, &[1, 2, 3]), Err(SdoAbort::DataTransfer));
        let mut keep = Keep(Vec::new());
        assert_eq!(d.write_with(0x1F50, 1, &[1, 2, 3, 4, 5, 6, 7, 8, 9], &mut keep), Ok(()));
        assert_eq!(keep.0, [1, 2, 3, 4, 5, 6, 7, 8, 9]);
    }
}
