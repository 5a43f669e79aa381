//! Server and client against CiA 301 frame layouts, and against each other.

use super::*;
use crate::can::CanFrame;
use crate::plan::SdoWrite;
use crate::slave::ObjectDictionary;
use crate::time::{Duration, Instant};
use crate::{Access, Entry};

/// `n` ms after the epoch.
fn ms(n: u64) -> Instant {
    Instant::from_millis(n)
}

/// A small dictionary: 0x1000 UNSIGNED32 ro, 0x2000 UNSIGNED8 rw (max 100), 0x2001 a string
/// of up to 40 bytes rw, 0x2002 UNSIGNED16 wo, 0x1600 a mapping record rw.
struct Od {
    u8v: u8,
    text: [u8; 40],
    text_len: usize,
    wo: u16,
    map: [u32; 3],
    map_n: u8,
}

impl Default for Od {
    fn default() -> Self {
        Self { u8v: 0, text: [0; 40], text_len: 0, wo: 0, map: [0; 3], map_n: 0 }
    }
}

fn put(buf: &mut [u8], b: &[u8]) -> Result<usize, SdoAbort> {
    buf.get_mut(..b.len()).ok_or(SdoAbort::TooShort)?.copy_from_slice(b);
    Ok(b.len())
}

impl ObjectDictionary for Od {
    fn read(&self, index: u16, sub: u8, buf: &mut [u8]) -> Result<usize, SdoAbort> {
        match (index, sub) {
            (0x1000, 0) => put(buf, &0x0002_0192u32.to_le_bytes()),
            (0x2000, 0) => put(buf, &[self.u8v]),
            (0x2001, 0) => put(buf, &self.text[..self.text_len]),
            (0x2002, 0) => Err(SdoAbort::ReadOfWriteOnly),
            (0x1600, 0) => put(buf, &[self.map_n]),
            (0x1600, s @ 1..=3) => put(buf, &self.map[usize::from(s) - 1].to_le_bytes()),
            (0x1000 | 0x2000 | 0x2001 | 0x2002 | 0x1600, _) => Err(SdoAbort::NoSuchSub),
            _ => Err(SdoAbort::NoSuchObject),
        }
    }

    fn write(&mut self, index: u16, sub: u8, data: &[u8]) -> Result<(), SdoAbort> {
        let exact = |n: usize| match data.len() {
            l if l < n => Err(SdoAbort::TooShort),
            l if l > n => Err(SdoAbort::TooLong),
            _ => Ok(()),
        };
        match (index, sub) {
            (0x1000, 0) => Err(SdoAbort::WriteOfReadOnly),
            (0x2000, 0) => {
                exact(1)?;
                if data[0] > 100 {
                    return Err(SdoAbort::ValueTooHigh);
                }
                self.u8v = data[0];
                Ok(())
            }
            (0x2001, 0) => {
                self.text.get_mut(..data.len()).ok_or(SdoAbort::TooLong)?.copy_from_slice(data);
                self.text_len = data.len();
                Ok(())
            }
            (0x2002, 0) => {
                exact(2)?;
                self.wo = u16::from_le_bytes([data[0], data[1]]);
                Ok(())
            }
            (0x1600, 0) => {
                exact(1)?;
                self.map_n = data[0];
                Ok(())
            }
            (0x1600, s @ 1..=3) => {
                exact(4)?;
                self.map[usize::from(s) - 1] =
                    u32::from_le_bytes([data[0], data[1], data[2], data[3]]);
                Ok(())
            }
            (0x1000 | 0x2000 | 0x2001 | 0x2002 | 0x1600, _) => Err(SdoAbort::NoSuchSub),
            _ => Err(SdoAbort::NoSuchObject),
        }
    }
}

const NODE: crate::cob::NodeId = crate::node_id!(5);

fn req(b: [u8; 8]) -> CanFrame {
    CanFrame::new(0x605, b).unwrap()
}

fn resp(b: [u8; 8]) -> Option<CanFrame> {
    Some(CanFrame::new(0x585, b).unwrap())
}

fn abort_code(f: Option<CanFrame>) -> Option<u32> {
    let f = f?;
    (f.data[0] == 0x80).then(|| u32::from_le_bytes([f.data[4], f.data[5], f.data[6], f.data[7]]))
}

#[test]
fn server_expedited() {
    let mut s = Server::<64>::new(NODE);
    let mut od = Od::default();
    // Upload of a 4-byte value: scs=2, n=0, e=1, s=1.
    assert_eq!(
        s.handle(
            &mut od,
            &req([0x40, 0x00, 0x10, 0x00, 0, 0, 0, 0]),
            crate::time::Instant::from_millis(0)
        ),
        resp([0x43, 0x00, 0x10, 0x00, 0x92, 0x01, 0x02, 0x00])
    );
    // Download of one byte: ccs=1, n=3, e=1, s=1 -> 0x2F; answer scs=3.
    assert_eq!(
        s.handle(
            &mut od,
            &req([0x2F, 0x00, 0x20, 0x00, 42, 0, 0, 0]),
            crate::time::Instant::from_millis(0)
        ),
        resp([0x60, 0x00, 0x20, 0x00, 0, 0, 0, 0])
    );
    assert_eq!(od.u8v, 42);
    // Upload of one byte: n=3 -> 0x4F.
    assert_eq!(
        s.handle(
            &mut od,
            &req([0x40, 0x00, 0x20, 0x00, 0, 0, 0, 0]),
            crate::time::Instant::from_millis(0)
        ),
        resp([0x4F, 0x00, 0x20, 0x00, 42, 0, 0, 0])
    );
    // e=1, s=0: size unspecified, the server takes the object's size (1 byte).
    assert_eq!(
        s.handle(
            &mut od,
            &req([0x22, 0x00, 0x20, 0x00, 7, 0xAA, 0xBB, 0xCC]),
            crate::time::Instant::from_millis(0)
        ),
        resp([0x60, 0x00, 0x20, 0x00, 0, 0, 0, 0])
    );
    assert_eq!(od.u8v, 7);
    // Frames of other nodes are not ours.
    assert_eq!(
        s.handle(
            &mut od,
            &CanFrame::new(0x606, [0x40, 0, 0x10, 0, 0, 0, 0, 0]).unwrap(),
            crate::time::Instant::from_millis(0)
        ),
        None
    );
    assert!(!s.is_busy());
}

#[test]
fn server_aborts() {
    let mut s = Server::<64>::new(NODE);
    let mut od = Od::default();
    let mut ask = |b| abort_code(s.handle(&mut od, &req(b), crate::time::Instant::from_millis(0)));
    assert_eq!(ask([0x23, 0x00, 0x10, 0x00, 0, 0, 0, 0]), Some(0x0601_0002));
    assert_eq!(ask([0x40, 0x00, 0x30, 0x00, 0, 0, 0, 0]), Some(0x0602_0000));
    assert_eq!(ask([0x40, 0x00, 0x10, 0x07, 0, 0, 0, 0]), Some(0x0609_0011));
    assert_eq!(ask([0x40, 0x02, 0x20, 0x00, 0, 0, 0, 0]), Some(0x0601_0001));
    assert_eq!(ask([0x2F, 0x00, 0x20, 0x00, 101, 0, 0, 0]), Some(0x0609_0031));
    assert_eq!(ask([0x2B, 0x00, 0x20, 0x00, 1, 0, 0, 0]), Some(0x0607_0012));
    // The abort frame echoes the multiplexer.
    let f = s.handle(
        &mut od,
        &req([0x23, 0x00, 0x10, 0x00, 0, 0, 0, 0]),
        crate::time::Instant::from_millis(0),
    );
    assert_eq!(f, resp([0x80, 0x00, 0x10, 0x00, 0x02, 0x00, 0x01, 0x06]));
    // Block download to a missing object, block upload with blksize 0 (block transfer is in
    // protocol_tests/block.rs); ccs 7 is no command at all.
    let mut ask = |b| abort_code(s.handle(&mut od, &req(b), crate::time::Instant::from_millis(0)));
    assert_eq!(ask([0xC6, 0x00, 0x30, 0x00, 1, 0, 0, 0]), Some(0x0602_0000));
    assert_eq!(ask([0xA0, 0x00, 0x20, 0x00, 0, 0, 0, 0]), Some(0x0504_0002));
    assert_eq!(ask([0xE0, 0x00, 0x20, 0x00, 0, 0, 0, 0]), Some(0x0504_0001));
    // A segment without an initiated transfer.
    assert_eq!(ask([0x60, 0, 0, 0, 0, 0, 0, 0]), Some(0x0504_0001));
    assert_eq!(ask([0x00, 1, 2, 3, 4, 5, 6, 7]), Some(0x0504_0001));
    // Segmented download larger than the buffer.
    assert_eq!(ask([0x21, 0x01, 0x20, 0x00, 65, 0, 0, 0]), Some(0x0504_0005));
    // Segmented download to a missing object is refused at the initiate.
    assert_eq!(ask([0x21, 0x00, 0x30, 0x00, 10, 0, 0, 0]), Some(0x0602_0000));
}

#[test]
fn server_segmented_download_and_upload() {
    let mut s = Server::<64>::new(NODE);
    let mut od = Od::default();
    // "hello, world!" (13 bytes): initiate with size, then 7 + 6 bytes.
    assert_eq!(
        s.handle(
            &mut od,
            &req([0x21, 0x01, 0x20, 0x00, 13, 0, 0, 0]),
            crate::time::Instant::from_millis(0)
        ),
        resp([0x60, 0x01, 0x20, 0x00, 0, 0, 0, 0])
    );
    assert!(s.is_busy());
    assert_eq!(
        s.handle(&mut od, &req(*b"\x00hello, "), crate::time::Instant::from_millis(1)),
        resp([0x20, 0, 0, 0, 0, 0, 0, 0])
    );
    // Toggle 1, n = 1 (6 bytes), last: 0x10 | 1 << 1 | 1 = 0x13.
    assert_eq!(
        s.handle(&mut od, &req(*b"\x13world!\0"), crate::time::Instant::from_millis(2)),
        resp([0x30, 0, 0, 0, 0, 0, 0, 0])
    );
    assert_eq!(&od.text[..od.text_len], b"hello, world!");
    assert!(!s.is_busy());
    // Upload: scs=2, s=1, size 13.
    assert_eq!(
        s.handle(
            &mut od,
            &req([0x40, 0x01, 0x20, 0x00, 0, 0, 0, 0]),
            crate::time::Instant::from_millis(3)
        ),
        resp([0x41, 0x01, 0x20, 0x00, 13, 0, 0, 0])
    );
    assert_eq!(
        s.handle(&mut od, &req([0x60, 0, 0, 0, 0, 0, 0, 0]), crate::time::Instant::from_millis(4)),
        resp(*b"\x00hello, ")
    );
    assert_eq!(
        s.handle(&mut od, &req([0x70, 0, 0, 0, 0, 0, 0, 0]), crate::time::Instant::from_millis(5)),
        resp(*b"\x13world!\0")
    );
    assert!(!s.is_busy());
    // An empty value: segmented with size 0, one empty last segment (n = 7).
    od.text_len = 0;
    assert_eq!(
        s.handle(
            &mut od,
            &req([0x40, 0x01, 0x20, 0x00, 0, 0, 0, 0]),
            crate::time::Instant::from_millis(3)
        ),
        resp([0x41, 0x01, 0x20, 0x00, 0, 0, 0, 0])
    );
    assert_eq!(
        s.handle(&mut od, &req([0x60, 0, 0, 0, 0, 0, 0, 0]), crate::time::Instant::from_millis(4)),
        resp([0x0F, 0, 0, 0, 0, 0, 0, 0])
    );
}

#[test]
fn server_toggle_size_and_timeout() {
    let mut s = Server::<64>::new(NODE).with_timeout(crate::time::Duration::from_millis(100));
    let mut od = Od::default();
    s.handle(
        &mut od,
        &req([0x21, 0x01, 0x20, 0x00, 10, 0, 0, 0]),
        crate::time::Instant::from_millis(0),
    );
    // First segment with toggle 1: abort 0x05030000, transfer over.
    assert_eq!(
        abort_code(s.handle(&mut od, &req(*b"\x10abcdefg"), crate::time::Instant::from_millis(1))),
        Some(0x0503_0000)
    );
    assert!(!s.is_busy());
    // A size indication the segments do not match: 0x06070010.
    s.handle(
        &mut od,
        &req([0x21, 0x01, 0x20, 0x00, 10, 0, 0, 0]),
        crate::time::Instant::from_millis(0),
    );
    assert_eq!(
        abort_code(s.handle(&mut od, &req(*b"\x01abcdefg"), crate::time::Instant::from_millis(1))),
        Some(0x0607_0010)
    );
    assert_eq!(od.text_len, 0);
    // Upload segment with the wrong toggle.
    od.text_len = 20;
    s.handle(
        &mut od,
        &req([0x40, 0x01, 0x20, 0x00, 0, 0, 0, 0]),
        crate::time::Instant::from_millis(0),
    );
    assert_eq!(
        abort_code(s.handle(
            &mut od,
            &req([0x70, 0, 0, 0, 0, 0, 0, 0]),
            crate::time::Instant::from_millis(1)
        )),
        Some(0x0503_0000)
    );
    // Timeout: nothing before the deadline, the abort after it.
    s.handle(
        &mut od,
        &req([0x40, 0x01, 0x20, 0x00, 0, 0, 0, 0]),
        crate::time::Instant::from_millis(1000),
    );
    assert_eq!(s.poll(crate::time::Instant::from_millis(1100)), None);
    assert_eq!(
        s.poll(crate::time::Instant::from_millis(1101)),
        resp([0x80, 0x01, 0x20, 0x00, 0x00, 0x00, 0x04, 0x05])
    );
    assert!(!s.is_busy());
    // A client abort ends the transfer without answer.
    s.handle(
        &mut od,
        &req([0x40, 0x01, 0x20, 0x00, 0, 0, 0, 0]),
        crate::time::Instant::from_millis(0),
    );
    assert_eq!(
        s.handle(
            &mut od,
            &req([0x80, 0x01, 0x20, 0x00, 0, 0, 0x04, 0x05]),
            crate::time::Instant::from_millis(1)
        ),
        None
    );
    assert!(!s.is_busy());
    assert_eq!(s.poll(crate::time::Instant::from_millis(10_000)), None);
}

/// A bus on which an in-process server answers at once.
struct Loop {
    server: Server<64>,
    od: Od,
    pending: Option<CanFrame>,
    now: Instant,
    /// Drop the server's answers (to test timeouts).
    mute: bool,
    /// Flip the toggle bit of segment answers (to test the client's check).
    flip_toggle: bool,
    sent: usize,
    last_sent: Option<CanFrame>,
}

impl Loop {
    fn new() -> Self {
        Self {
            server: Server::new(NODE),
            od: Od::default(),
            pending: None,
            now: Instant::ZERO,
            mute: false,
            flip_toggle: false,
            sent: 0,
            last_sent: None,
        }
    }
}

impl Bus for Loop {
    type Error = ();
    fn send(&mut self, frame: &CanFrame) -> Result<(), ()> {
        self.sent += 1;
        self.last_sent = Some(*frame);
        let mut r = self.server.handle(&mut self.od, frame, self.now);
        if let Some(f) = r.as_mut().filter(|f| self.flip_toggle && f.data[0] >> 5 <= 1) {
            f.data[0] ^= 0x10;
        }
        self.pending = if self.mute { None } else { r };
        Ok(())
    }
    fn recv(&mut self, deadline: Instant) -> Result<Option<CanFrame>, ()> {
        match self.pending.take() {
            Some(f) => {
                self.now += Duration::from_millis(1);
                Ok(Some(f))
            }
            None => {
                self.now = deadline;
                Ok(None)
            }
        }
    }
    fn now(&mut self) -> Instant {
        self.now
    }
}

#[test]
fn client_and_server_every_length() {
    let mut bus = Loop::new();
    let mut c = Client::<64>::new(NODE);
    let text = *b"0123456789abcdefghijklmnopqrstuvwxyzABCD";
    for n in 0..=40 {
        c.download(&mut bus, 0x2001, 0, &text[..n]).unwrap();
        assert_eq!(&bus.od.text[..bus.od.text_len], &text[..n]);
        assert_eq!(c.upload(&mut bus, 0x2001, 0).unwrap(), &text[..n]);
    }
    // Too long for the server's dictionary entry: its abort reaches the client.
    assert_eq!(
        c.download(&mut bus, 0x2001, 0, &[b'x'; 41]),
        Err(SdoError::Remote(SdoAbort::TooLong))
    );
    assert_eq!(c.upload(&mut bus, 0x3000, 0), Err(SdoError::Remote(SdoAbort::NoSuchObject)));
    assert!(!bus.server.is_busy());
}

#[test]
fn client_typed_and_plans() {
    const DEVICE_TYPE: Entry<u32> = Entry::new(0x1000, 0, "Device type", Access::Ro, false);
    const SETTING: Entry<u8> = Entry::new(0x2000, 0, "Setting", Access::Rw, false);
    let mut bus = Loop::new();
    let mut c = Client::<64>::new(NODE);
    assert_eq!(c.read(&mut bus, &DEVICE_TYPE), Ok(0x0002_0192));
    c.write(&mut bus, &SETTING, 55).unwrap();
    assert_eq!(c.read(&mut bus, &SETTING), Ok(55));
    assert_eq!(c.write(&mut bus, &SETTING, 200), Err(SdoError::Remote(SdoAbort::ValueTooHigh)));
    assert_eq!(
        c.write(&mut bus, &DEVICE_TYPE, 1),
        Err(SdoError::Remote(SdoAbort::WriteOfReadOnly))
    );
    let plan = [
        SdoWrite::u8(0x1600, 0, 0),
        SdoWrite::u32(0x1600, 1, 0x6040_0010),
        SdoWrite::u32(0x1600, 2, 0x607A_0020),
        SdoWrite::u8(0x1600, 0, 2),
    ];
    c.execute(&mut bus, &plan).unwrap();
    assert_eq!((bus.od.map_n, bus.od.map[0], bus.od.map[1]), (2, 0x6040_0010, 0x607A_0020));
    // The failing write's position is reported.
    let bad = [SdoWrite::u8(0x1600, 0, 0), SdoWrite::u32(0x1600, 9, 1)];
    assert_eq!(c.execute(&mut bus, &bad), Err((1, SdoError::Remote(SdoAbort::NoSuchSub))));
}

/// A write at a fixed width: the request carries the value zero- or sign-extended to the
/// width (CiA 301 expedited download with size indicated: 4 bytes is command 23h).
#[test]
fn client_widened_writes() {
    const WO: Entry<u16> = Entry::new(0x2002, 0, "Write only", Access::Wo, false);
    const SIGNED: Entry<i16> = Entry::new(0x2002, 0, "Signed", Access::Wo, false);
    let mut bus = Loop::new();
    let mut c = Client::<64>::new(NODE);
    // The test dictionary takes exactly 2 bytes: the server's abort for 4 comes back, and
    // the request was sent as asked.
    assert_eq!(c.write_widened(&mut bus, &WO, 0x1234, 4), Err(SdoError::Remote(SdoAbort::TooLong)));
    assert_eq!(bus.last_sent.map(|f| f.data), Some([0x23, 0x02, 0x20, 0x00, 0x34, 0x12, 0, 0]));
    let _ = c.write_widened(&mut bus, &SIGNED, -2, 4);
    assert_eq!(
        bus.last_sent.map(|f| f.data),
        Some([0x23, 0x02, 0x20, 0x00, 0xFE, 0xFF, 0xFF, 0xFF])
    );
    let _ = c.write_widened(&mut bus, &SIGNED, 2, 4);
    assert_eq!(bus.last_sent.map(|f| f.data), Some([0x23, 0x02, 0x20, 0x00, 0x02, 0, 0, 0]));
    // At the object's own width it is the ordinary write (2Bh).
    c.write_widened(&mut bus, &WO, 0x1234, 2).unwrap();
    assert_eq!(bus.od.wo, 0x1234);
    assert_eq!(bus.last_sent.map(|f| f.data[0]), Some(0x2B));
    // Narrower than the value, or beyond an expedited transfer: refused before sending.
    let sent = bus.sent;
    assert_eq!(c.write_widened(&mut bus, &WO, 1, 1), Err(SdoError::Local(SdoAbort::TooLong)));
    assert_eq!(c.write_widened(&mut bus, &WO, 1, 5), Err(SdoError::Local(SdoAbort::TooLong)));
    assert_eq!(bus.sent, sent);
}

#[test]
fn client_timeout_toggle_and_busy() {
    let mut bus = Loop::new();
    let mut c = Client::<64>::new(NODE).with_timeout(Duration::from_millis(50));
    bus.mute = true;
    assert_eq!(c.upload(&mut bus, 0x1000, 0), Err(SdoError::Local(SdoAbort::Timeout)));
    // The client sent the abort frame after the request.
    assert_eq!(bus.sent, 2);
    let f = bus.last_sent.unwrap();
    assert_eq!(f, CanFrame::new(0x605, [0x80, 0x00, 0x10, 0x00, 0x00, 0x00, 0x04, 0x05]).unwrap());
    assert!(!c.is_busy());
    bus.mute = false;
    bus.flip_toggle = true;
    bus.od.text_len = 20;
    assert_eq!(c.upload(&mut bus, 0x2001, 0), Err(SdoError::Local(SdoAbort::ToggleBit)));
    // The server got the client's abort and is idle again.
    assert!(!bus.server.is_busy());
    assert_eq!(
        c.download(&mut bus, 0x2001, 0, b"long enough"),
        Err(SdoError::Local(SdoAbort::ToggleBit))
    );
    // Frame level: one transfer at a time, responses of other nodes ignored.
    let first = c.start_upload(0x1000, 0, ms(0)).unwrap();
    assert_eq!(first, CanFrame::new(0x605, [0x40, 0x00, 0x10, 0x00, 0, 0, 0, 0]).unwrap());
    assert_eq!(c.start_upload(0x1000, 0, ms(0)), Err(SdoError::Busy));
    assert_eq!(
        c.handle(&CanFrame::new(0x586, [0x43, 0, 0x10, 0, 1, 2, 3, 4]).unwrap(), ms(1)),
        None
    );
    // A response for another object is a protocol error.
    let step = c.handle(&CanFrame::new(0x585, [0x43, 0, 0x20, 0, 1, 2, 3, 4]).unwrap(), ms(1));
    assert!(matches!(step, Some(Step::Failed(SdoError::Local(SdoAbort::InvalidCommand), Some(_)))));
    // Expedited without size indication: four bytes, the type takes the low ones.
    c.start_upload(0x2000, 0, ms(0)).unwrap();
    assert_eq!(
        c.handle(&CanFrame::new(0x585, [0x42, 0, 0x20, 0, 9, 0, 0, 0]).unwrap(), ms(1)),
        Some(Step::Done)
    );
    assert_eq!(c.data(), &[9, 0, 0, 0]);
}

mod block;

/// CiA 301: SDOs are 11-bit data frames. A remote or extended frame with the request's or the
/// response's CAN-ID is another message, which neither side may take as a step.
#[test]
fn remote_and_extended_frames_are_not_sdo() {
    let upload = [0x40, 0x00, 0x10, 0x00, 0, 0, 0, 0];
    let mut s = Server::<64>::new(NODE);
    let mut od = Od::default();
    let extended = CanFrame::extended(0x605, &upload).unwrap();
    assert_eq!(s.handle(&mut od, &extended, crate::time::Instant::from_millis(0)), None);
    assert_eq!(
        s.handle(
            &mut od,
            &CanFrame::remote(0x605, 8).unwrap(),
            crate::time::Instant::from_millis(0)
        ),
        None
    );
    assert!(!s.is_busy());
    // The data frame is still served.
    assert_eq!(
        s.handle(&mut od, &req(upload), crate::time::Instant::from_millis(0)),
        resp([0x43, 0x00, 0x10, 0x00, 0x92, 0x01, 0x02, 0x00])
    );

    let mut c = Client::<64>::new(NODE);
    c.start_upload(0x1000, 0, ms(0)).unwrap();
    let answer = [0x43, 0x00, 0x10, 0x00, 0x92, 0x01, 0x02, 0x00];
    assert_eq!(c.handle(&CanFrame::extended(0x585, &answer).unwrap(), ms(0)), None);
    assert_eq!(c.handle(&CanFrame::remote(0x585, 8).unwrap(), ms(0)), None);
    assert_eq!(c.handle(&CanFrame::new(0x585, answer).unwrap(), ms(0)), Some(Step::Done));
    assert_eq!(c.data(), &0x0002_0192u32.to_le_bytes());
}
