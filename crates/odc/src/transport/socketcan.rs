//! Linux SocketCAN (the `socketcan` crate): a [`Bus`] over a raw CAN socket on an interface
//! such as `can0` or the virtual `vcan0`.
//!
//! Frames a CANopen stack cannot use (CAN error frames) are skipped by `recv`, which then
//! waits for the next frame until the deadline.

use std::io;
use std::time::Instant as StdInstant;

use socketcan::{CanSocket, Socket};

use super::Bus;
use crate::can::CanFrame;
use crate::time::Instant;

/// A [`Bus`] over a SocketCAN interface, with a clock from its opening.
pub struct SocketCan {
    socket: CanSocket,
    start: StdInstant,
}

impl SocketCan {
    /// Opens interface `ifname` (`"can0"`, `"vcan0"`).
    ///
    /// # Errors
    ///
    /// When the interface does not exist or the socket cannot be opened.
    pub fn open(ifname: &str) -> io::Result<Self> {
        Ok(Self::from_socket(CanSocket::open(ifname)?))
    }

    /// Wraps an open socket (with the filters the caller set).
    pub fn from_socket(socket: CanSocket) -> Self {
        Self { socket, start: StdInstant::now() }
    }

    /// The socket.
    pub fn socket(&self) -> &CanSocket {
        &self.socket
    }
}

impl Bus for SocketCan {
    type Error = io::Error;

    fn send(&mut self, frame: &CanFrame) -> io::Result<()> {
        let f: socketcan::CanFrame = frame.to_frame().ok_or_else(|| {
            io::Error::new(io::ErrorKind::InvalidInput, "CAN id too wide for its frame format")
        })?;
        self.socket.write_frame_insist(&f)
    }

    fn recv(&mut self, deadline: Instant) -> io::Result<Option<CanFrame>> {
        loop {
            let now = self.now();
            if now >= deadline {
                return Ok(None);
            }
            match self.socket.read_frame_timeout((deadline - now).into()) {
                Ok(socketcan::CanFrame::Error(_)) => {}
                Ok(f) => return Ok(Some(CanFrame::from_frame(&f))),
                Err(e)
                    if matches!(e.kind(), io::ErrorKind::TimedOut | io::ErrorKind::WouldBlock) =>
                {
                    return Ok(None);
                }
                Err(e) if e.kind() == io::ErrorKind::Interrupted => {}
                Err(e) => return Err(e),
            }
        }
    }

    fn now(&mut self) -> Instant {
        Instant::since(self.start)
    }
}
