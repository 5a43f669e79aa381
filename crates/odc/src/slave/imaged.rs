//! The rows of a generated dictionary whose initial values the generator wrote as bytes (its
//! `INITIAL` image): they keep the limits of their value ([`Limits`]) or only its type
//! ([`Unlimited`]), not its default, so that a firmware links a download check per value type
//! and no typed initial value; and the `$NODEID` defaults ([`NodeIdDefault`]) that `new` and
//! `reset` write over the image for the node.

use super::table::{Slot, SpecRef};
use crate::cob::NodeId;
use crate::{DataType, Entry, ObjValue, SdoAbort};

/// The limits of an entry's value without its default: the [`Spec`](super::Spec) of a row
/// whose initial value is in the generated dictionary's `INITIAL` image
/// ([`row_limits!`](crate::slave::row_limits) makes the row).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Limits<T> {
    low: Option<T>,
    high: Option<T>,
}

impl<T: ObjValue> Entry<T> {
    /// The limits of the entry, for a [`Row`](super::Row) whose initial value is kept
    /// elsewhere.
    pub const fn limits(&self) -> Limits<T> {
        Limits { low: self.low, high: self.high }
    }

    /// The type of the entry, for a [`Row`](super::Row) without limits whose initial value
    /// is kept elsewhere.
    pub const fn unlimited(&self) -> Unlimited<T> {
        Unlimited(core::marker::PhantomData)
    }
}

impl<T> Slot for Limits<T>
where
    T: ObjValue + PartialOrd + Sync + 'static,
{
    fn check(&self, data: &[u8]) -> Result<(), SdoAbort> {
        crate::check_range(&T::decode(data)?, self.low.as_ref(), self.high.as_ref())
    }

    /// Nothing: the dictionary's image holds the initial value (see
    /// [`Table::init`](super::Table::init)).
    fn init(&self, _: &mut [u8], _: Option<NodeId>) {}

    fn len(&self) -> usize {
        T::MAX_LEN
    }

    fn data_type(&self) -> DataType {
        T::DATA_TYPE
    }
}

/// The type of an entry's value without limits or default: the [`Spec`](super::Spec) of a
/// row whose initial value is in the image (as for [`Limits`]) and whose type no entry of the
/// device limits, so that a download's check is the decoding alone
/// ([`row_unlimited!`](crate::slave::row_unlimited) makes the row). The marker is of
/// `fn() -> T`: `Sync` whatever `T`, as a `static` must be.
pub struct Unlimited<T>(core::marker::PhantomData<fn() -> T>);

impl<T> Slot for Unlimited<T>
where
    T: ObjValue + 'static,
{
    fn check(&self, data: &[u8]) -> Result<(), SdoAbort> {
        T::decode(data).map(|_| ()).map_err(SdoAbort::from)
    }

    /// Nothing, as for [`Limits`].
    fn init(&self, _: &mut [u8], _: Option<NodeId>) {}

    fn len(&self) -> usize {
        T::MAX_LEN
    }

    fn data_type(&self) -> DataType {
        T::DATA_TYPE
    }
}

impl SpecRef {
    /// The reference to `unlimited`, for [`row_unlimited!`](crate::slave::row_unlimited).
    pub const fn unlimited<T>(unlimited: &'static Unlimited<T>) -> SpecRef
    where
        T: ObjValue + 'static,
    {
        SpecRef(unlimited)
    }

    /// The reference to `limits`, for [`row_limits!`](crate::slave::row_limits).
    pub const fn limits<T>(limits: &'static Limits<T>) -> SpecRef
    where
        T: ObjValue + PartialOrd + Sync + 'static,
    {
        SpecRef(limits)
    }
}

/// An entry of an imaged dictionary whose default is `$NODEID + offset`: where its integer
/// value is stored, its width and sign. The image holds the value without node-ID (the default
/// taken as absent); [`NodeIdDefault::apply`] writes the sum for a node, when it fits the
/// type (as [`DefaultValue::resolve`](crate::DefaultValue::resolve) decides). 8 bytes.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct NodeIdDefault {
    offset: u32,
    /// The value's place in the storage in bits 0–19, its length in bytes in bits 20–23,
    /// whether it is signed in bit 24.
    packed: u32,
}

impl NodeIdDefault {
    /// The default `$NODEID + offset` of the `len`-byte integer (`signed` or not) stored at
    /// `at`, for the generated `NODE_ID_DEFAULTS`.
    pub const fn new(at: u32, len: u8, signed: bool, offset: u32) -> Self {
        // Evaluated when the generated `const` is built: a compile error, not a run-time panic.
        assert!(at < 1 << 20 && len >= 1 && len <= 8, "a $NODEID default out of range");
        let packed = at | (len as u32) << 20 | (signed as u32) << 24;
        NodeIdDefault { offset, packed }
    }

    /// Writes every default of `defaults` for `node_id` into `values` (the image): nothing
    /// for a node without node-ID (LSS), nor for a sum that does not fit its type.
    pub fn apply(defaults: &[NodeIdDefault], values: &mut [u8], node_id: Option<NodeId>) {
        let Some(id) = node_id else { return };
        for d in defaults {
            let at = (d.packed & 0xF_FFFF) as usize;
            let len = (d.packed >> 20 & 0xF) as usize;
            let bytes = (u64::from(d.offset) + u64::from(id.get())).to_le_bytes();
            // The sum fits the type when no byte beyond its length is set, nor the sign bit
            // of a signed one.
            let (value, above) = bytes.split_at(len.min(bytes.len()));
            let negative = d.packed >> 24 & 1 != 0 && value.last().is_some_and(|b| b & 0x80 != 0);
            if negative || above.iter().any(|&b| b != 0) {
                continue;
            }
            if let Some(stored) = values.get_mut(at..at + len) {
                for (s, v) in stored.iter_mut().zip(value) {
                    *s = *v;
                }
            }
        }
    }
}
