//! Transports: how frames reach a CAN bus. One small trait, [`Bus`], and adapters behind
//! features, so the SDO client (and a node's main loop) is written once for any interface.
//!
//! - `mem` (`std`): an in-memory bus with any number of ports, for tests and simulation;
//! - `embedded_can` (`embedded-can`): any MCU HAL that implements the `embedded_can`
//!   traits, with the conversions between [`CanFrame`] and `embedded_can::Frame` types;
//! - `socketcan` (`socketcan`, Linux): a SocketCAN interface (`can0`, `vcan0`);
//! - `tcp` (`std`): the 16-byte SocketCAN-layout records over TCP of `tests/interop`;
//! - `socketcand` (`std`): the ASCII protocol of a socketcand server, in raw mode.
//! - `slcan` (`slcan`): the Lawicel serial protocol's codec, and with `slcan-serial` a bus
//!   over an slcan adapter (CANable, CANUSB) on a serial port.

use crate::can::CanFrame;
use crate::time::Instant;

#[cfg(feature = "embedded-can")]
pub mod embedded_can;
#[cfg(all(feature = "std", feature = "transport-mem"))]
pub mod mem;
#[cfg(feature = "slcan")]
pub mod slcan;
#[cfg(all(feature = "socketcan", target_os = "linux"))]
pub mod socketcan;
#[cfg(all(feature = "std", feature = "transport-socketcand"))]
pub mod socketcand;
#[cfg(all(feature = "std", feature = "transport-tcp"))]
pub mod tcp;

/// One read of a blocking TCP stream that gives up after `wait`: `Some(n)` bytes read into
/// `buf` (0 after an interrupted read: look at the clock again), `None` when nothing came in
/// time. The receive loop of the TCP virtual bus and of socketcand.
///
/// # Errors
///
/// `UnexpectedEof` once the peer closed the connection; the socket's own.
#[cfg(all(feature = "std", any(feature = "transport-tcp", feature = "transport-socketcand")))]
fn read_within(
    stream: &mut std::net::TcpStream,
    wait: core::time::Duration,
    buf: &mut [u8],
) -> std::io::Result<Option<usize>> {
    use std::io::{ErrorKind, Read};
    stream.set_read_timeout(Some(wait))?;
    match stream.read(buf) {
        Ok(0) => Err(ErrorKind::UnexpectedEof.into()),
        Ok(n) => Ok(Some(n)),
        Err(e) if matches!(e.kind(), ErrorKind::WouldBlock | ErrorKind::TimedOut) => Ok(None),
        Err(e) if e.kind() == ErrorKind::Interrupted => Ok(Some(0)),
        Err(e) => Err(e),
    }
}

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
