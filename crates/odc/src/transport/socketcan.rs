//! Linux SocketCAN (the `socketcan` crate): a [`Bus`] over a raw CAN socket on an interface
//! such as `can0` or the virtual `vcan0`.
//!
//! Frames a CANopen stack cannot use (CAN error frames) are skipped by `recv`, which then
//! waits for the next frame until the deadline.

use std::io;
use std::time::{Duration, Instant};

use socketcan::{CanSocket, Socket};

use super::Bus;
use crate::can::CanFrame;

/// A [`Bus`] over a SocketCAN interface, with a millisecond clock from its opening.
pub struct SocketCan {
    socket: CanSocket,
    start: Instant,
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
        Self { socket, start: Instant::now() }
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

    fn recv(&mut self, deadline_ms: u64) -> io::Result<Option<CanFrame>> {
        loop {
            let now = self.now_ms();
            if now >= deadline_ms {
                return Ok(None);
            }
            match self.socket.read_frame_timeout(Duration::from_millis(deadline_ms - now)) {
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

    fn now_ms(&mut self) -> u64 {
        u64::try_from(self.start.elapsed().as_millis()).unwrap_or(u64::MAX)
    }
}
