//! Support for generated device-side object dictionaries (`slave` modules of odc-generated
//! code): lookup in a sorted `const` table, initial values, the shared read and write paths,
//! and the write hook.
//!
//! A generated `Dictionary::read` is `find` in its `KEYS`, `check_read` in its `ACCESS`, then
//! one match arm per readable entry calling [`upload`]; `write_with` is the same with
//! [`check_write`] and [`download`]. The per-type work lives here, once per value type, so
//! that an arm costs a few instructions and a dictionary of hundreds of entries stays small in
//! flash.
//!
//! A generated dictionary is served by an SDO [`Server`](crate::sdo::Server); the application
//! reads and sets its values as plain fields, one per entry, and a [`WriteHook`] learns of (or
//! vetoes) what the bus writes:
//!
//! ```
//! # mod lxm23a { odc_macros::include_device!("../../eds/lxm23a.eds", role = "slave"); }
//! use odc::can::CanFrame;
//! use odc::sdo::Server;
//! use odc::slave::ObjectDictionary;
//! use odc::SdoAbort;
//!
//! // `lxm23a` generated from eds/lxm23a.eds (odc-build or include_device!), role "slave".
//! let mut od = lxm23a::slave::Dictionary::new(5); // node 5: $NODEID defaults resolved
//! let mut server = Server::<64>::new(5);
//! // A master uploads 0x1000 (device type): request on 0x605, answer on 0x585.
//! let request = CanFrame::new(0x605, [0x40, 0x00, 0x10, 0x00, 0, 0, 0, 0]);
//! let answer = server.handle(&mut od, &request, 0).ok_or("no answer")?;
//! assert_eq!(answer, CanFrame::new(0x585, [0x43, 0x00, 0x10, 0x00, 0x92, 0x01, 0x02, 0x00]));
//! // The same dictionary, from the application: fields, and the checked SDO paths.
//! assert_eq!(od.device_type, 0x0002_0192);
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
//! assert_eq!(od.target_position, 0);
//! od.write(0x607A, 0, &1000i32.to_le_bytes())?;
//! assert_eq!(od.target_position, 1000);
//! # Ok::<(), Box<dyn std::error::Error>>(())
//! ```

use crate::{
    Access, DefaultValue, Entry, EntryInfo, ObjValue, ObjectAddr, SdoAbort, VisibleString,
};

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
}

/// The hook that accepts everything.
impl WriteHook for () {}

/// Finds `index:sub` in a table sorted by address.
///
/// # Errors
///
/// [`SdoAbort::NoSuchObject`] when no entry has `index`, [`SdoAbort::NoSuchSub`] when the
/// object exists but not the sub-index.
pub fn locate(table: &[EntryInfo], index: u16, sub: u8) -> Result<usize, SdoAbort> {
    let key = ObjectAddr::new(index, sub);
    match table.binary_search_by(|e| e.addr.cmp(&key)) {
        Ok(pos) => Ok(pos),
        Err(pos) => {
            let same_object = |p: usize| table.get(p).is_some_and(|e| e.addr.index == index);
            if same_object(pos) || pos.checked_sub(1).is_some_and(same_object) {
                Err(SdoAbort::NoSuchSub)
            } else {
                Err(SdoAbort::NoSuchObject)
            }
        }
    }
}

/// The search key of `index:sub`: `index << 8 | sub`. Keys sort as addresses do.
pub const fn key(index: u16, sub: u8) -> u32 {
    (index as u32) << 8 | sub as u32
}

/// Finds `index:sub` in `keys` (sorted [`key`]s, a generated `slave::KEYS`).
///
/// # Errors
///
/// [`SdoAbort::NoSuchObject`] when no key has `index`, [`SdoAbort::NoSuchSub`] when the object
/// exists but not the sub-index.
#[inline]
pub fn find(keys: &[u32], index: u16, sub: u8) -> Result<usize, SdoAbort> {
    match keys.binary_search(&key(index, sub)) {
        Ok(pos) => Ok(pos),
        Err(pos) => {
            let same_object = |p: usize| keys.get(p).is_some_and(|&k| k >> 8 == u32::from(index));
            if same_object(pos) || pos.checked_sub(1).is_some_and(same_object) {
                Err(SdoAbort::NoSuchSub)
            } else {
                Err(SdoAbort::NoSuchObject)
            }
        }
    }
}

/// Whether an SDO upload may read entry `pos` of a dictionary with these access rights.
///
/// # Errors
///
/// [`SdoAbort::ReadOfWriteOnly`], or [`SdoAbort::NoSuchObject`] when `pos` is out of range.
#[inline]
pub fn check_read(access: &[Access], pos: usize) -> Result<(), SdoAbort> {
    match access.get(pos) {
        Some(a) if a.readable() => Ok(()),
        Some(_) => Err(SdoAbort::ReadOfWriteOnly),
        None => Err(SdoAbort::NoSuchObject),
    }
}

/// Whether an SDO download may write entry `pos` of a dictionary with these access rights.
///
/// # Errors
///
/// [`SdoAbort::WriteOfReadOnly`], or [`SdoAbort::NoSuchObject`] when `pos` is out of range.
#[inline]
pub fn check_write(access: &[Access], pos: usize) -> Result<(), SdoAbort> {
    match access.get(pos) {
        Some(a) if a.writable() => Ok(()),
        Some(_) => Err(SdoAbort::WriteOfReadOnly),
        None => Err(SdoAbort::NoSuchObject),
    }
}

/// SDO upload of one stored value into `buf` (after [`check_read`]); returns the length.
///
/// # Errors
///
/// [`SdoAbort::TooShort`] when `buf` cannot hold the value, or the value's own encoding error.
pub fn upload<T: ObjValue>(value: &T, buf: &mut [u8]) -> Result<usize, SdoAbort> {
    Ok(value.encode(buf)?)
}

/// SDO download of `data` into one stored value (after [`check_write`]): decode, check the
/// limits, ask `hook`, store, tell `hook`.
///
/// # Errors
///
/// The length or value error of the decoding, [`SdoAbort::ValueTooHigh`]/`ValueTooLow`/
/// `MaxLessThanMin` from [`crate::check_range`], or what `hook.before_write` answered;
/// the value is then unchanged.
pub fn download<T: ObjValue + PartialOrd, H: WriteHook + ?Sized>(
    field: &mut T,
    data: &[u8],
    low: Option<T>,
    high: Option<T>,
    addr: ObjectAddr,
    hook: &mut H,
) -> Result<(), SdoAbort> {
    let value = T::decode(data)?;
    crate::check_range(&value, low.as_ref(), high.as_ref())?;
    hook.before_write(addr, data)?;
    *field = value;
    hook.after_write(addr);
    Ok(())
}

/// The value an entry starts with when it does not depend on the node id: its fixed default,
/// else `fallback`. For the `const` initial dictionary of generated code; entries with a
/// `$NODEID`-relative default, or without default but with limits, get [`initial`] at run
/// time instead.
pub const fn fixed_default<T: Copy>(entry: &Entry<T>, fallback: T) -> T {
    match entry.default {
        Some(DefaultValue::Value(v)) => v,
        _ => fallback,
    }
}

/// The value an entry starts with on node `node_id`: its default with `$NODEID` applied, else
/// `fallback` (also when a node-relative default does not fit the type) moved into the entry's
/// limits, so that a dictionary never starts with a value it would refuse by SDO (an entry
/// with `LowLimit=1` and no default starts at 1, not 0: a master that reads it and writes it
/// back must not get 0x06090032).
pub fn initial<T: ObjValue + PartialOrd>(entry: &Entry<T>, node_id: u8, fallback: T) -> T {
    if let Some(v) = entry.default.and_then(|d| d.resolve(node_id)) {
        return v;
    }
    match (entry.low, entry.high) {
        (Some(lo), _) if fallback < lo => lo,
        (_, Some(hi)) if fallback > hi => hi,
        _ => fallback,
    }
}

/// An empty `VisibleString<N>`, the storage of a string entry without default.
pub fn empty_string<const N: usize>() -> VisibleString<N> {
    match VisibleString::new("") {
        Some(s) => s,
        // Unreachable: the empty string fits every `N` and has no invisible byte.
        None => empty_string(),
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::{Access, DataType, DefaultValue};

    const fn info(index: u16, sub: u8) -> EntryInfo {
        EntryInfo {
            addr: ObjectAddr::new(index, sub),
            name: "",
            data_type: DataType::Unsigned8,
            access: Access::Rw,
            pdo_mappable: false,
        }
    }

    #[test]
    fn lookup() {
        let t = [info(0x1000, 0), info(0x1018, 0), info(0x1018, 2), info(0x6040, 0)];
        assert_eq!(locate(&t, 0x1018, 2), Ok(2));
        assert_eq!(locate(&t, 0x1018, 1), Err(SdoAbort::NoSuchSub));
        assert_eq!(locate(&t, 0x1018, 9), Err(SdoAbort::NoSuchSub));
        assert_eq!(locate(&t, 0x1000, 1), Err(SdoAbort::NoSuchSub));
        assert_eq!(locate(&t, 0x2000, 0), Err(SdoAbort::NoSuchObject));
        assert_eq!(locate(&t, 0x7000, 0), Err(SdoAbort::NoSuchObject));
        assert_eq!(locate(&[], 0x7000, 0), Err(SdoAbort::NoSuchObject));
    }

    #[test]
    fn find_by_key() {
        let keys = [key(0x1000, 0), key(0x1018, 0), key(0x1018, 2), key(0x6040, 0)];
        assert!(keys.windows(2).all(|w| w[0] < w[1]));
        assert_eq!(find(&keys, 0x1000, 0), Ok(0));
        assert_eq!(find(&keys, 0x1018, 2), Ok(2));
        assert_eq!(find(&keys, 0x6040, 0), Ok(3));
        assert_eq!(find(&keys, 0x1018, 1), Err(SdoAbort::NoSuchSub));
        assert_eq!(find(&keys, 0x1018, 9), Err(SdoAbort::NoSuchSub));
        assert_eq!(find(&keys, 0x1000, 1), Err(SdoAbort::NoSuchSub));
        assert_eq!(find(&keys, 0x0FFF, 0xFF), Err(SdoAbort::NoSuchObject));
        assert_eq!(find(&keys, 0x2000, 0), Err(SdoAbort::NoSuchObject));
        assert_eq!(find(&keys, 0x7000, 0), Err(SdoAbort::NoSuchObject));
        assert_eq!(find(&[], 0x7000, 0), Err(SdoAbort::NoSuchObject));
    }

    #[test]
    fn access_checks() {
        let access = [Access::Ro, Access::Wo, Access::Rw, Access::Const];
        assert_eq!(check_read(&access, 0), Ok(()));
        assert_eq!(check_read(&access, 1), Err(SdoAbort::ReadOfWriteOnly));
        assert_eq!(check_read(&access, 3), Ok(()));
        assert_eq!(check_read(&access, 4), Err(SdoAbort::NoSuchObject));
        assert_eq!(check_write(&access, 0), Err(SdoAbort::WriteOfReadOnly));
        assert_eq!(check_write(&access, 1), Ok(()));
        assert_eq!(check_write(&access, 2), Ok(()));
        assert_eq!(check_write(&access, 3), Err(SdoAbort::WriteOfReadOnly));
        assert_eq!(check_write(&access, 9), Err(SdoAbort::NoSuchObject));
    }

    #[test]
    fn upload_and_download() {
        struct Veto(u32);
        impl WriteHook for Veto {
            fn before_write(&mut self, addr: ObjectAddr, data: &[u8]) -> Result<(), SdoAbort> {
                assert_eq!((addr, data), (ObjectAddr::new(0x2000, 1), &[7, 0][..]));
                Err(SdoAbort::DeviceState)
            }
            fn after_write(&mut self, _: ObjectAddr) {
                self.0 += 1;
            }
        }
        let addr = ObjectAddr::new(0x2000, 1);
        let mut v: u16 = 0x1234;
        let mut buf = [0u8; 2];
        assert_eq!(upload(&v, &mut buf), Ok(2));
        assert_eq!(buf, [0x34, 0x12]);
        assert_eq!(upload(&v, &mut buf[..1]), Err(SdoAbort::TooShort));
        assert_eq!(download(&mut v, &[7, 0], Some(1), Some(9), addr, &mut ()), Ok(()));
        assert_eq!(v, 7);
        assert_eq!(
            download(&mut v, &[0, 0], Some(1), None, addr, &mut ()),
            Err(SdoAbort::ValueTooLow)
        );
        assert_eq!(
            download(&mut v, &[10, 0], None, Some(9), addr, &mut ()),
            Err(SdoAbort::ValueTooHigh)
        );
        assert_eq!(
            download(&mut v, &[5, 0], Some(9), Some(1), addr, &mut ()),
            Err(SdoAbort::MaxLessThanMin)
        );
        assert_eq!(download(&mut v, &[5], None, None, addr, &mut ()), Err(SdoAbort::TooShort));
        assert_eq!(download(&mut v, &[5, 0, 0], None, None, addr, &mut ()), Err(SdoAbort::TooLong));
        assert_eq!(v, 7);
        let mut hook = Veto(0);
        assert_eq!(
            download(&mut v, &[7, 0], None, None, addr, &mut hook),
            Err(SdoAbort::DeviceState)
        );
        assert_eq!(hook.0, 0);
    }

    #[test]
    fn fixed_defaults_are_const() {
        const FIXED: Entry<u32> =
            Entry::new(1, 0, "", Access::Rw, false).with_default(DefaultValue::Value(9));
        const RELATIVE: Entry<u32> =
            Entry::new(1, 0, "", Access::Rw, false).with_default(DefaultValue::NodeIdPlus(0x80));
        const NONE: Entry<u32> = Entry::new(1, 0, "", Access::Rw, false);
        const VALUES: [u32; 3] =
            [fixed_default(&FIXED, 1), fixed_default(&RELATIVE, 1), fixed_default(&NONE, 1)];
        assert_eq!(VALUES, [9, 1, 1]);
        const EMPTY: VisibleString<4> = VisibleString::EMPTY;
        assert!(EMPTY.is_empty());
    }

    #[test]
    fn initial_values() {
        let e: Entry<u32> = Entry::new(0x1014, 0, "", Access::Rw, false)
            .with_default(DefaultValue::NodeIdPlus(0x80));
        assert_eq!(initial(&e, 5, 0), 0x85);
        let e: Entry<u8> =
            Entry::new(1, 0, "", Access::Rw, false).with_default(DefaultValue::NodeIdPlus(0xF0));
        assert_eq!(initial(&e, 0x20, 7), 7);
        // Without default, zero moves into the limits.
        let e: Entry<u32> = Entry::new(1, 0, "", Access::Rw, false).with_limits(Some(1), Some(3));
        assert_eq!(initial(&e, 5, 0), 1);
        let e: Entry<i8> = Entry::new(1, 0, "", Access::Rw, false).with_limits(None, Some(-4));
        assert_eq!(initial(&e, 5, 0), -4);
        let e: Entry<u8> = Entry::new(1, 0, "", Access::Rw, false).with_limits(Some(0), Some(9));
        assert_eq!(initial(&e, 5, 0), 0);
        assert!(empty_string::<4>().is_empty());
    }
}
