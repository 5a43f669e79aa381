//! Typed `const` descriptors of object-dictionary entries.

use crate::cob::NodeId;
use crate::{Access, DataType, ObjValue, ObjectAddr, SdoAbort};
use core::marker::PhantomData;

/// Default value of an entry, possibly relative to the node id (EDS `$NODEID+0x180`).
///
/// Kept symbolic until the node id is known, because one device file serves every node.
#[derive(Clone, Copy, Debug, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum DefaultValue<T> {
    /// A fixed value.
    Value(T),
    /// `$NODEID` plus this offset.
    NodeIdPlus(u32),
}

impl<T: ObjValue> DefaultValue<T> {
    /// The concrete value for `node_id`; `None` if the sum does not fit the type.
    pub fn resolve(&self, node_id: NodeId) -> Option<T> {
        match *self {
            Self::Value(v) => Some(v),
            Self::NodeIdPlus(off) => T::from_u64(u64::from(off) + u64::from(node_id.get())),
        }
    }
}

/// Typed descriptor of one object or sub-object, meant for `pub const` items in generated code.
///
/// `T` is the Rust value type, so SDO helpers taking `Entry<T>` and `T` reject a value of the
/// wrong type at compile time.
///
/// Generated `od` modules hold one per object and sub-object; by hand:
///
/// ```
/// use odc::{Access, DataType, DefaultValue, Entry, ObjectAddr, SdoAbort};
///
/// // Profile velocity (CiA 402), 1..=3000 rpm, 100 by default.
/// const PROFILE_VELOCITY: Entry<u32> = Entry::new(0x6081, 0, "Profile velocity", Access::Rw, true)
///     .with_limits(Some(1), Some(3000))
///     .with_default(DefaultValue::Value(100));
///
/// assert_eq!(PROFILE_VELOCITY.addr, ObjectAddr::new(0x6081, 0));
/// assert_eq!(PROFILE_VELOCITY.data_type(), DataType::Unsigned32);
/// assert_eq!(PROFILE_VELOCITY.default.and_then(|d| d.resolve(odc::node_id!(5))), Some(100));
/// // What a server does with a download: access, length and limits, with CiA 301 aborts.
/// assert_eq!(PROFILE_VELOCITY.decode_download(&500u32.to_le_bytes()), Ok(500));
/// let too_fast = 5000u32.to_le_bytes();
/// assert_eq!(PROFILE_VELOCITY.decode_download(&too_fast), Err(SdoAbort::ValueTooHigh));
/// assert_eq!(PROFILE_VELOCITY.decode_download(&[1, 2]), Err(SdoAbort::TooShort));
///
/// // A COB-ID default relative to the node id (`$NODEID+0x180`) resolves per node.
/// const TPDO1_COB_ID: Entry<u32> = Entry::new(0x1800, 1, "COB-ID", Access::Rw, false)
///     .with_default(DefaultValue::NodeIdPlus(0x180));
/// assert_eq!(TPDO1_COB_ID.default.and_then(|d| d.resolve(odc::node_id!(5))), Some(0x185));
/// ```
///
/// The type is checked where the entry is used: `Client::write(&mut bus, &PROFILE_VELOCITY,
/// -1i16)` does not compile ([`sdo::Client`](crate::sdo::Client)).
#[derive(Debug)]
pub struct Entry<T> {
    /// Where the entry lives.
    pub addr: ObjectAddr,
    /// Name from the device file (`ParameterName`).
    pub name: &'static str,
    /// Access right.
    pub access: Access,
    /// Whether the device file allows PDO mapping.
    pub pdo_mappable: bool,
    /// Lowest allowed value, if the device file sets one.
    pub low: Option<T>,
    /// Highest allowed value, if the device file sets one.
    pub high: Option<T>,
    /// Default value, if the device file sets one.
    pub default: Option<DefaultValue<T>>,
    _ty: PhantomData<fn() -> T>,
}

impl<T: Copy> Clone for Entry<T> {
    fn clone(&self) -> Self {
        *self
    }
}
impl<T: Copy> Copy for Entry<T> {}

impl<T: ObjValue> Entry<T> {
    /// A descriptor without limits or default.
    pub const fn new(
        index: u16,
        sub: u8,
        name: &'static str,
        access: Access,
        pdo_mappable: bool,
    ) -> Self {
        Self {
            addr: ObjectAddr::new(index, sub),
            name,
            access,
            pdo_mappable,
            low: None,
            high: None,
            default: None,
            _ty: PhantomData,
        }
    }

    /// A descriptor with every field given, for generated code.
    #[allow(clippy::too_many_arguments)]
    pub const fn full(
        index: u16,
        sub: u8,
        name: &'static str,
        access: Access,
        pdo_mappable: bool,
        low: Option<T>,
        high: Option<T>,
        default: Option<DefaultValue<T>>,
    ) -> Self {
        Self {
            addr: ObjectAddr::new(index, sub),
            name,
            access,
            pdo_mappable,
            low,
            high,
            default,
            _ty: PhantomData,
        }
    }

    /// The same descriptor with limits.
    pub const fn with_limits(self, low: Option<T>, high: Option<T>) -> Self {
        Self::full(
            self.addr.index,
            self.addr.sub,
            self.name,
            self.access,
            self.pdo_mappable,
            low,
            high,
            self.default,
        )
    }

    /// The same descriptor with a default.
    pub const fn with_default(self, default: DefaultValue<T>) -> Self {
        Self::full(
            self.addr.index,
            self.addr.sub,
            self.name,
            self.access,
            self.pdo_mappable,
            self.low,
            self.high,
            Some(default),
        )
    }

    /// The same descriptor with `value` as its default when there is one: for a value a
    /// checked constructor makes (`VisibleString::new`), which generated code has checked.
    pub const fn with_default_checked(self, value: Option<T>) -> Self
    where
        T: Copy,
    {
        match value {
            Some(v) => self.with_default(DefaultValue::Value(v)),
            None => self,
        }
    }

    /// The CiA 301 data type.
    pub const fn data_type(&self) -> DataType {
        T::DATA_TYPE
    }

    /// The untyped view, for tables and diagnostics.
    pub const fn info(&self) -> EntryInfo {
        EntryInfo {
            addr: self.addr,
            name: self.name,
            data_type: T::DATA_TYPE,
            access: self.access,
            pdo_mappable: self.pdo_mappable,
        }
    }

    /// Check a value against the limits, with the abort code a server would answer.
    pub fn check(&self, v: &T) -> Result<(), SdoAbort>
    where
        T: PartialOrd,
    {
        check_range(v, self.low.as_ref(), self.high.as_ref())
    }

    /// Check that an SDO download may write the entry, then decode and limit-check the bytes.
    pub fn decode_download(&self, bytes: &[u8]) -> Result<T, SdoAbort>
    where
        T: PartialOrd,
    {
        if !self.access.writable() {
            return Err(SdoAbort::WriteOfReadOnly);
        }
        let v = T::decode(bytes)?;
        self.check(&v)?;
        Ok(v)
    }

    /// Check that an SDO upload may read the entry, then encode `v`.
    pub fn encode_upload(&self, v: &T, buf: &mut [u8]) -> Result<usize, SdoAbort> {
        if !self.access.readable() {
            return Err(SdoAbort::ReadOfWriteOnly);
        }
        Ok(v.encode(buf)?)
    }
}

/// Checks `v` against optional limits, with the abort code a server answers:
/// [`SdoAbort::MaxLessThanMin`] when the limits contradict each other, else
/// [`SdoAbort::ValueTooHigh`] or [`SdoAbort::ValueTooLow`].
///
/// # Errors
///
/// As above.
pub fn check_range<T: PartialOrd>(
    v: &T,
    low: Option<&T>,
    high: Option<&T>,
) -> Result<(), SdoAbort> {
    if let (Some(lo), Some(hi)) = (low, high)
        && hi < lo
    {
        return Err(SdoAbort::MaxLessThanMin);
    }
    if high.is_some_and(|hi| v > hi) {
        return Err(SdoAbort::ValueTooHigh);
    }
    if low.is_some_and(|lo| v < lo) {
        return Err(SdoAbort::ValueTooLow);
    }
    Ok(())
}

/// Untyped description of an entry, for `const` tables indexed at run time.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
#[cfg_attr(feature = "serde", derive(serde::Serialize))]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct EntryInfo {
    /// Where the entry lives.
    pub addr: ObjectAddr,
    /// Name from the device file.
    pub name: &'static str,
    /// CiA 301 data type.
    pub data_type: DataType,
    /// Access right.
    pub access: Access,
    /// Whether PDO mapping is allowed.
    pub pdo_mappable: bool,
}

#[cfg(test)]
mod tests {
    use super::*;

    const TARGET_POSITION: Entry<i32> = Entry::new(0x607A, 0, "Target position", Access::Rww, true)
        .with_limits(Some(-1000), Some(1000));
    const COB_ID_EMCY: Entry<u32> = Entry::new(0x1014, 0, "COB-ID EMCY", Access::Rw, false)
        .with_default(DefaultValue::NodeIdPlus(0x80));
    const DEVICE_TYPE: Entry<u32> = Entry::new(0x1000, 0, "Device type", Access::Ro, false);

    fn write<T: ObjValue + PartialOrd>(e: Entry<T>, v: T) -> Result<(), SdoAbort> {
        e.check(&v)
    }

    #[test]
    fn typed_descriptor() {
        assert_eq!(write(TARGET_POSITION, 10i32), Ok(()));
        assert_eq!(write(TARGET_POSITION, 1001), Err(SdoAbort::ValueTooHigh));
        assert_eq!(write(TARGET_POSITION, -1001), Err(SdoAbort::ValueTooLow));
        assert_eq!(TARGET_POSITION.data_type(), DataType::Integer32);
        assert_eq!(TARGET_POSITION.info().addr, ObjectAddr::new(0x607A, 0));
        let bad: Entry<u8> = Entry::new(1, 0, "", Access::Rw, false).with_limits(Some(5), Some(1));
        assert_eq!(bad.check(&3), Err(SdoAbort::MaxLessThanMin));
    }

    #[test]
    fn node_id_default() {
        assert_eq!(COB_ID_EMCY.default.unwrap().resolve(crate::node_id!(5)), Some(0x85));
        let d: DefaultValue<u8> = DefaultValue::NodeIdPlus(0xF0);
        assert_eq!(d.resolve(crate::node_id!(0x20)), None);
        assert_eq!(DefaultValue::Value(3u8).resolve(crate::node_id!(9)), Some(3));
    }

    #[test]
    fn access_checked_transfers() {
        assert_eq!(DEVICE_TYPE.decode_download(&[0; 4]), Err(SdoAbort::WriteOfReadOnly));
        assert_eq!(TARGET_POSITION.decode_download(&[0; 3]), Err(SdoAbort::TooShort));
        assert_eq!(
            TARGET_POSITION.decode_download(&2000i32.to_le_bytes()),
            Err(SdoAbort::ValueTooHigh)
        );
        assert_eq!(TARGET_POSITION.decode_download(&5i32.to_le_bytes()), Ok(5));
        let wo: Entry<u8> = Entry::new(1, 0, "", Access::Wo, false);
        assert_eq!(wo.encode_upload(&1, &mut [0; 1]), Err(SdoAbort::ReadOfWriteOnly));
        let mut b = [0u8; 4];
        assert_eq!(DEVICE_TYPE.encode_upload(&0x0002_0192, &mut b), Ok(4));
    }
}
