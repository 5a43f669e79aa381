//! The controller side of a CANopen network: one [`Master`] over any [`Bus`] (the transports
//! of [`crate::transport`]: SocketCAN, embedded-can HALs, TCP, in-memory).
//!
//! - NMT master: commands to one node or all; each node's state as its boot-up, heartbeat or
//!   guarding answer last said; a heartbeat consumer that makes a lost node an event;
//! - SYNC producer (with the CiA 301 counter when asked for);
//! - SDO client for every node (expedited, segmented; block transfer with
//!   [`Master::upload_block`]), typed by generated descriptors;
//! - PDO exchange with generated structs: send an RPDO struct, receive a TPDO struct by COB-ID;
//! - execution of generated configuration plans;
//! - EMCY consumer: the code, its CiA 301/402 meaning and the error register;
//! - LSS master ([`lss`]);
//! - a CiA 402 drive on PDOs and SYNC, with the runtime's driver ([`axis`]).
//!
//! Blocking and single-threaded, like the SDO client it is built on. A frame that arrives
//! while the master waits for something else is kept, in order, and handed out later by
//! [`Master::poll`] or the next wait that wants it: nothing is dropped. Timeouts and errors
//! are values, never panics. `std` only (it keeps queues); firmware uses [`crate::node`].
//!
//! ```
//! use odc::master::{Event, Master};
//! use odc::nmt::{NmtCommand, NmtState};
//! use odc::transport::{Bus, mem::MemBus};
//! use odc::can::CanFrame;
//!
//! let bus = MemBus::new();
//! let (mut device, port) = (bus.port(), bus.port());
//! let mut master = Master::new(port).with_timeout(100);
//! // A device says it booted, and later that it is operational.
//! device.send(&CanFrame::from_slice(0x705, &[0x00]).unwrap()).unwrap();
//! master.wait_boot_up(5)?;
//! assert_eq!(master.state(5), Some(NmtState::PreOperational));
//! master.nmt(NmtCommand::Start, 5)?;
//! device.send(&CanFrame::from_slice(0x705, &[0x05]).unwrap()).unwrap();
//! let deadline = master.now_ms() + 100;
//! assert_eq!(master.poll(deadline)?, Some(Event::State { node: 5, state: NmtState::Operational }));
//! # Ok::<(), odc::master::Error<odc::transport::mem::Closed>>(())
//! ```

pub mod axis;
pub mod lss;

use std::boxed::Box;
use std::collections::{BTreeMap, VecDeque};
use std::fmt;
use std::vec::Vec;

use crate::can::CanFrame;
use crate::emcy::EmcyFrame;
use crate::nmt::{NmtCommand, NmtState};
use crate::plan::SdoWrite;
use crate::sdo::{Client, SdoError};
use crate::transport::Bus;
use crate::{Entry, ObjValue, Pdo};

/// Bytes of the largest SDO value the master transfers (segmented or block).
pub const SDO_BUFFER: usize = 4096;

/// Default time the master waits for an answer, in ms.
pub const DEFAULT_TIMEOUT_MS: u64 = 1000;

/// Something that happened on the bus.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Event {
    /// A node sent its boot-up message (it is now pre-operational).
    BootUp {
        /// The node.
        node: u8,
    },
    /// A node's heartbeat or guarding answer reported a state other than the last one.
    State {
        /// The node.
        node: u8,
        /// Its state.
        state: NmtState,
    },
    /// A node watched with [`Master::watch_heartbeat`] missed its heartbeat time.
    HeartbeatLost {
        /// The node.
        node: u8,
    },
    /// An emergency message (`EmcyCode`'s `Display` gives its CiA 301/402 meaning).
    Emcy {
        /// The node.
        node: u8,
        /// Code, error register, manufacturer bytes.
        emcy: EmcyFrame,
    },
    /// A PDO (COB-ID 0x181–0x57F).
    Pdo {
        /// Its CAN-ID.
        cob_id: u32,
        /// The frame.
        frame: CanFrame,
    },
    /// A SYNC from another producer.
    Sync {
        /// Its counter, when it has one.
        counter: Option<u8>,
    },
    /// Any other frame (SDO of other clients, TIME, LSS, extended or remote frames, ...).
    Other(CanFrame),
}

/// Why a master operation failed.
#[derive(Debug)]
pub enum Error<E> {
    /// The bus failed.
    Bus(E),
    /// An SDO transfer failed: the server's abort or this client's (timeout, protocol).
    Sdo {
        /// The node.
        node: u8,
        /// Object index.
        index: u16,
        /// Sub-index.
        sub: u8,
        /// Why.
        error: SdoError<E>,
    },
    /// A write of a configuration plan failed.
    Plan {
        /// The node.
        node: u8,
        /// Position of the write in the plan.
        step: usize,
        /// The write.
        write: SdoWrite,
        /// Why.
        error: SdoError<E>,
    },
    /// Nothing came in time.
    Timeout {
        /// What was waited for.
        what: &'static str,
    },
    /// A PDO struct does not pack, or a received PDO does not unpack into it.
    Pdo {
        /// The CAN-ID.
        cob_id: u32,
        /// What the layout engine said.
        reason: crate::PackError,
    },
    /// A received PDO does not unpack into the struct asked for.
    Unpack {
        /// The CAN-ID.
        cob_id: u32,
        /// What the layout engine said.
        reason: crate::UnpackError,
    },
    /// An LSS service failed.
    Lss(lss::LssError),
    /// A CiA 402 job failed (fault, timeout, mode refused, …).
    Drive(crate::cia402::DriverError),
    /// A node-ID outside 1..=127, or an argument the protocol cannot carry.
    Invalid(&'static str),
}

impl<E: fmt::Display> fmt::Display for Error<E> {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Self::Bus(e) => write!(f, "bus error: {e}"),
            Self::Sdo { node, index, sub, error } => {
                write!(f, "SDO to node {node}, 0x{index:04X}:{sub:02X}: {error}")
            }
            Self::Plan { node, step, write, error } => write!(
                f,
                "write {step} of the plan for node {node} (0x{:04X}:{:02X}): {error}",
                write.index, write.sub
            ),
            Self::Timeout { what } => write!(f, "timeout: no {what}"),
            Self::Pdo { cob_id, reason } => {
                write!(f, "PDO 0x{cob_id:03X} does not pack: {reason:?}")
            }
            Self::Unpack { cob_id, reason } => {
                write!(f, "PDO 0x{cob_id:03X} does not unpack: {reason:?}")
            }
            Self::Lss(e) => write!(f, "LSS: {e}"),
            Self::Drive(e) => write!(f, "CiA 402: {e}"),
            Self::Invalid(what) => f.write_str(what),
        }
    }
}

impl<E: fmt::Debug + fmt::Display> core::error::Error for Error<E> {}

/// Which way a frame went, for an observer.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Dir {
    /// Sent by the master.
    Sent,
    /// Received from the bus.
    Received,
}

type Observer = Box<dyn FnMut(Dir, &CanFrame) + Send>;

/// The bus with the frames not yet handed out, and an observer of every frame.
struct Link<B> {
    bus: B,
    pending: VecDeque<CanFrame>,
    observer: Option<Observer>,
    /// The SDO response CAN-ID the current transfer waits for.
    sdo_response: Option<u32>,
}

impl<B: Bus> Link<B> {
    fn send(&mut self, frame: &CanFrame) -> Result<(), B::Error> {
        if let Some(o) = &mut self.observer {
            o(Dir::Sent, frame);
        }
        self.bus.send(frame)
    }

    /// The next frame from the bus (not the queue), waiting until `deadline_ms`.
    fn receive(&mut self, deadline_ms: u64) -> Result<Option<CanFrame>, B::Error> {
        let frame = self.bus.recv(deadline_ms)?;
        if let (Some(o), Some(f)) = (&mut self.observer, &frame) {
            o(Dir::Received, f);
        }
        Ok(frame)
    }

    /// The first frame (queued first) that `want` accepts, waiting until `deadline_ms`; the
    /// others received meanwhile are queued.
    fn take(
        &mut self,
        deadline_ms: u64,
        want: impl Fn(&CanFrame) -> bool,
    ) -> Result<Option<CanFrame>, B::Error> {
        if let Some(pos) = self.pending.iter().position(&want) {
            return Ok(self.pending.remove(pos));
        }
        loop {
            match self.receive(deadline_ms)? {
                Some(f) if want(&f) => return Ok(Some(f)),
                Some(f) => self.pending.push_back(f),
                None => return Ok(None),
            }
        }
    }
}

/// The SDO client's view: its responses only; the rest is queued for the master.
impl<B: Bus> Bus for Link<B> {
    type Error = B::Error;

    fn send(&mut self, frame: &CanFrame) -> Result<(), B::Error> {
        Link::send(self, frame)
    }

    fn recv(&mut self, deadline_ms: u64) -> Result<Option<CanFrame>, B::Error> {
        let id = self.sdo_response;
        self.take(deadline_ms, |f| Some(f.id) == id && !f.extended && !f.remote)
    }

    fn now_ms(&mut self) -> u64 {
        self.bus.now_ms()
    }
}

/// What the master knows of one node.
#[derive(Clone, Copy, Debug, Default)]
struct Watch {
    state: Option<NmtState>,
    /// Heartbeat consumer time, when watched.
    timeout_ms: Option<u64>,
    last_seen_ms: u64,
    lost: bool,
}

/// The SYNC producer.
#[derive(Clone, Copy, Debug)]
struct SyncProducer {
    period_ms: u64,
    next_ms: u64,
}

/// A CANopen master over a bus.
pub struct Master<B: Bus> {
    link: Link<B>,
    timeout_ms: u64,
    clients: BTreeMap<u8, Box<Client<SDO_BUFFER>>>,
    nodes: BTreeMap<u8, Watch>,
    sync: Option<SyncProducer>,
    /// The SYNC counter's overflow value (0x1019), when SYNCs carry a counter.
    sync_overflow: Option<u8>,
    sync_counter: u8,
}

fn valid(node: u8) -> bool {
    (1..=127).contains(&node)
}

impl<B: Bus> Master<B> {
    /// A master on `bus`, waiting [`DEFAULT_TIMEOUT_MS`] for answers.
    pub fn new(bus: B) -> Self {
        Master {
            link: Link { bus, pending: VecDeque::new(), observer: None, sdo_response: None },
            timeout_ms: DEFAULT_TIMEOUT_MS,
            clients: BTreeMap::new(),
            nodes: BTreeMap::new(),
            sync: None,
            sync_overflow: None,
            sync_counter: 1,
        }
    }

    /// The same master with another answer timeout (SDO responses, boot-up, PDOs).
    pub fn with_timeout(mut self, ms: u64) -> Self {
        self.timeout_ms = ms;
        self.clients.clear();
        self
    }

    /// Calls `observer` with every frame sent and received (a bus log, a monitor).
    pub fn observe(&mut self, observer: impl FnMut(Dir, &CanFrame) + Send + 'static) {
        self.link.observer = Some(Box::new(observer));
    }

    /// The bus.
    pub fn bus_mut(&mut self) -> &mut B {
        &mut self.link.bus
    }

    /// The bus's clock, in ms.
    pub fn now_ms(&mut self) -> u64 {
        self.link.bus.now_ms()
    }

    fn deadline(&mut self) -> u64 {
        self.now_ms().saturating_add(self.timeout_ms)
    }

    /// Sends a frame as it is.
    ///
    /// # Errors
    ///
    /// The bus error.
    pub fn send(&mut self, frame: &CanFrame) -> Result<(), Error<B::Error>> {
        self.link.send(frame).map_err(Error::Bus)
    }

    // ---- NMT -----------------------------------------------------------------------------

    /// An NMT command to `node`, or to every node when `node` is 0.
    ///
    /// # Errors
    ///
    /// A node-ID above 127, or the bus error.
    pub fn nmt(&mut self, command: NmtCommand, node: u8) -> Result<(), Error<B::Error>> {
        if node > 127 {
            return Err(Error::Invalid("NMT node-ID above 127"));
        }
        self.send(&frame(0, &command.frame(node))?)
    }

    /// The state `node` last reported (boot-up counts as pre-operational); `None` before it
    /// said anything.
    pub fn state(&self, node: u8) -> Option<NmtState> {
        self.nodes.get(&node).and_then(|w| w.state)
    }

    /// Consumes `node`'s heartbeat: when none comes for `timeout_ms`, [`Master::poll`] gives
    /// [`Event::HeartbeatLost`] once, until it comes back.
    pub fn watch_heartbeat(&mut self, node: u8, timeout_ms: u64) {
        let now = self.now_ms();
        let w = self.nodes.entry(node).or_default();
        w.timeout_ms = Some(timeout_ms);
        w.last_seen_ms = now;
        w.lost = false;
    }

    /// Waits for `node`'s boot-up message.
    ///
    /// # Errors
    ///
    /// [`Error::Timeout`] when none comes in time, or the bus error.
    pub fn wait_boot_up(&mut self, node: u8) -> Result<(), Error<B::Error>> {
        let id = 0x700 + u32::from(node);
        let deadline = self.deadline();
        let boot = |f: &CanFrame| f.is_data(id) && f.bytes() == [0];
        match self.link.take(deadline, boot).map_err(Error::Bus)? {
            Some(f) => {
                self.note(&f);
                Ok(())
            }
            None => Err(Error::Timeout { what: "boot-up message" }),
        }
    }

    /// Waits until `node` reports `state` (by heartbeat); the frames in between are kept.
    ///
    /// # Errors
    ///
    /// [`Error::Timeout`], or the bus error.
    pub fn wait_state(&mut self, node: u8, state: NmtState) -> Result<(), Error<B::Error>> {
        let id = 0x700 + u32::from(node);
        let deadline = self.deadline();
        let want = |f: &CanFrame| {
            f.is_data(id) && f.bytes().first().and_then(|b| NmtState::from_u8(*b)) == Some(state)
        };
        match self.link.take(deadline, want).map_err(Error::Bus)? {
            Some(f) => {
                self.note(&f);
                Ok(())
            }
            None => Err(Error::Timeout { what: "heartbeat with the state waited for" }),
        }
    }

    /// Records what a frame says about a node; returns the event it makes, or `None` for a
    /// heartbeat that repeats the node's known state (it only updates the node's watch). A
    /// heartbeat with a state byte CiA 301 does not define is handed out as [`Event::Other`].
    fn note(&mut self, f: &CanFrame) -> Option<Event> {
        let id = f.id;
        if f.extended || f.remote {
            return Some(Event::Other(*f));
        }
        let now = self.link.bus.now_ms();
        let event = match id {
            0x080 => Event::Sync { counter: f.bytes().first().copied() },
            0x081..=0x0FF => match EmcyFrame::decode(f.bytes()) {
                Ok(emcy) => Event::Emcy { node: (id - 0x80) as u8, emcy },
                Err(_) => Event::Other(*f),
            },
            0x181..=0x57F => Event::Pdo { cob_id: id, frame: *f },
            0x701..=0x77F => {
                let node = (id - 0x700) as u8;
                let Some(state) = f.bytes().first().and_then(|b| NmtState::from_u8(*b)) else {
                    return Some(Event::Other(*f));
                };
                let w = self.nodes.entry(node).or_default();
                w.last_seen_ms = now;
                w.lost = false;
                if state == NmtState::BootUp {
                    w.state = Some(NmtState::PreOperational);
                    return Some(Event::BootUp { node });
                }
                if w.state == Some(state) {
                    return None;
                }
                w.state = Some(state);
                Event::State { node, state }
            }
            _ => Event::Other(*f),
        };
        Some(event)
    }

    // ---- Events and SYNC -------------------------------------------------------------------

    /// The next event, waiting until `deadline_ms` at the latest: queued frames first, then
    /// lost heartbeats, then the bus. Also sends the SYNCs that fall due meanwhile. Repeated
    /// heartbeats of an unchanged state are not events (they update the node's watch).
    ///
    /// # Errors
    ///
    /// The bus error.
    pub fn poll(&mut self, deadline_ms: u64) -> Result<Option<Event>, Error<B::Error>> {
        loop {
            if let Some(f) = self.link.pending.pop_front() {
                match self.note(&f) {
                    Some(event) => return Ok(Some(event)),
                    None => continue,
                }
            }
            let now = self.now_ms();
            if let Some(node) = self.lost_node(now) {
                return Ok(Some(Event::HeartbeatLost { node }));
            }
            self.sync_due(now)?;
            if now >= deadline_ms {
                return Ok(None);
            }
            // Wake for the next SYNC or heartbeat deadline, whichever is first.
            let wake = [self.sync.map(|s| s.next_ms), self.next_heartbeat_deadline()]
                .into_iter()
                .flatten()
                .fold(deadline_ms, u64::min);
            if let Some(f) = self.link.receive(wake.max(now)).map_err(Error::Bus)? {
                self.link.pending.push_back(f);
            }
        }
    }

    fn lost_node(&mut self, now: u64) -> Option<u8> {
        for (node, w) in &mut self.nodes {
            if let Some(t) = w.timeout_ms
                && !w.lost
                && now > w.last_seen_ms.saturating_add(t)
            {
                w.lost = true;
                return Some(*node);
            }
        }
        None
    }

    fn next_heartbeat_deadline(&self) -> Option<u64> {
        self.nodes
            .values()
            .filter(|w| !w.lost)
            .filter_map(|w| {
                w.timeout_ms.map(|t| w.last_seen_ms.saturating_add(t).saturating_add(1))
            })
            .min()
    }

    fn sync_due(&mut self, now: u64) -> Result<(), Error<B::Error>> {
        if let Some(s) = self.sync
            && now >= s.next_ms
        {
            // One SYNC per call, on the period's grid (a late poll does not send a burst).
            let next = s.next_ms.saturating_add(s.period_ms).max(now.saturating_add(1));
            self.sync = Some(SyncProducer { period_ms: s.period_ms, next_ms: next });
            self.sync()?;
        }
        Ok(())
    }

    /// Sends one SYNC now (with the counter when [`Master::set_sync_counter`] set one).
    ///
    /// # Errors
    ///
    /// The bus error.
    pub fn sync(&mut self) -> Result<(), Error<B::Error>> {
        let frame = match self.sync_overflow {
            Some(overflow) => {
                let c = self.sync_counter;
                // CiA 301 7.2.5.2: 1 ..= overflow, then 1 again.
                self.sync_counter = if c >= overflow { 1 } else { c + 1 };
                frame(0x080, &[c])?
            }
            None => frame(0x080, &[])?,
        };
        self.send(&frame)
    }

    /// Makes [`Master::poll`] send a SYNC every `period_ms` (none with `None`).
    pub fn set_sync_period(&mut self, period_ms: Option<u64>) {
        let now = self.now_ms();
        self.sync = period_ms
            .filter(|p| *p > 0)
            .map(|period_ms| SyncProducer { period_ms, next_ms: now.saturating_add(period_ms) });
    }

    /// SYNCs carry a counter from 1 to `overflow` (0x1019, 2..=240), or none with `None`.
    ///
    /// # Errors
    ///
    /// An overflow value CiA 301 does not allow.
    pub fn set_sync_counter(&mut self, overflow: Option<u8>) -> Result<(), Error<B::Error>> {
        if overflow.is_some_and(|o| !(2..=240).contains(&o)) {
            return Err(Error::Invalid("SYNC counter overflow must be 2..=240 (CiA 301 0x1019)"));
        }
        self.sync_overflow = overflow;
        self.sync_counter = 1;
        Ok(())
    }

    // ---- SDO -----------------------------------------------------------------------------

    /// Reads a generated descriptor's entry of `node`.
    ///
    /// # Errors
    ///
    /// [`Error::Sdo`] with the abort, or the bus error.
    pub fn read<T: ObjValue>(&mut self, node: u8, entry: &Entry<T>) -> Result<T, Error<B::Error>> {
        let (index, sub) = (entry.addr.index, entry.addr.sub);
        self.transfer(node, index, sub, |c, link| c.read(link, entry))
    }

    /// Writes `value` into a generated descriptor's entry of `node`.
    ///
    /// # Errors
    ///
    /// [`Error::Sdo`] with the abort, or the bus error.
    pub fn write<T: ObjValue>(
        &mut self,
        node: u8,
        entry: &Entry<T>,
        value: T,
    ) -> Result<(), Error<B::Error>> {
        let (index, sub) = (entry.addr.index, entry.addr.sub);
        self.transfer(node, index, sub, |c, link| c.write(link, entry, value))
    }

    /// Uploads `index:sub` of `node` (any size up to [`SDO_BUFFER`]).
    ///
    /// # Errors
    ///
    /// [`Error::Sdo`] with the abort, or the bus error.
    pub fn upload(&mut self, node: u8, index: u16, sub: u8) -> Result<Vec<u8>, Error<B::Error>> {
        self.transfer(node, index, sub, |c, link| c.upload(link, index, sub).map(<[u8]>::to_vec))
    }

    /// Downloads `data` into `index:sub` of `node`.
    ///
    /// # Errors
    ///
    /// [`Error::Sdo`] with the abort, or the bus error.
    pub fn download(
        &mut self,
        node: u8,
        index: u16,
        sub: u8,
        data: &[u8],
    ) -> Result<(), Error<B::Error>> {
        self.transfer(node, index, sub, |c, link| c.download(link, index, sub, data))
    }

    /// Block-uploads `index:sub` of `node` (CiA 301 block transfer with CRC: for large
    /// values, where the server supports it).
    ///
    /// # Errors
    ///
    /// [`Error::Sdo`] with the abort (a server without block transfer aborts), or the bus
    /// error.
    pub fn upload_block(
        &mut self,
        node: u8,
        index: u16,
        sub: u8,
    ) -> Result<Vec<u8>, Error<B::Error>> {
        self.transfer(node, index, sub, |c, link| {
            c.upload_block(link, index, sub).map(<[u8]>::to_vec)
        })
    }

    /// Block-downloads `data` into `index:sub` of `node`.
    ///
    /// # Errors
    ///
    /// As [`Master::upload_block`].
    pub fn download_block(
        &mut self,
        node: u8,
        index: u16,
        sub: u8,
        data: &[u8],
    ) -> Result<(), Error<B::Error>> {
        self.transfer(node, index, sub, |c, link| c.download_block(link, index, sub, data))
    }

    /// Executes a configuration plan (a generated `master::plan(node)`) on `node`, write by
    /// write, stopping at the first failure.
    ///
    /// # Errors
    ///
    /// [`Error::Plan`]: which write failed, and why.
    pub fn execute(&mut self, node: u8, plan: &[SdoWrite]) -> Result<(), Error<B::Error>> {
        let mut client = self.take_client(node)?;
        let r = client.execute(&mut self.link, plan);
        self.clients.insert(node, client);
        r.map_err(|(step, error)| {
            let write = plan.get(step).copied().unwrap_or(SdoWrite::u8(0, 0, 0));
            Error::Plan { node, step, write, error }
        })
    }

    /// Runs one transfer with `node`'s client; its error names the node and the object.
    fn transfer<T>(
        &mut self,
        node: u8,
        index: u16,
        sub: u8,
        run: impl FnOnce(&mut Client<SDO_BUFFER>, &mut Link<B>) -> Result<T, SdoError<B::Error>>,
    ) -> Result<T, Error<B::Error>> {
        let mut client = self.take_client(node)?;
        let r = run(&mut client, &mut self.link);
        self.clients.insert(node, client);
        r.map_err(|error| Error::Sdo { node, index, sub, error })
    }

    /// The node's client, out of the map while it runs (it borrows the link mutably); the
    /// link then lets its responses through.
    fn take_client(&mut self, node: u8) -> Result<Box<Client<SDO_BUFFER>>, Error<B::Error>> {
        if !valid(node) {
            return Err(Error::Invalid("SDO node-ID outside 1..=127"));
        }
        self.link.sdo_response = Some(0x580 + u32::from(node));
        let timeout = self.timeout_ms;
        Ok(self
            .clients
            .remove(&node)
            .unwrap_or_else(|| Box::new(Client::new(node).with_timeout(timeout))))
    }

    // ---- PDO -----------------------------------------------------------------------------

    /// Sends an RPDO: the struct's bytes on the CAN-ID of `cob_id` (its bit 31 and the other
    /// flags dropped).
    ///
    /// # Errors
    ///
    /// A value that does not fit its field, or the bus error.
    pub fn send_pdo<P: Pdo>(&mut self, cob_id: u32, pdo: &P) -> Result<(), Error<B::Error>> {
        let id = cob_id & 0x7FF;
        let bytes = pdo.pack().map_err(|reason| Error::Pdo { cob_id: id, reason })?;
        let frame = CanFrame::from_slice(id, bytes.as_ref())
            .ok_or(Error::Invalid("a PDO of more than 8 bytes"))?;
        self.send(&frame)
    }

    /// The next TPDO on `cob_id`, unpacked (queued ones first).
    ///
    /// # Errors
    ///
    /// [`Error::Timeout`], a frame that does not unpack into `P`, or the bus error.
    pub fn recv_pdo<P: Pdo>(&mut self, cob_id: u32) -> Result<P, Error<B::Error>> {
        let id = cob_id & 0x7FF;
        let deadline = self.deadline();
        let frame = self
            .link
            .take(deadline, |f| f.is_data(id))
            .map_err(Error::Bus)?
            .ok_or(Error::Timeout { what: "PDO" })?;
        P::unpack(frame.bytes()).map_err(|reason| Error::Unpack { cob_id: id, reason })
    }

    /// The next data frame with CAN-ID `id` (queued ones first), as it is: for process data
    /// without a struct, or a vendor protocol.
    ///
    /// # Errors
    ///
    /// [`Error::Timeout`], or the bus error.
    pub fn recv_frame(&mut self, id: u32) -> Result<CanFrame, Error<B::Error>> {
        let deadline = self.deadline();
        self.link
            .take(deadline, |f| f.is_data(id))
            .map_err(Error::Bus)?
            .ok_or(Error::Timeout { what: "frame" })
    }

    /// The LSS master (CiA 305) on this master's bus.
    pub fn lss(&mut self) -> lss::LssMaster<'_, B> {
        lss::LssMaster::new(self)
    }
}

/// The CiA 301 writes that give a PDO a mapping of the application's choice (for a device
/// whose file has no default mapping, or another one): invalidate the COB-ID (bit 31), clear
/// the mapping, write `P::MAPPING`, set the count and the transmission type, validate the
/// COB-ID (CiA 301 7.5.2.36), by the one procedure, [`PdoConfig`](crate::plan::PdoConfig).
/// Run it with [`Master::execute`].
pub fn mapping_plan<P: Pdo>(
    comm_index: u16,
    mapping_index: u16,
    cob_id: u32,
    transmission_type: u8,
) -> Vec<SdoWrite> {
    let mapping: Vec<u32> = P::MAPPING.iter().map(|e| e.to_u32()).collect();
    crate::plan::PdoConfig::new(mapping_index, &mapping)
        .with_comm(comm_index, true)
        .with_transmission_type(transmission_type)
        .to_vec(cob_id)
}

/// A data frame of at most 8 bytes.
fn frame<E>(id: u32, data: &[u8]) -> Result<CanFrame, Error<E>> {
    CanFrame::from_slice(id, data).ok_or(Error::Invalid("a frame of more than 8 bytes"))
}
