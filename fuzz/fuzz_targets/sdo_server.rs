//! The SDO server (`odc::sdo::Server`) fed arbitrary frames at arbitrary times, checked
//! against CiA 301's protocol as a client sees it (`common/sdo_model.rs`): every request to
//! its COB-ID gets exactly one confirmation or abort (but for the exceptions the protocol
//! has), on 0x580 + node, 8 bytes; frames on other COB-IDs, remote and extended frames get
//! nothing; the dictionary is written exactly when a download is confirmed; uploads carry
//! the dictionary's bytes; a stalled transfer is aborted with 0x05040000 after the timeout.
//!
//! Interleaved with the garbage, a well-behaved client runs whole transfers (abort first,
//! then an expedited, segmented or block download of random bytes, or a segmented upload):
//! whatever came before, they succeed and the dictionary then holds what was sent.
#![no_main]

#[path = "common/dict.rs"]
mod dict;
#[path = "common/sdo_model.rs"]
mod sdo_model;

use arbitrary::{Arbitrary, Unstructured};
use dict::Dict;
use libfuzzer_sys::fuzz_target;
use odc::can::CanFrame;
use odc::cob::NodeId;
use odc::time::{Duration, Instant};
use sdo_model::Model;

const NODE: u8 = 5;
const REQ: u32 = 0x600 + NODE as u32;
const RESP: u32 = 0x580 + NODE as u32;
/// The server's timeout, in µs (the clock's unit): 100 ms.
const TIMEOUT_US: u64 = 100_000;
const TIMEOUT: Duration = Duration::from_micros(TIMEOUT_US);
/// The server's transfer buffer.
const N: usize = 32;

type Server = odc::sdo::Server<N>;

/// Every call into the runtime goes through these functions (its frame, time and node-ID
/// types; only here needs adapting).
fn server_new(blksize: u8) -> Server {
    let node = NodeId::new(NODE).expect("a node-ID");
    Server::new(node).with_timeout(TIMEOUT).with_blksize(blksize)
}

fn serve(server: &mut Server, dict: &mut Dict, frame: &CanFrame, now: Instant) -> Vec<CanFrame> {
    let mut out = Vec::new();
    server.handle_into(dict, frame, now, &mut |f| out.push(f));
    out
}

fn tick(server: &mut Server, now: Instant) -> Vec<CanFrame> {
    let mut out = Vec::new();
    while let Some(f) = server.poll(now) {
        out.push(f);
        assert!(out.len() <= 1, "poll gave more than one frame between requests: {out:02X?}");
    }
    out
}

fn frame(id: u32, bytes: &[u8]) -> CanFrame {
    CanFrame::from_slice(id, bytes).expect("at most 8 bytes, by construction")
}

struct Harness {
    server: Server,
    dict: Dict,
    model: Model,
    now: Instant,
}

impl Harness {
    /// One frame to the server, checked; the answers.
    fn send(&mut self, f: &CanFrame) -> Vec<CanFrame> {
        let writes = self.dict.writes;
        let busy_before = self.server.is_busy();
        let out = serve(&mut self.server, &mut self.dict, f, self.now);
        for o in &out {
            sdo_model::check_frame(o, RESP);
        }
        let wrote = self.dict.writes - writes;
        if f.is_data(REQ) {
            let dict = &self.dict;
            let read = |m: [u8; 3]| dict.value(u16::from_le_bytes([m[0], m[1]]), m[2]);
            self.model.request(f.bytes(), &out, Some(wrote), self.now, &read);
        } else {
            assert!(out.is_empty(), "{f:?} is no request to this server, answered {out:02X?}");
            assert_eq!(wrote, 0);
            assert_eq!(self.server.is_busy(), busy_before, "{f:?} changed the transfer");
        }
        assert_eq!(
            self.server.is_busy(),
            self.model.busy(),
            "busy, model in {:?}",
            self.model.phase
        );
        out
    }

    /// `dt_us`: microseconds.
    fn advance(&mut self, dt_us: u64) {
        self.now = self.now.saturating_add(Duration::from_micros(dt_us));
        let out = tick(&mut self.server, self.now);
        for o in &out {
            sdo_model::check_frame(o, RESP);
        }
        self.model.poll(&out, self.now);
        assert_eq!(self.server.is_busy(), self.model.busy());
    }

    /// One request of the well-behaved client; it must not be aborted.
    fn ok(&mut self, bytes: [u8; 8]) -> Vec<CanFrame> {
        let out = self.send(&frame(REQ, &bytes));
        assert!(out.iter().all(|f| f.data()[0] != 0x80), "{bytes:02X?} aborted: {out:02X?}");
        out
    }

    fn download(&mut self, (index, sub): (u16, u8), value: &[u8], how: u8) {
        let [i0, i1] = index.to_le_bytes();
        // A client abort ends whatever transfer the garbage left open.
        self.send(&frame(REQ, &[0x80, i0, i1, sub, 0, 0, 0, 0x08]));
        match how {
            0 if (1..=4).contains(&value.len()) => {
                let mut b = [0x23 | ((4 - value.len() as u8) << 2), i0, i1, sub, 0, 0, 0, 0];
                b[4..4 + value.len()].copy_from_slice(value);
                self.ok(b);
            }
            0 | 1 => {
                let size = (value.len() as u32).to_le_bytes();
                self.ok([0x21, i0, i1, sub, size[0], size[1], size[2], size[3]]);
                let mut toggle = 0u8;
                let mut chunks = value.chunks(7).peekable();
                if value.is_empty() {
                    self.ok([toggle | (7 << 1) | 1, 0, 0, 0, 0, 0, 0, 0]);
                }
                while let Some(c) = chunks.next() {
                    let last = u8::from(chunks.peek().is_none());
                    let mut b = [toggle | ((7 - c.len() as u8) << 1) | last, 0, 0, 0, 0, 0, 0, 0];
                    b[1..1 + c.len()].copy_from_slice(c);
                    self.ok(b);
                    toggle ^= 0x10;
                }
            }
            _ => {
                let size = (value.len() as u32).to_le_bytes();
                let init = self.ok([0xC6, i0, i1, sub, size[0], size[1], size[2], size[3]]);
                let mut blksize = init[0].data()[4];
                let segments: Vec<&[u8]> =
                    if value.is_empty() { vec![&[][..]] } else { value.chunks(7).collect() };
                let mut seq = 0u8;
                for (k, c) in segments.iter().enumerate() {
                    let last = k + 1 == segments.len();
                    seq += 1;
                    let mut b = [seq | if last { 0x80 } else { 0 }, 0, 0, 0, 0, 0, 0, 0];
                    b[1..1 + c.len()].copy_from_slice(c);
                    let out = self.ok(b);
                    if last || seq == blksize {
                        assert_eq!(out.len(), 1, "no acknowledgement of a sub-block");
                        assert_eq!(out[0].data()[1], seq, "not every segment acknowledged");
                        blksize = out[0].data()[2];
                        seq = 0;
                    }
                }
                let unused = (7 - segments.last().map_or(0, |c| c.len())) as u8;
                let crc = odc::sdo::block::crc16(value).to_le_bytes();
                self.ok([0xC1 | (unused << 2), crc[0], crc[1], 0, 0, 0, 0, 0]);
            }
        }
        assert_eq!(self.dict.value(index, sub).as_deref(), Some(value), "download not kept");
    }

    fn upload(&mut self, (index, sub): (u16, u8)) {
        let [i0, i1] = index.to_le_bytes();
        self.send(&frame(REQ, &[0x80, i0, i1, sub, 0, 0, 0, 0x08]));
        let want = self.dict.value(index, sub).expect("the client uploads readable objects");
        let init = self.ok([0x40, i0, i1, sub, 0, 0, 0, 0]);
        let mut got = Vec::new();
        let first = init[0].data();
        if first[0] & 0b10 != 0 {
            got.extend_from_slice(&first[4..4 + 4 - usize::from((first[0] >> 2) & 3)]);
        } else {
            let mut toggle = 0u8;
            loop {
                let seg = self.ok([0x60 | toggle, 0, 0, 0, 0, 0, 0, 0]);
                let b = seg[0].data();
                got.extend_from_slice(&b[1..8 - usize::from((b[0] >> 1) & 7)]);
                toggle ^= 0x10;
                if b[0] & 1 != 0 {
                    break;
                }
            }
        }
        assert_eq!(got, want, "upload differs from the dictionary");
    }
}

fn run(u: &mut Unstructured<'_>) -> arbitrary::Result<()> {
    let mut h = Harness {
        server: server_new(u.int_in_range(1..=127)?),
        dict: Dict::new(),
        model: Model::new(TIMEOUT),
        now: Instant::ZERO,
    };
    while !u.is_empty() {
        match u.int_in_range(0..=15u8)? {
            // A request to the server: any bytes, any length, often a known command byte.
            0..=8 => {
                let len = u.int_in_range(0..=8usize)?;
                let mut b = [0u8; 8];
                u.fill_buffer(&mut b[..len])?;
                if len > 0 && u.ratio(1, 2)? {
                    let cs = [
                        0x20, 0x21, 0x23, 0x2F, 0x40, 0x60, 0x70, 0x00, 0x10, 0x01, 0xA0, 0xA4,
                        0xA3, 0xA2, 0xA1, 0xC0, 0xC4, 0xC6, 0xC1, 0xCD, 0x80, 0x81, 0x85,
                    ];
                    b[0] = *u.choose(&cs)?;
                }
                if len > 3 && u.ratio(2, 3)? {
                    let (i, s) = *u.choose(&[
                        (0x1000, 0),
                        (0x2000, 0),
                        (0x2001, 0),
                        (0x2001, 1),
                        (0x2002, 0),
                        (0x2003, 0),
                        (0x2004, 0),
                        (0x2005, 0),
                        (0x2000, 1),
                    ])?;
                    b[1..3].copy_from_slice(&u16::to_le_bytes(i));
                    b[3] = s;
                }
                h.send(&frame(REQ, &b[..len]));
            }
            // Something that is not a request to this server.
            9 => {
                let mut b = [0u8; 8];
                u.fill_buffer(&mut b)?;
                let f = match u.int_in_range(0..=3u8)? {
                    0 => CanFrame::remote(REQ, u.int_in_range(0..=8)?).expect("11 bits, 0-8"),
                    1 => CanFrame::extended(REQ, &b).expect("8 bytes"),
                    2 => frame(RESP, &b),
                    _ => frame(u.int_in_range(0..=0x7FF)?, &b),
                };
                if !f.is_data(REQ) {
                    h.send(&f);
                }
            }
            10..=12 => {
                // Steps in µs, the clock's resolution: 0-2 µs; the former steps in whole
                // milliseconds (0-2 ms, 0 to twice the timeout), whose sums land on the
                // deadline; 0 to twice the timeout in µs; the timeout, 1 µs less or more;
                // anything.
                let dt = match u.int_in_range(0..=5u8)? {
                    0 => u64::from(u.int_in_range(0..=2u8)?),
                    1 => u64::from(u.int_in_range(0..=2u8)?) * 1000,
                    2 => u64::from(u.int_in_range(0..=TIMEOUT_US as u32 / 1000 * 2)?) * 1000,
                    3 => u64::from(u.int_in_range(0..=TIMEOUT_US as u32 * 2)?),
                    4 => TIMEOUT_US - 1 + u64::from(u.int_in_range(0..=2u8)?),
                    _ => u64::arbitrary(u)?,
                };
                h.advance(dt);
            }
            13 => {
                let len = u.int_in_range(0..=N)?;
                let value = u.bytes(len)?.to_vec();
                let how = u.int_in_range(0..=2)?;
                h.download(dict::DOMAIN, &value, how);
            }
            14 => {
                let v = u32::arbitrary(u)?.to_le_bytes();
                let how = u.int_in_range(0..=2)?;
                h.download(dict::RW32, &v, how);
            }
            _ => {
                let what = *u.choose(&[dict::DOMAIN, dict::STRING, dict::RW32])?;
                h.upload(what);
            }
        }
    }
    Ok(())
}

fuzz_target!(|data: &[u8]| {
    let _ = run(&mut Unstructured::new(data));
});
