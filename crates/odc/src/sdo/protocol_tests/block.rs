//! Block transfer: the server against frames written from CiA 301's layouts, and client
//! against server, with lost and damaged frames.

extern crate std;

use super::{NODE, Od, abort_code, ms, req, resp};
use crate::SdoAbort;
use crate::can::CanFrame;
use crate::sdo::{Bus, Client, SdoError, Server, Step};
use crate::time::{Duration, Instant};
use std::collections::VecDeque;
use std::vec::Vec;

/// 22 bytes: segments "Hello, " "block t" "ransfer" "!" (the last holds 1 byte, n = 6).
const TEXT: &[u8] = b"Hello, block transfer!";
/// CRC-16 of `TEXT` by CiA 301's polynomial, from an implementation outside this crate
/// (Python's `binascii.crc_hqx(TEXT, 0)`).
const TEXT_CRC: u16 = 0xCBC7;

fn all(s: &mut Server<64>, od: &mut Od, f: [u8; 8], now: u64) -> Vec<CanFrame> {
    let mut out = Vec::new();
    s.handle_into(od, &req(f), crate::time::Instant::from_millis(now), &mut |f| out.push(f));
    out
}

fn seg(n: u8, bytes: &[u8]) -> [u8; 8] {
    let mut b = [n, 0, 0, 0, 0, 0, 0, 0];
    b[1..1 + bytes.len()].copy_from_slice(bytes);
    b
}

#[test]
fn server_block_download_worked() {
    let mut s = Server::<64>::new(NODE);
    let mut od = Od::default();
    // Initiate: ccs=6, cc=1, s=1 -> 0xC6, 0x2001:00, size 22. Answer: scs=5, sc=1 -> 0xA4,
    // blksize 127.
    assert_eq!(
        s.handle(
            &mut od,
            &req([0xC6, 0x01, 0x20, 0x00, 22, 0, 0, 0]),
            crate::time::Instant::from_millis(0)
        ),
        resp([0xA4, 0x01, 0x20, 0x00, 127, 0, 0, 0])
    );
    // Segments 1-3 need no answer; segment 4 has c=1 (0x84) and ends the sub-block: ack
    // scs=5 ss=2 (0xA2), ackseq 4, blksize 127.
    assert_eq!(
        s.handle(&mut od, &req(seg(1, b"Hello, ")), crate::time::Instant::from_millis(1)),
        None
    );
    assert_eq!(
        s.handle(&mut od, &req(seg(2, b"block t")), crate::time::Instant::from_millis(2)),
        None
    );
    assert_eq!(
        s.handle(&mut od, &req(seg(3, b"ransfer")), crate::time::Instant::from_millis(3)),
        None
    );
    assert_eq!(
        s.handle(&mut od, &req(seg(0x84, b"!")), crate::time::Instant::from_millis(4)),
        resp([0xA2, 4, 127, 0, 0, 0, 0, 0])
    );
    // End: ccs=6, n=6, cs=1 -> 0xC0 | 6 << 2 | 1 = 0xD9, CRC LE. Answer: 0xA1.
    let [lo, hi] = TEXT_CRC.to_le_bytes();
    assert_eq!(
        s.handle(
            &mut od,
            &req([0xD9, lo, hi, 0, 0, 0, 0, 0]),
            crate::time::Instant::from_millis(5)
        ),
        resp([0xA1, 0, 0, 0, 0, 0, 0, 0])
    );
    assert_eq!(&od.text[..od.text_len], TEXT);
    assert!(!s.is_busy());
}

#[test]
fn server_block_download_errors() {
    let mut od = Od::default();
    let start = [0xC6, 0x01, 0x20, 0x00, 22, 0, 0, 0];
    // A wrong CRC: 0x05040004, and nothing written.
    let mut s = Server::<64>::new(NODE);
    s.handle(&mut od, &req(start), crate::time::Instant::from_millis(0));
    for (i, chunk) in TEXT.chunks(7).enumerate() {
        let n = i as u8 + 1;
        s.handle(
            &mut od,
            &req(seg(if chunk.len() < 7 { 0x80 | n } else { n }, chunk)),
            crate::time::Instant::from_millis(0),
        );
    }
    let [lo, hi] = (TEXT_CRC ^ 1).to_le_bytes();
    assert_eq!(
        abort_code(s.handle(
            &mut od,
            &req([0xD9, lo, hi, 0, 0, 0, 0, 0]),
            crate::time::Instant::from_millis(0)
        )),
        Some(0x0504_0004)
    );
    assert_eq!(od.text_len, 0);
    // A lost segment: sub-blocks of 2; segment 1 then 3 of the first... the second segment
    // of a sub-block is its last, so the server acks 1 and the client repeats from there.
    let mut s = Server::<64>::new(NODE).with_blksize(2);
    assert_eq!(
        s.handle(&mut od, &req(start), crate::time::Instant::from_millis(0)),
        resp([0xA4, 0x01, 0x20, 0x00, 2, 0, 0, 0])
    );
    assert_eq!(
        s.handle(&mut od, &req(seg(1, b"Hello, ")), crate::time::Instant::from_millis(0)),
        None
    );
    // Segment 2 lost; a segment numbered 3 is out of sequence and ignored; the client's
    // sub-block ends at 2, which does not come: the server acks at the sub-block's last
    // number it sees. Here the client resends "2" late as seqno 2 after a 3: in sequence again.
    assert_eq!(
        s.handle(&mut od, &req(seg(3, b"XXXXXXX")), crate::time::Instant::from_millis(0)),
        resp([0xA2, 1, 2, 0, 0, 0, 0, 0])
    );
    // Repeated from segment 2 ("block t"), renumbered from 1.
    assert_eq!(
        s.handle(&mut od, &req(seg(1, b"block t")), crate::time::Instant::from_millis(0)),
        None
    );
    assert_eq!(
        s.handle(&mut od, &req(seg(2, b"ransfer")), crate::time::Instant::from_millis(0)),
        resp([0xA2, 2, 2, 0, 0, 0, 0, 0])
    );
    assert_eq!(
        s.handle(&mut od, &req(seg(0x81, b"!")), crate::time::Instant::from_millis(0)),
        resp([0xA2, 1, 2, 0, 0, 0, 0, 0])
    );
    let [lo, hi] = TEXT_CRC.to_le_bytes();
    assert_eq!(
        s.handle(
            &mut od,
            &req([0xD9, lo, hi, 0, 0, 0, 0, 0]),
            crate::time::Instant::from_millis(0)
        ),
        resp([0xA1, 0, 0, 0, 0, 0, 0, 0])
    );
    assert_eq!(&od.text[..od.text_len], TEXT);
    // Sequence number 0 (byte 0 = 0x00) is no segment: 0x05040003.
    let mut s = Server::<64>::new(NODE);
    s.handle(&mut od, &req(start), crate::time::Instant::from_millis(0));
    assert_eq!(
        abort_code(s.handle(&mut od, &req(seg(0, b"x")), crate::time::Instant::from_millis(0))),
        Some(0x0504_0003)
    );
    // A size over the buffer: 0x05040005; the timeout between segments: 0x05040000.
    assert_eq!(
        abort_code(s.handle(
            &mut od,
            &req([0xC6, 0x01, 0x20, 0x00, 65, 0, 0, 0]),
            crate::time::Instant::from_millis(0)
        )),
        Some(0x0504_0005)
    );
    s.handle(&mut od, &req(start), crate::time::Instant::from_millis(0));
    assert_eq!(s.poll(crate::time::Instant::from_millis(1000)), None);
    assert_eq!(abort_code(s.poll(crate::time::Instant::from_millis(1001))), Some(0x0504_0000));
    // The client's abort (0x80 with the multiplexer) ends the transfer without answer.
    s.handle(&mut od, &req(start), crate::time::Instant::from_millis(0));
    assert_eq!(
        s.handle(
            &mut od,
            &req([0x80, 0x01, 0x20, 0, 0, 0, 0x04, 0x05]),
            crate::time::Instant::from_millis(0)
        ),
        None
    );
    assert!(!s.is_busy());
}

#[test]
fn server_block_upload_worked() {
    let mut s = Server::<64>::new(NODE);
    let mut od = Od::default();
    od.text[..TEXT.len()].copy_from_slice(TEXT);
    od.text_len = TEXT.len();
    // Initiate: ccs=5, cc=1 -> 0xA4, blksize 127, pst 0. Answer: scs=6, sc=1, s=1 -> 0xC6,
    // size 22.
    assert_eq!(
        all(&mut s, &mut od, [0xA4, 0x01, 0x20, 0x00, 127, 0, 0, 0], 0),
        [CanFrame::new(0x585, [0xC6, 0x01, 0x20, 0x00, 22, 0, 0, 0]).unwrap()]
    );
    // Start (0xA3): the whole sub-block at once.
    let r = |b| CanFrame::new(0x585, b).unwrap();
    assert_eq!(
        all(&mut s, &mut od, [0xA3, 0, 0, 0, 0, 0, 0, 0], 1),
        [r(seg(1, b"Hello, ")), r(seg(2, b"block t")), r(seg(3, b"ransfer")), r(seg(0x84, b"!")),]
    );
    // Ack all 4: end, scs=6, n=6, ss=1 -> 0xD9, CRC; the client's end response is unanswered.
    let [lo, hi] = TEXT_CRC.to_le_bytes();
    assert_eq!(
        all(&mut s, &mut od, [0xA2, 4, 127, 0, 0, 0, 0, 0], 2),
        [r([0xD9, lo, hi, 0, 0, 0, 0, 0])]
    );
    assert!(all(&mut s, &mut od, [0xA1, 0, 0, 0, 0, 0, 0, 0], 3).is_empty());
    assert!(!s.is_busy());

    // Sub-blocks of 2, the first acked only to 1: the server repeats from segment 2, and
    // `handle` alone gives one frame, `poll` the rest.
    all(&mut s, &mut od, [0xA4, 0x01, 0x20, 0x00, 2, 0, 0, 0], 0);
    assert_eq!(
        s.handle(&mut od, &req([0xA3, 0, 0, 0, 0, 0, 0, 0]), crate::time::Instant::from_millis(0)),
        Some(r(seg(1, b"Hello, ")))
    );
    assert_eq!(s.poll(crate::time::Instant::from_millis(0)), Some(r(seg(2, b"block t"))));
    assert_eq!(s.poll(crate::time::Instant::from_millis(0)), None);
    assert_eq!(
        all(&mut s, &mut od, [0xA2, 1, 3, 0, 0, 0, 0, 0], 0),
        [r(seg(1, b"block t")), r(seg(2, b"ransfer")), r(seg(0x83, b"!"))]
    );
    assert_eq!(
        all(&mut s, &mut od, [0xA2, 3, 3, 0, 0, 0, 0, 0], 0),
        [r([0xD9, lo, hi, 0, 0, 0, 0, 0])]
    );
}

#[test]
fn server_block_upload_errors_and_switch() {
    let mut s = Server::<64>::new(NODE);
    let mut od = Od::default();
    // blksize 0 and 128: 0x05040002.
    for b in [0u8, 128] {
        let f = all(&mut s, &mut od, [0xA4, 0x01, 0x20, 0x00, b, 0, 0, 0], 0);
        assert_eq!(abort_code(f.first().copied()), Some(0x0504_0002));
    }
    // An ack beyond the segments sent: 0x05040003.
    od.text_len = 20;
    all(&mut s, &mut od, [0xA4, 0x01, 0x20, 0x00, 127, 0, 0, 0], 0);
    assert_eq!(all(&mut s, &mut od, [0xA3, 0, 0, 0, 0, 0, 0, 0], 0).len(), 3);
    let f = all(&mut s, &mut od, [0xA2, 4, 127, 0, 0, 0, 0, 0], 0);
    assert_eq!(abort_code(f.first().copied()), Some(0x0504_0003));
    // A value within the protocol switch threshold goes by the normal upload protocol: the
    // 4 bytes of 0x1000 with pst 4 come expedited (0x43).
    assert_eq!(
        all(&mut s, &mut od, [0xA4, 0x00, 0x10, 0x00, 127, 4, 0, 0], 0),
        [CanFrame::new(0x585, [0x43, 0x00, 0x10, 0x00, 0x92, 0x01, 0x02, 0x00]).unwrap()]
    );
    // The dictionary's own aborts come through the block initiate.
    let f = all(&mut s, &mut od, [0xA4, 0x00, 0x30, 0x00, 127, 0, 0, 0], 0);
    assert_eq!(abort_code(f.first().copied()), Some(0x0602_0000));
    // No ack in time: 0x05040000.
    all(&mut s, &mut od, [0xA4, 0x01, 0x20, 0x00, 127, 0, 0, 0], 0);
    all(&mut s, &mut od, [0xA3, 0, 0, 0, 0, 0, 0, 0], 0);
    assert_eq!(abort_code(s.poll(crate::time::Instant::from_millis(1001))), Some(0x0504_0000));
}

/// A bus with an in-process server that can lose or damage chosen frames.
struct Lossy {
    server: Server<64>,
    od: Od,
    queue: VecDeque<CanFrame>,
    now: Instant,
    /// Client frames seen (1-based) that are lost before the server sees them.
    lose_request: Vec<usize>,
    /// Server frames (1-based) that are lost before the client sees them.
    lose_response: Vec<usize>,
    /// Flip a data bit of the server's frames with this number.
    damage_response: Option<usize>,
    requests: usize,
    responses: usize,
}

impl Lossy {
    fn new(server: Server<64>) -> Self {
        Self {
            server,
            od: Od::default(),
            queue: VecDeque::new(),
            now: Instant::ZERO,
            lose_request: Vec::new(),
            lose_response: Vec::new(),
            damage_response: None,
            requests: 0,
            responses: 0,
        }
    }
}

impl Bus for Lossy {
    type Error = ();
    fn send(&mut self, frame: &CanFrame) -> Result<(), ()> {
        self.requests += 1;
        if self.lose_request.contains(&self.requests) {
            return Ok(());
        }
        let mut out = Vec::new();
        self.server.handle_into(&mut self.od, frame, self.now, &mut |f| out.push(f));
        for mut f in out {
            self.responses += 1;
            if self.lose_response.contains(&self.responses) {
                continue;
            }
            if self.damage_response == Some(self.responses) {
                f.data[3] ^= 0x01;
            }
            self.queue.push_back(f);
        }
        Ok(())
    }
    fn recv(&mut self, deadline: Instant) -> Result<Option<CanFrame>, ()> {
        self.now += Duration::from_millis(1);
        let f = self.queue.pop_front();
        if f.is_none() {
            self.now = deadline;
            // Time passes on the server too.
            if let Some(f) = self.server.poll(self.now + Duration::from_millis(1)) {
                self.queue.push_back(f);
            }
        }
        Ok(f)
    }
    fn now(&mut self) -> Instant {
        self.now
    }
}

#[test]
fn client_and_server_block_every_length() {
    let text = *b"0123456789abcdefghijklmnopqrstuvwxyzABCD";
    for blksize in [1u8, 2, 5, 127] {
        let mut bus = Lossy::new(Server::new(NODE).with_blksize(blksize));
        let mut c = Client::<64>::new(NODE);
        for n in 0..=40 {
            c.download_block(&mut bus, 0x2001, 0, &text[..n]).unwrap();
            assert_eq!(&bus.od.text[..bus.od.text_len], &text[..n], "blksize {blksize}, {n} bytes");
            assert_eq!(c.upload_block(&mut bus, 0x2001, 0).unwrap(), &text[..n]);
        }
        assert!(!bus.server.is_busy());
    }
    // Frames: initiate, 6 segments, end = 8 out, and 1 + 1 + 1 back, for 40 bytes.
    let mut bus = Lossy::new(Server::new(NODE));
    let mut c = Client::<64>::new(NODE);
    c.download_block(&mut bus, 0x2001, 0, &text).unwrap();
    assert_eq!((bus.requests, bus.responses), (8, 3));
    // The dictionary's abort reaches the client.
    assert_eq!(
        c.download_block(&mut bus, 0x2001, 0, &[b'x'; 41]),
        Err(SdoError::Remote(SdoAbort::TooLong))
    );
}

#[test]
fn client_and_server_block_recover_lost_segments() {
    let text = *b"0123456789abcdefghijklmnopqrstuvwxyzABCD";
    // Download, sub-blocks of 3: request 3 is segment 2 of the first sub-block, lost. The
    // server acks 1; the client repeats segments 2 and 3 and goes on.
    let mut bus = Lossy::new(Server::new(NODE).with_blksize(3));
    bus.lose_request = std::vec![3];
    let mut c = Client::<64>::new(NODE);
    c.download_block(&mut bus, 0x2001, 0, &text).unwrap();
    assert_eq!(&bus.od.text[..bus.od.text_len], &text[..]);
    // Upload: response 3 is segment 2 of the first sub-block, lost; the client acks 1 at the
    // sub-block's end (127 segments, or the last), the server repeats.
    let mut bus = Lossy::new(Server::new(NODE));
    bus.od.text = text;
    bus.od.text_len = 40;
    bus.lose_response = std::vec![3];
    assert_eq!(c.upload_block(&mut bus, 0x2001, 0).unwrap(), &text[..]);
    // A damaged segment: the CRC catches it, the client aborts with 0x05040004.
    let mut bus = Lossy::new(Server::new(NODE));
    bus.od.text = text;
    bus.od.text_len = 40;
    bus.damage_response = Some(3);
    assert_eq!(c.upload_block(&mut bus, 0x2001, 0), Err(SdoError::Local(SdoAbort::CrcError)));
    assert!(!bus.server.is_busy(), "the client's abort reached the server");
}

#[test]
fn client_block_falls_back_and_times_out() {
    // A server that answers a block upload with a normal one (as CiA 301 lets it): here
    // the frames by hand, an expedited answer of 4 bytes.
    let mut c = Client::<64>::new(NODE);
    let f = c.start_block_upload(0x1000, 0, ms(0)).unwrap();
    assert_eq!(f.data, [0xA4, 0x00, 0x10, 0x00, 127, 0, 0, 0]);
    let answer = CanFrame::new(0x585, [0x43, 0x00, 0x10, 0x00, 0x92, 0x01, 0x02, 0x00]).unwrap();
    assert_eq!(c.handle(&answer, ms(1)), Some(Step::Done));
    assert_eq!(c.data(), [0x92, 0x01, 0x02, 0x00]);
    // Block download without an answer: local timeout, abort frame 0x05040000.
    c.start_block_download(0x2001, 0, b"abc", ms(0)).unwrap();
    let Some(Step::Failed(e, Some(abort))) = c.poll(ms(1001)) else { panic!("no timeout") };
    assert_eq!(e, SdoError::Local(SdoAbort::Timeout));
    assert_eq!(abort.data, [0x80, 0x01, 0x20, 0x00, 0x00, 0x00, 0x04, 0x05]);
    // A server blksize of 0: 0x05040002.
    c.start_block_download(0x2001, 0, b"abc", ms(0)).unwrap();
    let bad = CanFrame::new(0x585, [0xA4, 0x01, 0x20, 0x00, 0, 0, 0, 0]).unwrap();
    let Some(Step::Failed(e, _)) = c.handle(&bad, ms(1)) else { panic!("accepted blksize 0") };
    assert_eq!(e, SdoError::Local(SdoAbort::InvalidBlockSize));
}
