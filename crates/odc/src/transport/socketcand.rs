//! socketcand: the ASCII protocol over TCP with which [socketcand] shares a Linux CAN bus,
//! and which python-can's `socketcand` interface and Kayak speak. This module has the codec
//! (both directions, so a server can use it too) and [`Socketcand`], a client [`Bus`] in raw
//! mode.
//!
//! The protocol, from socketcand's `doc/protocol.md` and the code that serves it
//! (`src/state_nobus.c`, `src/state_raw.c`), as far as raw mode goes:
//!
//! - every message is an element `< … >`: words separated by spaces between `<` and `>`;
//!   bytes outside elements are ignored;
//! - the server greets with `< hi >`; the client opens a bus with `< open CHANNEL >` (at
//!   most 16 characters; answer `< ok >`, or `< error could not open bus >` and the
//!   connection ends), then switches to raw mode with `< rawmode >` (answer `< ok >`);
//! - the client sends a frame with `< send ID DLC DATA… >`: the identifier in hex, eight
//!   digits for a 29-bit one (socketcand's rule: an identifier of 8 characters is extended),
//!   the length, then each byte in hex with spaces between (`< send 1AAAAAAA 2 1 f1 >`);
//! - the server sends each frame on the bus as `< frame ID SECONDS.MICROSECONDS DATA >`: the
//!   identifier as `%03X` or `%08X`, the reception time, and the data as uppercase hex
//!   without spaces (`< frame 123 23.424242 1A220344 >`);
//! - `< echo >` is answered with `< echo >`; an unknown command with
//!   `< error unknown command >`; error frames come as `< error … >`.
//!
//! Remote (RTR) frames have no syntax in raw mode (socketcand drops them: "TODO implement"
//! in `state_raw.c`), so a remote frame cannot be sent through this transport.
//!
//! [socketcand]: https://github.com/linux-can/socketcand
//!
//! ```
//! use odc::can::CanFrame;
//! use odc::transport::socketcand::{Element, format_send, parse};
//!
//! let sdo = CanFrame::new(0x605, [0x40, 0x00, 0x10, 0x00, 0, 0, 0, 0]).unwrap();
//! let line = format_send(&sdo).unwrap();
//! assert_eq!(line, "< send 605 8 40 0 10 0 0 0 0 0 >");
//! assert_eq!(parse(&line), Ok(Element::Send(sdo)));
//! ```

use std::fmt::Write as _;
use std::format;
use std::io::{self, Read, Write};
use std::net::{Shutdown, TcpStream};
use std::string::{String, ToString};
use std::time::{Duration, Instant};
use std::vec::Vec;

use crate::can::CanFrame;
use crate::transport::Bus;

/// The longest element kept while waiting for its `>`: a `< frame >` of an extended frame is
/// 50 characters; a longer run without `>` is no element and is dropped.
pub const MAX_ELEMENT: usize = 512;

/// The longest bus name socketcand accepts (`< open CHANNEL >`).
pub const MAX_CHANNEL: usize = 16;

/// A message of the protocol.
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum Element {
    /// `< hi >`: the server's greeting.
    Hi,
    /// `< ok >`: a command succeeded.
    Ok,
    /// `< echo >`: a ping, answered with itself.
    Echo,
    /// `< open CHANNEL >`: the bus the client wants.
    Open(String),
    /// `< rawmode >`: every frame on the bus, as it comes.
    RawMode,
    /// `< bcmmode >`: back to the broadcast manager mode (the mode after `open`).
    BcmMode,
    /// `< send … >`: a frame the client puts on the bus.
    Send(CanFrame),
    /// `< frame … >`: a frame the server received on the bus, and when.
    Frame {
        /// The frame.
        frame: CanFrame,
        /// The reception time (socketcand: the kernel's, since the Unix epoch).
        timestamp: Duration,
    },
    /// `< error … >`: the words after `error` (a message, or an error frame's class and time).
    Error(String),
    /// Any other element (BCM, ISO-TP and control mode commands): its words.
    Other(String),
}

/// Why an element is not a message this codec knows the form of.
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum ParseError {
    /// No `<` … `>` around it.
    NotAnElement(String),
    /// An identifier that is no hex number, or too wide (11 bits unless written with 8
    /// digits, then 29).
    Identifier(String),
    /// A length that is no number from 0 to 8.
    Length(String),
    /// A data byte that is no hex byte, or fewer or more bytes than the length says.
    Data(String),
    /// A timestamp that is not `SECONDS.MICROSECONDS`.
    Timestamp(String),
    /// A command without its argument (`< open >`, `< send 123 >`).
    Missing(&'static str),
}

impl core::fmt::Display for ParseError {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        match self {
            Self::NotAnElement(s) => write!(f, "`{s}` is no socketcand element `< … >`"),
            Self::Identifier(s) => write!(f, "`{s}` is no CAN identifier (hex, 3 or 8 digits)"),
            Self::Length(s) => write!(f, "`{s}` is no CAN frame length (0 to 8)"),
            Self::Data(s) => write!(f, "bad frame data: {s}"),
            Self::Timestamp(s) => write!(f, "`{s}` is no timestamp SECONDS.MICROSECONDS"),
            Self::Missing(what) => write!(f, "the command has no {what}"),
        }
    }
}

impl core::error::Error for ParseError {}

/// Parses one element (`< … >`, as [`Splitter`] cuts them).
///
/// # Errors
///
/// [`ParseError`]: a `send`, `frame` or `open` whose arguments are not what the protocol
/// says. Commands this codec does not know are [`Element::Other`], not errors.
pub fn parse(element: &str) -> Result<Element, ParseError> {
    let inner = element
        .trim()
        .strip_prefix('<')
        .and_then(|s| s.strip_suffix('>'))
        .ok_or_else(|| ParseError::NotAnElement(element.to_string()))?;
    let mut words = inner.split_ascii_whitespace();
    let Some(command) = words.next() else { return Ok(Element::Other(String::new())) };
    Ok(match command {
        "hi" => Element::Hi,
        "ok" => Element::Ok,
        "echo" => Element::Echo,
        "rawmode" => Element::RawMode,
        "bcmmode" => Element::BcmMode,
        "open" => Element::Open(words.next().ok_or(ParseError::Missing("bus name"))?.into()),
        "send" => Element::Send(parse_send(&mut words)?),
        "frame" => parse_frame(&mut words)?,
        "error" => Element::Error(words.collect::<Vec<_>>().join(" ")),
        _ => Element::Other(inner.trim().to_string()),
    })
}

/// `ID DLC BYTE…` of `< send >`.
fn parse_send<'a>(words: &mut impl Iterator<Item = &'a str>) -> Result<CanFrame, ParseError> {
    let (id, extended) = parse_id(words.next().ok_or(ParseError::Missing("identifier"))?)?;
    let len_word = words.next().ok_or(ParseError::Missing("length"))?;
    let len = len_word
        .parse::<u8>()
        .ok()
        .filter(|n| *n <= 8)
        .ok_or_else(|| ParseError::Length(len_word.into()))?;
    let mut data = Vec::with_capacity(8);
    for w in words {
        let byte = (w.len() <= 2).then(|| u8::from_str_radix(w, 16).ok()).flatten();
        data.push(byte.ok_or_else(|| ParseError::Data(format!("`{w}` is no hex byte")))?);
    }
    if data.len() != usize::from(len) {
        return Err(ParseError::Data(format!("length {len} but {} bytes", data.len())));
    }
    make(id, extended, &data)
}

/// `ID SECONDS.MICROSECONDS [DATA]` of `< frame >`.
fn parse_frame<'a>(words: &mut impl Iterator<Item = &'a str>) -> Result<Element, ParseError> {
    let (id, extended) = parse_id(words.next().ok_or(ParseError::Missing("identifier"))?)?;
    let time = words.next().ok_or(ParseError::Missing("timestamp"))?;
    let timestamp = parse_time(time).ok_or_else(|| ParseError::Timestamp(time.into()))?;
    let hex = words.next().unwrap_or("");
    if let Some(extra) = words.next() {
        return Err(ParseError::Data(format!("`{extra}` after the data")));
    }
    if !hex.len().is_multiple_of(2) || hex.len() > 16 {
        return Err(ParseError::Data(format!("`{hex}` is not 0 to 8 hex bytes")));
    }
    let data = (0..hex.len())
        .step_by(2)
        .map(|i| hex.get(i..i + 2).and_then(|b| u8::from_str_radix(b, 16).ok()))
        .collect::<Option<Vec<u8>>>()
        .ok_or_else(|| ParseError::Data(format!("`{hex}` is not hex")))?;
    Ok(Element::Frame { frame: make(id, extended, &data)?, timestamp })
}

/// An identifier and whether it is extended: 8 digits are a 29-bit identifier, fewer an
/// 11-bit one (socketcand's `element_length(buf, 2) == 8`).
fn parse_id(word: &str) -> Result<(u32, bool), ParseError> {
    let bad = || ParseError::Identifier(word.into());
    if word.is_empty() || word.len() > 8 {
        return Err(bad());
    }
    let id = u32::from_str_radix(word, 16).map_err(|_| bad())?;
    let extended = word.len() == 8;
    let max = if extended { 0x1FFF_FFFF } else { 0x7FF };
    if id > max {
        return Err(bad());
    }
    Ok((id, extended))
}

/// `SECONDS.MICROSECONDS` (the fraction may have fewer than 6 digits, or none).
fn parse_time(word: &str) -> Option<Duration> {
    let (secs, frac) = word.split_once('.').unwrap_or((word, ""));
    let secs = secs.parse::<u64>().ok()?;
    if frac.len() > 6 || !frac.bytes().all(|b| b.is_ascii_digit()) {
        return None;
    }
    let micros = format!("{frac:0<6}").parse::<u32>().ok()?;
    Some(Duration::from_secs(secs) + Duration::from_micros(u64::from(micros)))
}

fn make(id: u32, extended: bool, data: &[u8]) -> Result<CanFrame, ParseError> {
    let frame =
        if extended { CanFrame::extended(id, data) } else { CanFrame::from_slice(id, data) };
    frame.ok_or_else(|| ParseError::Data(format!("{} bytes (at most 8)", data.len())))
}

/// A remote frame: raw mode has no syntax for one.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct RemoteFrame;

impl core::fmt::Display for RemoteFrame {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        f.write_str("socketcand's raw mode carries no remote (RTR) frames")
    }
}

impl core::error::Error for RemoteFrame {}

fn id_text(frame: &CanFrame) -> String {
    if frame.is_extended() { format!("{:08X}", frame.id()) } else { format!("{:03X}", frame.id()) }
}

/// `< send ID DLC DATA… >` of a frame, bytes in lowercase unpadded hex as the protocol
/// document writes them.
///
/// # Errors
///
/// [`RemoteFrame`] for a remote frame.
pub fn format_send(frame: &CanFrame) -> Result<String, RemoteFrame> {
    if frame.is_remote() {
        return Err(RemoteFrame);
    }
    let mut s = format!("< send {} {}", id_text(frame), frame.len());
    for b in frame.bytes() {
        // Writing to a String does not fail.
        let _ = write!(s, " {b:x}");
    }
    s.push_str(" >");
    Ok(s)
}

/// `< frame ID SECONDS.MICROSECONDS DATA >` of a frame received at `timestamp`, as
/// socketcand's `state_raw.c` prints it (a frame without data has an empty data word:
/// `< frame 123 1.000000  >`).
///
/// # Errors
///
/// [`RemoteFrame`] for a remote frame.
pub fn format_frame(frame: &CanFrame, timestamp: Duration) -> Result<String, RemoteFrame> {
    if frame.is_remote() {
        return Err(RemoteFrame);
    }
    let mut s = format!(
        "< frame {} {}.{:06} ",
        id_text(frame),
        timestamp.as_secs(),
        timestamp.subsec_micros()
    );
    for b in frame.bytes() {
        let _ = write!(s, "{b:02X}");
    }
    s.push_str(" >");
    Ok(s)
}

/// Cuts a byte stream into elements: bytes in as they arrive, `< … >` out, as socketcand's
/// `receive_command` does (bytes before a `<` are dropped).
#[derive(Clone, Debug, Default)]
pub struct Splitter {
    pending: Vec<u8>,
}

/// What the splitter dropped: a run of [`MAX_ELEMENT`] bytes without `>`, or bytes that are
/// not ASCII text inside an element.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Garbage;

impl core::fmt::Display for Garbage {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        write!(f, "no socketcand element (no `>` within {MAX_ELEMENT} bytes, or not ASCII)")
    }
}

impl core::error::Error for Garbage {}

impl Splitter {
    /// An empty splitter.
    pub const fn new() -> Self {
        Self { pending: Vec::new() }
    }

    /// Appends received bytes.
    pub fn push(&mut self, bytes: &[u8]) {
        self.pending.extend_from_slice(bytes);
    }

    /// The next whole element, if one is buffered.
    ///
    /// # Errors
    ///
    /// [`Garbage`], once per dropped run; the splitter goes on after it.
    pub fn next_element(&mut self) -> Option<Result<String, Garbage>> {
        let Some(start) = self.pending.iter().position(|&b| b == b'<') else {
            self.pending.clear();
            return None;
        };
        self.pending.drain(..start);
        let Some(end) = self.pending.iter().position(|&b| b == b'>') else {
            if self.pending.len() > MAX_ELEMENT {
                self.pending.clear();
                return Some(Err(Garbage));
            }
            return None;
        };
        let element: Vec<u8> = self.pending.drain(..=end).collect();
        Some(String::from_utf8(element).ok().filter(|s| s.is_ascii()).ok_or(Garbage))
    }
}

/// A client of a socketcand server in raw mode: a [`Bus`], with a clock since it was made.
#[derive(Debug)]
pub struct Socketcand {
    stream: TcpStream,
    splitter: Splitter,
    start: Instant,
    /// Frames sent and received.
    pub frames: usize,
    /// Elements received that were no frame (errors, error frames, unknown ones).
    pub other: usize,
    /// The last of them.
    pub last_other: Option<String>,
}

/// Whether socketcand accepts `channel` as a bus name (1 to [`MAX_CHANNEL`] characters, no
/// white space or `<` `>`, which would end the element).
///
/// # Errors
///
/// `InvalidInput`, naming the bus.
pub fn check_channel(channel: &str) -> io::Result<()> {
    if channel.is_empty()
        || channel.len() > MAX_CHANNEL
        || channel.contains(|c: char| c.is_whitespace() || c == '<' || c == '>')
    {
        let why = format!("`{channel}` is no bus name (1 to 16 characters, no spaces)");
        return Err(io::Error::new(io::ErrorKind::InvalidInput, why));
    }
    Ok(())
}

/// How long the handshake may take at each step.
const HANDSHAKE: Duration = Duration::from_secs(5);

impl Socketcand {
    /// Connects to `addr`, opens bus `channel` and switches to raw mode (`< hi >`,
    /// `< open CHANNEL >`, `< ok >`, `< rawmode >`, `< ok >`).
    ///
    /// # Errors
    ///
    /// The connection's; `InvalidData` when the server answers other than the protocol says
    /// (its answer in the message), `TimedOut` when it does not answer within 5 s.
    pub fn connect(addr: impl std::net::ToSocketAddrs, channel: &str) -> io::Result<Self> {
        check_channel(channel)?;
        let stream = TcpStream::connect(addr)?;
        stream.set_nodelay(true)?;
        let mut link = Self {
            stream,
            splitter: Splitter::new(),
            start: Instant::now(),
            frames: 0,
            other: 0,
            last_other: None,
        };
        link.expect(&Element::Hi, "the greeting")?;
        link.stream.write_all(format!("< open {channel} >").as_bytes())?;
        link.expect(&Element::Ok, &format!("< open {channel} >"))?;
        link.stream.write_all(b"< rawmode >")?;
        link.expect(&Element::Ok, "< rawmode >")?;
        Ok(link)
    }

    /// Reads the next element and fails unless it is `want`.
    fn expect(&mut self, want: &Element, after: &str) -> io::Result<()> {
        self.stream.set_read_timeout(Some(HANDSHAKE))?;
        let element = loop {
            if let Some(e) = self.splitter.next_element() {
                break e.map_err(|e| io::Error::new(io::ErrorKind::InvalidData, e))?;
            }
            let mut buf = [0u8; 256];
            match self.stream.read(&mut buf) {
                Ok(0) => {
                    let why = format!("socketcand closed the connection after {after}");
                    return Err(io::Error::new(io::ErrorKind::UnexpectedEof, why));
                }
                Ok(n) => self.splitter.push(buf.get(..n).unwrap_or(&[])),
                Err(e) if e.kind() == io::ErrorKind::Interrupted => {}
                Err(e) if e.kind() == io::ErrorKind::WouldBlock => {
                    let why = format!("socketcand did not answer {after} within 5 s");
                    return Err(io::Error::new(io::ErrorKind::TimedOut, why));
                }
                Err(e) => return Err(e),
            }
        };
        match parse(&element) {
            Ok(e) if e == *want => Ok(()),
            _ => {
                let why = format!("socketcand answered {after} with `{element}`");
                Err(io::Error::new(io::ErrorKind::InvalidData, why))
            }
        }
    }

    /// Closes both directions; the server reads the end of the stream.
    ///
    /// # Errors
    ///
    /// The socket's.
    pub fn shutdown(&self) -> io::Result<()> {
        self.stream.shutdown(Shutdown::Both)
    }
}

impl Bus for Socketcand {
    type Error = io::Error;

    /// `Err(InvalidInput)` for a remote frame (raw mode has no syntax for one).
    fn send(&mut self, frame: &CanFrame) -> io::Result<()> {
        let line =
            format_send(frame).map_err(|e| io::Error::new(io::ErrorKind::InvalidInput, e))?;
        self.frames += 1;
        self.stream.write_all(line.as_bytes())
    }

    /// `Err(UnexpectedEof)` once the server closed the connection, `Err(InvalidData)` for a
    /// `< frame >` that is no frame. Other elements are counted in [`Socketcand::other`].
    fn recv(&mut self, deadline: crate::time::Instant) -> io::Result<Option<CanFrame>> {
        loop {
            while let Some(element) = self.splitter.next_element() {
                let element = element.map_err(|e| io::Error::new(io::ErrorKind::InvalidData, e))?;
                match parse(&element) {
                    Ok(Element::Frame { frame, .. }) => {
                        self.frames += 1;
                        return Ok(Some(frame));
                    }
                    Ok(_) => {
                        self.other += 1;
                        self.last_other = Some(element);
                    }
                    Err(e) => return Err(io::Error::new(io::ErrorKind::InvalidData, e)),
                }
            }
            let now = self.now();
            if now >= deadline {
                return Ok(None);
            }
            let mut buf = [0u8; 1024];
            match super::read_within(&mut self.stream, (deadline - now).into(), &mut buf)? {
                Some(n) => self.splitter.push(buf.get(..n).unwrap_or(&[])),
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

    // The lines below are the examples of socketcand's doc/protocol.md and the replies its
    // src/state_nobus.c and src/state_raw.c print.

    #[test]
    fn send_examples_of_the_protocol_document() {
        // "// ID: 123, no data  < send 123 0 >"
        assert_eq!(
            parse("< send 123 0 >"),
            Ok(Element::Send(CanFrame::from_slice(0x123, &[]).unwrap()))
        );
        // "// ID: 1AAAAAAA, Length: 2, Data: 0x01 0xF1  < send 1AAAAAAA 2 1 f1 >"
        let ext = CanFrame::extended(0x1AAA_AAAA, &[0x01, 0xF1]).unwrap();
        assert_eq!(parse("< send 1AAAAAAA 2 1 f1 >"), Ok(Element::Send(ext)));
        assert_eq!(format_send(&ext).unwrap(), "< send 1AAAAAAA 2 1 f1 >");
        // An extended identifier is told by its 8 digits, not its value.
        let low = CanFrame::extended(0x123, &[]).unwrap();
        assert_eq!(parse("< send 00000123 0 >"), Ok(Element::Send(low)));
        assert_eq!(format_send(&low).unwrap(), "< send 00000123 0 >");
    }

    #[test]
    fn frame_example_of_the_protocol_document() {
        // "Reception of a CAN frame with CAN ID 0x123, data length 4 and data 0x1A, 0x22, 0x03
        // and 0x44 at time 23.424242:  < frame 123 23.424242 1A220344 >"
        let frame = CanFrame::from_slice(0x123, &[0x1A, 0x22, 0x03, 0x44]).unwrap();
        let timestamp = Duration::from_micros(23_424_242);
        let line = "< frame 123 23.424242 1A220344 >";
        assert_eq!(parse(line), Ok(Element::Frame { frame, timestamp }));
        assert_eq!(format_frame(&frame, timestamp).unwrap(), line);
        // state_raw.c: "%08X" for an extended identifier, "%02X" per byte, and an empty data
        // word for a frame without data.
        let ext = CanFrame::extended(0x18FF_0001, &[]).unwrap();
        let t = Duration::from_secs(1_700_000_000) + Duration::from_micros(5);
        assert_eq!(format_frame(&ext, t).unwrap(), "< frame 18FF0001 1700000000.000005  >");
        assert_eq!(
            parse("< frame 18FF0001 1700000000.000005  >"),
            Ok(Element::Frame { frame: ext, timestamp: t })
        );
    }

    #[test]
    fn commands_and_replies() {
        assert_eq!(parse("< hi >"), Ok(Element::Hi));
        assert_eq!(parse("< ok >"), Ok(Element::Ok));
        assert_eq!(parse("< echo >"), Ok(Element::Echo));
        assert_eq!(parse("< open can0 >"), Ok(Element::Open("can0".into())));
        assert_eq!(parse("< rawmode >"), Ok(Element::RawMode));
        assert_eq!(parse("< bcmmode >"), Ok(Element::BcmMode));
        assert_eq!(
            parse("< error unknown command >"),
            Ok(Element::Error("unknown command".into()))
        );
        assert_eq!(
            parse("< error could not open bus >"),
            Ok(Element::Error("could not open bus".into()))
        );
        // A BCM command of the document: known form, not served here.
        assert_eq!(
            parse("< add 1 0 123 8 11 22 33 44 55 66 77 88 >"),
            Ok(Element::Other("add 1 0 123 8 11 22 33 44 55 66 77 88".into()))
        );
    }

    #[test]
    fn python_can_sends_are_read() {
        // python-can 4.6's convert_can_message_to_ascii_message: f"< send {id:03X} {dlc:X} "
        // + " ".join(f"{x:x}") + " >": an SDO upload request of 0x1000 to node 5.
        let sdo = CanFrame::new(0x605, [0x40, 0x00, 0x10, 0x00, 0, 0, 0, 0]).unwrap();
        assert_eq!(parse("< send 605 8 40 0 10 0 0 0 0 0 >"), Ok(Element::Send(sdo)));
    }

    #[test]
    fn bad_elements_are_errors() {
        assert!(matches!(parse("send 123 0"), Err(ParseError::NotAnElement(_))));
        assert!(matches!(parse("< send 800 0 >"), Err(ParseError::Identifier(_))));
        assert!(matches!(parse("< send 20000000 0 >"), Err(ParseError::Identifier(_))));
        assert!(matches!(parse("< send 1234567890 0 >"), Err(ParseError::Identifier(_))));
        assert!(matches!(parse("< send xyz 0 >"), Err(ParseError::Identifier(_))));
        assert!(matches!(parse("< send 123 9 >"), Err(ParseError::Length(_))));
        assert!(matches!(parse("< send 123 2 1 >"), Err(ParseError::Data(_))));
        assert!(matches!(parse("< send 123 1 1ff >"), Err(ParseError::Data(_))));
        assert!(matches!(parse("< send 123 >"), Err(ParseError::Missing("length"))));
        assert!(matches!(parse("< open >"), Err(ParseError::Missing("bus name"))));
        assert!(matches!(parse("< frame 123 x 11 >"), Err(ParseError::Timestamp(_))));
        assert!(matches!(parse("< frame 123 1.1234567 11 >"), Err(ParseError::Timestamp(_))));
        assert!(matches!(parse("< frame 123 1.0 111 >"), Err(ParseError::Data(_))));
        assert!(matches!(parse("< frame 123 1.0 111111111111111111 >"), Err(ParseError::Data(_))));
        assert_eq!(format_send(&CanFrame::remote(0x705, 1).unwrap()), Err(RemoteFrame));
    }

    #[test]
    fn splitter_cuts_elements_from_a_stream() {
        let mut s = Splitter::new();
        s.push(b"junk< hi >< ok ><");
        assert_eq!(s.next_element(), Some(Ok("< hi >".into())));
        assert_eq!(s.next_element(), Some(Ok("< ok >".into())));
        assert_eq!(s.next_element(), None);
        s.push(b" frame 123 0.5 01 >");
        assert_eq!(s.next_element(), Some(Ok("< frame 123 0.5 01 >".into())));
        s.push(&[b'<'; MAX_ELEMENT + 1]);
        assert_eq!(s.next_element(), Some(Err(Garbage)));
        assert_eq!(s.next_element(), None);
        s.push(&[b'<', 0xFF, b'>']);
        assert_eq!(s.next_element(), Some(Err(Garbage)));
    }

    /// A server that says what socketcand says: the client's handshake, a frame each way.
    #[test]
    fn client_handshake_and_frames() {
        let listener = std::net::TcpListener::bind("127.0.0.1:0").unwrap();
        let addr = listener.local_addr().unwrap();
        let server = std::thread::spawn(move || {
            let (mut s, _) = listener.accept().unwrap();
            let read = |s: &mut TcpStream| {
                let mut buf = [0u8; 256];
                let n = s.read(&mut buf).unwrap();
                String::from_utf8(buf[..n].to_vec()).unwrap()
            };
            s.write_all(b"< hi >").unwrap();
            assert_eq!(read(&mut s), "< open vcan0 >");
            s.write_all(b"< ok >").unwrap();
            assert_eq!(read(&mut s), "< rawmode >");
            s.write_all(b"< ok >").unwrap();
            assert_eq!(read(&mut s), "< send 000 2 1 5 >");
            s.write_all(b"< error 004 1.000000 >< frame 705 1.5 05 >").unwrap();
        });
        let mut bus = Socketcand::connect(addr, "vcan0").unwrap();
        bus.send(&CanFrame::from_slice(0x000, &[1, 5]).unwrap()).unwrap();
        let deadline = bus.now() + crate::time::Duration::from_secs(5);
        assert_eq!(bus.recv(deadline).unwrap(), CanFrame::from_slice(0x705, &[5]));
        assert_eq!((bus.other, bus.last_other.as_deref()), (1, Some("< error 004 1.000000 >")));
        server.join().unwrap();
        let deadline = bus.now() + crate::time::Duration::from_secs(5);
        assert_eq!(bus.recv(deadline).unwrap_err().kind(), io::ErrorKind::UnexpectedEof);
    }

    #[test]
    fn a_refused_open_is_an_error_that_quotes_the_server() {
        let listener = std::net::TcpListener::bind("127.0.0.1:0").unwrap();
        let addr = listener.local_addr().unwrap();
        let server = std::thread::spawn(move || {
            let (mut s, _) = listener.accept().unwrap();
            s.write_all(b"< hi >").unwrap();
            let mut buf = [0u8; 64];
            let _ = s.read(&mut buf).unwrap();
            s.write_all(b"< error could not open bus >").unwrap();
        });
        let err = Socketcand::connect(addr, "can9").unwrap_err();
        assert_eq!(err.kind(), io::ErrorKind::InvalidData);
        assert!(err.to_string().contains("< error could not open bus >"), "{err}");
        server.join().unwrap();
        let err = Socketcand::connect(addr, "a name").unwrap_err();
        assert_eq!(err.kind(), io::ErrorKind::InvalidInput);
    }
}
