//! CAN logs as other tools write them, read into one list of timed frames for the monitor:
//! candump's two text formats (and its CAN FD lines), Vector's ASC and BLF as python-can
//! writes them, and Wireshark/tcpdump captures (pcap and pcapng) of a SocketCAN interface.
//!
//! The format is [`detect`]ed from the first bytes (the magic numbers of pcap, pcapng and
//! BLF; ASC's `date`/`base` header; candump's line shapes), or named by the caller. Each reader
//! goes on past a bad record and reports it as a [`Problem`] with its line or byte offset,
//! so one damaged line does not hide the rest of a log.
//!
//! Whole files are read into memory: logs of a bench session are megabytes, not gigabytes.

use odc::can::CanFrame;

mod blf;
mod pcap;
mod text;

/// A log file's format.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Format {
    /// candump's `-l` lines (`(1700000000.000000) can0 185#4006`, FD `185##1…`) and its
    /// default screen lines (`  can0  185   [2]  40 06`, with or without `-t` times).
    Candump,
    /// Vector's ASCII log (`.asc`), as CANalyzer and python-can's `ASCWriter` write it.
    Asc,
    /// Vector's Binary Logging Format (`.blf`), as python-can's `BLFWriter` writes it.
    Blf,
    /// A pcap or pcapng capture with link type 227 (`LINKTYPE_CAN_SOCKETCAN`).
    Pcap,
}

impl Format {
    /// All formats, for messages.
    pub const ALL: [Self; 4] = [Self::Candump, Self::Asc, Self::Blf, Self::Pcap];

    /// The format's name (`candump`, `asc`, `blf`, `pcap`).
    pub const fn name(self) -> &'static str {
        match self {
            Self::Candump => "candump",
            Self::Asc => "asc",
            Self::Blf => "blf",
            Self::Pcap => "pcap",
        }
    }
}

/// A CAN FD frame (up to 64 bytes), which the CANopen decoder leaves raw.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct FdFrame {
    /// CAN-ID.
    pub id: u32,
    /// A 29-bit identifier.
    pub extended: bool,
    /// Bit rate switch.
    pub brs: bool,
    /// Error state indicator.
    pub esi: bool,
    /// The data, 0 to 64 bytes.
    pub data: Vec<u8>,
}

/// A logged frame.
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum Frame {
    /// Classic CAN.
    Can(CanFrame),
    /// CAN FD.
    Fd(FdFrame),
}

/// One frame of a log and its time.
#[derive(Clone, Debug, PartialEq)]
pub struct Entry {
    /// Seconds, as the log gives them (since 1970, or since the start of the recording);
    /// `None` for candump screen lines without `-t`.
    pub time: Option<f64>,
    /// The frame.
    pub frame: Frame,
}

/// Where in a file a problem is.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Location {
    /// A text format's line, from 1.
    Line(usize),
    /// A binary format's byte offset.
    Offset(usize),
    /// A capture's packet, from 1 as Wireshark numbers them (0: the file header).
    Packet(usize),
}

/// A record of a log that could not be read.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Problem {
    /// Where.
    pub at: Location,
    /// What is wrong.
    pub message: String,
}

impl std::fmt::Display for Location {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            Location::Line(n) => write!(f, "{n}"),
            Location::Offset(n) => write!(f, "byte {n}"),
            Location::Packet(n) => write!(f, "packet {n}"),
        }
    }
}

/// A log read: its frames in file order and what could not be read.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Log {
    /// The frames.
    pub entries: Vec<Entry>,
    /// The records that are not frames the format allows.
    pub problems: Vec<Problem>,
}

/// The format of a log from its first bytes, `None` when no reader knows it.
pub fn detect(bytes: &[u8]) -> Option<Format> {
    match bytes.get(..4).unwrap_or(&[]) {
        // pcap in either byte order, microsecond or nanosecond times; pcapng's section
        // header block type.
        [0xD4, 0xC3, 0xB2, 0xA1]
        | [0xA1, 0xB2, 0xC3, 0xD4]
        | [0x4D, 0x3C, 0xB2, 0xA1]
        | [0xA1, 0xB2, 0x3C, 0x4D]
        | [0x0A, 0x0D, 0x0D, 0x0A] => return Some(Format::Pcap),
        b"LOGG" => return Some(Format::Blf),
        _ => {}
    }
    text::detect(&String::from_utf8_lossy(bytes.get(..4096).unwrap_or(bytes)))
}

/// Reads a whole log of the given format.
pub fn read(bytes: &[u8], format: Format) -> Log {
    let mut log = Log::default();
    match format {
        Format::Candump => text::candump(&String::from_utf8_lossy(bytes), &mut log),
        Format::Asc => text::asc(&String::from_utf8_lossy(bytes), &mut log),
        Format::Blf => blf::read(bytes, &mut log),
        Format::Pcap => pcap::read(bytes, &mut log),
    }
    log
}

/// The record of a CAN FD frame, which the CANopen decoder does not read: its bytes, and
/// its flags as the text.
pub fn fd_record(frame: &FdFrame, time: Option<f64>) -> crate::Record {
    let data: Vec<String> = frame.data.iter().map(|b| format!("{b:02X}")).collect();
    let flags: Vec<&str> = [(frame.brs, "bit rate switch"), (frame.esi, "error state indicator")]
        .iter()
        .filter_map(|&(on, name)| on.then_some(name))
        .collect();
    crate::Record {
        time,
        id: frame.id,
        extended: frame.extended,
        remote: false,
        data: data.join(" "),
        kind: "CAN FD".into(),
        node: None,
        text: format!(
            "{} bytes{}{}",
            frame.data.len(),
            if flags.is_empty() { "" } else { ", " },
            flags.join(", ")
        ),
        fields: Vec::new(),
    }
}

/// The frame of an identifier, flags and bytes a log gives, or why there is none.
fn classic(id: u32, extended: bool, remote: bool, len: u8, data: &[u8]) -> Result<Frame, String> {
    let frame = match (extended, remote) {
        (false, false) => CanFrame::from_slice(id, data),
        (true, false) => CanFrame::extended(id, data),
        (false, true) => CanFrame::remote(id, len),
        (true, true) => CanFrame::remote_extended(id, len),
    };
    frame.map(Frame::Can).ok_or_else(|| {
        format!(
            "no CAN frame: ID 0x{id:X} (extended: {extended}), {} bytes",
            data.len().max(len.into())
        )
    })
}

/// The CAN FD frame, or why there is none.
fn fd(id: u32, extended: bool, brs: bool, esi: bool, data: &[u8]) -> Result<Frame, String> {
    let valid = [0usize, 1, 2, 3, 4, 5, 6, 7, 8, 12, 16, 20, 24, 32, 48, 64].contains(&data.len());
    if !valid || id > if extended { 0x1FFF_FFFF } else { 0x7FF } {
        return Err(format!("no CAN FD frame: ID 0x{id:X}, {} bytes", data.len()));
    }
    Ok(Frame::Fd(FdFrame { id, extended, brs, esi, data: data.to_vec() }))
}

/// The length of a CAN FD data length code.
fn fd_len(dlc: u8) -> Option<usize> {
    [0, 1, 2, 3, 4, 5, 6, 7, 8, 12, 16, 20, 24, 32, 48, 64].get(usize::from(dlc)).copied()
}

#[cfg(test)]
mod tests;
