//! The async [`Master`]: the shared state behind `&self`, the bus task that routes frames
//! ([`Master::run`]), NMT, the heartbeat consumer, events, SYNC and PDO exchange.

use core::future::poll_fn;
use core::task::Poll;
use std::boxed::Box;
use std::collections::{BTreeMap, VecDeque};
use std::sync::{Mutex, MutexGuard, PoisonError};

use super::wait::{Either, Waiters, both, first, yield_now};
use super::{CanRx, CanTx, Clock, Error, Stopped};
use crate::Pdo;
use crate::can::CanFrame;
use crate::cob::{CobId, NodeId};
use crate::emcy::EmcyFrame;
use crate::master::{DEFAULT_TIMEOUT, Event, SDO_BUFFER, Waited};
use crate::nmt::{NmtCommand, NmtState};
use crate::sdo::Client;
use crate::time::{Duration, Instant};

/// Events kept for [`Master::next_event`] before the oldest are dropped (a program that
/// never reads them must not grow without bound).
pub const EVENT_QUEUE: usize = 1024;

/// Received frames [`Master::run`] dispatches in one poll before it lets the other futures of
/// its task run: an interface that hands over a backlog at once (a socket's buffer after a late
/// wake) must not keep the cycle from its SYNC until the last frame is routed.
pub const RECEIVED_PER_POLL: usize = 8;

/// The order in which queued frames go out: every `High` frame before any `Low` one, each
/// class first in, first out.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Priority {
    /// NMT, SYNC and PDOs: the cycle's frames.
    High,
    /// SDO and LSS: they wait while cyclic frames are due.
    Low,
}

/// One node's SDO client and the responses routed to it while a transfer runs.
#[derive(Debug, Default)]
pub(super) struct SdoSlot {
    /// The client; `None` while a transfer has it.
    pub(super) client: Option<Box<Client<SDO_BUFFER>>>,
    /// Whether a transfer runs (its responses are routed here).
    pub(super) active: bool,
    pub(super) responses: VecDeque<CanFrame>,
    pub(super) waiters: Waiters,
}

/// The last frame on one PDO COB-ID and how many came.
#[derive(Debug, Default)]
struct PdoSlot {
    frame: Option<CanFrame>,
    count: u64,
    waiters: Waiters,
}

/// What the master knows of one node.
#[derive(Clone, Copy, Debug, Default)]
struct Watch {
    state: Option<NmtState>,
    /// Heartbeat consumer time, when watched.
    timeout: Option<Duration>,
    last_seen: Instant,
    lost: bool,
}

#[derive(Debug, Default)]
pub(super) struct Inner {
    high: VecDeque<CanFrame>,
    low: VecDeque<CanFrame>,
    tx: Waiters,
    stopped: bool,
    pub(super) sdo: BTreeMap<NodeId, SdoSlot>,
    pdos: BTreeMap<u32, PdoSlot>,
    nodes: BTreeMap<NodeId, Watch>,
    heard: BTreeMap<NodeId, Instant>,
    events: VecDeque<Event>,
    dropped_events: u64,
    event_waiters: Waiters,
    pub(super) lss: VecDeque<CanFrame>,
    pub(super) lss_waiters: Waiters,
    /// Whether an [`LssMaster`](super::lss::LssMaster) exists.
    pub(super) lss_active: bool,
    sync_overflow: Option<u8>,
    sync_counter: u8,
}

impl Inner {
    /// Queues `frame`; [`Stopped`] once the bus task ended.
    pub(super) fn queue(&mut self, priority: Priority, frame: CanFrame) -> Result<(), Stopped> {
        if self.stopped {
            return Err(Stopped);
        }
        match priority {
            Priority::High => self.high.push_back(frame),
            Priority::Low => self.low.push_back(frame),
        }
        self.tx.wake();
        Ok(())
    }

    pub(super) fn check(&self) -> Result<(), Stopped> {
        if self.stopped { Err(Stopped) } else { Ok(()) }
    }

    fn stop(&mut self) {
        self.stopped = true;
        self.tx.wake();
        self.event_waiters.wake();
        self.lss_waiters.wake();
        for s in self.sdo.values_mut() {
            s.waiters.wake();
        }
        for s in self.pdos.values_mut() {
            s.waiters.wake();
        }
    }

    fn event(&mut self, event: Event) {
        if self.events.len() >= EVENT_QUEUE {
            self.events.pop_front();
            self.dropped_events += 1;
        }
        self.events.push_back(event);
        self.event_waiters.wake();
    }

    /// Routes a received frame: SDO responses to the transfer of their node, LSS answers to
    /// the LSS master, PDOs to their slot, the rest into events.
    fn dispatch(&mut self, f: &CanFrame, now: Instant) {
        if f.is_remote() {
            return self.event(Event::Other(*f));
        }
        if f.is_extended() {
            return self.pdo(f);
        }
        let id = f.id();
        match id {
            0x080 => self.event(Event::Sync { counter: f.bytes().first().copied() }),
            0x081..=0x0FF => match (NodeId::of_emcy(id), EmcyFrame::decode(f.bytes())) {
                (Some(node), Ok(emcy)) => {
                    self.heard.insert(node, now);
                    self.event(Event::Emcy { node, emcy });
                }
                _ => self.event(Event::Other(*f)),
            },
            0x181..=0x57F => {
                if let Some(node) = crate::cob::classify(id as u16).and_then(|(_, n)| n) {
                    self.heard.insert(node, now);
                }
                self.pdo(f);
            }
            0x581..=0x5FF => {
                let node = NodeId::new((id - 0x580) as u8);
                let slot = node.and_then(|n| self.sdo.get_mut(&n));
                match (node, slot) {
                    (Some(node), Some(slot)) if slot.active => {
                        self.heard.insert(node, now);
                        slot.responses.push_back(*f);
                        slot.waiters.wake();
                    }
                    (node, _) => {
                        if let Some(node) = node {
                            self.heard.insert(node, now);
                        }
                        self.event(Event::Other(*f));
                    }
                }
            }
            0x701..=0x77F => self.error_control(f, now),
            id if id == crate::lss::RESPONSE_ID.raw() && self.lss_active => {
                self.lss.push_back(*f);
                self.lss_waiters.wake();
            }
            _ => self.event(Event::Other(*f)),
        }
    }

    fn pdo(&mut self, f: &CanFrame) {
        let slot = self.pdos.entry(CobId::of_frame(f).0).or_default();
        slot.frame = Some(*f);
        slot.count += 1;
        slot.waiters.wake();
    }

    /// A heartbeat or boot-up: the node's watch, and an event when its state changed.
    fn error_control(&mut self, f: &CanFrame, now: Instant) {
        let node = NodeId::of_error_control(f.id());
        let state = f.bytes().first().and_then(|b| NmtState::from_u8(*b));
        let (Some(node), Some(state), 1) = (node, state, f.len()) else {
            return self.event(Event::Other(*f));
        };
        self.heard.insert(node, now);
        let w = self.nodes.entry(node).or_default();
        w.last_seen = now;
        w.lost = false;
        if state == NmtState::BootUp {
            w.state = Some(NmtState::PreOperational);
            return self.event(Event::BootUp { node });
        }
        if w.state != Some(state) {
            w.state = Some(state);
            self.event(Event::State { node, state });
        }
    }

    /// The first watched node whose heartbeat is overdue at `now` (marked lost), else the
    /// time the next one falls due.
    fn lost_node(&mut self, now: Instant) -> Result<NodeId, Option<Instant>> {
        let mut next: Option<Instant> = None;
        for (node, w) in &mut self.nodes {
            let (Some(t), false) = (w.timeout, w.lost) else { continue };
            let due = w.last_seen + t + Duration::MICROSECOND;
            if now >= due {
                w.lost = true;
                return Ok(*node);
            }
            next = Some(next.map_or(due, |n| n.min(due)));
        }
        Err(next)
    }
}

/// Takes the lock; a task that panicked while holding it left the state consistent (every
/// change under the lock is a single push or field write), so a poisoned lock is used as is.
pub(super) fn lock(m: &Mutex<Inner>) -> MutexGuard<'_, Inner> {
    m.lock().unwrap_or_else(PoisonError::into_inner)
}

/// The async CANopen master. Shared by reference: every method takes `&self`, so several
/// tasks (or futures joined in one task) use it at once.
///
/// [`Master::run`] carries its frames; see the module example.
pub struct Master<C: Clock> {
    pub(super) inner: Mutex<Inner>,
    pub(super) clock: C,
    pub(super) timeout: Duration,
}

impl<C: Clock> core::fmt::Debug for Master<C> {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        f.debug_struct("Master").field("timeout", &self.timeout).finish_non_exhaustive()
    }
}

/// Marks the master stopped when [`Master::run`] ends or is dropped.
struct StopOnDrop<'a>(&'a Mutex<Inner>);

impl Drop for StopOnDrop<'_> {
    fn drop(&mut self) {
        lock(self.0).stop();
    }
}

impl<C: Clock> Master<C> {
    /// A master on `clock`'s time, waiting [`DEFAULT_TIMEOUT`] for answers.
    pub fn new(clock: C) -> Self {
        let inner = Inner { sync_counter: 1, ..Inner::default() };
        Self { inner: Mutex::new(inner), clock, timeout: DEFAULT_TIMEOUT }
    }

    /// The same master with another answer timeout (SDO responses, boot-up, PDOs).
    pub fn with_timeout(mut self, timeout: Duration) -> Self {
        self.timeout = timeout;
        self
    }

    /// The answer timeout.
    pub fn timeout(&self) -> Duration {
        self.timeout
    }

    /// The clock.
    pub fn clock(&self) -> &C {
        &self.clock
    }

    /// Now, on the master's clock.
    pub fn now(&self) -> Instant {
        self.clock.now()
    }

    pub(super) fn lock(&self) -> MutexGuard<'_, Inner> {
        lock(&self.inner)
    }

    /// The bus task: queued frames out ([`Priority::High`] first, one at a time), received
    /// frames to whoever waits for them. Runs until the bus fails; poll it alongside every
    /// other use of the master.
    ///
    /// It gives way to the futures polled with it (`join!`, `select!`, the same task) after
    /// each [`Priority::Low`] frame it sends and every [`RECEIVED_PER_POLL`] frames it
    /// receives, even where the interface takes and gives frames at once (a socket): a cycle
    /// whose SYNC falls due during an SDO burst queues it after at most one SDO frame.
    ///
    /// # Errors
    ///
    /// The bus error; from then on (or once this future is dropped) every operation fails
    /// with [`Stopped`].
    pub async fn run<T, R>(&self, tx: T, rx: R) -> Result<(), T::Error>
    where
        T: CanTx,
        R: CanRx<Error = T::Error>,
    {
        let _stop = StopOnDrop(&self.inner);
        both(self.transmit(tx), self.receive(rx)).await
    }

    async fn transmit<T: CanTx>(&self, mut tx: T) -> Result<(), T::Error> {
        loop {
            let (frame, priority) = poll_fn(|cx| {
                let mut g = self.lock();
                if let Some(f) = g.high.pop_front() {
                    return Poll::Ready((f, Priority::High));
                }
                match g.low.pop_front() {
                    Some(f) => Poll::Ready((f, Priority::Low)),
                    None => {
                        g.tx.register(cx.waker());
                        Poll::Pending
                    }
                }
            })
            .await;
            tx.send(&frame).await?;
            // A send that completes at once (a socket) would otherwise drain a whole SDO burst
            // in this one poll while a SYNC falls due; the cycle's own frames go back to back.
            if priority == Priority::Low {
                yield_now().await;
            }
        }
    }

    async fn receive<R: CanRx>(&self, mut rx: R) -> Result<(), R::Error> {
        loop {
            for _ in 0..RECEIVED_PER_POLL {
                let frame = rx.recv().await?;
                let now = self.clock.now();
                self.lock().dispatch(&frame, now);
            }
            yield_now().await;
        }
    }

    /// Queues a frame as it is.
    ///
    /// # Errors
    ///
    /// [`Stopped`] once the bus task ended.
    pub fn send(&self, priority: Priority, frame: CanFrame) -> Result<(), Error> {
        self.lock().queue(priority, frame).map_err(Error::Bus)
    }

    /// When `node` was last heard (any frame it sends: boot-up, heartbeat, EMCY, TPDO, SDO
    /// response); `None` if never.
    pub fn last_heard(&self, node: NodeId) -> Option<Instant> {
        self.lock().heard.get(&node).copied()
    }

    /// The timeout error of a wait for `what` from `node` that began at `since`.
    pub(super) fn timeout_error(
        &self,
        node: Option<NodeId>,
        what: Waited,
        since: Instant,
    ) -> Error {
        let g = self.lock();
        let heard = node.and_then(|n| g.heard.get(&n)).is_some_and(|t| *t >= since);
        let state = node.and_then(|n| g.nodes.get(&n)).and_then(|w| w.state);
        Error::Timeout { node, what, waited: self.timeout, heard, state }
    }

    // ---- NMT and events ------------------------------------------------------------------

    /// An NMT command to `node`.
    ///
    /// # Errors
    ///
    /// [`Stopped`].
    pub fn nmt(&self, command: NmtCommand, node: NodeId) -> Result<(), Error> {
        self.send(Priority::High, nmt_frame(command.frame(Some(node))))
    }

    /// An NMT command to every node (node-ID byte 0).
    ///
    /// # Errors
    ///
    /// [`Stopped`].
    pub fn nmt_all(&self, command: NmtCommand) -> Result<(), Error> {
        self.send(Priority::High, nmt_frame(command.frame(None)))
    }

    /// The state `node` last reported (boot-up counts as pre-operational).
    pub fn state(&self, node: NodeId) -> Option<NmtState> {
        self.lock().nodes.get(&node).and_then(|w| w.state)
    }

    /// Consumes `node`'s heartbeat: when none comes for `timeout`, [`Master::next_event`]
    /// gives [`Event::HeartbeatLost`] once, until it comes back.
    pub fn watch_heartbeat(&self, node: NodeId, timeout: Duration) {
        let now = self.now();
        let mut g = self.lock();
        let w = g.nodes.entry(node).or_default();
        w.timeout = Some(timeout);
        w.last_seen = now;
        w.lost = false;
    }

    /// The next event (boot-up, state change, lost heartbeat, EMCY, SYNC of another
    /// producer, other frames), waiting as long as it takes. PDOs are not events: they are
    /// in [`Master::latest_pdo`].
    ///
    /// # Errors
    ///
    /// [`Stopped`].
    pub async fn next_event(&self) -> Result<Event, Error> {
        loop {
            let wake = {
                let now = self.now();
                let mut g = self.lock();
                if let Some(e) = g.events.pop_front() {
                    return Ok(e);
                }
                g.check().map_err(Error::Bus)?;
                match g.lost_node(now) {
                    Ok(node) => return Ok(Event::HeartbeatLost { node }),
                    Err(next) => next,
                }
            };
            let event = poll_fn(|cx| {
                let mut g = self.lock();
                if !g.events.is_empty() || g.stopped {
                    return Poll::Ready(());
                }
                g.event_waiters.register(cx.waker());
                Poll::Pending
            });
            match wake {
                Some(t) => {
                    first(event, self.clock.sleep_until(t)).await;
                }
                None => event.await,
            }
        }
    }

    /// Events dropped because [`EVENT_QUEUE`] were waiting unread.
    pub fn dropped_events(&self) -> u64 {
        self.lock().dropped_events
    }

    /// Waits until `node` reports `state` (boot-up for pre-operational counts), at most the
    /// timeout. Other events meanwhile stay queued.
    ///
    /// # Errors
    ///
    /// [`Error::Timeout`] or [`Stopped`].
    pub async fn wait_state(&self, node: NodeId, state: NmtState) -> Result<(), Error> {
        let since = self.now();
        let reached = poll_fn(|cx| {
            let mut g = self.lock();
            if g.nodes.get(&node).and_then(|w| w.state) == Some(state) {
                return Poll::Ready(Ok(()));
            }
            g.check().map_err(Error::Bus)?;
            g.event_waiters.register(cx.waker());
            Poll::Pending
        });
        match first(reached, self.clock.sleep_until(since + self.timeout)).await {
            Either::Left(r) => r,
            Either::Right(()) => Err(self.timeout_error(Some(node), Waited::State(state), since)),
        }
    }

    // ---- SYNC ----------------------------------------------------------------------------

    /// Queues one SYNC (with the counter when [`Master::set_sync_counter`] set one).
    ///
    /// # Errors
    ///
    /// [`Stopped`].
    pub fn sync(&self) -> Result<(), Error> {
        let mut g = self.lock();
        let frame = match g.sync_overflow {
            Some(overflow) => {
                let c = g.sync_counter;
                // CiA 301 7.2.5.2: 1 ..= overflow, then 1 again.
                g.sync_counter = if c >= overflow { 1 } else { c + 1 };
                CanFrame::standard_len(
                    crate::can::StdId::masked(0x080),
                    [c, 0, 0, 0, 0, 0, 0, 0],
                    1,
                )
            }
            None => CanFrame::standard_len(crate::can::StdId::masked(0x080), [0; 8], 0),
        };
        g.queue(Priority::High, frame).map_err(Error::Bus)
    }

    /// SYNCs carry a counter from 1 to `overflow` (0x1019, 2..=240), or none with `None`.
    ///
    /// # Errors
    ///
    /// An overflow value CiA 301 does not allow.
    pub fn set_sync_counter(&self, overflow: Option<u8>) -> Result<(), Error> {
        if overflow.is_some_and(|o| !(2..=240).contains(&o)) {
            return Err(Error::Invalid("SYNC counter overflow must be 2..=240 (CiA 301 0x1019)"));
        }
        let mut g = self.lock();
        g.sync_overflow = overflow;
        g.sync_counter = 1;
        Ok(())
    }

    /// A cycle timer of `period` starting one period from now: [`Cycle::tick`] wakes on the
    /// period's grid. The cycle's body queues its RPDOs, then [`Master::sync`].
    pub fn cycle(&self, period: Duration) -> Cycle<'_, C> {
        let next = self.now() + period;
        Cycle { clock: &self.clock, period, next, ticks: 0, missed: 0 }
    }

    // ---- PDO -----------------------------------------------------------------------------

    /// Queues an RPDO: the struct's bytes on `cob_id`'s identifier.
    ///
    /// # Errors
    ///
    /// A value that does not fit its field, or [`Stopped`].
    pub fn send_pdo<P: Pdo>(&self, cob_id: CobId, pdo: &P) -> Result<(), Error> {
        let bytes = pdo.pack().map_err(|reason| Error::Pdo { cob_id, reason })?;
        let frame =
            cob_id.frame(bytes.as_ref()).ok_or(Error::Invalid("a PDO of more than 8 bytes"))?;
        self.send(Priority::High, frame)
    }

    /// The last frame received on `cob_id` and how many came so far (0: none yet).
    pub fn latest_frame(&self, cob_id: CobId) -> (Option<CanFrame>, u64) {
        let g = self.lock();
        g.pdos.get(&pdo_key(cob_id)).map_or((None, 0), |s| (s.frame, s.count))
    }

    /// The last TPDO received on `cob_id`, unpacked; `None` before the first.
    ///
    /// # Errors
    ///
    /// A frame that does not unpack into `P`.
    pub fn latest_pdo<P: Pdo>(&self, cob_id: CobId) -> Result<Option<P>, Error> {
        match self.latest_frame(cob_id).0 {
            Some(f) => {
                P::unpack(f.bytes()).map(Some).map_err(|reason| Error::Unpack { cob_id, reason })
            }
            None => Ok(None),
        }
    }

    /// The next TPDO on `cob_id` received after this call, unpacked, within the timeout.
    ///
    /// # Errors
    ///
    /// [`Error::Timeout`], a frame that does not unpack into `P`, or [`Stopped`].
    pub async fn next_pdo<P: Pdo>(&self, cob_id: CobId) -> Result<P, Error> {
        let since = self.now();
        let key = pdo_key(cob_id);
        let seen = self.latest_frame(cob_id).1;
        let arrived = poll_fn(|cx| {
            let mut g = self.lock();
            g.check().map_err(Error::Bus)?;
            let slot = g.pdos.entry(key).or_default();
            match slot.frame {
                Some(f) if slot.count > seen => Poll::Ready(Ok(f)),
                _ => {
                    slot.waiters.register(cx.waker());
                    Poll::Pending
                }
            }
        });
        let f = match first(arrived, self.clock.sleep_until(since + self.timeout)).await {
            Either::Left(r) => r?,
            Either::Right(()) => {
                let node = match cob_id.is_extended() {
                    true => None,
                    false => crate::cob::classify(cob_id.can_id() as u16).and_then(|(_, n)| n),
                };
                return Err(self.timeout_error(node, Waited::Frame(cob_id), since));
            }
        };
        P::unpack(f.bytes()).map_err(|reason| Error::Unpack { cob_id, reason })
    }
}

/// The NMT frame with `bytes`.
fn nmt_frame(bytes: [u8; 2]) -> CanFrame {
    CanFrame::standard_len(crate::can::StdId::masked(0), [bytes[0], bytes[1], 0, 0, 0, 0, 0, 0], 2)
}

/// The PDO slot key of `cob_id`: as [`CobId::of_frame`] gives it for its frames.
fn pdo_key(cob_id: CobId) -> u32 {
    match cob_id.is_extended() {
        true => cob_id.can_id() | CobId::FRAME_29BIT,
        false => cob_id.can_id(),
    }
}

/// A periodic timer on a fixed grid ([`Master::cycle`]): a late wake-up does not shift the
/// grid, and the grid points it slept through count as missed.
#[derive(Debug)]
pub struct Cycle<'m, C: Clock> {
    clock: &'m C,
    period: Duration,
    next: Instant,
    ticks: u64,
    missed: u64,
}

impl<C: Clock> Cycle<'_, C> {
    /// Waits for the next grid point and returns it (the time the cycle was due).
    ///
    /// On a clock of coarse [`Clock::resolution`] R it asks to wake 3/4 R early: the timer
    /// rounds that up to its one step within [due - 3/4 R, due + 1/4 R), the same phase every
    /// period, instead of the step after `due` (up to R late, and late by more than a period
    /// whenever scheduling adds to it).
    pub async fn tick(&mut self) -> Instant {
        let r = self.clock.resolution().as_micros();
        let early = Duration::from_micros(r * 3 / 4).min(self.period);
        self.clock.sleep_until(self.next.saturating_sub(early)).await;
        let due = self.next;
        let now = self.clock.now();
        // Grid points that passed while this one was late: those cycles are lost.
        let late = now.saturating_duration_since(due).as_micros() / self.period.as_micros().max(1);
        self.missed += late;
        self.next = due + self.period.saturating_mul(late + 1);
        self.ticks += 1;
        due
    }

    /// Cycles run.
    pub fn ticks(&self) -> u64 {
        self.ticks
    }

    /// Grid points skipped because a tick came more than a period late.
    pub fn missed(&self) -> u64 {
        self.missed
    }

    /// The period.
    pub fn period(&self) -> Duration {
        self.period
    }
}
