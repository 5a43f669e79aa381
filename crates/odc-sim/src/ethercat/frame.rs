//! The EtherCAT frame and its datagrams (ETG.1000.4 §5.3–5.4): the codec the simulated chain
//! runs every frame through, in place, as an ESC does while the frame passes it.
//!
//! An Ethernet frame (destination, source, EtherType 0x88A4) carries a 2-byte EtherCAT header
//! (length 11 bits, reserved 1 bit, type 4 bits: 1 = datagrams), then datagrams:
//!
//! | bytes | field |
//! |---|---|
//! | 0 | command |
//! | 1 | index (the master's, returned as sent) |
//! | 2–5 | address: position or station address (ADP, 2 bytes) and register (ADO, 2 bytes), or a 32-bit logical address |
//! | 6–7 | length (bits 0–10), reserved (11–13), circulating (14), more datagrams follow (15) |
//! | 8–9 | IRQ |
//! | 10… | data |
//! | last 2 | working counter |

use core::fmt;

/// The EtherType of EtherCAT.
pub const ETHERTYPE: u16 = 0x88A4;
/// Bytes of an Ethernet header without VLAN tag.
pub const ETHERNET_HEADER: usize = 14;
/// Bytes of the EtherCAT header.
pub const ECAT_HEADER: usize = 2;
/// Bytes of a datagram header (command to IRQ).
pub const DATAGRAM_HEADER: usize = 10;
/// Bytes of the working counter.
pub const WKC: usize = 2;
/// The EtherCAT header's type for datagrams (ETG.1000.4 Table 5).
pub const TYPE_DATAGRAMS: u8 = 1;

/// The datagram commands (ETG.1000.4 Table 7).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Command {
    /// No operation.
    Nop,
    /// Auto-increment physical read.
    Aprd,
    /// Auto-increment physical write.
    Apwr,
    /// Auto-increment physical read-write.
    Aprw,
    /// Configured-address physical read.
    Fprd,
    /// Configured-address physical write.
    Fpwr,
    /// Configured-address physical read-write.
    Fprw,
    /// Broadcast read.
    Brd,
    /// Broadcast write.
    Bwr,
    /// Broadcast read-write.
    Brw,
    /// Logical read.
    Lrd,
    /// Logical write.
    Lwr,
    /// Logical read-write.
    Lrw,
    /// Auto-increment read, multiple write.
    Armw,
    /// Configured-address read, multiple write.
    Frmw,
}

impl Command {
    /// The command of a code; `None` for the reserved codes 15–255.
    pub const fn from_u8(code: u8) -> Option<Self> {
        Some(match code {
            0 => Self::Nop,
            1 => Self::Aprd,
            2 => Self::Apwr,
            3 => Self::Aprw,
            4 => Self::Fprd,
            5 => Self::Fpwr,
            6 => Self::Fprw,
            7 => Self::Brd,
            8 => Self::Bwr,
            9 => Self::Brw,
            10 => Self::Lrd,
            11 => Self::Lwr,
            12 => Self::Lrw,
            13 => Self::Armw,
            14 => Self::Frmw,
            _ => return None,
        })
    }

    /// The wire code.
    pub const fn code(self) -> u8 {
        match self {
            Self::Nop => 0,
            Self::Aprd => 1,
            Self::Apwr => 2,
            Self::Aprw => 3,
            Self::Fprd => 4,
            Self::Fpwr => 5,
            Self::Fprw => 6,
            Self::Brd => 7,
            Self::Bwr => 8,
            Self::Brw => 9,
            Self::Lrd => 10,
            Self::Lwr => 11,
            Self::Lrw => 12,
            Self::Armw => 13,
            Self::Frmw => 14,
        }
    }
}

/// Why a frame cannot be processed: the chain then forwards it unchanged, as an ESC forwards
/// a frame it cannot parse (and counts it as an error).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum FrameError {
    /// Shorter than its headers say.
    Truncated,
    /// Another EtherType than 0x88A4.
    NotEtherCat,
    /// An EtherCAT header type other than datagrams.
    NotDatagrams(u8),
}

impl fmt::Display for FrameError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Self::Truncated => f.write_str("frame shorter than its headers say"),
            Self::NotEtherCat => f.write_str("not an EtherCAT frame (EtherType 0x88A4)"),
            Self::NotDatagrams(t) => write!(f, "EtherCAT header type {t}, not datagrams (1)"),
        }
    }
}

impl core::error::Error for FrameError {}

/// One datagram of a frame, borrowed in place: what a device reads and changes as it passes.
#[derive(Debug)]
pub struct Datagram<'a> {
    header: &'a mut [u8],
    /// The data field.
    pub data: &'a mut [u8],
    wkc: &'a mut [u8],
}

impl Datagram<'_> {
    /// The command code.
    pub fn code(&self) -> u8 {
        self.header.first().copied().unwrap_or(0)
    }

    /// The command; `None` for a reserved code.
    pub fn command(&self) -> Option<Command> {
        Command::from_u8(self.code())
    }

    fn u16_at(&self, at: usize) -> u16 {
        match self.header.get(at..at + 2) {
            Some(&[lo, hi]) => u16::from_le_bytes([lo, hi]),
            _ => 0,
        }
    }

    /// The position or station address (ADP).
    pub fn adp(&self) -> u16 {
        self.u16_at(2)
    }

    /// Sets ADP (the auto-increment of a passing device).
    pub fn set_adp(&mut self, adp: u16) {
        if let Some(b) = self.header.get_mut(2..4) {
            b.copy_from_slice(&adp.to_le_bytes());
        }
    }

    /// The register address (ADO).
    pub fn ado(&self) -> u16 {
        self.u16_at(4)
    }

    /// The logical address (LRD, LWR, LRW).
    pub fn logical(&self) -> u32 {
        u32::from(self.adp()) | u32::from(self.ado()) << 16
    }

    /// The working counter.
    pub fn wkc(&self) -> u16 {
        match *self.wkc {
            [lo, hi] => u16::from_le_bytes([lo, hi]),
            _ => 0,
        }
    }

    /// Adds to the working counter (wrapping, as the 16-bit field does).
    pub fn add_wkc(&mut self, n: u16) {
        let v = self.wkc().wrapping_add(n);
        self.wkc.copy_from_slice(&v.to_le_bytes());
    }
}

/// The EtherCAT payload of an Ethernet frame (after the EtherType), checked.
///
/// # Errors
///
/// [`FrameError`]: too short, another EtherType.
pub fn ecat_payload(frame: &mut [u8]) -> Result<&mut [u8], FrameError> {
    let ethertype = match frame.get(12..14) {
        Some(&[hi, lo]) => u16::from_be_bytes([hi, lo]),
        _ => return Err(FrameError::Truncated),
    };
    if ethertype != ETHERTYPE {
        return Err(FrameError::NotEtherCat);
    }
    frame.get_mut(ETHERNET_HEADER..).ok_or(FrameError::Truncated)
}

/// Runs `f` on each datagram of an EtherCAT payload (EtherCAT header first), in order.
///
/// # Errors
///
/// [`FrameError`]: a header type other than datagrams, or a datagram past the length.
pub fn for_each_datagram(
    payload: &mut [u8],
    mut f: impl FnMut(&mut Datagram<'_>),
) -> Result<(), FrameError> {
    let header = match payload.get(..ECAT_HEADER) {
        Some(&[lo, hi]) => u16::from_le_bytes([lo, hi]),
        _ => return Err(FrameError::Truncated),
    };
    let len = usize::from(header & 0x07FF);
    let kind = (header >> 12) as u8;
    if kind != TYPE_DATAGRAMS {
        return Err(FrameError::NotDatagrams(kind));
    }
    let mut rest = payload.get_mut(ECAT_HEADER..ECAT_HEADER + len).ok_or(FrameError::Truncated)?;
    loop {
        if rest.len() < DATAGRAM_HEADER + WKC {
            return Err(FrameError::Truncated);
        }
        let (header, tail) = rest.split_at_mut(DATAGRAM_HEADER);
        let len_field = match header.get(6..8) {
            Some(&[lo, hi]) => u16::from_le_bytes([lo, hi]),
            _ => return Err(FrameError::Truncated),
        };
        let data_len = usize::from(len_field & 0x07FF);
        if tail.len() < data_len + WKC {
            return Err(FrameError::Truncated);
        }
        let (data, tail) = tail.split_at_mut(data_len);
        let (wkc, tail) = tail.split_at_mut(WKC);
        f(&mut Datagram { header, data, wkc });
        if len_field & 0x8000 == 0 {
            return Ok(());
        }
        rest = tail;
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// An APRD of 2 bytes of register 0x0130 at position 0 (ETG.1000.4 Table 6 order: Cmd,
    /// Idx, ADP, ADO, Len/R/C/M, IRQ, data, WKC), alone in its frame.
    const APRD: [u8; 30] = [
        0xFF, 0xFF, 0xFF, 0xFF, 0xFF, 0xFF, // destination: broadcast
        0x10, 0x10, 0x10, 0x10, 0x10, 0x10, // source
        0x88, 0xA4, // EtherType, big-endian
        0x0E, 0x10, // EtherCAT header: length 14, type 1
        0x01, 0x2A, 0x00, 0x00, 0x30, 0x01, // APRD, index 0x2A, ADP 0, ADO 0x0130
        0x02, 0x00, 0x00, 0x00, // length 2, not circulating, last; IRQ 0
        0x00, 0x00, // data
        0x00, 0x00, // WKC
    ];

    #[test]
    fn datagram_fields_where_etg1000_puts_them() {
        let mut frame = APRD;
        let payload = ecat_payload(&mut frame).unwrap();
        let mut seen = 0;
        for_each_datagram(payload, |d| {
            assert_eq!(d.command(), Some(Command::Aprd));
            assert_eq!((d.adp(), d.ado(), d.data.len()), (0, 0x0130, 2));
            d.set_adp(1);
            d.add_wkc(3);
            seen += 1;
        })
        .unwrap();
        assert_eq!(seen, 1);
        assert_eq!(&frame[18..20], &[0x01, 0x00]);
        assert_eq!(&frame[28..30], &[0x03, 0x00]);
    }

    #[test]
    fn more_follows_bit_chains_datagrams() {
        // Two datagrams: a BRD of 1 byte with M set, then an LRW of 2 bytes at 0x00010000.
        let mut payload = vec![0x1B, 0x10];
        payload.extend([0x07, 0x01, 0, 0, 0, 0, 0x01, 0x80, 0, 0, 0xAA, 0, 0]);
        payload.extend([0x0C, 0x02, 0x00, 0x00, 0x01, 0x00, 0x02, 0x00, 0, 0, 1, 2, 0, 0]);
        let mut got = Vec::new();
        for_each_datagram(&mut payload, |d| got.push((d.command(), d.logical(), d.data.len())))
            .unwrap();
        assert_eq!(got, [(Some(Command::Brd), 0, 1), (Some(Command::Lrw), 0x0001_0000, 2)]);
    }

    #[test]
    fn malformed_frames_are_refused() {
        let mut frame = APRD;
        frame[13] = 0x00;
        assert_eq!(ecat_payload(&mut frame).err(), Some(FrameError::NotEtherCat));
        // The header promises more than the frame has.
        let mut payload = vec![0x20, 0x10, 0x01, 0x00];
        assert_eq!(for_each_datagram(&mut payload, |_| {}), Err(FrameError::Truncated));
        // Type 4 (network variables) is not datagrams.
        let mut payload = vec![0x00, 0x40];
        assert_eq!(for_each_datagram(&mut payload, |_| {}), Err(FrameError::NotDatagrams(4)));
    }
}
