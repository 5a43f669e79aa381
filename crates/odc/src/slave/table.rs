//! The table of a generated dictionary and the one read and write path that serves every
//! entry of it.

use core::fmt;

use super::{WriteHook, initial_value, key, search};
use crate::cob::NodeId;
use crate::{Access, DataType, DefaultValue, Entry, ObjValue, ObjectAddr, SdoAbort};

/// What the dictionary needs of an entry's value beyond its address and access: the limits
/// and the default of its descriptor, typed, without its name. [`Entry::spec`] makes it, and
/// the [`row!`](crate::slave::row) of generated code keeps it in a promoted `static`, where
/// entries with the same type, limits and default share one copy.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Spec<T> {
    low: Option<T>,
    high: Option<T>,
    default: Option<DefaultValue<T>>,
}

impl<T: ObjValue> Entry<T> {
    /// The limits and default of the entry, for its [`Row`].
    pub const fn spec(&self) -> Spec<T> {
        Spec { low: self.low, high: self.high, default: self.default }
    }
}

/// What the shared paths need of one entry's value type, implemented once per type (for
/// [`Spec<T>`]): the typed work of an SDO download and of the initial value.
///
/// Private: a [`Row`] is made only from an `Entry`, so every stored value went through the
/// entry's type. Every method of a trait object is linked with it: it has only what needs the
/// type (an upload copies the stored encoding, see [`Table::read`]; no name, no formatting).
pub(super) trait Slot: Sync {
    /// Decodes `data` as a value of the type and checks it against the limits.
    fn check(&self, data: &[u8]) -> Result<(), SdoAbort>;
    /// Stores the initial value on node `node_id` into zeroed `stored`.
    fn init(&self, stored: &mut [u8], node_id: Option<NodeId>);
    /// The encoded size of the type: the bytes the value takes in the storage.
    fn len(&self) -> usize;
    /// The CiA 301 data type.
    fn data_type(&self) -> DataType;
}

impl<T> Slot for Spec<T>
where
    T: ObjValue + PartialOrd + Sync + 'static,
{
    fn check(&self, data: &[u8]) -> Result<(), SdoAbort> {
        crate::check_range(&T::decode(data)?, self.low.as_ref(), self.high.as_ref())
    }

    fn init(&self, stored: &mut [u8], node_id: Option<NodeId>) {
        // Zeroed storage decodes as the type's zero (0, false, 0.0, the empty string); the
        // storage is the type's encoded size, so the encoding fits.
        if let Ok(zero) = T::decode(stored) {
            let value = initial_value(self.default, self.low, self.high, node_id, zero);
            let _ = value.encode(stored);
        }
    }

    fn len(&self) -> usize {
        T::MAX_LEN
    }

    fn data_type(&self) -> DataType {
        T::DATA_TYPE
    }
}

/// Copies checked download `data` into the `stored` bytes of its entry: the encoding the type
/// decoded it from, a string without the zeros that may pad it (padded with zeros to the
/// capacity instead), a time without the 4 reserved bits CiA 301 says to ignore.
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

/// The [`Spec`] of a row's value as the shared paths use it: a `static` that rows with the
/// same spec share, so that a [`Row`] points at it with a thin pointer (4 bytes on a 32-bit
/// target, where the trait object's own pointer would take 8 in every row).
#[derive(Clone, Copy)]
pub struct SpecRef(pub(super) &'static dyn Slot);

impl SpecRef {
    /// The reference to `spec`, for [`row!`](crate::slave::row).
    pub const fn new<T>(spec: &'static Spec<T>) -> SpecRef
    where
        T: ObjValue + PartialOrd + Sync + 'static,
    {
        SpecRef(spec)
    }
}

/// One entry of a generated dictionary: its address, access right, the [`Spec`] of its value
/// and where the value is stored; 10 bytes on a 32-bit target (rows are most of a
/// dictionary's flash: 170 of them for CiA 301's communication objects alone).
///
/// A row is a table entry, not code: the dictionary's read and write paths ([`Table::read`],
/// [`Table::write`]) serve every row. Generated code writes `row!(od::CONTROLWORD)`.
///
/// Packed to 2-byte alignment, so that a row takes 10 bytes and not 12; no reference to a
/// field is ever taken (the compiler refuses one), fields are copied out.
#[derive(Clone, Copy)]
#[repr(C, packed(2))]
pub struct Row {
    spec: &'static SpecRef,
    /// [`key`] of the address in bits 0–23, the access right's code in bits 24–26, bits
    /// 16–19 of the offset in bits 27–30, whether the file allows PDO mapping in bit 31
    /// ([`MAPPABLE`]).
    key: u32,
    /// Bits 0–15 of the offset of the value in the dictionary's storage ([`Row::new`] puts
    /// the value's length in the offset, [`Table::new`] the offset).
    at: u16,
}

/// Offsets and lengths in a [`Row`] are below 1 MiB (20 bits).
const AT_LIMIT: usize = 1 << 20;
/// [`Row::key`]'s bit for an entry the file allows to map into PDOs.
pub(super) const MAPPABLE: u32 = 1 << 31;

/// The access rights by their code in [`Row::key`].
const ACCESS: [Access; 6] =
    [Access::Ro, Access::Wo, Access::Rw, Access::Rwr, Access::Rww, Access::Const];

impl Row {
    /// The row of `entry`, whose limits and default are `spec`: `SpecRef::new(&entry.spec())`,
    /// as [`row!`](crate::slave::row) writes it (a spec made from another entry would give the
    /// value that entry's checks and size).
    pub const fn new<T>(entry: &Entry<T>, spec: &'static SpecRef) -> Row
    where
        T: ObjValue + PartialOrd + Sync + 'static,
    {
        let access = entry.access as u32;
        let mappable = if entry.pdo_mappable { MAPPABLE } else { 0 };
        let key = key(entry.addr.index, entry.addr.sub) | access << 24 | mappable;
        // Evaluated when the `const` table is built: a compile error, not a run-time panic.
        assert!(T::MAX_LEN < AT_LIMIT, "a dictionary value of 1 MiB or more");
        Row { spec, key, at: 0 }.with_at(T::MAX_LEN)
    }

    /// The offset (or, before [`Table::new`], the length) of the value.
    const fn at(&self) -> usize {
        let key = self.key;
        let low = self.at;
        low as usize | ((key >> 27 & 0xF) as usize) << 16
    }

    /// The same row with offset (or length) `at`, below [`AT_LIMIT`].
    const fn with_at(mut self, at: usize) -> Row {
        self.at = at as u16;
        self.key = self.key & 0x87FF_FFFF | ((at >> 16) as u32 & 0xF) << 27;
        self
    }

    fn spec(&self) -> &'static dyn Slot {
        let spec = self.spec;
        spec.0
    }

    /// The entry's address.
    pub const fn addr(&self) -> ObjectAddr {
        let key = self.key;
        ObjectAddr::new((key >> 8) as u16, key as u8)
    }

    /// The entry's access right.
    pub fn access(&self) -> Access {
        let key = self.key;
        match ACCESS.get((key >> 24 & 7) as usize) {
            Some(&a) => a,
            // Unreachable: `Row::new` stores the code of an `Access`.
            None => Access::Ro,
        }
    }

    /// The entry's CiA 301 data type.
    pub fn data_type(&self) -> DataType {
        self.spec().data_type()
    }
}

impl fmt::Debug for Row {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.debug_struct("Row")
            .field("addr", &self.addr())
            .field("access", &self.access())
            .field("data_type", &self.data_type())
            .field("at", &self.at())
            .finish()
    }
}

/// What the shared read and write paths need of a row: the const [`Row`] of generated code,
/// and (feature `alloc`) the row of a table built at run time, which owns its [`Slot`].
pub(super) trait RowLike {
    /// [`key`] in bits 0–23, the access code in bits 24–26, [`MAPPABLE`] in bit 31 (the
    /// other bits are the row's own).
    fn packed(&self) -> u32;
    /// Offset of the value in the storage.
    fn at(&self) -> usize;
    /// The typed work of the value.
    fn slot(&self) -> &dyn Slot;

    fn addr(&self) -> ObjectAddr {
        let k = self.packed();
        ObjectAddr::new((k >> 8) as u16, k as u8)
    }
    fn access(&self) -> Access {
        match ACCESS.get((self.packed() >> 24 & 7) as usize) {
            Some(&a) => a,
            // Unreachable: rows store the code of an `Access`.
            None => Access::Ro,
        }
    }
    /// Whether the file allows mapping the entry into PDOs.
    fn mappable(&self) -> bool {
        self.packed() & MAPPABLE != 0
    }
    /// The search key of its address ([`key`]).
    fn search_key(&self) -> u32 {
        self.packed() & 0xFF_FFFF
    }
    fn of<'v>(&self, values: &'v [u8]) -> Result<&'v [u8], SdoAbort> {
        let at = self.at();
        // `values` is a dictionary's storage, its table's size long: always `Some`.
        values.get(at..at + self.slot().len()).ok_or(SdoAbort::General)
    }
    fn of_mut<'v>(&self, values: &'v mut [u8]) -> Result<&'v mut [u8], SdoAbort> {
        let at = self.at();
        values.get_mut(at..at + self.slot().len()).ok_or(SdoAbort::General)
    }
}

impl RowLike for Row {
    fn packed(&self) -> u32 {
        // A copy of the packed field, no reference to it.
        self.key
    }
    fn at(&self) -> usize {
        Row::at(self)
    }
    fn slot(&self) -> &dyn Slot {
        self.spec()
    }
}

/// The rows of a generated dictionary, sorted by address, with their search keys and the
/// storage layout: what `Dictionary` needs besides its stored bytes.
///
/// Generated code builds it in a `const` (`Table::new([row!(od::DEVICE_TYPE), …])`) and
/// keeps the values in a `[u8; TABLE.size()]`; every SDO transfer goes through [`Table::read`]
/// and [`Table::write`], the firmware's own accesses through [`Table::get`] and
/// [`Table::set`].
#[derive(Clone, Copy, Debug)]
pub struct Table<const N: usize> {
    rows: [Row; N],
    size: usize,
}

impl<const N: usize> Table<N> {
    /// The table of `rows`, which must be sorted by address without duplicates (generated
    /// tables are); lays the values out one after the other in row order.
    pub const fn new(mut rows: [Row; N]) -> Self {
        let mut at = 0;
        let mut i = 0;
        // `i < N`: the indexing cannot fail.
        while i < N {
            let len = rows[i].at();
            rows[i] = rows[i].with_at(at);
            at += len;
            i += 1;
        }
        // Evaluated when the `const` table is built: a compile error, not a run-time panic.
        assert!(at < AT_LIMIT, "a dictionary of 1 MiB or more");
        Table { rows, size: at }
    }

    /// The size of the storage in bytes: the encoded sizes of every entry's type.
    pub const fn size(&self) -> usize {
        self.size
    }

    /// The number of entries.
    pub const fn len(&self) -> usize {
        N
    }

    /// Whether the table has no entry.
    pub const fn is_empty(&self) -> bool {
        N == 0
    }

    /// The rows, in address order.
    pub const fn rows(&self) -> &[Row] {
        &self.rows
    }

    /// Fills `values` (zeroed, [`Table::size`] bytes) with every entry's initial value on
    /// node `node_id`: its default (`$NODEID` applied), else zero moved into its limits (see
    /// [`initial`](super::initial)). A node without node-ID (`None`, LSS) takes no `$NODEID`
    /// default. A row of [`row_limits!`](crate::slave::row_limits) keeps its zeros: its
    /// initial value is in the generated dictionary's `INITIAL` image, which generated code
    /// copies instead of calling this.
    pub fn init(&self, values: &mut [u8], node_id: Option<NodeId>) {
        Rows(&self.rows).init(values, node_id);
    }

    /// The access of `index:sub`, if the table has it.
    pub fn access(&self, index: u16, sub: u8) -> Option<Access> {
        Rows(&self.rows).access(index, sub)
    }

    /// Whether `index:sub` may be mapped into a transmit (`tx`) or receive PDO: its size in
    /// bits (see [`ObjectDictionary::pdo_mappable`](super::ObjectDictionary::pdo_mappable)).
    ///
    /// # Errors
    ///
    /// [`SdoAbort::NoSuchObject`], [`SdoAbort::NoSuchSub`] or [`SdoAbort::NotMappable`].
    pub fn pdo_mappable(&self, index: u16, sub: u8, tx: bool) -> Result<u32, SdoAbort> {
        Rows(&self.rows).pdo_mappable(index, sub, tx)
    }

    /// SDO upload of `index:sub` from `values` into `buf`; returns the length.
    ///
    /// # Errors
    ///
    /// [`SdoAbort::NoSuchObject`] or [`SdoAbort::NoSuchSub`] (see [`Table::read`]),
    /// [`SdoAbort::ReadOfWriteOnly`], [`SdoAbort::TooShort`] when `buf` cannot hold the value,
    /// [`SdoAbort::NoData`] (0x08000024) for a DOMAIN, whose data the table does not keep.
    pub fn read(
        &self,
        values: &[u8],
        index: u16,
        sub: u8,
        buf: &mut [u8],
    ) -> Result<usize, SdoAbort> {
        Rows(&self.rows).read(values, index, sub, buf)
    }

    /// SDO download of `data` into `index:sub` of `values`: the checks, then `hook` before
    /// and after the value is stored.
    ///
    /// # Errors
    ///
    /// In this order: [`SdoAbort::NoSuchObject`] or [`SdoAbort::NoSuchSub`],
    /// [`SdoAbort::WriteOfReadOnly`], the length or value error of decoding `data`
    /// ([`SdoAbort::TooShort`], `TooLong`, `InvalidValue`), the limits
    /// ([`SdoAbort::MaxLessThanMin`], `ValueTooHigh`, `ValueTooLow`, see
    /// [`crate::check_range`]), or what `hook.before_write` answered (for a DOMAIN, then
    /// `hook.write_domain`); the value is then unchanged.
    pub fn write(
        &self,
        values: &mut [u8],
        index: u16,
        sub: u8,
        data: &[u8],
        hook: &mut dyn WriteHook,
    ) -> Result<(), SdoAbort> {
        Rows(&self.rows).write(values, index, sub, data, hook)
    }

    /// The value of `entry` in `values`, for the firmware: no access check.
    ///
    /// # Errors
    ///
    /// [`SdoAbort::NoSuchObject`] or [`SdoAbort::NoSuchSub`] when the table has no entry at
    /// that address, [`SdoAbort::LengthMismatch`] when it has one of another type: `entry` is
    /// not from this dictionary's `od` module.
    pub fn get<T: ObjValue>(&self, values: &[u8], entry: &Entry<T>) -> Result<T, SdoAbort> {
        Rows(&self.rows).get(values, entry.addr.index, entry.addr.sub)
    }

    /// Stores `value` for `entry` in `values`, for the firmware: no access or limit check,
    /// no hook (a drive sets its read-only statusword this way).
    ///
    /// # Errors
    ///
    /// As for [`Table::get`], or the encoding error of a time value out of range.
    pub fn set<T: ObjValue>(
        &self,
        values: &mut [u8],
        entry: &Entry<T>,
        value: T,
    ) -> Result<(), SdoAbort> {
        Rows(&self.rows).set(values, entry.addr.index, entry.addr.sub, value)
    }

    /// The stored bytes of `index:sub` in `values`, for the firmware's process data: no
    /// access check.
    pub fn raw<'v>(&self, values: &'v [u8], index: u16, sub: u8) -> Option<&'v [u8]> {
        Rows(&self.rows).raw(values, index, sub)
    }

    /// The stored bytes of `index:sub` in `values`, to change in place (process data): no
    /// access or limit check.
    pub fn raw_mut<'v>(&self, values: &'v mut [u8], index: u16, sub: u8) -> Option<&'v mut [u8]> {
        Rows(&self.rows).raw_mut(values, index, sub)
    }

    /// The entry at position `pos` in address order.
    pub fn entry_at(&self, pos: usize) -> Option<super::EntryMeta> {
        Rows(&self.rows).entry_at(pos)
    }

    /// The position of the first entry at or after `index:sub` (the number of entries when
    /// there is none).
    pub fn position(&self, index: u16, sub: u8) -> usize {
        Rows(&self.rows).position(index, sub)
    }

    /// Shows `values` as a map from address to typed value, for `Debug`.
    ///
    /// # Errors
    ///
    /// The formatter's.
    pub fn fmt_values(&self, values: &[u8], f: &mut fmt::Formatter<'_>) -> fmt::Result {
        Rows(&self.rows).fmt_values(values, f)
    }
}

/// The rows a [`Rows`] path serves: a const table's array, whose length the compiler then
/// knows (a firmware image's searches and bounds checks come out shorter), or any slice.
pub(super) trait RowSlice {
    /// The row type.
    type Row: RowLike;
    /// The rows, sorted by address.
    fn rows(&self) -> &[Self::Row];
}

impl<const N: usize> RowSlice for [Row; N] {
    type Row = Row;
    fn rows(&self) -> &[Row] {
        self
    }
}

impl<R: RowLike> RowSlice for [R] {
    type Row = R;
    fn rows(&self) -> &[R] {
        self
    }
}

/// The one read and write path, over the rows of any table.
///
/// Taken by value, over the table's own array: a `Table`'s path is a pointer and a constant
/// length. Behind `&self` over a slice, every caller built the slice on its stack and every
/// search took its length as a variable (`tests/slave-size`'s `canopennode` image: 22,203 B
/// that way; `tests/no-std`'s firmware: 50,756 B).
pub(super) struct Rows<'r, S: ?Sized>(pub(super) &'r S);

impl<S: ?Sized> Clone for Rows<'_, S> {
    fn clone(&self) -> Self {
        *self
    }
}
impl<S: ?Sized> Copy for Rows<'_, S> {}

impl<'r, S: RowSlice + ?Sized> Rows<'r, S> {
    pub(super) fn init(self, values: &mut [u8], node_id: Option<NodeId>) {
        for row in self.0.rows() {
            if let Ok(stored) = row.of_mut(values) {
                row.slot().init(stored, node_id);
            }
        }
    }

    pub(super) fn access(self, index: u16, sub: u8) -> Option<Access> {
        self.row(index, sub).ok().map(S::Row::access)
    }

    pub(super) fn pdo_mappable(self, index: u16, sub: u8, tx: bool) -> Result<u32, SdoAbort> {
        let row = self.row(index, sub)?;
        let access = row.access();
        let allowed = if tx { access.tpdo_allowed() } else { access.rpdo_allowed() };
        if !row.mappable() || !allowed {
            return Err(SdoAbort::NotMappable);
        }
        Ok(row.slot().len() as u32 * 8)
    }

    fn row(self, index: u16, sub: u8) -> Result<&'r S::Row, SdoAbort> {
        let pos = search(self.0.rows(), S::Row::search_key, index, sub)?;
        self.0.rows().get(pos).ok_or(SdoAbort::NoSuchObject)
    }

    pub(super) fn read(
        self,
        values: &[u8],
        index: u16,
        sub: u8,
        buf: &mut [u8],
    ) -> Result<usize, SdoAbort> {
        let row = self.row(index, sub)?;
        if !row.access().readable() {
            return Err(SdoAbort::ReadOfWriteOnly);
        }
        let stored = row.of(values)?;
        // The stored bytes are the encoding, but for the zeros that pad a shorter string. A
        // DOMAIN's data is the application's (`WriteHook::write_domain`): none here.
        let len = match row.slot().data_type() {
            DataType::VisibleString => stored.iter().rposition(|&b| b != 0).map_or(0, |p| p + 1),
            DataType::UnicodeString => crate::value::unicode_len(stored),
            DataType::Domain => return Err(SdoAbort::NoData),
            _ => stored.len(),
        };
        let (src, dst) = (stored.get(..len), buf.get_mut(..len));
        let (Some(src), Some(dst)) = (src, dst) else { return Err(SdoAbort::TooShort) };
        for (d, s) in dst.iter_mut().zip(src) {
            *d = *s;
        }
        Ok(len)
    }

    pub(super) fn write(
        self,
        values: &mut [u8],
        index: u16,
        sub: u8,
        data: &[u8],
        hook: &mut dyn WriteHook,
    ) -> Result<(), SdoAbort> {
        let row = self.row(index, sub)?;
        if !row.access().writable() {
            return Err(SdoAbort::WriteOfReadOnly);
        }
        row.slot().check(data)?;
        let addr = row.addr();
        hook.before_write(addr, data)?;
        if row.slot().data_type() == DataType::Domain {
            hook.write_domain(addr, data)?;
        }
        store(row.slot().data_type(), data, row.of_mut(values)?);
        hook.after_write(addr);
        Ok(())
    }

    /// The row at `index:sub`, if it holds a `T`.
    fn typed<T: ObjValue>(self, index: u16, sub: u8) -> Result<&'r S::Row, SdoAbort> {
        let row = self.row(index, sub)?;
        if row.slot().data_type() != T::DATA_TYPE || row.slot().len() != T::MAX_LEN {
            return Err(SdoAbort::LengthMismatch);
        }
        Ok(row)
    }

    pub(super) fn get<T: ObjValue>(
        self,
        values: &[u8],
        index: u16,
        sub: u8,
    ) -> Result<T, SdoAbort> {
        Ok(T::decode(self.typed::<T>(index, sub)?.of(values)?)?)
    }

    pub(super) fn set<T: ObjValue>(
        self,
        values: &mut [u8],
        index: u16,
        sub: u8,
        value: T,
    ) -> Result<(), SdoAbort> {
        let stored = self.typed::<T>(index, sub)?.of_mut(values)?;
        stored.fill(0);
        value.encode(stored)?;
        Ok(())
    }

    pub(super) fn raw(self, values: &[u8], index: u16, sub: u8) -> Option<&[u8]> {
        self.row(index, sub).ok()?.of(values).ok()
    }

    pub(super) fn raw_mut(self, values: &mut [u8], index: u16, sub: u8) -> Option<&mut [u8]> {
        self.row(index, sub).ok()?.of_mut(values).ok()
    }

    pub(super) fn entry_at(self, pos: usize) -> Option<super::EntryMeta> {
        let row = self.0.rows().get(pos)?;
        Some(super::EntryMeta {
            addr: row.addr(),
            access: row.access(),
            data_type: row.slot().data_type(),
            len: row.slot().len(),
        })
    }

    pub(super) fn position(self, index: u16, sub: u8) -> usize {
        let k = key(index, sub);
        self.0.rows().partition_point(|r| r.search_key() < k)
    }

    pub(super) fn fmt_values(self, values: &[u8], f: &mut fmt::Formatter<'_>) -> fmt::Result {
        struct Shown<'a>(&'a dyn Slot, Result<&'a [u8], SdoAbort>);
        impl fmt::Debug for Shown<'_> {
            fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
                match self.1 {
                    Ok(stored) => show(self.0.data_type(), stored, f),
                    Err(_) => f.write_str("<missing>"),
                }
            }
        }
        struct Addr(ObjectAddr);
        impl fmt::Debug for Addr {
            fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
                fmt::Display::fmt(&self.0, f)
            }
        }
        f.debug_map()
            .entries(self.0.rows().iter().map(|r| (Addr(r.addr()), Shown(r.slot(), r.of(values)))))
            .finish()
    }
}

/// Shows stored bytes by their data type: numbers and strings as such, the rest as bytes.
/// Untyped, so that `Debug` of a dictionary links no formatting per value type.
fn show(data_type: DataType, stored: &[u8], f: &mut fmt::Formatter<'_>) -> fmt::Result {
    let mut le = [0u8; 8];
    for (d, s) in le.iter_mut().zip(stored) {
        *d = *s;
    }
    let raw = u64::from_le_bytes(le);
    let bits = u32::try_from(stored.len() * 8).unwrap_or(64).min(64);
    match data_type {
        DataType::Boolean => write!(f, "{}", raw != 0),
        DataType::Real32 => write!(f, "{:?}", f32::from_bits(raw as u32)),
        DataType::Real64 => write!(f, "{:?}", f64::from_bits(raw)),
        DataType::Integer8
        | DataType::Integer16
        | DataType::Integer24
        | DataType::Integer32
        | DataType::Integer40
        | DataType::Integer48
        | DataType::Integer56
        | DataType::Integer64 => write!(f, "{}", crate::bits::sign_extend(raw, bits)),
        DataType::VisibleString => {
            let end = stored.iter().position(|&b| b == 0).unwrap_or(stored.len());
            let text = stored.get(..end).and_then(|b| core::str::from_utf8(b).ok());
            write!(f, "{:?}", text.unwrap_or(""))
        }
        _ if data_type.bits().is_some() && stored.len() <= 8 => write!(f, "{raw}"),
        _ => write!(f, "{stored:02X?}"),
    }
}
