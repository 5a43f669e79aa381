//! Transports: how frames reach a CAN bus. One small trait, [`Bus`], and adapters behind
//! features, so the SDO client (and a node's main loop) is written once for any interface.
//!
//! - `mem` (`std`): an in-memory bus with any number of ports, for tests and simulation;
//! - `embedded_can` (`embedded-can`): any MCU HAL that implements the `embedded_can`
//!   traits, with the conversions between [`CanFrame`] and `embedded_can::Frame` types;
//! - `socketcan` (`socketcan`, Linux): a SocketCAN interface (`can0`, `vcan0`);
//! - `tcp` (`std`): the 16-byte SocketCAN-layout records over TCP of `tests/interop`.

use crate::can::CanFrame;
use crate::time::Instant;

#[cfg(feature = "embedded-can")]
pub mod embedded_can;
#[cfg(all(feature = "std", feature = "transport-mem"))]
pub mod mem;
#[cfg(all(feature = "socketcan", target_os = "linux"))]
pub mod socketcan;
#[cfg(all(feature = "std", feature = "transport-tcp"))]
pub mod tcp;

/// What the blocking SDO client (and a node's loop) need from a CAN interface and a clock.
pub trait Bus {
    /// The interface's error.
    type Error;

    /// Sends a frame.
    ///
    /// # Errors
    ///
    /// When the interface fails.
    fn send(&mut self, frame: &CanFrame) -> Result<(), Self::Error>;

    /// The next received frame, waiting until the clock ([`Bus::now`]) reaches `deadline` at
    /// the latest; `None` if nothing arrived by then.
    ///
    /// # Errors
    ///
    /// When the interface fails.
    fn recv(&mut self, deadline: Instant) -> Result<Option<CanFrame>, Self::Error>;

    /// The interface's monotonic clock: the time base of `recv`'s deadline and of every
    /// timeout the SDO client and the master keep.
    fn now(&mut self) -> Instant;
}

/// A borrowed bus is a bus: a master or client can work on one it does not own.
impl<B: Bus + ?Sized> Bus for &mut B {
    type Error = B::Error;

    fn send(&mut self, frame: &CanFrame) -> Result<(), B::Error> {
        (**self).send(frame)
    }

    fn recv(&mut self, deadline: Instant) -> Result<Option<CanFrame>, B::Error> {
        (**self).recv(deadline)
    }

    fn now(&mut self) -> Instant {
        (**self).now()
    }
}
