//! EtherCAT start-up data of an ESI device, as generated `startup` modules declare it.
//!
//! A master brings a SubDevice from PRE-OP to SAFE-OP by writing, over CoE, the ESI's init
//! commands, the mapping of each configurable PDO and the sync managers' PDO assignment
//! (ETG.2000 `InitCmd`s, ETG.1000.6 0x1C10+n). [`Startup`] is that sequence as `const` data, with the
//! identity to check first; any master can run it, and with the feature `ethercrab` the
//! `ethercrab` module runs it on an ethercrab SubDevice.

#[cfg(feature = "esc-spi")]
pub mod esc_spi;
#[cfg(feature = "ethercrab")]
pub mod ethercrab;
#[cfg(feature = "subdevice")]
pub mod subdevice;

/// Vendor, product and revision as the ESI's `Vendor/Id` and `Type` give them; a SubDevice's
/// SII carries the same three numbers.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub struct Identity {
    /// Vendor id.
    pub vendor_id: u32,
    /// Product code.
    pub product_code: u32,
    /// Revision number.
    pub revision: u32,
    /// Which revisions the ESI accepts (`Type@CheckRevisionNo`).
    pub revision_check: RevisionCheck,
}

impl Identity {
    /// Whether a device reporting these numbers is one this identity describes: vendor and
    /// product code equal, the revision as [`Identity::revision_check`] says.
    pub const fn matches(&self, vendor_id: u32, product_code: u32, revision: u32) -> bool {
        vendor_id == self.vendor_id
            && product_code == self.product_code
            && self.revision_check.accepts(self.revision, revision)
    }
}

/// How a device's revision number is compared with the ESI's (`Type@CheckRevisionNo`; the
/// high word is the major revision, the low word the minor one).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
pub enum RevisionCheck {
    /// `EQ`, and the choice where the ESI says nothing: the same revision.
    #[default]
    Equal,
    /// `EQ_OR_G`: the same revision or a later one.
    EqualOrGreater,
    /// `LW_EQ`: the same low word.
    LowWordEqual,
    /// `LW_EQ_HW_EQ_OR_G`: the same low word, the same or a later high word.
    LowWordEqualHighWordEqualOrGreater,
}

impl RevisionCheck {
    /// Whether `found` passes against the ESI's revision `esi`.
    pub const fn accepts(self, esi: u32, found: u32) -> bool {
        let (low, high) = (esi & 0xFFFF, esi >> 16);
        match self {
            Self::Equal => found == esi,
            Self::EqualOrGreater => found >= esi,
            Self::LowWordEqual => found & 0xFFFF == low,
            Self::LowWordEqualHighWordEqualOrGreater => {
                found & 0xFFFF == low && found >> 16 >= high
            }
        }
    }
}

/// One CoE SDO download of the start-up.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub struct SdoDownload {
    /// Object index.
    pub index: u16,
    /// Sub-index (with `complete_access`, the first sub-index written: 0 or 1).
    pub sub: u8,
    /// Whether the whole object is written in one transfer (CoE complete access).
    pub complete_access: bool,
    /// The bytes, little-endian as on the wire.
    pub data: &'static [u8],
}

/// A distributed-clocks operation mode (ESI `Dc/OpMode`).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub struct DcOpMode {
    /// `Name` (e.g. `DC`, `FreeRun`, `SM-Synchron`).
    pub name: &'static str,
    /// Value for the ESC registers 0x0980:0x0981 (`0x0300`: SYNC0 on, `0x0700`: SYNC0 and
    /// SYNC1; `0` for a mode without distributed clocks).
    pub assign_activate: u16,
    /// SYNC0 cycle time in ns, `0` for "the bus cycle".
    pub cycle_time_sync0: u32,
    /// SYNC0 shift time in ns.
    pub shift_time_sync0: i32,
    /// SYNC1 cycle time in ns (added to SYNC0's), `0` for none.
    pub cycle_time_sync1: u32,
}

/// The start-up of one device with its default process data.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub struct Startup {
    /// The identity the device must report before anything is written.
    pub identity: Identity,
    /// The ESI's init commands of the INIT→PRE-OP and PRE-OP→SAFE-OP transitions, in order:
    /// sent first.
    pub downloads: &'static [SdoDownload],
    /// Then the process data, by the runtime's one procedure ([`crate::plan::PlanBuilder`]):
    /// per sync manager, clear its assignment 0x1C1x, the CiA 301 mapping procedure of each
    /// configurable PDO, assign the PDOs and set the count (each part when the ESI lets the
    /// master do it: `PdoAssign`, `PdoConfig`).
    pub pdo_writes: &'static [crate::plan::SdoWrite],
    /// Bytes of the outputs (master → device) and inputs (device → master) the master maps.
    pub output_len: usize,
    /// See `output_len`.
    pub input_len: usize,
}

/// Without the feature `ethercrab`: nothing (see the feature's `impl_wire!`).
#[cfg(not(feature = "ethercrab"))]
#[macro_export]
macro_rules! impl_wire {
    ($($ty:ty),* $(,)?) => {};
}

/// Without the feature `ethercrab`: nothing (see the feature's `configure_fn!`).
#[cfg(not(feature = "ethercrab"))]
#[macro_export]
macro_rules! configure_fn {
    ($plan:path) => {};
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn revision_checks() {
        let esi = 0x0012_0005;
        assert!(RevisionCheck::Equal.accepts(esi, 0x0012_0005));
        assert!(!RevisionCheck::Equal.accepts(esi, 0x0013_0005));
        assert!(RevisionCheck::EqualOrGreater.accepts(esi, 0x0012_0006));
        assert!(!RevisionCheck::EqualOrGreater.accepts(esi, 0x0012_0004));
        assert!(RevisionCheck::LowWordEqual.accepts(esi, 0x0001_0005));
        assert!(!RevisionCheck::LowWordEqual.accepts(esi, 0x0012_0006));
        let check = RevisionCheck::LowWordEqualHighWordEqualOrGreater;
        assert!(check.accepts(esi, 0x0013_0005));
        assert!(!check.accepts(esi, 0x0011_0005));
        assert!(!check.accepts(esi, 0x0013_0006));
        let id = Identity {
            vendor_id: 2,
            product_code: 0x03F0_3052,
            revision: esi,
            revision_check: RevisionCheck::LowWordEqual,
        };
        assert!(id.matches(2, 0x03F0_3052, 0x0099_0005));
        assert!(!id.matches(3, 0x03F0_3052, esi));
    }
}
