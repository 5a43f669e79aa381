//! SDO block transfer frames (CiA 301 §7.2.4.3.9–16) and their CRC.
//!
//! Block transfer moves a value in sub-blocks of up to 127 segments of 7 bytes, each sub-block
//! acknowledged once, and checks the whole value with a CRC at the end.
//!
//! | byte 0 | client → server | server → client |
//! |---|---|---|
//! | `110 00 cc s 0` | initiate download (size in bytes 4–7) | — |
//! | `101 00 sc 00` | — | initiate download response (blksize in byte 4) |
//! | `c seqno` | download sub-block segment (7 data bytes) | upload sub-block segment |
//! | `101 000 10` | upload block ack (ackseq, blksize) | download block ack (ackseq, blksize) |
//! | `110 nnn 0 1` | end download (CRC in bytes 1–2) | — |
//! | `101 000 01` | end upload response | end download response |
//! | `101 00 cc 00` | initiate upload (blksize in byte 4, pst in byte 5) | — |
//! | `110 00 sc s 0` | — | initiate upload response (size in bytes 4–7) |
//! | `101 000 11` | start upload | — |
//! | `110 nnn 0 1` | — | end upload (CRC in bytes 1–2) |
//!
//! `cc`/`sc` = CRC supported by the client/server, `s` = size indicated, `c` = no more
//! segments, `seqno` = 1–127 in the sub-block, `nnn` = bytes of the last segment that hold no
//! data. Segments carry no command specifier: which frames are segments follows from the
//! state of the transfer, so the state machines decode them with [`BlockSegment::decode`].

use crate::{ObjectAddr, SdoAbort};
use crc::{CRC_16_XMODEM, Crc, NoTable};

/// The largest sub-block (CiA 301: blksize 1–127).
pub const MAX_BLKSIZE: u8 = 127;

/// CiA 301's block CRC: polynomial x^16 + x^12 + x^5 + 1, initial value 0, no reflection, as
/// CRC-16/XMODEM. Table-free: a CAN bus delivers at most a few hundred bytes per millisecond,
/// and firmware keeps the 512 bytes a table would take.
const CRC: Crc<u16, NoTable> = Crc::<u16, NoTable>::new(&CRC_16_XMODEM);

/// The CRC of `data` as block transfer computes it.
pub fn crc16(data: &[u8]) -> u16 {
    CRC.checksum(data)
}

/// The number of 7-byte segments `len` bytes take (at least one: an empty value is one empty
/// last segment).
pub(crate) const fn segments(len: usize) -> usize {
    if len == 0 { 1 } else { len.div_ceil(7) }
}

/// A block request, client → server, other than a sub-block segment.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum BlockRequest {
    /// Initiate block download: whether the client computes the CRC, the size if indicated.
    InitiateDownload {
        /// The object.
        addr: ObjectAddr,
        /// `cc`: the client supports the CRC.
        crc: bool,
        /// The value's size in bytes, if indicated.
        size: Option<u32>,
    },
    /// End block download: bytes of the last segment without data (0–6), the CRC.
    EndDownload {
        /// `n`: bytes of the last segment that held no data.
        unused: u8,
        /// The CRC of the whole value (0 when either side does not support it).
        crc: u16,
    },
    /// Initiate block upload.
    InitiateUpload {
        /// The object.
        addr: ObjectAddr,
        /// `cc`: the client supports the CRC.
        crc: bool,
        /// Segments per sub-block the client takes (1–127).
        blksize: u8,
        /// Protocol switch threshold: a value of at most this many bytes may be sent with
        /// the normal upload protocol instead; 0 forbids the switch.
        pst: u8,
    },
    /// Start block upload: the server may send the first sub-block.
    StartUpload,
    /// Upload sub-block acknowledged up to `ackseq`; the next sub-block has `blksize` segments.
    Ack {
        /// The last segment received in sequence (0: none).
        ackseq: u8,
        /// Segments of the next sub-block.
        blksize: u8,
    },
    /// End block upload response: the transfer is complete.
    EndUpload,
}

/// A block response, server → client, other than a sub-block segment.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum BlockResponse {
    /// Initiate block download response.
    InitiateDownload {
        /// The object.
        addr: ObjectAddr,
        /// `sc`: the server supports the CRC.
        crc: bool,
        /// Segments per sub-block the server takes (1–127).
        blksize: u8,
    },
    /// Download sub-block acknowledged up to `ackseq`; the next has `blksize` segments.
    Ack {
        /// The last segment received in sequence (0: none).
        ackseq: u8,
        /// Segments of the next sub-block.
        blksize: u8,
    },
    /// End block download response: the value is written.
    EndDownload,
    /// Initiate block upload response.
    InitiateUpload {
        /// The object.
        addr: ObjectAddr,
        /// `sc`: the server supports the CRC.
        crc: bool,
        /// The value's size in bytes, if indicated.
        size: Option<u32>,
    },
    /// End block upload: bytes of the last segment without data, the CRC.
    EndUpload {
        /// `n`: bytes of the last segment that held no data.
        unused: u8,
        /// The CRC of the whole value (0 when either side does not support it).
        crc: u16,
    },
}

fn with_mux(b0: u8, addr: ObjectAddr, d: [u8; 4]) -> [u8; 8] {
    let i = addr.index.to_le_bytes();
    [b0, i[0], i[1], addr.sub, d[0], d[1], d[2], d[3]]
}

fn mux(b: &[u8; 8]) -> ObjectAddr {
    ObjectAddr::new(u16::from_le_bytes([b[1], b[2]]), b[3])
}

fn size(b0: u8, b: &[u8; 8]) -> Option<u32> {
    (b0 & 0b10 != 0).then(|| u32::from_le_bytes([b[4], b[5], b[6], b[7]]))
}

fn end(cs: u8, unused: u8, crc: u16) -> [u8; 8] {
    let c = crc.to_le_bytes();
    [(cs << 5) | ((unused & 0b111) << 2) | 0b01, c[0], c[1], 0, 0, 0, 0, 0]
}

fn crc_of(b: &[u8; 8]) -> u16 {
    u16::from_le_bytes([b[1], b[2]])
}

impl BlockRequest {
    /// The 8 bytes on the wire.
    pub fn encode(&self) -> [u8; 8] {
        match *self {
            Self::InitiateDownload { addr, crc, size } => {
                let b0 = 0xC0 | (u8::from(crc) << 2) | (u8::from(size.is_some()) << 1);
                with_mux(b0, addr, size.unwrap_or(0).to_le_bytes())
            }
            Self::EndDownload { unused, crc } => end(6, unused, crc),
            Self::InitiateUpload { addr, crc, blksize, pst } => {
                with_mux(0xA0 | (u8::from(crc) << 2), addr, [blksize, pst, 0, 0])
            }
            Self::StartUpload => [0xA3, 0, 0, 0, 0, 0, 0, 0],
            Self::Ack { ackseq, blksize } => [0xA2, ackseq, blksize, 0, 0, 0, 0, 0],
            Self::EndUpload => [0xA1, 0, 0, 0, 0, 0, 0, 0],
        }
    }

    /// Decodes a request of command specifier 5 or 6 (the caller has checked bits 7–5).
    ///
    /// # Errors
    ///
    /// [`SdoAbort::InvalidCommand`] for another command specifier.
    pub fn decode(b: &[u8; 8]) -> Result<Self, SdoAbort> {
        Ok(match (b[0] >> 5, b[0] & 0b11) {
            (5, 0) => Self::InitiateUpload {
                addr: mux(b),
                crc: b[0] & 0b100 != 0,
                blksize: b[4],
                pst: b[5],
            },
            (5, 1) => Self::EndUpload,
            (5, 2) => Self::Ack { ackseq: b[1], blksize: b[2] },
            (5, 3) => Self::StartUpload,
            (6, 0 | 2) => {
                Self::InitiateDownload { addr: mux(b), crc: b[0] & 0b100 != 0, size: size(b[0], b) }
            }
            (6, 1 | 3) => Self::EndDownload { unused: (b[0] >> 2) & 0b111, crc: crc_of(b) },
            _ => return Err(SdoAbort::InvalidCommand),
        })
    }
}

impl BlockResponse {
    /// The 8 bytes on the wire.
    pub fn encode(&self) -> [u8; 8] {
        match *self {
            Self::InitiateDownload { addr, crc, blksize } => {
                with_mux(0xA0 | (u8::from(crc) << 2), addr, [blksize, 0, 0, 0])
            }
            Self::Ack { ackseq, blksize } => [0xA2, ackseq, blksize, 0, 0, 0, 0, 0],
            Self::EndDownload => [0xA1, 0, 0, 0, 0, 0, 0, 0],
            Self::InitiateUpload { addr, crc, size } => {
                let b0 = 0xC0 | (u8::from(crc) << 2) | (u8::from(size.is_some()) << 1);
                with_mux(b0, addr, size.unwrap_or(0).to_le_bytes())
            }
            Self::EndUpload { unused, crc } => end(6, unused, crc),
        }
    }

    /// Decodes a response of command specifier 5 or 6 (the caller has checked bits 7–5).
    ///
    /// # Errors
    ///
    /// [`SdoAbort::InvalidCommand`] for another command specifier or sub-command.
    pub fn decode(b: &[u8; 8]) -> Result<Self, SdoAbort> {
        Ok(match (b[0] >> 5, b[0] & 0b11) {
            (5, 0) => {
                Self::InitiateDownload { addr: mux(b), crc: b[0] & 0b100 != 0, blksize: b[4] }
            }
            (5, 1) => Self::EndDownload,
            (5, 2) => Self::Ack { ackseq: b[1], blksize: b[2] },
            (6, 0 | 2) => {
                Self::InitiateUpload { addr: mux(b), crc: b[0] & 0b100 != 0, size: size(b[0], b) }
            }
            (6, 1 | 3) => Self::EndUpload { unused: (b[0] >> 2) & 0b111, crc: crc_of(b) },
            _ => return Err(SdoAbort::InvalidCommand),
        })
    }
}

/// One segment of a sub-block: its sequence number, the last-segment bit and 7 data bytes
/// (how many of the last segment's count is said by the end frame that follows).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct BlockSegment {
    /// 1–127 within the sub-block.
    pub seqno: u8,
    /// `c`: no more segments follow in the transfer.
    pub last: bool,
    /// The data bytes (the last segment's tail is padding).
    pub data: [u8; 7],
}

impl BlockSegment {
    /// The segment carrying `bytes` (at most 7; fewer are zero-padded).
    pub fn new(seqno: u8, last: bool, bytes: &[u8]) -> Self {
        let mut data = [0u8; 7];
        let n = bytes.len().min(7);
        if let (Some(dst), Some(src)) = (data.get_mut(..n), bytes.get(..n)) {
            crate::bits::copy_bytes(dst, src);
        }
        Self { seqno, last, data }
    }

    /// The 8 bytes on the wire.
    pub fn encode(&self) -> [u8; 8] {
        let d = self.data;
        [(u8::from(self.last) << 7) | (self.seqno & 0x7F), d[0], d[1], d[2], d[3], d[4], d[5], d[6]]
    }

    /// Reads a frame as a segment; `None` for sequence number 0, which no segment has (that
    /// byte 0 is an abort, 0x80, or nothing valid).
    pub fn decode(b: &[u8; 8]) -> Option<Self> {
        let seqno = b[0] & 0x7F;
        if seqno == 0 {
            return None;
        }
        let [_, data @ ..] = *b;
        Some(Self { seqno, last: b[0] & 0x80 != 0, data })
    }
}

/// `7 - bytes in the last segment` for a value of `len` bytes, as the end frames carry it.
pub(crate) const fn unused_in_last(len: usize) -> u8 {
    let r = len % 7;
    if r == 0 && len > 0 { 0 } else { (7 - r) as u8 }
}

#[cfg(test)]
mod tests {
    use super::*;

    const A: ObjectAddr = ObjectAddr::new(0x1F50, 0x01);

    #[test]
    fn crc_is_cia301s() {
        // CRC-16/XMODEM's check value (the catalogue's "123456789"), and the CRC of nothing.
        assert_eq!(crc16(b"123456789"), 0x31C3);
        assert_eq!(crc16(&[]), 0);
        // By hand from x^16 + x^12 + x^5 + 1, initial 0: one byte 0x01 shifts the polynomial
        // 0x1021 through 8 bits: 0x1021.
        assert_eq!(crc16(&[0x01]), 0x1021);
    }

    #[test]
    fn download_frames() {
        // ccs=6, cc=1, s=1, cs=0: 0xC6; size 0x0000_0123 in bytes 4-7.
        let r = BlockRequest::InitiateDownload { addr: A, crc: true, size: Some(0x123) };
        assert_eq!(r.encode(), [0xC6, 0x50, 0x1F, 0x01, 0x23, 0x01, 0, 0]);
        assert_eq!(BlockRequest::decode(&r.encode()), Ok(r));
        // scs=5, sc=1, ss=0: 0xA4, blksize 127 in byte 4.
        let r = BlockResponse::InitiateDownload { addr: A, crc: true, blksize: 127 };
        assert_eq!(r.encode(), [0xA4, 0x50, 0x1F, 0x01, 0x7F, 0, 0, 0]);
        assert_eq!(BlockResponse::decode(&r.encode()), Ok(r));
        // Block ack: scs=5, ss=2.
        let r = BlockResponse::Ack { ackseq: 5, blksize: 20 };
        assert_eq!(r.encode(), [0xA2, 5, 20, 0, 0, 0, 0, 0]);
        // End: ccs=6, n=3 in bits 4-2, cs=1: 0xC0 | 3 << 2 | 1 = 0xCD; CRC LE.
        let r = BlockRequest::EndDownload { unused: 3, crc: 0x31C3 };
        assert_eq!(r.encode(), [0xCD, 0xC3, 0x31, 0, 0, 0, 0, 0]);
        assert_eq!(BlockRequest::decode(&r.encode()), Ok(r));
        assert_eq!(BlockResponse::EndDownload.encode()[0], 0xA1);
    }

    #[test]
    fn upload_frames() {
        // ccs=5, cc=1, cs=0: 0xA4; blksize byte 4, pst byte 5.
        let r = BlockRequest::InitiateUpload { addr: A, crc: true, blksize: 127, pst: 0 };
        assert_eq!(r.encode(), [0xA4, 0x50, 0x1F, 0x01, 0x7F, 0, 0, 0]);
        assert_eq!(BlockRequest::decode(&r.encode()), Ok(r));
        // scs=6, sc=1, s=1, ss=0: 0xC6.
        let r = BlockResponse::InitiateUpload { addr: A, crc: true, size: Some(10) };
        assert_eq!(r.encode(), [0xC6, 0x50, 0x1F, 0x01, 10, 0, 0, 0]);
        assert_eq!(BlockResponse::decode(&r.encode()), Ok(r));
        assert_eq!(BlockRequest::StartUpload.encode()[0], 0xA3);
        assert_eq!(
            BlockRequest::decode(&[0xA2, 9, 127, 0, 0, 0, 0, 0]),
            Ok(BlockRequest::Ack { ackseq: 9, blksize: 127 })
        );
        assert_eq!(BlockRequest::decode(&[0xA1, 0, 0, 0, 0, 0, 0, 0]), Ok(BlockRequest::EndUpload));
        // End upload: scs=6, n=4: 0xC0 | 4 << 2 | 1 = 0xD1.
        let r = BlockResponse::EndUpload { unused: 4, crc: 0xBEEF };
        assert_eq!(r.encode(), [0xD1, 0xEF, 0xBE, 0, 0, 0, 0, 0]);
        assert_eq!(BlockResponse::decode(&r.encode()), Ok(r));
        // scs=5 ss=3 is no response.
        assert_eq!(
            BlockResponse::decode(&[0xA3, 0, 0, 0, 0, 0, 0, 0]),
            Err(SdoAbort::InvalidCommand)
        );
    }

    #[test]
    fn segments_and_counts() {
        let s = BlockSegment::new(3, false, b"abcdefg");
        assert_eq!(s.encode(), [0x03, b'a', b'b', b'c', b'd', b'e', b'f', b'g']);
        let s = BlockSegment::new(2, true, b"xy");
        assert_eq!(s.encode(), [0x82, b'x', b'y', 0, 0, 0, 0, 0]);
        assert_eq!(BlockSegment::decode(&s.encode()), Some(s));
        // Byte 0 = 0x80 is an abort, not segment 0.
        assert_eq!(BlockSegment::decode(&[0x80, 0, 0, 0, 0, 0, 0x04, 0x05]), None);
        assert_eq!((segments(0), segments(7), segments(8), segments(889)), (1, 1, 2, 127));
        assert_eq!((unused_in_last(0), unused_in_last(7), unused_in_last(9)), (7, 0, 5));
    }
}
