//! CiA 301's SDO protocol (§7.2.4.3) as the client side sees it, written from the standard
//! and not from `odc::sdo::Server`: which frames a server may send for each request, given
//! the transfer under way. Shared by the `sdo_server` and `node` targets.
//!
//! What it asserts, per request to the server's COB-ID:
//! - every frame sent is on the response COB-ID, an 11-bit data frame of 8 bytes;
//! - a request is answered by exactly one frame (its confirmation or an abort), except a
//!   client abort (none), a sub-block segment of a block download (an acknowledgement only
//!   at the end of the sub-block, or an abort), the start or acknowledgement of a block
//!   upload (the next sub-block, 1 to blksize segments numbered from 1, or the end frame),
//!   and the client's last frame of a block upload (none);
//! - a confirmation answers the request (initiate responses echo the multiplexer, segment
//!   responses the toggle bit); an abort carries a non-zero code, and the request's
//!   multiplexer when it answers an initiate;
//! - the dictionary takes a value exactly when a download is confirmed (one write), never
//!   otherwise;
//! - uploaded bytes, expedited or segmented, are the dictionary's value at the initiate;
//! - a transfer under way is aborted with 0x05040000 once the timeout passes, and the server
//!   says it is busy exactly while the model has a transfer under way.

use odc::can::CanFrame;
use odc::time::{Duration, Instant};

/// What the client may send next, by CiA 301.
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum Phase {
    Idle,
    /// Segmented download: the next segment's toggle bit.
    Download,
    /// Segmented upload: the value and how many of its bytes came already.
    Upload {
        value: Option<Vec<u8>>,
        pos: usize,
    },
    /// Block download, sub-block segments due: the server's block size, the next sequence
    /// number in order, and whether the in-order segments included the last one.
    BlockDlSegments {
        blksize: u8,
        expect: u8,
        saw_last: bool,
    },
    /// Block download: all segments acknowledged, the end frame due.
    BlockDlEnd,
    /// Block upload initiated: the client's start is due.
    BlockUlInitiated {
        blksize: u8,
    },
    /// Block upload: `sent` segments of a sub-block are out, the acknowledgement is due.
    BlockUlAwaitAck {
        sent: u8,
    },
    /// Block upload: the end frame is out; the client's end response is due.
    BlockUlAwaitEnd,
}

/// The client-side view of one server.
pub struct Model {
    pub phase: Phase,
    /// Time of the last request.
    last: Instant,
    timeout: Duration,
}

/// The 8 bytes of a request, zero-padded (a server reads a short request as padded).
fn pad(b: &[u8]) -> [u8; 8] {
    let mut p = [0u8; 8];
    for (d, s) in p.iter_mut().zip(b) {
        *d = *s;
    }
    p
}

fn mux(b: &[u8; 8]) -> [u8; 3] {
    [b[1], b[2], b[3]]
}

fn is_abort(f: &CanFrame) -> bool {
    f.data()[0] == 0x80
}

fn abort_code(f: &CanFrame) -> u32 {
    let d = f.data();
    u32::from_le_bytes([d[4], d[5], d[6], d[7]])
}

/// Checks one frame a server sent: response COB-ID, standard data frame, 8 bytes.
pub fn check_frame(f: &CanFrame, resp_id: u32) {
    assert_eq!(f.id(), resp_id, "SDO response on another COB-ID: {f:?}");
    assert!(
        !f.is_extended() && !f.is_remote() && f.len() == 8,
        "SDO response not an 8-byte data frame: {f:?}"
    );
}

impl Model {
    pub fn new(timeout: Duration) -> Self {
        Self { phase: Phase::Idle, last: Instant::ZERO, timeout }
    }

    pub fn busy(&self) -> bool {
        self.phase != Phase::Idle
    }

    /// One request (`req`: its bytes as received) and the frames the server sent for it;
    /// `wrote`: successful dictionary writes during the call, when the harness can count
    /// them; `read`: the dictionary's value
    /// of an object now, when the harness can tell it.
    pub fn request(
        &mut self,
        req: &[u8],
        out: &[CanFrame],
        wrote: Option<usize>,
        now: Instant,
        read: &dyn Fn([u8; 3]) -> Option<Vec<u8>>,
    ) {
        self.last = now;
        let b = pad(req);
        let ccs = b[0] >> 5;
        let one = |what: &str| {
            assert_eq!(
                out.len(),
                1,
                "{what}: expected exactly one answer to {req:02X?}, got {out:02X?}"
            );
        };
        let aborted = out.len() == 1 && is_abort(&out[0]);
        if aborted {
            assert_ne!(abort_code(&out[0]), 0, "abort without a code: {out:02X?}");
        }
        // Where a write is allowed: set when a download is confirmed.
        let mut confirmed_write = false;

        if let Phase::BlockDlSegments { blksize, expect, saw_last } = self.phase.clone()
            && b[0] != 0x80
        {
            // A sub-block segment: sequence number 1-127, bit 7 the last one.
            let seq = b[0] & 0x7F;
            let last = b[0] & 0x80 != 0;
            assert!(out.len() <= 1, "segment answered by several frames: {out:02X?}");
            if seq == 0 {
                one("segment with sequence number 0");
                assert!(aborted, "segment 0 not aborted: {out:02X?}");
            }
            let (expect, saw_last) =
                if seq == expect { (expect + 1, last) } else { (expect, saw_last) };
            let ack_due = seq != 0 && (last || seq >= blksize);
            if ack_due {
                one("end of a sub-block");
            }
            if let Some(f) = out.first()
                && !is_abort(f)
            {
                assert!(ack_due, "sub-block acknowledged before its end: {req:02X?} -> {f:02X?}");
                assert_eq!(f.data()[0], 0xA2, "not a block acknowledgement: {f:02X?}");
                assert_eq!(f.data()[1], expect - 1, "ackseq is not the last segment in order");
                assert!(
                    (1..=127).contains(&f.data()[2]),
                    "block size {} out of 1-127",
                    f.data()[2]
                );
                self.phase = if saw_last {
                    Phase::BlockDlEnd
                } else {
                    Phase::BlockDlSegments { blksize: f.data()[2], expect: 1, saw_last: false }
                };
            } else if aborted {
                self.phase = Phase::Idle;
            } else {
                self.phase = Phase::BlockDlSegments { blksize, expect, saw_last };
            }
            assert!(wrote.unwrap_or(0) == 0, "a block segment wrote the dictionary");
            return;
        }

        if !req.is_empty() && ccs == 4 {
            assert!(out.is_empty(), "a client abort was answered: {out:02X?}");
            assert!(wrote.unwrap_or(0) == 0, "a client abort wrote the dictionary");
            self.phase = Phase::Idle;
            return;
        }
        let phase = std::mem::replace(&mut self.phase, Phase::Idle);
        let ss = b[0] & 0b11;
        if req.is_empty() {
            one("empty request");
            assert!(aborted, "empty request not aborted: {out:02X?}");
        } else if aborted {
            // An abort is always a possible answer to a request; the multiplexer of an
            // initiate is echoed.
            if matches!((ccs, ss), (1 | 2, _) | (5, 0) | (6, 0 | 2)) {
                assert_eq!(mux(&out[0].data()), mux(&b), "abort names another object: {out:02X?}");
            }
        } else {
            match (ccs, phase) {
                (0, Phase::Download) => {
                    one("download segment");
                    let f = &out[0];
                    assert_eq!(
                        f.data()[0] & 0xEF,
                        0x20,
                        "not a download segment response: {f:02X?}"
                    );
                    assert_eq!(f.data()[0] & 0x10, b[0] & 0x10, "toggle bit not echoed");
                    if b[0] & 1 == 0 {
                        self.phase = Phase::Download;
                    } else {
                        confirmed_write = true;
                    }
                }
                (1, _) => {
                    one("initiate download");
                    let f = &out[0];
                    assert_eq!(f.data()[0], 0x60, "not an initiate download response: {f:02X?}");
                    assert_eq!(
                        mux(&f.data()),
                        mux(&b),
                        "initiate download response for another object"
                    );
                    if b[0] & 0b10 != 0 {
                        confirmed_write = true;
                    } else {
                        self.phase = Phase::Download;
                    }
                }
                (2, _) => self.upload_initiated(&b, out, read),
                (3, Phase::Upload { value, pos }) => {
                    one("upload segment");
                    let f = &out[0];
                    assert_eq!(f.data()[0] >> 5, 0, "not an upload segment: {f:02X?}");
                    assert_eq!(f.data()[0] & 0x10, b[0] & 0x10, "toggle bit not echoed");
                    let n = 7 - usize::from((f.data()[0] >> 1) & 0b111);
                    let last = f.data()[0] & 1 != 0;
                    if let Some(v) = &value {
                        assert_eq!(
                            v.get(pos..pos + n),
                            Some(&f.data()[1..1 + n]),
                            "uploaded bytes differ"
                        );
                        assert_eq!(
                            last,
                            pos + n == v.len(),
                            "last bit wrong at {pos}+{n} of {}",
                            v.len()
                        );
                    }
                    if !last {
                        self.phase = Phase::Upload { value, pos: pos + n };
                    }
                }
                (5, _) if ss == 0 => {
                    one("initiate block upload");
                    let f = &out[0];
                    assert!((1..=127).contains(&b[4]), "block size {} taken", b[4]);
                    if f.data()[0] >> 5 == 2 {
                        // Protocol switch threshold: the normal upload answers.
                        assert!(b[5] != 0, "switched to a normal upload without a threshold");
                        self.upload_initiated(&b, out, read);
                    } else {
                        assert_eq!(
                            f.data()[0] & 0xE1,
                            0xC0,
                            "not an initiate block upload response: {f:02X?}"
                        );
                        assert_eq!(
                            mux(&f.data()),
                            mux(&b),
                            "block upload response for another object"
                        );
                        self.phase = Phase::BlockUlInitiated { blksize: b[4] };
                    }
                }
                (5, Phase::BlockUlInitiated { blksize }) if ss == 3 => {
                    self.phase = sub_block(out, blksize, req);
                }
                (5, Phase::BlockUlAwaitAck { sent }) if ss == 2 => {
                    assert!(
                        b[1] <= sent,
                        "ackseq {} past the {sent} segments sent was taken",
                        b[1]
                    );
                    assert!((1..=127).contains(&b[2]), "block size {} taken", b[2]);
                    if out.len() == 1 && out[0].data()[0] >> 5 == 6 && out[0].data()[0] & 0b11 == 1
                    {
                        self.phase = Phase::BlockUlAwaitEnd;
                    } else {
                        self.phase = sub_block(out, b[2], req);
                    }
                }
                (5, Phase::BlockUlAwaitEnd) if ss == 1 => {
                    assert!(out.is_empty(), "the end of a block upload was answered: {out:02X?}");
                }
                (6, _) if ss & 1 == 0 => {
                    one("initiate block download");
                    let f = &out[0];
                    assert_eq!(
                        f.data()[0] & 0xE3,
                        0xA0,
                        "not an initiate block download response: {f:02X?}"
                    );
                    assert_eq!(
                        mux(&f.data()),
                        mux(&b),
                        "block download response for another object"
                    );
                    assert!(
                        (1..=127).contains(&f.data()[4]),
                        "block size {} out of 1-127",
                        f.data()[4]
                    );
                    self.phase =
                        Phase::BlockDlSegments { blksize: f.data()[4], expect: 1, saw_last: false };
                }
                (6, Phase::BlockDlEnd) => {
                    one("end of a block download");
                    assert_eq!(out[0].data()[0], 0xA1, "not an end block download response");
                    confirmed_write = true;
                }
                (_, p) => panic!("{req:02X?} in {p:?} must be aborted, got {out:02X?}"),
            }
        }
        if aborted {
            self.phase = Phase::Idle;
        }
        if let Some(wrote) = wrote {
            let want = usize::from(confirmed_write);
            assert_eq!(wrote, want, "{wrote} writes for {req:02X?} answered {out:02X?}");
        }
    }

    fn upload_initiated(
        &mut self,
        b: &[u8; 8],
        out: &[CanFrame],
        read: &dyn Fn([u8; 3]) -> Option<Vec<u8>>,
    ) {
        assert_eq!(out.len(), 1, "initiate upload answered by {out:02X?}");
        let f = &out[0];
        assert_eq!(f.data()[0] >> 5, 2, "not an initiate upload response: {f:02X?}");
        assert_eq!(mux(&f.data()), mux(b), "upload response for another object");
        let value = read(mux(b));
        let e = f.data()[0] & 0b10 != 0;
        let s = f.data()[0] & 0b01 != 0;
        if e {
            assert!(s, "expedited upload without its size");
            let n = 4 - usize::from((f.data()[0] >> 2) & 0b11);
            if let Some(v) = &value {
                assert_eq!(
                    &f.data()[4..4 + n],
                    v.as_slice(),
                    "expedited upload differs from the dictionary"
                );
            }
        } else {
            assert!(s, "segmented upload without its size");
            let size = u32::from_le_bytes([f.data()[4], f.data()[5], f.data()[6], f.data()[7]]);
            if let Some(v) = &value {
                assert_eq!(size as usize, v.len(), "upload size differs from the dictionary's");
                // 1-4 bytes go expedited (CiA 301: 4 - n of them valid; 0 bytes cannot).
                assert!(
                    v.len() > 4 || v.is_empty(),
                    "a value of {} bytes uploaded segmented",
                    v.len()
                );
            }
            self.phase = Phase::Upload { value, pos: 0 };
        }
    }

    /// The server's own frames between requests (`Server::poll`, the node's poll).
    pub fn poll(&mut self, out: &[CanFrame], now: Instant) {
        let expired = self.busy() && now > self.last.saturating_add(self.timeout);
        if expired {
            assert_eq!(out.len(), 1, "timeout: expected one abort, got {out:02X?}");
            assert!(is_abort(&out[0]), "timeout answered by {out:02X?}");
            assert_eq!(abort_code(&out[0]), 0x0504_0000, "timeout abort code");
            self.phase = Phase::Idle;
        } else {
            assert!(out.is_empty(), "unprompted SDO frames {out:02X?} in {:?}", self.phase);
        }
    }
}

/// A block upload's sub-block: segments numbered 1..=k, the last with bit 7 or k = blksize.
fn sub_block(out: &[CanFrame], blksize: u8, req: &[u8]) -> Phase {
    assert!(!out.is_empty(), "no sub-block for {req:02X?}");
    assert!(
        out.len() <= usize::from(blksize),
        "{} segments in a sub-block of {blksize}",
        out.len()
    );
    for (i, f) in out.iter().enumerate() {
        let seq = f.data()[0] & 0x7F;
        assert_eq!(usize::from(seq), i + 1, "segment numbers out of order: {out:02X?}");
        let last = f.data()[0] & 0x80 != 0;
        assert!(!last || i + 1 == out.len(), "segments after the last one");
    }
    let end = out.last().map(|f| f.data()[0]).unwrap_or(0);
    assert!(end & 0x80 != 0 || out.len() == usize::from(blksize), "sub-block stopped early");
    Phase::BlockUlAwaitAck { sent: out.len() as u8 }
}
