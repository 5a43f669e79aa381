//! slcan, the Lawicel serial protocol of CANUSB, CAN232, CANable and many cheap USB-CAN
//! adapters: ASCII lines over a serial port, each ended by a carriage return (`\r`).
//!
//! This module is the `no_std`, allocation-free codec of both ends: a [`Decoder`] that splits
//! received bytes into [`Message`]s, and [`Message::encode`] that writes one into a [`Line`].
//! The same [`Message`] serves the host (it sends commands and frames, it receives frames and
//! answers) and the adapter (the other way round), so a firmware that *is* an slcan adapter
//! uses this codec as `odc simulate --slcan` does. The serial-port [`Bus`](super::Bus) is
//! `serial` (feature `slcan-serial`).
//!
//! What is read and written, after the LAWICEL CANUSB manual's "ASCII Command Set" (the
//! protocol's origin), which compatible adapters repeat (EasySYNC USB2-F-7x01 user guide §4.1,
//! the CANable firmware's command list):
//!
//! | line | meaning | answer |
//! |---|---|---|
//! | `O` / `L` / `C` | open the channel / open it listen-only / close it | `\r`, or BEL |
//! | `S0`–`S8` | bit rate 10, 20, 50, 100, 125, 250, 500, 800 kbit/s, 1 Mbit/s | `\r`, or BEL |
//! | `Z0` / `Z1` | received frames without / with a time stamp | `\r`, or BEL |
//! | `tiiildd…` | an 11-bit data frame: 3 hex digits of identifier, length 0–8, data | `z\r` |
//! | `Tiiiiiiiildd…` | a 29-bit data frame: 8 hex digits of identifier | `Z\r` |
//! | `riiil` / `Riiiiiiiil` | an 11-bit / 29-bit remote frame asking for `l` bytes | `z\r` / `Z\r` |
//! | `V` / `N` / `F` | version / serial number / status flags | `Vhhss\r` / `Nxxxx\r` / `Fxx\r` |
//!
//! A frame the adapter received carries, when time stamps are on (`Z1`), 4 more hex digits:
//! milliseconds 0x0000–0xEA5F, wrapping each minute. An error answer is the BEL byte (`\a`,
//! 0x07) with no `\r`. Hex digits are written in upper case and read in either case.
//!
//! ```
//! use odc::can::CanFrame;
//! use odc::transport::slcan::{Decoder, Message};
//!
//! let sdo = CanFrame::new(0x605, [0x40, 0x00, 0x10, 0x00, 0, 0, 0, 0]).unwrap();
//! let line = Message::Frame { frame: sdo, timestamp: None }.encode();
//! assert_eq!(line.as_bytes(), b"t60584000100000000000\r");
//! let mut decoder = Decoder::new();
//! let got: Vec<_> = line.as_bytes().iter().filter_map(|&b| decoder.push(b)).collect();
//! assert_eq!(got, [Ok(Message::Frame { frame: sdo, timestamp: None })]);
//! ```

use crate::can::CanFrame;

#[cfg(all(feature = "std", feature = "slcan-serial"))]
pub mod serial;

/// The carriage return that ends every line and is the "OK" answer.
pub const CR: u8 = b'\r';
/// The BEL byte, the error answer.
pub const BEL: u8 = 0x07;
/// The longest line: `T`, 8 + 1 + 16 + 4 hex digits, `\r`.
pub const MAX_LINE: usize = 31;
/// Time stamps count milliseconds and wrap after one minute (0xEA5F is the largest).
pub const TIMESTAMP_WRAP: u16 = 60_000;

/// The bit rates of `S0`–`S8`.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Bitrate {
    /// `S0`: 10 kbit/s.
    K10,
    /// `S1`: 20 kbit/s.
    K20,
    /// `S2`: 50 kbit/s.
    K50,
    /// `S3`: 100 kbit/s.
    K100,
    /// `S4`: 125 kbit/s.
    K125,
    /// `S5`: 250 kbit/s.
    K250,
    /// `S6`: 500 kbit/s.
    K500,
    /// `S7`: 800 kbit/s (python-can calls it 750 kbit/s; Lawicel and CANable say 800).
    K800,
    /// `S8`: 1 Mbit/s.
    M1,
}

impl Bitrate {
    const ALL: [(Self, u32); 9] = [
        (Self::K10, 10_000),
        (Self::K20, 20_000),
        (Self::K50, 50_000),
        (Self::K100, 100_000),
        (Self::K125, 125_000),
        (Self::K250, 250_000),
        (Self::K500, 500_000),
        (Self::K800, 800_000),
        (Self::M1, 1_000_000),
    ];

    /// The digit of `Sn`.
    pub const fn code(self) -> u8 {
        self as u8
    }

    /// The bit rate of `Sn`'s digit `n`, `None` past 8.
    pub fn from_code(n: u8) -> Option<Self> {
        Self::ALL.get(usize::from(n)).map(|&(b, _)| b)
    }

    /// Bits per second.
    pub fn bits_per_second(self) -> u32 {
        Self::ALL[self as usize].1
    }

    /// The setting for `bps` bits per second (750 000 as python-can names `S7`), `None`
    /// where no `Sn` has it.
    pub fn from_bits_per_second(bps: u32) -> Option<Self> {
        if bps == 750_000 {
            return Some(Self::K800);
        }
        Self::ALL.iter().find(|&&(_, r)| r == bps).map(|&(b, _)| b)
    }
}

/// One line (or the BEL byte) of the protocol, in either direction.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Message {
    /// A frame: to transmit (host to adapter) or received (adapter to host, with the time
    /// stamp when they are on).
    Frame {
        /// The frame.
        frame: CanFrame,
        /// Milliseconds within the minute (`Z1`), 0..60 000.
        timestamp: Option<u16>,
    },
    /// `O`: open the channel.
    Open,
    /// `L`: open the channel listen-only.
    ListenOnly,
    /// `C`: close the channel.
    Close,
    /// `Sn`: the bit rate.
    Bitrate(Bitrate),
    /// `Z0`/`Z1`: time stamps on received frames.
    Timestamps(bool),
    /// `V`: ask for the version.
    Version,
    /// `N`: ask for the serial number.
    SerialNumber,
    /// `F`: ask for the status flags.
    Status,
    /// `Vhhss`: the version answer (4 characters).
    VersionIs([u8; 4]),
    /// `Nxxxx`: the serial number answer (4 characters).
    SerialNumberIs([u8; 4]),
    /// `Fxx`: the status flags answer (a byte, bit 3 = data overrun, …).
    StatusIs(u8),
    /// An empty line: the "OK" answer to a command.
    Ok,
    /// `z` / `Z`: a transmitted 11-bit / 29-bit frame was queued.
    Sent {
        /// `Z`: after a 29-bit frame.
        extended: bool,
    },
    /// The BEL byte: the error answer.
    Error,
}

/// Why a line is no [`Message`].
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum DecodeError {
    /// A line that starts with a command this codec does not know (the byte).
    Unknown(u8),
    /// A known command with the wrong characters or length (its first byte).
    Syntax(u8),
    /// A line longer than any message ([`MAX_LINE`]): dropped up to its end.
    TooLong,
}

impl core::fmt::Display for DecodeError {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        match self {
            Self::Unknown(b) => write!(f, "slcan: unknown command {:?}", char::from(*b)),
            Self::Syntax(b) => write!(f, "slcan: malformed {:?} line", char::from(*b)),
            Self::TooLong => write!(f, "slcan: line longer than {MAX_LINE} bytes"),
        }
    }
}

impl core::error::Error for DecodeError {}

/// One encoded line, terminator included.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Line {
    buf: [u8; MAX_LINE],
    len: u8,
}

impl Line {
    const fn new() -> Self {
        Self { buf: [0; MAX_LINE], len: 0 }
    }

    /// The bytes to write.
    pub fn as_bytes(&self) -> &[u8] {
        self.buf.get(..usize::from(self.len)).unwrap_or(&[])
    }

    fn push(&mut self, b: u8) {
        if let Some(slot) = self.buf.get_mut(usize::from(self.len)) {
            *slot = b;
            self.len += 1;
        }
    }

    /// The low `digits` hex digits of `value`, most significant first.
    fn hex(&mut self, value: u32, digits: u32) {
        for i in (0..digits).rev() {
            let nibble = (value >> (4 * i)) & 0xF;
            self.push(b"0123456789ABCDEF"[nibble as usize]);
        }
    }
}

impl Message {
    /// The line of this message (for [`Message::Error`] the BEL byte alone).
    pub fn encode(&self) -> Line {
        let mut line = Line::new();
        match *self {
            Self::Frame { frame, timestamp } => {
                let kind = match (frame.is_extended(), frame.is_remote()) {
                    (false, false) => b't',
                    (true, false) => b'T',
                    (false, true) => b'r',
                    (true, true) => b'R',
                };
                line.push(kind);
                line.hex(frame.id(), if frame.is_extended() { 8 } else { 3 });
                line.hex(u32::from(frame.len()), 1);
                if !frame.is_remote() {
                    for &b in frame.bytes() {
                        line.hex(u32::from(b), 2);
                    }
                }
                if let Some(ms) = timestamp {
                    line.hex(u32::from(ms % TIMESTAMP_WRAP), 4);
                }
            }
            Self::Open => line.push(b'O'),
            Self::ListenOnly => line.push(b'L'),
            Self::Close => line.push(b'C'),
            Self::Bitrate(b) => {
                line.push(b'S');
                line.hex(u32::from(b.code()), 1);
            }
            Self::Timestamps(on) => {
                line.push(b'Z');
                line.push(if on { b'1' } else { b'0' });
            }
            Self::Version => line.push(b'V'),
            Self::SerialNumber => line.push(b'N'),
            Self::Status => line.push(b'F'),
            Self::VersionIs(text) | Self::SerialNumberIs(text) => {
                line.push(if matches!(self, Self::VersionIs(_)) { b'V' } else { b'N' });
                text.iter().for_each(|&b| line.push(b));
            }
            Self::StatusIs(flags) => {
                line.push(b'F');
                line.hex(u32::from(flags), 2);
            }
            Self::Ok => {}
            Self::Sent { extended } => line.push(if extended { b'Z' } else { b'z' }),
            Self::Error => {
                line.push(BEL);
                return line;
            }
        }
        line.push(CR);
        line
    }

    /// The message of one line, its terminator taken off.
    ///
    /// # Errors
    ///
    /// [`DecodeError`]: an unknown command or a malformed one.
    pub fn decode(line: &[u8]) -> Result<Self, DecodeError> {
        let Some((&first, rest)) = line.split_first() else {
            return Ok(Self::Ok);
        };
        let syntax = DecodeError::Syntax(first);
        let message = match (first, rest) {
            (b't' | b'T' | b'r' | b'R', _) => return frame(first, rest).ok_or(syntax),
            (b'O', []) => Self::Open,
            (b'L', []) => Self::ListenOnly,
            (b'C', []) => Self::Close,
            (b'S', &[n]) => Self::Bitrate(hex_digit(n).and_then(Bitrate::from_code).ok_or(syntax)?),
            (b'Z', []) => Self::Sent { extended: true },
            (b'z', []) => Self::Sent { extended: false },
            (b'Z', b"0") => Self::Timestamps(false),
            (b'Z', b"1") => Self::Timestamps(true),
            (b'V', []) => Self::Version,
            (b'N', []) => Self::SerialNumber,
            (b'F', []) => Self::Status,
            (b'V', &[a, b, c, d]) => Self::VersionIs([a, b, c, d]),
            (b'N', &[a, b, c, d]) => Self::SerialNumberIs([a, b, c, d]),
            (b'F', _) => {
                Self::StatusIs(hex(rest).and_then(|v| u8::try_from(v).ok()).ok_or(syntax)?)
            }
            (b'O' | b'L' | b'C' | b'S' | b'Z' | b'z' | b'V' | b'N', _) => return Err(syntax),
            _ => return Err(DecodeError::Unknown(first)),
        };
        Ok(message)
    }
}

/// A `t`/`T`/`r`/`R` line after its first byte: identifier, length, data, time stamp.
fn frame(kind: u8, rest: &[u8]) -> Option<Message> {
    let (extended, remote) = (kind.is_ascii_uppercase(), kind == b'r' || kind == b'R');
    let id_digits = if extended { 8 } else { 3 };
    let id = hex(rest.get(..id_digits)?)?;
    let len = hex_digit(*rest.get(id_digits)?)?;
    let tail = rest.get(id_digits + 1..)?;
    let data_digits = if remote { 0 } else { 2 * usize::from(len) };
    let timestamp = match tail.len().checked_sub(data_digits)? {
        0 => None,
        4 => Some(
            u16::try_from(hex(tail.get(data_digits..)?)?).ok().filter(|&t| t < TIMESTAMP_WRAP)?,
        ),
        _ => return None,
    };
    let frame = if remote {
        if extended { CanFrame::remote_extended(id, len)? } else { CanFrame::remote(id, len)? }
    } else {
        let mut data = [0u8; 8];
        for (i, pair) in tail.get(..data_digits)?.chunks_exact(2).enumerate() {
            *data.get_mut(i)? = u8::try_from(hex(pair)?).ok()?;
        }
        let bytes = data.get(..usize::from(len))?;
        if extended { CanFrame::extended(id, bytes)? } else { CanFrame::from_slice(id, bytes)? }
    };
    Some(Message::Frame { frame, timestamp })
}

fn hex_digit(b: u8) -> Option<u8> {
    char::from(b).to_digit(16).and_then(|d| u8::try_from(d).ok())
}

/// Up to 8 hex digits as a number; `None` for an empty slice or a non-hex byte.
fn hex(digits: &[u8]) -> Option<u32> {
    if digits.is_empty() || digits.len() > 8 {
        return None;
    }
    digits.iter().try_fold(0u32, |acc, &b| Some((acc << 4) | u32::from(hex_digit(b)?)))
}

/// Splits received bytes into messages: a byte in, a message out when it ends a line.
///
/// Line feeds are skipped (some terminals and adapters send `\r\n`); a line longer than
/// [`MAX_LINE`] is dropped up to its `\r` and reported once as [`DecodeError::TooLong`].
#[derive(Clone, Debug)]
pub struct Decoder {
    buf: [u8; MAX_LINE],
    len: usize,
    overflow: bool,
}

impl Default for Decoder {
    fn default() -> Self {
        Self::new()
    }
}

impl Decoder {
    /// An empty decoder.
    pub const fn new() -> Self {
        Self { buf: [0; MAX_LINE], len: 0, overflow: false }
    }

    /// Takes one received byte; at the end of a line, its message.
    ///
    /// # Errors
    ///
    /// The line's [`DecodeError`]; the decoder is then ready for the next line.
    pub fn push(&mut self, byte: u8) -> Option<Result<Message, DecodeError>> {
        match byte {
            b'\n' => None,
            CR => {
                let line = self.buf.get(..self.len).unwrap_or(&[]);
                let result =
                    if self.overflow { Err(DecodeError::TooLong) } else { Message::decode(line) };
                self.len = 0;
                self.overflow = false;
                Some(result)
            }
            // BEL ends nothing but is a message of its own.
            BEL => Some(Ok(Message::Error)),
            _ => {
                match self.buf.get_mut(self.len) {
                    Some(slot) => {
                        *slot = byte;
                        self.len += 1;
                    }
                    None => self.overflow = true,
                }
                None
            }
        }
    }
}

#[cfg(test)]
mod tests;
