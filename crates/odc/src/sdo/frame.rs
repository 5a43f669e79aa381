//! The SDO frame codec: CiA 301 §7.2.4.3 command specifiers and their bit fields.
//!
//! Every SDO frame has 8 bytes. Byte 0 holds the command specifier in bits 7–5 and the
//! per-command bits below; initiate and abort frames carry the multiplexer (index LE, sub)
//! in bytes 1–3; segment frames carry up to 7 data bytes in bytes 1–7.
//!
//! | byte 0 | client → server (ccs) | server → client (scs) |
//! |---|---|---|
//! | `000t nnnc` | download segment | upload segment |
//! | `001…` | initiate download (`nn e s` in bits 3–0) | download segment response (`t` bit 4) |
//! | `010…` | initiate upload | initiate upload response (`nn e s`) |
//! | `011…` | upload segment request (`t` bit 4) | initiate download response |
//! | `100…` | abort | abort |
//! | `101…`, `110…` | block upload, block download ([`super::block`]) | block download, block upload |
//!
//! `e` = expedited, `s` = size indicated, `nn` = bytes of the 4 that hold no data (valid when
//! `e` and `s`), `t` = toggle, `nnn` = bytes of the 7 that hold no data, `c` = last segment.

use super::block::{BlockRequest, BlockResponse};
use crate::{ObjectAddr, SdoAbort};

/// What an initiate frame says about the data: the 4 bytes themselves or the total size.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum Init {
    /// Expedited: `data[..len]` is the whole value. `sized` is false when the sender set
    /// `e` without `s` (CiA 301: the size is then "unspecified", all 4 bytes are sent).
    Expedited {
        /// The 4 data bytes of the frame.
        data: [u8; 4],
        /// Valid bytes, 1–4 (4 when not `sized`).
        len: u8,
        /// Whether the frame indicated the size.
        sized: bool,
    },
    /// Segmented: the size in bytes if indicated.
    Segmented(Option<u32>),
}

impl Init {
    /// The expedited form of `bytes` (1–4 of them), or `None` if it does not fit.
    pub fn expedited(bytes: &[u8]) -> Option<Self> {
        if bytes.is_empty() || bytes.len() > 4 {
            return None;
        }
        let mut data = [0u8; 4];
        crate::bits::copy_bytes(data.get_mut(..bytes.len())?, bytes);
        Some(Self::Expedited { data, len: bytes.len() as u8, sized: true })
    }

    /// Bits 3–0 of byte 0 and bytes 4–7.
    fn encode(self) -> (u8, [u8; 4]) {
        match self {
            Self::Expedited { data, len, sized: true } => {
                let n = 4u8.saturating_sub(len.clamp(1, 4));
                ((n << 2) | 0b11, data)
            }
            Self::Expedited { data, sized: false, .. } => (0b10, data),
            Self::Segmented(Some(size)) => (0b01, size.to_le_bytes()),
            Self::Segmented(None) => (0b00, [0; 4]),
        }
    }

    fn decode(b0: u8, d: [u8; 4]) -> Self {
        let (e, s) = (b0 & 0b10 != 0, b0 & 0b01 != 0);
        match (e, s) {
            (true, true) => Self::Expedited { data: d, len: 4 - ((b0 >> 2) & 0b11), sized: true },
            (true, false) => Self::Expedited { data: d, len: 4, sized: false },
            (false, true) => Self::Segmented(Some(u32::from_le_bytes(d))),
            (false, false) => Self::Segmented(None),
        }
    }
}

/// One segment: up to 7 data bytes, the toggle bit and the "last segment" bit.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct Segment {
    /// Toggle bit (0 on the first segment, alternating).
    pub toggle: bool,
    /// The 7 data bytes of the frame.
    pub data: [u8; 7],
    /// Valid bytes, 0–7.
    pub len: u8,
    /// No more segments follow (`c`).
    pub last: bool,
}

impl Segment {
    /// A segment of `bytes` (at most 7; more are cut off).
    pub fn new(toggle: bool, bytes: &[u8], last: bool) -> Self {
        let mut data = [0u8; 7];
        let n = bytes.len().min(7);
        if let (Some(dst), Some(src)) = (data.get_mut(..n), bytes.get(..n)) {
            crate::bits::copy_bytes(dst, src);
        }
        Self { toggle, data, len: n as u8, last }
    }

    /// The valid bytes.
    pub fn bytes(&self) -> &[u8] {
        self.data.get(..usize::from(self.len).min(7)).unwrap_or(&self.data)
    }

    fn encode(&self, cs: u8) -> [u8; 8] {
        let n = 7u8.saturating_sub(self.len.min(7));
        let d = self.data;
        let b0 = (cs << 5) | (u8::from(self.toggle) << 4) | (n << 1) | u8::from(self.last);
        [b0, d[0], d[1], d[2], d[3], d[4], d[5], d[6]]
    }

    fn decode(b: &[u8; 8]) -> Self {
        let [_, data @ ..] = *b;
        Self { toggle: b[0] & 0x10 != 0, data, len: 7 - ((b[0] >> 1) & 0b111), last: b[0] & 1 != 0 }
    }
}

/// A request, client → server (CAN-ID 0x600 + node).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum Request {
    /// ccs 1: initiate download.
    InitiateDownload(ObjectAddr, Init),
    /// ccs 0: download segment.
    DownloadSegment(Segment),
    /// ccs 2: initiate upload.
    InitiateUpload(ObjectAddr),
    /// ccs 3: upload segment request, with its toggle bit.
    UploadSegment(bool),
    /// ccs 4: abort transfer.
    Abort(ObjectAddr, SdoAbort),
    /// ccs 5 or 6: a block transfer request other than a sub-block segment (segments carry
    /// no command specifier; see [`super::block`]).
    Block(BlockRequest),
}

/// A response, server → client (CAN-ID 0x580 + node).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum Response {
    /// scs 3: initiate download response.
    InitiateDownload(ObjectAddr),
    /// scs 1: download segment response, echoing the segment's toggle bit.
    DownloadSegment(bool),
    /// scs 2: initiate upload response.
    InitiateUpload(ObjectAddr, Init),
    /// scs 0: upload segment.
    UploadSegment(Segment),
    /// scs 4: abort transfer.
    Abort(ObjectAddr, SdoAbort),
    /// scs 5 or 6: a block transfer response other than a sub-block segment.
    Block(BlockResponse),
}

fn mux(b: &[u8; 8]) -> ObjectAddr {
    ObjectAddr::new(u16::from_le_bytes([b[1], b[2]]), b[3])
}

fn with_mux(b0: u8, addr: ObjectAddr, d: [u8; 4]) -> [u8; 8] {
    let i = addr.index.to_le_bytes();
    [b0, i[0], i[1], addr.sub, d[0], d[1], d[2], d[3]]
}

fn tail(b: &[u8; 8]) -> [u8; 4] {
    [b[4], b[5], b[6], b[7]]
}

/// The 8 bytes of a frame; a shorter frame is zero-padded (CiA 301 wants 8, some devices send
/// fewer for short answers).
pub(crate) fn pad(bytes: &[u8]) -> [u8; 8] {
    let mut b = [0u8; 8];
    let n = bytes.len().min(8);
    if let (Some(dst), Some(src)) = (b.get_mut(..n), bytes.get(..n)) {
        crate::bits::copy_bytes(dst, src);
    }
    b
}

impl Request {
    /// The 8 bytes on the wire.
    pub fn encode(&self) -> [u8; 8] {
        match *self {
            Self::InitiateDownload(a, init) => {
                let (bits, d) = init.encode();
                with_mux(0x20 | bits, a, d)
            }
            Self::DownloadSegment(s) => s.encode(0),
            Self::InitiateUpload(a) => with_mux(0x40, a, [0; 4]),
            Self::UploadSegment(t) => [0x60 | (u8::from(t) << 4), 0, 0, 0, 0, 0, 0, 0],
            Self::Abort(a, code) => with_mux(0x80, a, code.to_u32().to_le_bytes()),
            Self::Block(r) => r.encode(),
        }
    }

    /// Decodes a request.
    ///
    /// # Errors
    ///
    /// [`SdoAbort::InvalidCommand`] for ccs 7, an unknown block sub-command (any block
    /// request without the feature `sdo-block`) or an empty frame.
    // Inlined into the server, whose match on the request then is the decoder's own.
    #[inline(always)]
    pub fn decode(bytes: &[u8]) -> Result<Self, SdoAbort> {
        if bytes.is_empty() {
            return Err(SdoAbort::InvalidCommand);
        }
        let b = pad(bytes);
        Ok(match b[0] >> 5 {
            0 => Self::DownloadSegment(Segment::decode(&b)),
            1 => Self::InitiateDownload(mux(&b), Init::decode(b[0], tail(&b))),
            2 => Self::InitiateUpload(mux(&b)),
            3 => Self::UploadSegment(b[0] & 0x10 != 0),
            4 => Self::Abort(mux(&b), SdoAbort::from_u32(u32::from_le_bytes(tail(&b)))),
            // A build without block transfer (feature `sdo-block`) reads no block request, as
            // its server serves none: both answer InvalidCommand.
            #[cfg(feature = "sdo-block")]
            5 | 6 => Self::Block(BlockRequest::decode(&b)?),
            _ => return Err(SdoAbort::InvalidCommand),
        })
    }
}

impl Response {
    /// The 8 bytes on the wire.
    // Inlined: where the variant is known (every answer of the server), only its arm is
    // linked, not the block responses' encoder into a server without block transfer.
    #[inline(always)]
    pub fn encode(&self) -> [u8; 8] {
        match *self {
            Self::InitiateDownload(a) => with_mux(0x60, a, [0; 4]),
            Self::DownloadSegment(t) => [0x20 | (u8::from(t) << 4), 0, 0, 0, 0, 0, 0, 0],
            Self::InitiateUpload(a, init) => {
                let (bits, d) = init.encode();
                with_mux(0x40 | bits, a, d)
            }
            Self::UploadSegment(s) => s.encode(0),
            Self::Abort(a, code) => with_mux(0x80, a, code.to_u32().to_le_bytes()),
            Self::Block(r) => r.encode(),
        }
    }

    /// Decodes a response.
    ///
    /// # Errors
    ///
    /// [`SdoAbort::InvalidCommand`] for scs 7, an unknown block sub-command or an empty frame.
    pub fn decode(bytes: &[u8]) -> Result<Self, SdoAbort> {
        if bytes.is_empty() {
            return Err(SdoAbort::InvalidCommand);
        }
        let b = pad(bytes);
        Ok(match b[0] >> 5 {
            0 => Self::UploadSegment(Segment::decode(&b)),
            1 => Self::DownloadSegment(b[0] & 0x10 != 0),
            2 => Self::InitiateUpload(mux(&b), Init::decode(b[0], tail(&b))),
            3 => Self::InitiateDownload(mux(&b)),
            4 => Self::Abort(mux(&b), SdoAbort::from_u32(u32::from_le_bytes(tail(&b)))),
            5 | 6 => Self::Block(BlockResponse::decode(&b)?),
            _ => return Err(SdoAbort::InvalidCommand),
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    const A: ObjectAddr = ObjectAddr::new(0x1018, 0x02);

    #[test]
    fn expedited_download_n_bits() {
        // CiA 301: ccs=1, n = 4 - len in bits 3-2, e=1, s=1.
        let r = Request::InitiateDownload(A, Init::expedited(&[0x11]).unwrap());
        assert_eq!(r.encode(), [0x2F, 0x18, 0x10, 0x02, 0x11, 0, 0, 0]);
        let r = Request::InitiateDownload(A, Init::expedited(&[1, 2]).unwrap());
        assert_eq!(r.encode()[0], 0x2B);
        let r = Request::InitiateDownload(A, Init::expedited(&[1, 2, 3]).unwrap());
        assert_eq!(r.encode()[0], 0x27);
        let r = Request::InitiateDownload(A, Init::expedited(&[1, 2, 3, 4]).unwrap());
        assert_eq!(r.encode(), [0x23, 0x18, 0x10, 0x02, 1, 2, 3, 4]);
        assert_eq!(Request::decode(&r.encode()), Ok(r));
        assert!(Init::expedited(&[]).is_none());
        assert!(Init::expedited(&[0; 5]).is_none());
        // e=1, s=0: size unspecified, all four bytes.
        let Ok(Request::InitiateDownload(_, i)) = Request::decode(&[0x22, 0, 0x20, 0, 9, 8, 7, 6])
        else {
            panic!("not a download")
        };
        assert_eq!(i, Init::Expedited { data: [9, 8, 7, 6], len: 4, sized: false });
    }

    #[test]
    fn segmented_initiate_and_segments() {
        // ccs=1, e=0, s=1: size in bytes 4-7.
        let r = Request::InitiateDownload(A, Init::Segmented(Some(10)));
        assert_eq!(r.encode(), [0x21, 0x18, 0x10, 0x02, 10, 0, 0, 0]);
        assert_eq!(Request::InitiateDownload(A, Init::Segmented(None)).encode()[0], 0x20);
        // First segment, toggle 0, 7 bytes, more to come: 0x00.
        let s = Segment::new(false, b"abcdefg", false);
        assert_eq!(
            Request::DownloadSegment(s).encode(),
            [0x00, b'a', b'b', b'c', b'd', b'e', b'f', b'g']
        );
        // Second segment, toggle 1, 3 bytes (n = 4), last: 0x10 | 4 << 1 | 1 = 0x19.
        let s = Segment::new(true, b"hij", true);
        let b = Request::DownloadSegment(s).encode();
        assert_eq!(b, [0x19, b'h', b'i', b'j', 0, 0, 0, 0]);
        assert_eq!(Request::decode(&b), Ok(Request::DownloadSegment(s)));
        // Download segment response: scs=1, toggle echoed.
        assert_eq!(Response::DownloadSegment(false).encode()[0], 0x20);
        assert_eq!(Response::DownloadSegment(true).encode()[0], 0x30);
        assert_eq!(Response::InitiateDownload(A).encode(), [0x60, 0x18, 0x10, 0x02, 0, 0, 0, 0]);
    }

    #[test]
    fn upload_frames() {
        assert_eq!(Request::InitiateUpload(A).encode(), [0x40, 0x18, 0x10, 0x02, 0, 0, 0, 0]);
        // Expedited upload response of 4 bytes: 0x43; 2 bytes: 0x4B; 1 byte: 0x4F.
        let r = Response::InitiateUpload(A, Init::expedited(&[1, 2, 3, 4]).unwrap());
        assert_eq!(r.encode()[0], 0x43);
        assert_eq!(
            Response::InitiateUpload(A, Init::expedited(&[1, 2]).unwrap()).encode()[0],
            0x4B
        );
        assert_eq!(Response::InitiateUpload(A, Init::expedited(&[1]).unwrap()).encode()[0], 0x4F);
        // Segmented upload response with size: 0x41.
        let r = Response::InitiateUpload(A, Init::Segmented(Some(0x1234)));
        assert_eq!(r.encode(), [0x41, 0x18, 0x10, 0x02, 0x34, 0x12, 0, 0]);
        assert_eq!(Response::decode(&r.encode()), Ok(r));
        // Upload segment request: ccs=3, toggle in bit 4.
        assert_eq!(Request::UploadSegment(false).encode()[0], 0x60);
        assert_eq!(Request::UploadSegment(true).encode()[0], 0x70);
        // Last upload segment of 5 bytes with toggle 1: 0x10 | 2 << 1 | 1 = 0x15.
        let s = Segment::new(true, b"12345", true);
        assert_eq!(Response::UploadSegment(s).encode()[0], 0x15);
        assert_eq!(
            Response::decode(&[0x15, 1, 2, 3, 4, 5, 0, 0]).map(|r| match r {
                Response::UploadSegment(s) => s.bytes().len(),
                _ => 99,
            }),
            Ok(5)
        );
        // An empty last segment: n = 7.
        assert_eq!(Response::UploadSegment(Segment::new(false, &[], true)).encode()[0], 0x0F);
    }

    #[test]
    fn abort_frames() {
        let r = Request::Abort(A, SdoAbort::ToggleBit);
        assert_eq!(r.encode(), [0x80, 0x18, 0x10, 0x02, 0x00, 0x00, 0x03, 0x05]);
        let r = Response::Abort(ObjectAddr::new(0x6040, 0), SdoAbort::WriteOfReadOnly);
        assert_eq!(r.encode(), [0x80, 0x40, 0x60, 0x00, 0x02, 0x00, 0x01, 0x06]);
        assert_eq!(Response::decode(&r.encode()), Ok(r));
        assert_eq!(
            Response::decode(&[0x80, 0, 0x20, 0, 0x30, 0, 0x09, 0x06]),
            Ok(Response::Abort(ObjectAddr::new(0x2000, 0), SdoAbort::InvalidValue))
        );
    }

    #[test]
    fn invalid_and_block_commands() {
        assert_eq!(Request::decode(&[0xE0, 0, 0, 0, 0, 0, 0, 0]), Err(SdoAbort::InvalidCommand));
        assert_eq!(Request::decode(&[]), Err(SdoAbort::InvalidCommand));
        assert_eq!(
            Request::decode(&[0xC4, 0, 0x20, 0, 0, 0, 0, 0]),
            Ok(Request::Block(BlockRequest::InitiateDownload {
                addr: ObjectAddr::new(0x2000, 0),
                crc: true,
                size: None
            }))
        );
        assert_eq!(Response::decode(&[0xA1]), Ok(Response::Block(BlockResponse::EndDownload)));
        // Short frames are zero-padded.
        assert_eq!(
            Request::decode(&[0x40, 0x00, 0x10]),
            Ok(Request::InitiateUpload(ObjectAddr::new(0x1000, 0)))
        );
    }
}
