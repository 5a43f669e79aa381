//! odc on an [ethercrab](https://docs.rs/ethercrab) master (feature `ethercrab`).
//!
//! - [`configure`] runs a generated [`Startup`] on a SubDevice in PRE-OP, after checking its
//!   identity;
//! - [`sdo_read`] and [`sdo_write`] take generated [`Entry`] descriptors, so the object and
//!   its value type come from the device file, not from the call site;
//! - [`impl_wire!`](crate::impl_wire) gives a generated process image `ethercrab_wire`'s
//!   traits, so `pdi::Inputs::unpack_from_slice(&subdevice.inputs_raw())` works.
//!
//! ethercrab names its traits in `ethercrab_wire`, re-exported here as [`wire`] so that
//! generated code needs no dependency of its own.

use core::fmt;

pub use ethercrab::{DcSync, SubDevice, SubDeviceRef, SubIndex};
pub use ethercrab_wire as wire;
use ethercrab_wire::{EtherCrabWireRead, EtherCrabWireSized, WireError};

use super::{DcOpMode, Identity, Startup};
use crate::{Entry, ObjValue};

/// Why [`configure`] stopped.
#[derive(Debug)]
pub enum ConfigureError {
    /// The SubDevice is another device than the one the code was generated for.
    WrongDevice {
        /// The identity of the ESI.
        expected: Identity,
        /// What the SubDevice reports.
        found: Identity,
    },
    /// A complete-access download starting at sub-index 0, which ethercrab cannot send (its
    /// complete access always starts at sub-index 1).
    Unsupported {
        /// The object.
        index: u16,
    },
    /// An SDO download failed.
    Sdo {
        /// The object.
        index: u16,
        /// The sub-index.
        sub: u8,
        /// What ethercrab reported.
        error: ethercrab::error::Error,
    },
}

impl fmt::Display for ConfigureError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Self::WrongDevice { expected, found } => write!(
                f,
                "expected vendor {:#010x} product {:#010x} revision {:#010x}, the SubDevice is \
                 vendor {:#010x} product {:#010x} revision {:#010x}",
                expected.vendor_id,
                expected.product_code,
                expected.revision,
                found.vendor_id,
                found.product_code,
                found.revision
            ),
            Self::Unsupported { index } => {
                write!(f, "complete access to {index:#06x} from sub-index 0 is not supported")
            }
            Self::Sdo { index, sub, error } => {
                write!(f, "SDO download {index:#06x}:{sub:02x} failed: {error}")
            }
        }
    }
}

impl core::error::Error for ConfigureError {}

/// Checks the SubDevice's identity against the plan's, then sends the plan's SDO downloads (the
/// init commands) and its process-data writes ([`Startup::pdo_writes`]) in
/// order. Call it in PRE-OP (ethercrab's `init_single_group` leaves SubDevices there), before
/// `into_op`, which then sizes the process image from what was written.
///
/// The identity check compares vendor and product code, and the revision as the ESI's
/// `CheckRevisionNo` says ([`Identity::matches`]).
///
/// # Errors
///
/// [`ConfigureError`]: the wrong device, or the first download that failed.
pub async fn configure<S>(
    subdevice: &SubDeviceRef<'_, S>,
    plan: &Startup,
) -> Result<(), ConfigureError>
where
    S: core::ops::Deref<Target = ethercrab::SubDevice>,
{
    let id = subdevice.identity();
    if !plan.identity.matches(id.vendor_id, id.product_id, id.revision) {
        let found = Identity {
            vendor_id: id.vendor_id,
            product_code: id.product_id,
            revision: id.revision,
            revision_check: plan.identity.revision_check,
        };
        return Err(ConfigureError::WrongDevice { expected: plan.identity, found });
    }
    for d in plan.downloads {
        let sub = match (d.complete_access, d.sub) {
            (false, sub) => SubIndex::Index(sub),
            (true, 1) => SubIndex::Complete,
            (true, _) => return Err(ConfigureError::Unsupported { index: d.index }),
        };
        subdevice.sdo_write(d.index, sub, d.data).await.map_err(|error| ConfigureError::Sdo {
            index: d.index,
            sub: d.sub,
            error,
        })?;
    }
    for w in plan.pdo_writes {
        let (bytes, n) = w.to_le_bytes();
        let data = bytes.get(..n).unwrap_or(&bytes);
        subdevice
            .sdo_write(w.index, SubIndex::Index(w.sub), data)
            .await
            .map_err(|error| ConfigureError::Sdo { index: w.index, sub: w.sub, error })?;
    }
    Ok(())
}

/// The SYNC signals of a DC op-mode (its `AssignActivate`, whose high byte goes to the ESC's
/// register 0x0981: bit 0 cyclic operation, bit 1 SYNC0, bit 2 SYNC1) as ethercrab's
/// [`DcSync`], for `SubDeviceRef::set_dc_sync` in PRE-OP. SYNC1's period is the op-mode's
/// `CycleTimeSync1` when it gives one, else `sync1_period`.
pub fn dc_sync(mode: &DcOpMode, sync1_period: core::time::Duration) -> DcSync {
    let activate = (mode.assign_activate >> 8) as u8;
    let cyclic_sync0 = activate & 0b011 == 0b011;
    match (cyclic_sync0, activate & 0b100 != 0) {
        (false, _) => DcSync::Disabled,
        (true, false) => DcSync::Sync0,
        (true, true) => DcSync::Sync01 {
            sync1_period: match mode.cycle_time_sync1 {
                0 => sync1_period,
                ns => core::time::Duration::from_nanos(u64::from(ns)),
            },
        },
    }
}

/// Reads the object `entry` describes, as its value type.
///
/// # Errors
///
/// ethercrab's error; a reply that is not a value of the type is
/// `Error::Wire(WireError::InvalidValue)`.
pub async fn sdo_read<T: ObjValue, S>(
    subdevice: &SubDeviceRef<'_, S>,
    entry: &Entry<T>,
) -> Result<T, ethercrab::error::Error>
where
    S: core::ops::Deref<Target = ethercrab::SubDevice>,
{
    let v: Wire<T> = subdevice.sdo_read(entry.addr.index, entry.addr.sub).await?;
    Ok(v.0)
}

/// Writes `value` to the object `entry` describes.
///
/// # Errors
///
/// ethercrab's error; a value that cannot be encoded is `Error::Wire(WireError::InvalidValue)`.
pub async fn sdo_write<T: ObjValue, S>(
    subdevice: &SubDeviceRef<'_, S>,
    entry: &Entry<T>,
    value: T,
) -> Result<(), ethercrab::error::Error>
where
    S: core::ops::Deref<Target = ethercrab::SubDevice>,
{
    let mut buf = [0u8; WIRE_BUF];
    let n = value.encode(&mut buf).map_err(|_| WireError::InvalidValue)?;
    let bytes = buf.get(..n).ok_or(WireError::WriteBufferTooShort)?;
    subdevice.sdo_write(entry.addr.index, entry.addr.sub, bytes).await
}

/// Largest value [`sdo_read`] and [`sdo_write`] carry, in bytes: the visible strings and
/// domains of a dictionary are longer than any number, and ethercrab needs a fixed buffer.
const WIRE_BUF: usize = 256;

/// An [`ObjValue`] as ethercrab reads it: the object's bytes decoded by odc's rules.
struct Wire<T>(T);

impl<T: ObjValue> EtherCrabWireRead for Wire<T> {
    fn unpack_from_slice(buf: &[u8]) -> Result<Self, WireError> {
        // Some devices answer a short value in a 4-byte expedited reply: the value's own
        // bytes are the first ones.
        let exact = buf.get(..T::MAX_LEN.min(buf.len())).unwrap_or(buf);
        T::decode(buf).or_else(|_| T::decode(exact)).map(Wire).map_err(|_| WireError::InvalidValue)
    }
}

impl<T: ObjValue> EtherCrabWireSized for Wire<T> {
    const PACKED_LEN: usize = WIRE_BUF;
    type Buffer = [u8; WIRE_BUF];
    fn buffer() -> Self::Buffer {
        [0; WIRE_BUF]
    }
}

/// The `ethercrab_wire` traits for a generated process image (a `#[derive(odc::Pdo)]`
/// struct): `EtherCrabWireRead`, `EtherCrabWireWrite` and `EtherCrabWireSized`, through the
/// struct's own `unpack` and `pack_into`. Without the feature `ethercrab` it expands to
/// nothing, so generated code can always invoke it.
///
/// `pack_to_slice` reports a field whose value does not fit its mapped width as
/// `WireError::InvalidValue`; `pack_to_slice_unchecked`, which cannot report, then returns an
/// empty slice (nothing packed), and panics only where ethercrab's contract asks it to: when
/// the buffer is too short.
#[macro_export]
macro_rules! impl_wire {
    ($($ty:ty),* $(,)?) => {$(
        impl $crate::ethercat::ethercrab::wire::EtherCrabWireRead for $ty {
            fn unpack_from_slice(
                buf: &[u8],
            ) -> ::core::result::Result<Self, $crate::ethercat::ethercrab::wire::WireError> {
                <$ty as $crate::Pdo>::unpack(buf).map_err(|e| match e {
                    $crate::UnpackError::BufferTooSmall { .. } => {
                        $crate::ethercat::ethercrab::wire::WireError::ReadBufferTooShort
                    }
                    _ => $crate::ethercat::ethercrab::wire::WireError::InvalidValue,
                })
            }
        }
        impl $crate::ethercat::ethercrab::wire::EtherCrabWireWrite for $ty {
            fn pack_to_slice<'buf>(
                &self,
                buf: &'buf mut [u8],
            ) -> ::core::result::Result<&'buf [u8], $crate::ethercat::ethercrab::wire::WireError> {
                let len = <$ty as $crate::Pdo>::LEN;
                match <$ty as $crate::Pdo>::pack_into(self, buf) {
                    ::core::result::Result::Ok(()) => ::core::result::Result::Ok(&buf[..len]),
                    ::core::result::Result::Err($crate::PackError::BufferTooSmall { .. }) => {
                        ::core::result::Result::Err(
                            $crate::ethercat::ethercrab::wire::WireError::WriteBufferTooShort,
                        )
                    }
                    ::core::result::Result::Err(_) => ::core::result::Result::Err(
                        $crate::ethercat::ethercrab::wire::WireError::InvalidValue,
                    ),
                }
            }
            fn pack_to_slice_unchecked<'buf>(&self, buf: &'buf mut [u8]) -> &'buf [u8] {
                let len = <$ty as $crate::Pdo>::LEN;
                // ethercrab's contract: a short buffer panics here.
                assert!(buf.len() >= len, "process image buffer too short");
                match <$ty as $crate::Pdo>::pack_into(self, buf) {
                    ::core::result::Result::Ok(()) => &buf[..len],
                    ::core::result::Result::Err(_) => &buf[..0],
                }
            }
            fn packed_len(&self) -> usize {
                <$ty as $crate::Pdo>::LEN
            }
        }
        impl $crate::ethercat::ethercrab::wire::EtherCrabWireSized for $ty {
            const PACKED_LEN: usize = <$ty as $crate::Pdo>::LEN;
            type Buffer = <$ty as $crate::Pdo>::Buffer;
            fn buffer() -> Self::Buffer {
                [0; <$ty as $crate::Pdo>::LEN]
            }
        }
    )*};
}

/// `pub async fn configure(subdevice)` running the given [`Startup`], for generated
/// `startup` modules; nothing without the feature `ethercrab`.
#[macro_export]
macro_rules! configure_fn {
    ($plan:path) => {
        /// Checks the SubDevice's identity, then writes the start-up of the default process
        /// data to it (in PRE-OP, before `into_op`).
        ///
        /// # Errors
        ///
        /// The wrong device, or the first SDO download that failed.
        pub async fn configure<S>(
            subdevice: &$crate::ethercat::ethercrab::SubDeviceRef<'_, S>,
        ) -> ::core::result::Result<(), $crate::ethercat::ethercrab::ConfigureError>
        where
            S: ::core::ops::Deref<Target = $crate::ethercat::ethercrab::SubDevice>,
        {
            $crate::ethercat::ethercrab::configure(subdevice, &$plan).await
        }
    };
}

#[cfg(test)]
mod tests {
    use core::time::Duration;

    use super::*;

    fn mode(assign_activate: u16, cycle_time_sync1: u32) -> DcOpMode {
        DcOpMode {
            name: "m",
            assign_activate,
            cycle_time_sync0: 0,
            shift_time_sync0: 0,
            cycle_time_sync1,
        }
    }

    #[test]
    fn sdo_values_through_the_wire_type() {
        // A UNSIGNED16 in its own two bytes, and in a 4-byte expedited reply.
        assert_eq!(Wire::<u16>::unpack_from_slice(&[0x34, 0x12]).map(|w| w.0), Ok(0x1234));
        assert_eq!(Wire::<u16>::unpack_from_slice(&[0x34, 0x12, 0, 0]).map(|w| w.0), Ok(0x1234));
        assert_eq!(
            Wire::<crate::cia402::Controlword>::unpack_from_slice(&[0x0F, 0x00]).map(|w| w.0),
            Ok(crate::cia402::Controlword::ENABLE_OPERATION)
        );
        // Too short for the type.
        assert_eq!(
            Wire::<u32>::unpack_from_slice(&[1, 2]).map(|w| w.0),
            Err(WireError::InvalidValue)
        );
    }

    #[test]
    fn assign_activate_to_dc_sync() {
        let bus = Duration::from_millis(1);
        assert_eq!(dc_sync(&mode(0x0000, 0), bus), DcSync::Disabled);
        // SYNC0 without cyclic operation does not run.
        assert_eq!(dc_sync(&mode(0x0200, 0), bus), DcSync::Disabled);
        assert_eq!(dc_sync(&mode(0x0300, 0), bus), DcSync::Sync0);
        assert_eq!(dc_sync(&mode(0x0700, 0), bus), DcSync::Sync01 { sync1_period: bus });
        assert_eq!(
            dc_sync(&mode(0x0700, 250_000), bus),
            DcSync::Sync01 { sync1_period: Duration::from_micros(250) }
        );
    }
}
