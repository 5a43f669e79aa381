//! The async master against SDO servers on a simulated bus, on tokio's paused clock: time
//! moves only when every task waits, so the durations below are exact and the same on any
//! machine.
//!
//! The bus: the master's frames take [`FRAME`] each on the wire (its transmit half sleeps
//! that long per frame, as a CAN controller is busy for a frame's length), the servers answer
//! after [`RESPONSE_DELAY`] (a device's processing time). All times are whole milliseconds,
//! the resolution of tokio's timer.

#![allow(clippy::unwrap_used, clippy::expect_used, clippy::panic, missing_docs)]

use std::future::{Future, poll_fn};
use std::sync::atomic::{AtomicU64, Ordering};
use std::sync::{Arc, Mutex};
use std::task::Poll;

use odc::SdoAbort;
use odc::asynch::tokio::TokioClock;
use odc::asynch::{CanRx, CanTx, Clock, Master, Priority, RECEIVED_PER_POLL};
use odc::can::CanFrame;
use odc::cob::NodeId;
use odc::sdo::Server;
use odc::slave::ObjectDictionary;
use odc::time::{Duration, Instant};
use tokio::sync::mpsc;

const FRAME: Duration = Duration::from_millis(1);
const RESPONSE_DELAY: Duration = Duration::from_millis(2);

/// The bus is gone (a test's device task ended).
#[derive(Debug)]
struct Closed;

/// A device's dictionary: 0x2000:00 a domain of any length, read and written by SDO.
struct Domain(Vec<u8>);

impl ObjectDictionary for Domain {
    fn read(&self, index: u16, sub: u8, buf: &mut [u8]) -> Result<usize, SdoAbort> {
        if (index, sub) != (0x2000, 0) {
            return Err(SdoAbort::NoSuchObject);
        }
        buf.get_mut(..self.0.len()).ok_or(SdoAbort::OutOfMemory)?.copy_from_slice(&self.0);
        Ok(self.0.len())
    }

    fn write(&mut self, index: u16, sub: u8, data: &[u8]) -> Result<(), SdoAbort> {
        if (index, sub) != (0x2000, 0) {
            return Err(SdoAbort::NoSuchObject);
        }
        self.0 = data.to_vec();
        Ok(())
    }
}

/// The master's transmit half: each frame is logged with the time it went on the wire, takes
/// [`FRAME`], then reaches the devices.
struct Wire {
    clock: TokioClock,
    to_devices: mpsc::UnboundedSender<CanFrame>,
    log: Arc<Mutex<Vec<(Instant, CanFrame)>>>,
}

impl CanTx for Wire {
    type Error = Closed;

    async fn send(&mut self, frame: &CanFrame) -> Result<(), Closed> {
        self.log.lock().map_err(|_| Closed)?.push((self.clock.now(), *frame));
        tokio::time::sleep(FRAME.into()).await;
        self.to_devices.send(*frame).map_err(|_| Closed)
    }
}

/// The master's receive half: the devices' frames.
struct Back(mpsc::UnboundedReceiver<CanFrame>);

impl CanRx for Back {
    type Error = Closed;

    async fn recv(&mut self) -> Result<CanFrame, Closed> {
        self.0.recv().await.ok_or(Closed)
    }
}

fn node(n: u8) -> NodeId {
    NodeId::new(n).unwrap()
}

/// A bus with one SDO server per value of `values` (nodes 1, 2, …, 0x2000 holding the value);
/// the wire's log, and the devices' dictionaries.
#[allow(clippy::type_complexity)]
fn bus(
    clock: TokioClock,
    values: Vec<Vec<u8>>,
) -> (Wire, Back, Arc<Mutex<Vec<(Instant, CanFrame)>>>, Arc<Mutex<Vec<Domain>>>) {
    let (to_devices, mut from_master) = mpsc::unbounded_channel::<CanFrame>();
    let (to_master, from_devices) = mpsc::unbounded_channel();
    let log = Arc::new(Mutex::new(Vec::new()));
    let mut servers: Vec<Server<4096>> =
        (1..=values.len()).map(|n| Server::new(node(n as u8))).collect();
    let dicts = Arc::new(Mutex::new(values.into_iter().map(Domain).collect::<Vec<_>>()));
    let devices = dicts.clone();
    tokio::spawn(async move {
        while let Some(f) = from_master.recv().await {
            let now = clock.now();
            let mut out = Vec::new();
            let mut dicts = devices.lock().unwrap();
            for (server, od) in servers.iter_mut().zip(dicts.iter_mut()) {
                server.handle_into(od, &f, now, &mut |r| out.push(r));
            }
            drop(dicts);
            for r in out {
                let to_master = to_master.clone();
                tokio::spawn(async move {
                    tokio::time::sleep(RESPONSE_DELAY.into()).await;
                    let _ = to_master.send(r);
                });
            }
        }
    });
    let wire = Wire { clock, to_devices, log: log.clone() };
    (wire, Back(from_devices), log, dicts)
}

fn pattern(len: usize, seed: u8) -> Vec<u8> {
    (0..len).map(|i| (i as u8).wrapping_mul(7).wrapping_add(seed)).collect()
}

#[tokio::test(start_paused = true)]
async fn concurrent_uploads_take_about_the_longest_not_the_sum() {
    let clock = TokioClock::new();
    let values = vec![pattern(40, 1), pattern(120, 2), pattern(200, 3)];
    let (tx, rx, _log, _) = bus(clock, values.clone());
    let master = Master::new(clock);
    let test = async {
        // Each alone, one after the other.
        let mut alone = Vec::new();
        for (i, v) in values.iter().enumerate() {
            let t0 = master.now();
            assert_eq!(&master.upload(node(i as u8 + 1), 0x2000, 0).await.unwrap(), v);
            alone.push(master.now() - t0);
        }
        // All three at once.
        let t0 = master.now();
        let (a, b, c) = tokio::join!(
            master.upload(node(1), 0x2000, 0),
            master.upload(node(2), 0x2000, 0),
            master.upload(node(3), 0x2000, 0),
        );
        let together = master.now() - t0;
        assert_eq!(
            [a.unwrap(), b.unwrap(), c.unwrap()],
            [&values[0], &values[1], &values[2]].map(|v| v.clone())
        );
        (alone, together)
    };
    let (alone, together) = tokio::select! {
        r = master.run(tx, rx) => panic!("the bus task ended: {r:?}"),
        r = test => r,
    };
    let sum: u64 = alone.iter().map(|d| d.as_micros()).sum();
    let longest = alone.iter().map(|d| d.as_micros()).max().unwrap();
    // Segmented uploads of 40, 120 and 200 bytes: 7, 19 and 30 round trips of one request
    // frame (1 ms) and the server's 2 ms; the frames of the three share one wire.
    assert_eq!(alone, [21, 57, 90].map(Duration::from_millis));
    assert!(together.as_micros() >= longest, "{together} < the longest alone");
    assert!(
        together.as_micros() * 10 <= longest * 11,
        "three at once took {together}; alone {alone:?} (sum {sum} µs)"
    );
    // Sequential would be the sum (168 ms).
    assert!(
        together.as_micros() * 5 < sum * 3,
        "three at once took {together}, near the sum {sum} µs"
    );
}

/// A SYNC falls due while SDO frames wait to go out (a block download's sub-block of 127
/// segments, segmented uploads): it goes out next, after at most the frame on the wire.
#[tokio::test(start_paused = true)]
async fn sdo_traffic_never_delays_a_sync_by_more_than_one_frame() {
    let clock = TokioClock::new();
    let values = vec![pattern(4, 0), pattern(200, 2), pattern(150, 3)];
    let (tx, rx, log, dicts) = bus(clock, values.clone());
    let master = Master::new(clock);
    let block = pattern(1500, 9);
    let mut due = Vec::new();
    let test = async {
        let mut cycle = master.cycle(Duration::from_millis(10));
        let cycles = async {
            for _ in 0..40 {
                due.push(cycle.tick().await);
                master.sync().unwrap();
            }
        };
        let sdo = async {
            master.download_block(node(1), 0x2000, 0, &block).await.unwrap();
            for _ in 0..3 {
                assert_eq!(master.upload(node(2), 0x2000, 0).await.unwrap(), values[1]);
            }
        };
        let more = async {
            for _ in 0..3 {
                assert_eq!(master.upload(node(3), 0x2000, 0).await.unwrap(), values[2]);
            }
        };
        tokio::join!(cycles, sdo, more);
    };
    tokio::select! {
        r = master.run(tx, rx) => panic!("the bus task ended: {r:?}"),
        () = test => {}
    };
    assert_eq!(dicts.lock().unwrap()[0].0, block, "the block download arrived whole");
    let log = log.lock().unwrap();
    let syncs: Vec<Instant> =
        log.iter().filter(|(_, f)| f.id() == 0x080).map(|(t, _)| *t).collect();
    assert_eq!(syncs.len(), due.len());
    let delays: Vec<u64> = syncs.iter().zip(&due).map(|(s, d)| (*s - *d).as_micros()).collect();
    assert!(delays.iter().all(|d| *d <= FRAME.as_micros()), "SYNC delays (µs): {delays:?}");
    // The SDO traffic really competed with the SYNCs: SDO frames went out during the cycles,
    // and over the whole run more of them than the cycles leave room for without sharing.
    let sdo_frames = log.iter().filter(|(_, f)| f.id() != 0x080).count();
    assert!(sdo_frames > 250, "only {sdo_frames} SDO frames");
    let first_sync = syncs[0];
    let last_sync = *syncs.last().unwrap();
    let between =
        log.iter().filter(|(t, f)| f.id() != 0x080 && *t > first_sync && *t < last_sync).count();
    assert!(between > 200, "only {between} SDO frames between the first and the last SYNC");
}

/// Time that passes only as frames go out: each frame the master sends takes [`FRAME`] on the
/// wire, while its transmit half takes the frame at once, as a socket does. A timer that is
/// not yet due wakes its task again at once (so the test needs no runtime timer).
#[derive(Clone, Default)]
struct FrameClock(Arc<AtomicU64>);

impl Clock for FrameClock {
    fn now(&self) -> Instant {
        Instant::from_micros(self.0.load(Ordering::Relaxed))
    }

    fn sleep_until(&self, deadline: Instant) -> impl Future<Output = ()> {
        let clock = self.clone();
        poll_fn(move |cx| {
            if clock.now() >= deadline {
                return Poll::Ready(());
            }
            cx.waker().wake_by_ref();
            Poll::Pending
        })
    }
}

/// A socket on [`FrameClock`]: `send` never waits; each frame is logged with the time it went
/// out and moves the clock on by one frame.
struct Socket {
    clock: FrameClock,
    log: Arc<Mutex<Vec<(Instant, CanFrame)>>>,
}

impl CanTx for Socket {
    type Error = Closed;

    async fn send(&mut self, frame: &CanFrame) -> Result<(), Closed> {
        self.log.lock().map_err(|_| Closed)?.push((self.clock.now(), *frame));
        self.clock.0.fetch_add(FRAME.as_micros(), Ordering::Relaxed);
        Ok(())
    }
}

/// A receive half with `frames` waiting at once (a socket's buffer after a late wake), then
/// nothing.
struct Backlog(std::vec::IntoIter<CanFrame>);

impl CanRx for Backlog {
    type Error = Closed;

    async fn recv(&mut self) -> Result<CanFrame, Closed> {
        match self.0.next() {
            Some(f) => Ok(f),
            None => std::future::pending().await,
        }
    }
}

fn sdo_request(n: u8) -> CanFrame {
    CanFrame::standard(
        odc::can::StdId::masked(0x600 + u32::from(n)),
        [0x40, 0, 0x20, 0, 0, 0, 0, 0],
    )
}

/// A SYNC falls due while 200 SDO frames are queued and the interface takes each at once: the
/// bus task gives way after each, so the SYNC goes out after at most one of them (in one poll
/// it would send all 200 first, the SYNC 190 frames late).
#[tokio::test]
async fn a_socket_that_never_waits_still_lets_the_sync_out_within_one_frame() {
    let clock = FrameClock::default();
    let log = Arc::new(Mutex::new(Vec::new()));
    let tx = Socket { clock: clock.clone(), log: log.clone() };
    let master = Master::new(clock);
    for i in 0..200 {
        master.send(Priority::Low, sdo_request(1 + (i % 3) as u8)).unwrap();
    }
    // Created before the bus task runs: its grid point is 10 frames from the start.
    let mut cycle = master.cycle(FRAME.saturating_mul(10));
    let cycle = async {
        let due = cycle.tick().await;
        master.sync().unwrap();
        // Until the SYNC is on the wire.
        poll_fn(|cx| {
            if log.lock().unwrap().iter().any(|(_, f)| f.id() == 0x080) {
                return Poll::Ready(());
            }
            cx.waker().wake_by_ref();
            Poll::Pending
        })
        .await;
        due
    };
    let due = tokio::select! {
        r = master.run(tx, Backlog(Vec::new().into_iter())) => panic!("the bus task ended: {r:?}"),
        due = cycle => due,
    };
    let log = log.lock().unwrap();
    let (i, (sent, _)) = log.iter().enumerate().find(|(_, (_, f))| f.id() == 0x080).unwrap();
    assert_eq!(due, Instant::from_micros(10 * FRAME.as_micros()));
    assert!(*sent - due <= FRAME, "SYNC due at {due:?}, out at {sent:?}");
    assert!((10..=11).contains(&i), "the SYNC went out as frame {i}");
}

/// 100 frames wait in the receive half at once: the bus task routes at most
/// [`RECEIVED_PER_POLL`] of them before the futures beside it run again.
#[tokio::test]
async fn a_receive_backlog_is_routed_a_few_frames_per_poll() {
    let clock = FrameClock::default();
    let tx = Socket { clock: clock.clone(), log: Arc::new(Mutex::new(Vec::new())) };
    let tpdo = odc::cob::CobId::new(0x183);
    let frames: Vec<CanFrame> =
        (0..100u8).map(|i| CanFrame::standard(odc::can::StdId::masked(0x183), [i; 8])).collect();
    let master = Master::new(clock);
    // At each of its polls, how many frames the bus task had routed.
    let mut seen = Vec::new();
    let watch = poll_fn(|cx| {
        let n = master.latest_frame(tpdo).1;
        seen.push(n);
        if n == 100 {
            return Poll::Ready(());
        }
        cx.waker().wake_by_ref();
        Poll::Pending
    });
    tokio::select! {
        biased;
        () = watch => {}
        r = master.run(tx, Backlog(frames.into_iter())) => panic!("the bus task ended: {r:?}"),
    };
    let most = seen.windows(2).map(|w| w[1] - w[0]).max().unwrap();
    assert_eq!(most, RECEIVED_PER_POLL as u64, "frames routed between polls: {seen:?}");
    assert_eq!(seen.first(), Some(&0));
}
