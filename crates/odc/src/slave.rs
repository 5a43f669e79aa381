//! Support for generated device-side object dictionaries (`slave` modules of odc-generated
//! code): lookup in a sorted `const` table, initial values, and the write hook.

use crate::{Entry, EntryInfo, ObjValue, ObjectAddr, SdoAbort, VisibleString};

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
