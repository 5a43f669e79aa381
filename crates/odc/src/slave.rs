//! Support for generated device-side object dictionaries (`slave` modules of odc-generated
//! code): the traits an SDO server and the application use ([`ObjectDictionary`],
//! [`WriteHook`]), and the table that makes a dictionary ([`Table`], [`Row`]).
//!
//! A generated dictionary is data, not code: a `const` [`Table`] with one [`Row`] per entry
//! (address, access, and the limits and default of its typed descriptor from the `od` module:
//! `row!(od::CONTROLWORD)`), and a
//! `Dictionary` holding the values as bytes, `[u8; TABLE.size()]`. Its `read` and `write` call
//! [`Table::read`] and [`Table::write`]: a binary search by address, the access check, then the
//! typed work of the entry's value type (decoding, limits, hook, encoding), once per type in
//! the image whatever the number of entries. Adding an entry adds a row.
//!
//! The values are stored in their SDO encoding (little-endian; strings padded with zeros), the
//! layout CANopenNode's `OD_RAM` has; the firmware reads and writes them typed through the
//! descriptors, `dict.get(od::CONTROLWORD)` and `dict.set(od::STATUSWORD, sw)`.
//!
//! Why bytes and not a struct with a typed field per entry (or per object): one read and one
//! write path must reach the value of any row at run time. CANopenNode does that with a
//! pointer into its struct; safe Rust cannot, so a typed struct needs generated code per entry
//! (a match arm, or an accessor function per row), which is what this table replaces (9.7 KB
//! of code for the 192 entries of the LXM23A, 4.5 KB now, and no more for more entries; see
//! `tests/slave-size`). The typing stays where the firmware meets the values: `get` and `set`
//! take the entry's `Entry<T>` and give or take a `T` (`Controlword` for 0x6040), and refuse a
//! descriptor of another type or dictionary. `Clone`, `PartialEq` and `Hash` of a dictionary
//! are those of its bytes; `Debug` shows each address with its value.
//!
//! A generated dictionary is served by an SDO [`Server`](crate::sdo::Server); the application
//! reads and sets its values typed through the `od` descriptors, and a [`WriteHook`] learns of
//! (or vetoes) what the bus writes:
//!
//! ```
//! # mod lxm23a { odc_macros::include_device!("../../eds/lxm23a.eds", role = "slave"); }
//! use odc::can::CanFrame;
//! use odc::sdo::Server;
//! use odc::slave::ObjectDictionary;
//! use odc::SdoAbort;
//!
//! // `lxm23a` generated from eds/lxm23a.eds (odc-build or include_device!), role "slave".
//! let mut od = lxm23a::slave::Dictionary::new(odc::node_id!(5)); // node 5: $NODEID defaults resolved
//! let mut server = Server::<64>::new(odc::node_id!(5));
//! // A master uploads 0x1000 (device type): request on 0x605, answer on 0x585.
//! let request = CanFrame::new(0x605, [0x40, 0x00, 0x10, 0x00, 0, 0, 0, 0]).unwrap();
//! let answer = server.handle(&mut od, &request, odc::time::Instant::ZERO).ok_or("no answer")?;
//! assert_eq!(answer, CanFrame::new(0x585, [0x43, 0x00, 0x10, 0x00, 0x92, 0x01, 0x02, 0x04]).unwrap());
//! // The same dictionary, from the application: typed values, and the checked SDO paths.
//! assert_eq!(od.get(lxm23a::od::DEVICE_TYPE)?, 0x0402_0192);
//! let mut buf = [0u8; 4];
//! assert_eq!(od.write(0x1000, 0, &buf), Err(SdoAbort::WriteOfReadOnly));
//! assert_eq!(od.read(0x1001, 7, &mut buf), Err(SdoAbort::NoSuchSub));
//!
//! // A hook that refuses new target positions while the drive is not ready.
//! struct NotReady;
//! impl odc::slave::WriteHook for NotReady {
//!     fn before_write(&mut self, addr: odc::ObjectAddr, _: &[u8]) -> Result<(), SdoAbort> {
//!         if addr.index == 0x607A { Err(SdoAbort::DeviceState) } else { Ok(()) }
//!     }
//! }
//! let r = od.write_with(0x607A, 0, &1000i32.to_le_bytes(), &mut NotReady);
//! assert_eq!(r, Err(SdoAbort::DeviceState));
//! assert_eq!(od.get(lxm23a::od::TARGET_POSITION)?, 0);
//! od.write(0x607A, 0, &1000i32.to_le_bytes())?;
//! assert_eq!(od.get(lxm23a::od::TARGET_POSITION)?, 1000);
//! # Ok::<(), Box<dyn std::error::Error>>(())
//! ```

mod describe;
mod imaged;
#[cfg(feature = "alloc")]
mod runtime;
mod table;

pub use describe::{Description, ObjectRow, entry_flag};
pub use imaged::{Limits, NodeIdDefault, Unlimited};
#[cfg(feature = "alloc")]
pub use runtime::{RuntimeDictionary, RuntimeTable, TableBuilder};
pub use table::{Row, Spec, SpecRef, Table};

use crate::cob::NodeId;
use crate::{Access, DefaultValue, Entry, ObjValue, ObjectAddr, SdoAbort};

/// What an SDO server needs from an object dictionary. Generated `Dictionary` types implement
/// it, so server code can be written once for every device.
pub trait ObjectDictionary {
    /// Uploads `index:sub` into `buf`; returns the number of bytes written.
    ///
    /// # Errors
    ///
    /// The SDO abort the server answers with.
    fn read(&self, index: u16, sub: u8, buf: &mut [u8]) -> Result<usize, SdoAbort>;

    /// Downloads `data` into `index:sub`.
    ///
    /// # Errors
    ///
    /// The SDO abort the server answers with.
    fn write(&mut self, index: u16, sub: u8, data: &[u8]) -> Result<(), SdoAbort>;

    /// The access of `index:sub`, where the dictionary knows it (`None` by default, and for
    /// an entry it does not have). A node checks it before the CiA 301 rules that depend on
    /// other values, so a read-only COB-ID is refused as read-only (0x06010002).
    fn access(&self, index: u16, sub: u8) -> Option<Access> {
        let _ = (index, sub);
        None
    }

    /// Whether `index:sub` may be mapped into a transmit PDO (`tx`) or a receive PDO:
    /// `Ok(bits)`, the size of its value, when the dictionary has it and its file allows it
    /// (`PDOMapping=1` and an access of that direction, [`Access::tpdo_allowed`] /
    /// [`Access::rpdo_allowed`]). A node checks it when a master writes a mapping entry
    /// (CiA 301 §7.5.2.36/38).
    ///
    /// The default knows no mapping flag: it answers what a read tells (the entry exists,
    /// its size), so a dictionary that does not implement it refuses only a missing entry.
    ///
    /// # Errors
    ///
    /// [`SdoAbort::NoSuchObject`] or [`SdoAbort::NoSuchSub`] when the dictionary does not
    /// have it, [`SdoAbort::NotMappable`] when it may not be mapped that way.
    fn pdo_mappable(&self, index: u16, sub: u8, tx: bool) -> Result<u32, SdoAbort> {
        let _ = tx;
        match self.read(index, sub, &mut [0u8; 8]) {
            Ok(n) => Ok(n as u32 * 8),
            Err(e @ (SdoAbort::NoSuchObject | SdoAbort::NoSuchSub)) => Err(e),
            Err(_) => Ok(64),
        }
    }
}

/// What an entry is, without its value: address, access, type and the bytes its value takes
/// in the storage (a string's capacity).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct EntryMeta {
    /// The address.
    pub addr: ObjectAddr,
    /// The access right.
    pub access: Access,
    /// The CiA 301 data type.
    pub data_type: crate::DataType,
    /// The bytes of the value in the storage.
    pub len: usize,
}

/// A dictionary whose values the device's own stacks reach as bytes: process data copies
/// mapped entries between them and the sync managers, complete access and SDO Information walk
/// the entries in address order. Generated `Dictionary` types implement it, and so does
/// `RuntimeDictionary` (feature `alloc`).
pub trait Storage: ObjectDictionary {
    /// The stored bytes of `index:sub` (no access check).
    fn raw(&self, index: u16, sub: u8) -> Option<&[u8]>;
    /// The stored bytes of `index:sub`, to change in place (no access or limit check).
    fn raw_mut(&mut self, index: u16, sub: u8) -> Option<&mut [u8]>;
    /// The entry at position `pos` in address order.
    fn entry_at(&self, pos: usize) -> Option<EntryMeta>;
    /// The position of the first entry at or after `index:sub`.
    fn position(&self, index: u16, sub: u8) -> usize;
}

/// How the application learns about (and may veto) SDO writes into a generated dictionary.
///
/// `before_write` runs once the value has passed the access, length and limit checks, before it
/// is stored; an error aborts the transfer with that code (say
/// [`SdoAbort::DeviceState`]). `after_write` runs once it is stored.
pub trait WriteHook {
    /// Called before a checked value is stored.
    ///
    /// # Errors
    ///
    /// The abort to answer instead of storing.
    fn before_write(&mut self, addr: ObjectAddr, data: &[u8]) -> Result<(), SdoAbort> {
        let _ = (addr, data);
        Ok(())
    }

    /// Called after a value was stored.
    fn after_write(&mut self, addr: ObjectAddr) {
        let _ = addr;
    }

    /// Takes the data of a DOMAIN download (after `before_write`): the dictionary stores no
    /// DOMAIN bytes, so they are the application's to keep or act on (a program image for
    /// 0x1F50, a file). It comes whole, at most the SDO server's buffer long (`N` of
    /// `Server<N>` and `Node<N>`; a longer download is refused with 0x05040005).
    ///
    /// # Errors
    ///
    /// The abort to answer. By default [`SdoAbort::DataTransfer`] (0x08000020, "cannot be
    /// stored to the application"): a dictionary without a hook for it refuses the data
    /// instead of dropping it.
    fn write_domain(&mut self, addr: ObjectAddr, data: &[u8]) -> Result<(), SdoAbort> {
        let _ = (addr, data);
        Err(SdoAbort::DataTransfer)
    }
}

/// The hook that accepts everything.
impl WriteHook for () {}

/// The search key of `index:sub`: `index << 8 | sub`. Keys sort as addresses do.
const fn key(index: u16, sub: u8) -> u32 {
    (index as u32) << 8 | sub as u32
}

/// Finds `index:sub` in `items` sorted by their [`key`] (`key_of`).
///
/// # Errors
///
/// [`SdoAbort::NoSuchObject`] when no item has `index`, [`SdoAbort::NoSuchSub`] when the
/// object exists but not the sub-index.
fn search<T>(
    items: &[T],
    key_of: impl Fn(&T) -> u32,
    index: u16,
    sub: u8,
) -> Result<usize, SdoAbort> {
    match items.binary_search_by_key(&key(index, sub), &key_of) {
        Ok(pos) => Ok(pos),
        Err(pos) => {
            let same_object =
                |p: usize| items.get(p).is_some_and(|t| key_of(t) >> 8 == u32::from(index));
            if same_object(pos) || pos.checked_sub(1).is_some_and(same_object) {
                Err(SdoAbort::NoSuchSub)
            } else {
                Err(SdoAbort::NoSuchObject)
            }
        }
    }
}

/// The value an entry starts with on node `node_id` (`None`: a node without one, whose
/// `$NODEID` defaults are taken as absent): its default with `$NODEID` applied, else
/// `fallback` (also when a node-relative default does not fit the type) moved into the entry's
/// limits, so that a dictionary never starts with a value it would refuse by SDO (an entry
/// with `LowLimit=1` and no default starts at 1, not 0: a master that reads it and writes it
/// back must not get 0x06090032).
pub fn initial<T: ObjValue + PartialOrd>(
    entry: &Entry<T>,
    node_id: Option<NodeId>,
    fallback: T,
) -> T {
    initial_value(entry.default, entry.low, entry.high, node_id, fallback)
}

/// [`initial`] from the parts of a descriptor.
fn initial_value<T: ObjValue + PartialOrd>(
    default: Option<DefaultValue<T>>,
    low: Option<T>,
    high: Option<T>,
    node_id: Option<NodeId>,
    fallback: T,
) -> T {
    if let Some(v) = default.and_then(|d| match d {
        DefaultValue::Value(v) => Some(v),
        DefaultValue::NodeIdPlus(_) => d.resolve(node_id?),
    }) {
        return v;
    }
    match (low, high) {
        (Some(lo), _) if fallback < lo => lo,
        (_, Some(hi)) if fallback > hi => hi,
        _ => fallback,
    }
}

/// The [`Row`] of a descriptor, for the `const` table of generated code: `row!(od::X)` is
/// `Row::new(&od::X, &SpecRef::new(&od::X.spec()))`, the [`Spec`] and its [`SpecRef`]
/// promoted to `static`s that entries with the same limits and default share.
#[macro_export]
#[doc(hidden)]
macro_rules! __slave_row {
    ($entry:expr) => {
        $crate::slave::Row::new(&$entry, &$crate::slave::SpecRef::new(&$entry.spec()))
    };
}

#[doc(inline)]
pub use crate::__slave_row as row;

/// The [`Row`] of a descriptor whose initial value the generated dictionary keeps in its
/// `INITIAL` image: `row_limits!(od::X)` is `Row::new(&od::X, &SpecRef::limits(&od::X.limits()))`,
/// the [`Limits`] shared as [`row!`]'s `Spec`s are. Such a row links the limit check of its
/// type and no initial value ([`Table::init`] leaves it zero).
#[macro_export]
#[doc(hidden)]
macro_rules! __slave_row_limits {
    ($entry:expr) => {
        $crate::slave::Row::new(&$entry, &$crate::slave::SpecRef::limits(&$entry.limits()))
    };
}

#[doc(inline)]
pub use crate::__slave_row_limits as row_limits;

/// The [`Row`] of a descriptor as [`row_limits!`] makes it, for a value type that no entry of
/// the device limits: `row_unlimited!(od::X)` is
/// `Row::new(&od::X, &SpecRef::unlimited(&od::X.unlimited()))`. A download is checked by
/// decoding it alone.
#[macro_export]
#[doc(hidden)]
macro_rules! __slave_row_unlimited {
    ($entry:expr) => {
        $crate::slave::Row::new(&$entry, &$crate::slave::SpecRef::unlimited(&$entry.unlimited()))
    };
}

#[doc(inline)]
pub use crate::__slave_row_unlimited as row_unlimited;

#[cfg(test)]
mod tests;
