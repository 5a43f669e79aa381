//! CAN frames over a TCP stream: one 16-byte record per frame, the layout of Linux SocketCAN's
//! `struct can_frame` in little-endian (the format of `tests/interop` and of `odc simulate
//! --tcp`, and of `tests/interop/python/socketbus.py` on the python-can side):
//!
//! | bytes | field |
//! |---|---|
//! | 0–3 | CAN identifier, u32 LE; bit 31 = 29-bit identifier, bit 30 = remote frame (RTR) |
//! | 4 | data length code, 0–8 |
//! | 5–7 | zero |
//! | 8–15 | data, zero-padded |
//!
//! Why not a CAN-over-IP standard: SocketCAN's record is what Linux tools and python-can
//! already speak, needs no framing beyond its fixed length, and a record read from a stream
//! is a `can_frame` a test can hand to a real interface unchanged.
//!
//! ```
//! use odc::can::CanFrame;
//! use odc::transport::tcp::{decode, encode};
//!
//! let sdo = CanFrame::new(0x605, [0x40, 0x00, 0x10, 0x00, 0, 0, 0, 0]).unwrap();
//! let record = encode(&sdo);
//! assert_eq!(record[..8], [0x05, 0x06, 0, 0, 8, 0, 0, 0]);
//! assert_eq!(decode(&record), Ok(sdo));
//! ```

use std::io::{self, Write};
use std::net::{Shutdown, TcpStream};
use std::time::Instant;
use std::vec::Vec;

use crate::can::CanFrame;
use crate::transport::Bus;

/// Bytes per frame record.
pub const RECORD_LEN: usize = 16;

/// Bit 31 of the identifier word: a 29-bit (extended) identifier.
pub const EXTENDED_FLAG: u32 = 0x8000_0000;
/// Bit 30 of the identifier word: a remote (RTR) frame.
pub const REMOTE_FLAG: u32 = 0x4000_0000;
/// The identifier bits of the identifier word.
pub const ID_MASK: u32 = 0x1FFF_FFFF;

/// Why a record is not a frame.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum DecodeError {
    /// The data length code is over 8 (CAN FD is not part of the format).
    Length(u8),
    /// An 11-bit identifier above 0x7FF (bit 31 clear).
    Identifier(u32),
}

impl core::fmt::Display for DecodeError {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        match self {
            Self::Length(n) => write!(f, "CAN frame record with data length {n} (at most 8)"),
            Self::Identifier(id) => {
                write!(f, "CAN frame record with 11-bit identifier 0x{id:X} (above 0x7FF)")
            }
        }
    }
}

impl core::error::Error for DecodeError {}

/// The record of `frame`. A remote frame's length is the length it asks for, and its data is
/// sent as zeros.
pub fn encode(frame: &CanFrame) -> [u8; RECORD_LEN] {
    let (extended, remote) = (frame.extended, frame.remote);
    let mut word = frame.id & ID_MASK;
    if extended {
        word |= EXTENDED_FLAG;
    }
    if remote {
        word |= REMOTE_FLAG;
    }
    let mut record = [0u8; RECORD_LEN];
    let (head, data) = record.split_at_mut(8);
    head[..4].copy_from_slice(&word.to_le_bytes());
    head[4] = frame.len.min(8);
    if !remote {
        let n = usize::from(frame.len.min(8));
        data[..n].copy_from_slice(&frame.data[..n]);
    }
    record
}

/// The frame of a record. Bytes 5–7 and data bytes past the length are ignored, as SocketCAN
/// does.
///
/// # Errors
///
/// [`DecodeError`]: a length over 8, or an 11-bit identifier over 0x7FF.
pub fn decode(record: &[u8; RECORD_LEN]) -> Result<CanFrame, DecodeError> {
    let [w0, w1, w2, w3, len, _, _, _, data @ ..] = *record;
    let word = u32::from_le_bytes([w0, w1, w2, w3]);
    let (extended, remote) = (word & EXTENDED_FLAG != 0, word & REMOTE_FLAG != 0);
    let id = word & ID_MASK;
    if len > 8 {
        return Err(DecodeError::Length(len));
    }
    if !extended && id > 0x7FF {
        return Err(DecodeError::Identifier(id));
    }
    let mut frame = CanFrame { id, extended, remote, len, data: [0; 8] };
    if !remote {
        let n = usize::from(len);
        frame.data[..n].copy_from_slice(&data[..n]);
    }
    Ok(frame)
}

/// Splits a byte stream into records: bytes in as they arrive, whole frames out.
#[derive(Clone, Debug, Default)]
pub struct Decoder {
    pending: Vec<u8>,
}

impl Decoder {
    /// An empty decoder.
    pub const fn new() -> Self {
        Self { pending: Vec::new() }
    }

    /// Appends received bytes.
    pub fn push(&mut self, bytes: &[u8]) {
        self.pending.extend_from_slice(bytes);
    }

    /// The next whole record's frame, if one is buffered.
    ///
    /// # Errors
    ///
    /// The record's [`DecodeError`]; the record is consumed, so the stream stays aligned.
    pub fn next_frame(&mut self) -> Option<Result<CanFrame, DecodeError>> {
        let record: [u8; RECORD_LEN] = self.pending.get(..RECORD_LEN)?.try_into().ok()?;
        self.pending.drain(..RECORD_LEN);
        Some(decode(&record))
    }
}

/// One end of a TCP CAN link, with a clock since it was made: a [`Bus`].
#[derive(Debug)]
pub struct TcpCan {
    stream: TcpStream,
    decoder: Decoder,
    start: Instant,
    /// Frames sent and received.
    pub frames: usize,
}

impl TcpCan {
    /// Wraps a connected stream (and turns Nagle's algorithm off: a CAN frame is one small
    /// write that must go out at once).
    ///
    /// # Errors
    ///
    /// The socket option's.
    pub fn new(stream: TcpStream) -> io::Result<Self> {
        stream.set_nodelay(true)?;
        Ok(Self { stream, decoder: Decoder::new(), start: Instant::now(), frames: 0 })
    }

    /// Connects to `addr` (`"127.0.0.1:5000"`).
    ///
    /// # Errors
    ///
    /// The connection's.
    pub fn connect(addr: impl std::net::ToSocketAddrs) -> io::Result<Self> {
        Self::new(TcpStream::connect(addr)?)
    }

    /// Closes both directions; the peer reads the end of the stream.
    ///
    /// # Errors
    ///
    /// The socket's.
    pub fn shutdown(&self) -> io::Result<()> {
        self.stream.shutdown(Shutdown::Both)
    }
}

impl Bus for TcpCan {
    type Error = io::Error;

    fn send(&mut self, frame: &CanFrame) -> io::Result<()> {
        self.frames += 1;
        self.stream.write_all(&encode(frame))
    }

    /// `Err(UnexpectedEof)` once the peer closed the connection, `Err(InvalidData)` for a
    /// record that is no frame.
    fn recv(&mut self, deadline: crate::time::Instant) -> io::Result<Option<CanFrame>> {
        loop {
            if let Some(frame) = self.decoder.next_frame() {
                self.frames += 1;
                return frame.map(Some).map_err(|e| io::Error::new(io::ErrorKind::InvalidData, e));
            }
            let now = self.now();
            if now >= deadline {
                return Ok(None);
            }
            let mut buf = [0u8; 1024];
            match super::read_within(&mut self.stream, (deadline - now).into(), &mut buf)? {
                Some(n) => self.decoder.push(buf.get(..n).unwrap_or(&[])),
                None => return Ok(None),
            }
        }
    }

    fn now(&mut self) -> crate::time::Instant {
        crate::time::Instant::since(self.start)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn records_have_the_socketcan_layout() {
        // A heartbeat of node 5 in pre-operational: 0x705, one byte 0x7F.
        let hb = CanFrame::from_slice(0x705, &[0x7F]).unwrap();
        let r = encode(&hb);
        assert_eq!(r, [0x05, 0x07, 0, 0, 1, 0, 0, 0, 0x7F, 0, 0, 0, 0, 0, 0, 0]);
        assert_eq!(decode(&r), Ok(hb));
    }

    #[test]
    fn bad_records_are_errors() {
        let mut r = encode(&CanFrame::new(0x181, [1; 8]).unwrap());
        r[4] = 9;
        assert_eq!(decode(&r), Err(DecodeError::Length(9)));
        // An 11-bit record with identifier 0x800 (no CanFrame holds one: written by hand).
        let mut r = encode(&CanFrame::new(0x000, [0; 8]).unwrap());
        r[1] = 0x08;
        assert_eq!(decode(&r), Err(DecodeError::Identifier(0x800)));
        // Bit 31 (extended) and bit 30 (remote) are read, not masked away.
        let mut r = encode(&CanFrame::new(0x705, [0; 8]).unwrap());
        r[3] = 0x40;
        r[4] = 1;
        assert_eq!(decode(&r), Ok(CanFrame::remote(0x705, 1).unwrap()));
        r[3] = 0x80;
        let extended = CanFrame::extended(0x705, &[0]).unwrap();
        assert_eq!(decode(&r), Ok(extended));
        assert_eq!(encode(&extended), r);
    }

    #[test]
    fn decoder_splits_a_stream() {
        let a = CanFrame::from_slice(0x000, &[1, 5]).unwrap();
        let b = CanFrame::new(0x605, [0x40, 0, 0x10, 0, 0, 0, 0, 0]).unwrap();
        let bytes: Vec<u8> = [encode(&a), encode(&b)].concat();
        let mut d = Decoder::new();
        d.push(&bytes[..10]);
        assert_eq!(d.next_frame(), None);
        d.push(&bytes[10..]);
        assert_eq!(d.next_frame(), Some(Ok(a)));
        assert_eq!(d.next_frame(), Some(Ok(b)));
        assert_eq!(d.next_frame(), None);
    }

    #[test]
    fn tcp_link_carries_frames_both_ways() {
        let listener = std::net::TcpListener::bind("127.0.0.1:0").unwrap();
        let addr = listener.local_addr().unwrap();
        let mut client = TcpCan::connect(addr).unwrap();
        let mut server = TcpCan::new(listener.accept().unwrap().0).unwrap();
        let f = CanFrame::new(0x605, [0x40, 0x00, 0x10, 0x00, 0, 0, 0, 0]).unwrap();
        client.send(&f).unwrap();
        let deadline = server.now() + crate::time::Duration::from_secs(5);
        assert_eq!(server.recv(deadline).unwrap(), Some(f));
        server.send(&f).unwrap();
        let deadline = client.now() + crate::time::Duration::from_secs(5);
        assert_eq!(client.recv(deadline).unwrap(), Some(f));
        client.shutdown().unwrap();
        let deadline = server.now() + crate::time::Duration::from_secs(5);
        assert_eq!(server.recv(deadline).unwrap_err().kind(), io::ErrorKind::UnexpectedEof);
    }
}
