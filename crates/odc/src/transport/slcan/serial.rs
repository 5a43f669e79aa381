//! A [`Bus`] over slcan on a serial port, at either end of the line: the host that drives an
//! adapter (`odc sdo --slcan /dev/ttyACM0`), or the adapter itself (`odc simulate --slcan`:
//! the simulated device behind an slcan adapter that python-can's `slcan` interface opens).
//!
//! The port is the `serialport` crate's: it opens COM ports on Windows and ttys on Linux and
//! macOS the same way, puts a tty in raw mode (a cooked tty would turn each `\r` into `\n`
//! and echo the host's commands back), and makes pseudo-terminal pairs
//! ([`serialport::TTYPort::pair`]) for a simulated adapter. Plain file I/O on a tty would do
//! on Linux alone, and only after the same termios calls.

use std::boxed::Box;
use std::collections::VecDeque;
use std::io::{self, Read, Write};
use std::time::{Duration, Instant};

use serialport::SerialPort;

use super::{Bitrate, Decoder, Message};
use crate::can::CanFrame;
use crate::transport::Bus;

/// The serial line speed for a port opened by name. A USB adapter (CANable, CANUSB) ignores
/// it; a UART adapter is most often set to this.
pub const TTY_BAUD: u32 = 115_200;

/// The version an adapter of ours answers to `V` (hardware 1.0, software 1.0).
const VERSION: [u8; 4] = *b"1010";
/// The serial number it answers to `N`.
const SERIAL_NUMBER: [u8; 4] = *b"0DC1";

/// Which end of the line this is.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Role {
    /// The host: it sends commands and frames to transmit, and reads received frames.
    Host,
    /// The adapter: it answers the host's commands, hands the frames the host transmits to
    /// the bus (here: to whoever calls [`Bus::recv`]) and reports the bus's frames.
    Adapter,
}

/// One end of an slcan line.
pub struct Slcan {
    port: Box<dyn SerialPort>,
    role: Role,
    decoder: Decoder,
    received: VecDeque<CanFrame>,
    start: Instant,
    /// The adapter's state: channel open (`O` or `L`), listen-only, time stamps on.
    open: bool,
    listen_only: bool,
    timestamps: bool,
    /// The bit rate the host last set (adapter) or asked for (host).
    pub bitrate: Option<Bitrate>,
    /// Error answers (BEL) and malformed lines seen.
    pub errors: usize,
    /// Frames sent and received.
    pub frames: usize,
    /// Lines the adapter dropped because nobody read the port (a full pseudo-terminal).
    pub dropped: usize,
}

impl core::fmt::Debug for Slcan {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        f.debug_struct("Slcan")
            .field("port", &self.port.name())
            .field("role", &self.role)
            .field("open", &self.open)
            .field("bitrate", &self.bitrate)
            .field("errors", &self.errors)
            .field("frames", &self.frames)
            .finish_non_exhaustive()
    }
}

impl Slcan {
    /// Opens the adapter at `path` (`/dev/ttyACM0`, `COM3`) as its host and opens its CAN
    /// channel at `bitrate`.
    ///
    /// # Errors
    ///
    /// The port's, on opening or on the first writes.
    pub fn open(path: &str, bitrate: Option<Bitrate>) -> io::Result<Self> {
        let port = serialport::new(path, TTY_BAUD).timeout(Duration::from_millis(100)).open()?;
        Self::host(port, bitrate)
    }

    /// Drives the adapter on `port`: drops what is waiting in its input, closes its channel
    /// (an adapter left open refuses a new bit rate), sets `bitrate` (without one the adapter
    /// keeps the rate it has, as python-can does), and opens it. The
    /// answers are read with the frames and counted in [`Slcan::errors`] when they are BEL
    /// (the first, to a `C` on a closed channel, usually is).
    ///
    /// # Errors
    ///
    /// The port's.
    pub fn host(port: Box<dyn SerialPort>, bitrate: Option<Bitrate>) -> io::Result<Self> {
        let mut this = Self::new(port, Role::Host);
        this.port.clear(serialport::ClearBuffer::Input)?;
        this.write(Message::Close)?;
        if let Some(b) = bitrate {
            this.write(Message::Bitrate(b))?;
        }
        this.write(Message::Open)?;
        this.bitrate = bitrate;
        Ok(this)
    }

    /// Acts as an slcan adapter on `port` (one end of a pseudo-terminal, a serial cable):
    /// the channel is closed until the host opens it.
    pub fn adapter(port: Box<dyn SerialPort>) -> Self {
        Self::new(port, Role::Adapter)
    }

    fn new(port: Box<dyn SerialPort>, role: Role) -> Self {
        Self {
            port,
            role,
            decoder: Decoder::new(),
            received: VecDeque::new(),
            start: Instant::now(),
            open: false,
            listen_only: false,
            timestamps: false,
            bitrate: None,
            errors: 0,
            frames: 0,
            dropped: 0,
        }
    }

    /// This end's role.
    pub const fn role(&self) -> Role {
        self.role
    }

    /// Whether the CAN channel is open (as the adapter knows it).
    pub const fn is_open(&self) -> bool {
        self.open
    }

    /// The host closes the adapter's channel (`C`).
    ///
    /// # Errors
    ///
    /// The port's.
    pub fn close(&mut self) -> io::Result<()> {
        self.write(Message::Close)
    }

    /// Writes one line. An adapter whose host does not read (nobody holds the other end
    /// of a pseudo-terminal, its buffer is full) drops the line, as a real adapter drops
    /// frames on an overrun, instead of stopping the bus.
    fn write(&mut self, message: Message) -> io::Result<()> {
        let written =
            self.port.write_all(message.encode().as_bytes()).and_then(|()| self.port.flush());
        match written {
            Err(e)
                if self.role == Role::Adapter
                    && matches!(e.kind(), io::ErrorKind::TimedOut | io::ErrorKind::WouldBlock) =>
            {
                self.dropped += 1;
                Ok(())
            }
            other => other,
        }
    }

    /// Milliseconds within the minute, for a time stamp.
    fn stamp(&self) -> u16 {
        let ms = self.start.elapsed().as_millis() % u128::from(super::TIMESTAMP_WRAP);
        u16::try_from(ms).unwrap_or(0)
    }

    /// Takes one decoded line: a frame for [`Bus::recv`], or (adapter) a command to answer.
    fn take(&mut self, message: Result<Message, super::DecodeError>) -> io::Result<()> {
        match (self.role, message) {
            (_, Err(_)) | (Role::Host, Ok(Message::Error)) => {
                self.errors += 1;
                if self.role == Role::Adapter {
                    self.write(Message::Error)?;
                }
            }
            (Role::Host, Ok(Message::Frame { frame, .. })) => self.received.push_back(frame),
            // The answers to the host's commands: nothing to do but count the errors.
            (Role::Host, Ok(_)) => {}
            (Role::Adapter, Ok(m)) => self.answer(m)?,
        }
        Ok(())
    }

    /// The adapter's answer to a command, as the Lawicel command set gives it: BEL for a
    /// command the channel's state refuses (a frame on a closed channel, a bit rate on an
    /// open one).
    fn answer(&mut self, message: Message) -> io::Result<()> {
        let closed = !self.open;
        let reply = match message {
            Message::Frame { frame, .. } if self.open && !self.listen_only => {
                self.received.push_back(frame);
                Message::Sent { extended: frame.is_extended() }
            }
            Message::Open | Message::ListenOnly if closed => {
                self.open = true;
                self.listen_only = message == Message::ListenOnly;
                Message::Ok
            }
            Message::Close if self.open => {
                self.open = false;
                Message::Ok
            }
            Message::Bitrate(b) if closed => {
                self.bitrate = Some(b);
                Message::Ok
            }
            Message::Timestamps(on) if closed => {
                self.timestamps = on;
                Message::Ok
            }
            Message::Version => Message::VersionIs(VERSION),
            Message::SerialNumber => Message::SerialNumberIs(SERIAL_NUMBER),
            Message::Status => Message::StatusIs(0),
            // An empty line (python-can sends one for "no FD data rate") and the host's
            // stray answers: nothing.
            Message::Ok
            | Message::Sent { .. }
            | Message::Error
            | Message::VersionIs(_)
            | Message::SerialNumberIs(_)
            | Message::StatusIs(_) => return Ok(()),
            _ => Message::Error,
        };
        self.write(reply)
    }
}

/// A host closes the adapter's channel when it lets the port go, so the adapter stops
/// sending frames nobody reads.
impl Drop for Slcan {
    fn drop(&mut self) {
        if self.role == Role::Host {
            // Best effort: the port may be gone (an unplugged adapter).
            let _ = self.close();
        }
    }
}

impl Bus for Slcan {
    type Error = io::Error;

    /// The host transmits the frame; the adapter reports it as received from the bus, and
    /// drops it while its channel is closed (a closed adapter passes nothing on).
    fn send(&mut self, frame: &CanFrame) -> io::Result<()> {
        let timestamp = match self.role {
            Role::Host => None,
            Role::Adapter if !self.open => return Ok(()),
            Role::Adapter => self.timestamps.then(|| self.stamp()),
        };
        self.frames += 1;
        self.write(Message::Frame { frame: *frame, timestamp })
    }

    /// The next frame: one the adapter received (host), or one the host transmits
    /// (adapter). Commands and answers on the way are handled here.
    fn recv(&mut self, deadline: crate::time::Instant) -> io::Result<Option<CanFrame>> {
        loop {
            if let Some(frame) = self.received.pop_front() {
                self.frames += 1;
                return Ok(Some(frame));
            }
            let now = self.now();
            if now >= deadline {
                return Ok(None);
            }
            self.port.set_timeout((deadline - now).into())?;
            let mut buf = [0u8; 256];
            match self.port.read(&mut buf) {
                Ok(0) => return Err(io::ErrorKind::UnexpectedEof.into()),
                Ok(n) => {
                    for &b in buf.get(..n).unwrap_or(&[]) {
                        if let Some(message) = self.decoder.push(b) {
                            self.take(message)?;
                        }
                    }
                }
                Err(e)
                    if matches!(e.kind(), io::ErrorKind::WouldBlock | io::ErrorKind::TimedOut) =>
                {
                    return Ok(None);
                }
                Err(e) if e.kind() == io::ErrorKind::Interrupted => {}
                Err(e) => return Err(e),
            }
        }
    }

    fn now(&mut self) -> crate::time::Instant {
        crate::time::Instant::since(self.start)
    }
}

#[cfg(all(test, unix))]
#[allow(clippy::unwrap_used)] // The helpers of the tests fail the test on an error.
mod tests {
    use super::*;
    use crate::time::Duration as OdcDuration;
    use serialport::TTYPort;
    use std::vec::Vec;

    /// A pseudo-terminal pair: the host on one end, the adapter on the other.
    fn pair() -> (Slcan, Slcan) {
        let (master, slave) = TTYPort::pair().unwrap();
        let adapter = Slcan::adapter(Box::new(master));
        let host = Slcan::host(Box::new(slave), Some(Bitrate::K500)).unwrap();
        (host, adapter)
    }

    fn within(bus: &mut Slcan, ms: u64) -> Option<CanFrame> {
        let deadline = bus.now() + OdcDuration::from_millis(ms);
        bus.recv(deadline).unwrap()
    }

    #[test]
    fn host_and_adapter_carry_frames_both_ways() {
        let (mut host, mut adapter) = pair();
        // The host's C (refused: closed), S6 and O reach the adapter in its first recv.
        assert_eq!(within(&mut adapter, 200), None);
        assert!(adapter.is_open());
        assert_eq!(adapter.bitrate, Some(Bitrate::K500));
        assert_eq!(adapter.errors, 0);
        let sdo = CanFrame::new(0x605, [0x40, 0x00, 0x10, 0x00, 0, 0, 0, 0]).unwrap();
        host.send(&sdo).unwrap();
        assert_eq!(within(&mut adapter, 2000), Some(sdo));
        let ext = CanFrame::remote_extended(0x1234_5678, 4).unwrap();
        adapter.send(&ext).unwrap();
        assert_eq!(within(&mut host, 2000), Some(ext));
        // The host saw BEL (C on a closed channel), then OK, OK, and `z` for its frame.
        assert_eq!(host.errors, 1);
    }

    #[test]
    fn a_closed_adapter_refuses_frames_and_passes_none_on() {
        let (master, slave) = TTYPort::pair().unwrap();
        let mut adapter = Slcan::adapter(Box::new(master));
        let mut raw: Box<dyn SerialPort> = Box::new(slave);
        raw.write_all(b"t1000\r").unwrap();
        assert_eq!(within(&mut adapter, 200), None);
        adapter.send(&CanFrame::from_slice(0x705, &[0]).unwrap()).unwrap();
        // Time stamps on, then open: frames carry 4 more digits.
        raw.write_all(b"Z1\rO\rS4\r").unwrap();
        assert_eq!(within(&mut adapter, 200), None);
        adapter.send(&CanFrame::from_slice(0x705, &[0x05]).unwrap()).unwrap();
        raw.set_timeout(std::time::Duration::from_millis(500)).unwrap();
        let mut got = Vec::new();
        let mut buf = [0u8; 64];
        while got.len() < 16 {
            let n = raw.read(&mut buf).unwrap();
            got.extend_from_slice(&buf[..n]);
        }
        // BEL for the frame on the closed channel, OK for Z1 and O, BEL for S4 (open), then
        // the frame: nothing for the heartbeat sent while closed.
        assert_eq!(&got[..5], b"\x07\r\r\x07t");
        assert_eq!(&got[4..11], b"t705105");
        assert_eq!(got.len(), 16, "{:?}", std::string::String::from_utf8_lossy(&got));
        assert_eq!(got[15], b'\r');
        assert!(got[11..15].iter().all(u8::is_ascii_hexdigit));
    }
}
