//! A CANopen node (CiA 301 slave) over any [`ObjectDictionary`]: NMT, boot-up, heartbeat
//! producer and consumer, node guarding, SYNC, the PDO engine, EMCY, the SDO server (with
//! block transfer) and, with [`Node::with_lss`], the LSS slave (CiA 305). Node guarding, the
//! SYNC producer, block transfer and the LSS slave are odc's features `guarding`,
//! `sync-producer`, `sdo-block` and `lss-slave` (all default), for a firmware to leave out.
//!
//! `no_std`, no heap, no threads: the caller feeds every received frame to [`Node::handle`],
//! calls [`Node::poll`] often enough for its timers (heartbeat, event timers, inhibit times,
//! guarding; every millisecond is plenty, [`Node::next_deadline`] says when it must), and
//! passes the time of a monotonic clock ([`Instant`]); the node's frames
//! go to the `out` closure (a CAN driver's transmit queue), which may refuse one by returning
//! `Err` ([`Sent`]): the node keeps up to [`TX_QUEUE`] refused frames in order, offers them
//! first at its next call, and counts those that did not fit ([`Node::tx_lost`]). The node reads its parameters from
//! the dictionary (0x1005, 0x1006, 0x100C, 0x100D, 0x1014–0x1017, 0x1019, the PDO objects) and
//! reads them again after an SDO write to them, so a master configures it as any CANopen
//! device.
//!
//! ```
//! # mod lxm23a { odc_macros::include_device!("../../eds/lxm23a.eds", role = "slave"); }
//! use odc::can::CanFrame;
//! use odc::nmt::NmtState;
//! use odc::node::Node;
//! use odc::time::Instant;
//!
//! let mut od = lxm23a::slave::Dictionary::new(odc::node_id!(5));
//! let mut node: Node<64> = Node::new(odc::node_id!(5));
//! let mut sent = Vec::new();
//! node.start(&mut od, Instant::ZERO, &mut |f| sent.push(f));
//! assert_eq!(sent, [CanFrame::from_slice(0x705, &[0x00]).unwrap()]); // boot-up
//! // NMT "start remote node" for every node: operational.
//! let start = CanFrame::from_slice(0x000, &[0x01, 0]).unwrap();
//! let events = node.handle(&mut od, &start, Instant::from_millis(1), &mut |f| sent.push(f));
//! assert_eq!((events.state, node.state()), (Some(NmtState::Operational), NmtState::Operational));
//! ```
//!
//! NMT states and services (CiA 301 table 80): SDO in pre-operational and operational; PDOs
//! only in operational; SYNC and EMCY not in stopped; NMT, heartbeat and node guarding in
//! every state. Reset node and reset communication are reported in [`Events::reset`]: the
//! application restores the defaults of its dictionary (the whole of it, or 0x1000–0x1FFF,
//! for [`Node::next_node_id`]), and the node restarts (boot-up, pre-operational) at the next
//! [`Node::poll`] or [`Node::handle`]. LSS runs in every state; a node-ID it configures
//! becomes the node's at that restart, and a node started without one (0xFF) waits in
//! initialisation, without boot-up, until LSS gives it one (CiA 305).

mod emcy;
mod error_control;
#[cfg(feature = "lss-slave")]
mod lss;
#[cfg(feature = "lss-slave")]
use lss::LssSetup;
mod params;
pub mod pdo;
mod sync;
mod tx;
pub use tx::{Sent, TX_QUEUE};
#[cfg(test)]
mod tests;

use crate::can::{CanFrame, StdId};
use crate::cob::NodeId;
use crate::emcy::{EmcyCode, ErrorRegister};
use crate::lss::LssEvent;
#[cfg(feature = "lss-slave")]
use crate::lss::LssSlave;
use crate::nmt::{NmtCommand, NmtState};
use crate::sdo::Server;
use crate::slave::ObjectDictionary;
use crate::time::Instant;
use error_control::ErrorControl;
use params::{Dirty, View};

pub use emcy::{MAX_ACTIVE as MAX_ACTIVE_ERRORS, MAX_HISTORY, QUEUE as EMCY_QUEUE};
pub use pdo::{MAX_MAPPED, PdoError, PdoId};

/// EMCY "life guard error or heartbeat error" (CiA 301 table 21).
const HEARTBEAT_ERROR: EmcyCode = EmcyCode(0x8130);

/// Heartbeat consumers (0x1016 sub-indexes) a node watches; entries past this are ignored.
pub const MAX_HB_CONSUMERS: usize = 8;

/// An 11-bit data frame of one byte (boot-up, heartbeat, guarding answer, SYNC counter).
const fn one_byte(id: StdId, b: u8) -> CanFrame {
    CanFrame::standard_len(id, [b, 0, 0, 0, 0, 0, 0, 0], 1)
}

/// Which reset the NMT master asked for.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum Reset {
    /// Reset node: restore every object's default (application and communication).
    Node,
    /// Reset communication: restore the defaults of the communication objects
    /// (0x1000–0x1FFF).
    Communication,
}

/// What a master asked of the device's non-volatile memory over SDO (CiA 301, objects 0x1010 and 0x1011),
/// with the sub-index: 1 all parameters, 2 communication, 3 application, 4–127
/// manufacturer-specific. The node checked the signature; the application does the work.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum Storage {
    /// 0x1010 "save": store the parameters now.
    Save(u8),
    /// 0x1011 "load": the defaults are to be valid after the next reset (reset node for
    /// sub 1 and 3, reset communication for 2).
    Restore(u8),
}

/// What happened in one call of [`Node::handle`], [`Node::poll`] or the other calls, for the
/// application.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct Events {
    /// The node entered this NMT state.
    pub state: Option<NmtState>,
    /// A reset was requested: restore the dictionary's defaults before the next `poll`,
    /// which restarts the node with a boot-up message.
    pub reset: Option<Reset>,
    /// Bit n: the heartbeat of node n (0x1016) did not come in time. Reported once per loss;
    /// watching starts again with its next heartbeat.
    pub heartbeat_lost: u128,
    /// Bit n: the heartbeat of node n came (again) after it had not been seen or was lost.
    pub heartbeat_started: u128,
    /// No node-guarding request within the life time (0x100C × 0x100D). Once per loss.
    pub life_guarding_lost: bool,
    /// A SYNC was received (or produced), with its counter if it has one.
    pub sync: Option<Option<u8>>,
    /// Bit n-1: RPDO n was written into the dictionary.
    pub rpdo: u32,
    /// Bit n-1: TPDO n was sent.
    pub tpdo: u32,
    /// The SDO server wrote into the dictionary.
    pub sdo_written: bool,
    /// A PDO could not be packed or applied.
    pub pdo_error: Option<PdoError>,
    /// What an LSS request (CiA 305, on 0x7E5) asks of the application: store the
    /// configuration (answer with [`Node::lss_store_response`]), switch the CAN controller
    /// to [`LssSlave::bit_timing`] after the delay, or note a pending node-ID or bit timing.
    /// A node-ID becomes active by itself at the next reset ([`Events::reset`]).
    pub lss: Option<LssEvent>,
    /// A store (0x1010 "save") or restore (0x1011 "load") command: the application stores
    /// its parameters, or makes the defaults valid after the next reset.
    pub storage: Option<Storage>,
}

impl Events {
    fn merge(&mut self, o: pdo::Outcome) {
        self.rpdo |= o.rpdo;
        self.tpdo |= o.tpdo;
        if o.error.is_some() {
            self.pdo_error = o.error;
        }
    }

    /// Adds the events of a later call (a loop that polls and handles in one pass): flags
    /// and bits are joined, a later state, reset, SYNC, error or LSS event wins.
    pub fn absorb(&mut self, e: Events) {
        self.state = e.state.or(self.state);
        self.reset = e.reset.or(self.reset);
        self.heartbeat_lost |= e.heartbeat_lost;
        self.heartbeat_started |= e.heartbeat_started;
        self.life_guarding_lost |= e.life_guarding_lost;
        self.sync = e.sync.or(self.sync);
        self.rpdo |= e.rpdo;
        self.tpdo |= e.tpdo;
        self.sdo_written |= e.sdo_written;
        self.pdo_error = e.pdo_error.or(self.pdo_error);
        self.lss = e.lss.or(self.lss);
        self.storage = e.storage.or(self.storage);
    }
}

/// A CANopen node: NMT slave, heartbeat, node guarding, SYNC, PDOs, EMCY and the SDO server,
/// over a dictionary the caller passes to each call.
///
/// `N`: bytes of the SDO server's buffer (the largest value of a segmented transfer); `R`
/// and `T`: receive and transmit PDOs served (0x1400/0x1800 onward; 8 each by default, the
/// devices in `eds/` have 4). Every buffer is inside the node: `Node<64>` was 1376 bytes on
/// x86_64 and `Node<64, 4, 4>` 1024 before the transmit queue of [`TX_QUEUE`] frames, which
/// adds 80 (measured with `size_of`, LSS slave included; the SDO buffer is `N` of them);
/// `Node<32, 4, 4>` was 976 bytes on thumbv7em (`tests/slave-size`) before it.
#[derive(Clone, Debug)]
pub struct Node<const N: usize, const R: usize = 8, const T: usize = 8> {
    /// `None`: no node-ID (CiA 305's 0xFF), waiting for LSS.
    node_id: Option<NodeId>,
    next_node_id: Option<NodeId>,
    /// `None`: initialising (before `start`, or a reset pending).
    state: Option<NmtState>,
    pending_reset: Option<Reset>,
    sdo: Server<N>,
    dirty: Dirty,
    error_control: ErrorControl,
    sync: sync::Sync,
    emcy: emcy::Emcy,
    pdo: pdo::PdoEngine<R, T>,
    // LSS slave: what to build at the first start, then the slave (kept across resets).
    #[cfg(feature = "lss-slave")]
    lss_setup: Option<LssSetup>,
    #[cfg(feature = "lss-slave")]
    lss: Option<LssSlave>,
    /// Frames the sender refused, to offer again.
    tx: tx::TxQueue,
}

impl<const N: usize, const R: usize, const T: usize> Node<N, R, T> {
    /// A node with id `node_id`, initialising until [`Node::start`].
    pub fn new(node_id: NodeId) -> Self {
        Self::with_id(Some(node_id))
    }

    /// A node without node-ID (CiA 305's 0xFF): it stays initialising, without boot-up,
    /// until an LSS master gives it one ([`Node::with_lss`]).
    pub fn unconfigured() -> Self {
        Self::with_id(None)
    }

    fn with_id(node_id: Option<NodeId>) -> Self {
        Self {
            node_id,
            next_node_id: None,
            state: None,
            pending_reset: None,
            // A node without node-ID serves no SDO (it stays initialising): the server's id
            // is never used then.
            sdo: Server::new(match node_id {
                Some(n) => n,
                None => NodeId::MIN,
            }),
            dirty: Dirty::default(),
            error_control: ErrorControl::new(),
            sync: sync::Sync::new(),
            emcy: emcy::Emcy::new(),
            pdo: pdo::PdoEngine::new(),
            #[cfg(feature = "lss-slave")]
            lss_setup: None,
            #[cfg(feature = "lss-slave")]
            lss: None,
            tx: tx::TxQueue::default(),
        }
    }

    /// Every part but the LSS slave, the transmit queue, EMCY (which the start resets with
    /// the dictionary) and the PDOs (which its reload restarts, [`Dirty::RESTART`]) as
    /// [`Node::with_id`] makes them, in place: `*self = Self::with_id(id)` built a whole
    /// node on the stack and copied it, at every boot-up and reset (`tests/slave-size`,
    /// `llvm-objdump -d`: a 1,180 B frame with `with_id`'s 1,052 B below it).
    fn reset(&mut self, node_id: Option<NodeId>) {
        self.node_id = node_id;
        self.next_node_id = None;
        self.state = None;
        self.pending_reset = None;
        self.sdo = Server::new(match node_id {
            Some(n) => n,
            None => NodeId::MIN,
        });
        self.dirty = Dirty::default();
        self.error_control.reset();
        self.sync = sync::Sync::new();
    }

    /// The node id; `None` while it has none (LSS, CiA 305).
    pub fn node_id(&self) -> Option<NodeId> {
        self.node_id
    }

    /// The node-ID the next start (reset node or communication) takes: the one
    /// [`Node::set_node_id`] set, or the current one.
    #[cfg(not(feature = "lss-slave"))]
    pub fn next_node_id(&self) -> Option<NodeId> {
        self.next_node_id.or(self.node_id)
    }

    /// A new node id, taken at the next start (reset communication). With LSS, the LSS slave
    /// owns the node-ID from the first start on: this sets the one it starts with.
    pub fn set_node_id(&mut self, node_id: NodeId) {
        self.next_node_id = Some(node_id);
    }

    /// The NMT state; [`NmtState::BootUp`] while initialising.
    pub fn state(&self) -> NmtState {
        self.state.unwrap_or(NmtState::BootUp)
    }

    /// The error register (0x1001) as the node keeps it.
    pub fn error_register(&self) -> ErrorRegister {
        self.emcy.register()
    }

    /// The application sets the error register (CiA 301 0x1001 is the device's, and a
    /// device may set bits the node cannot know, or none for an error CiA 301 gives a
    /// class): with `Some`, every EMCY the node sends from now on (raise and "error reset")
    /// carries it and a read of 0x1001 answers it, until the next call; `None` gives it back
    /// to the node, which sets the bits of the active errors' classes (CiA 301 table 47) and
    /// the generic bit. It stays over resets.
    ///
    /// ```
    /// # use odc::{can::CanFrame, emcy::{EmcyCode, ErrorRegister}, node::Node, time::Instant};
    /// # struct Od;
    /// # impl odc::slave::ObjectDictionary for Od {
    /// #     fn read(&self, i: u16, _: u8, b: &mut [u8]) -> Result<usize, odc::SdoAbort> {
    /// #         if i == 0x1014 { b[..4].copy_from_slice(&0x85u32.to_le_bytes()); Ok(4) }
    /// #         else { Err(odc::SdoAbort::NoSuchObject) }
    /// #     }
    /// #     fn write(&mut self, _: u16, _: u8, _: &[u8]) -> Result<(), odc::SdoAbort> { Ok(()) }
    /// # }
    /// let (mut od, mut sent) = (Od, Vec::new());
    /// let mut node: Node<32> = Node::new(odc::node_id!(5));
    /// node.start(&mut od, Instant::ZERO, &mut |f| sent.push(f));
    /// // A device that reports a short circuit (2212h) with register 00h, as its manual says.
    /// node.set_error_register(Some(ErrorRegister::NONE));
    /// node.raise_emcy(EmcyCode(0x2212), [0; 5], Instant::ZERO, &mut |f| sent.push(f));
    /// assert_eq!(Some(sent[1]), CanFrame::new(0x85, [0x12, 0x22, 0x00, 0, 0, 0, 0, 0]));
    /// ```
    pub fn set_error_register(&mut self, register: Option<ErrorRegister>) {
        self.emcy.set_register(register);
    }

    /// The error history (0x1003), newest first: error code in bits 0–15, the first two
    /// manufacturer bytes in bits 16–31.
    pub fn error_history(&self) -> &[u32] {
        self.emcy.history()
    }

    /// Whether EMCY frames were lost because more than [`EMCY_QUEUE`] waited for the
    /// inhibit time.
    pub fn emcy_overflowed(&self) -> bool {
        self.emcy.overflowed()
    }

    /// [`Node::start`] once its sender keeps the frames it refuses.
    fn start_in<D: ObjectDictionary + ?Sized>(
        &mut self,
        dict: &mut D,
        now: Instant,
        out: &mut impl FnMut(CanFrame),
    ) {
        let requested = self.next_node_id.take().or(self.node_id);
        // The LSS slave (built at the first start) is kept across resets.
        #[cfg(feature = "lss-slave")]
        let id = {
            if self.lss.is_none()
                && let Some(s) = self.lss_setup
            {
                self.lss = Some(s.slave(&*dict, requested));
            }
            match self.lss.as_mut() {
                Some(l) => l.reset_communication(),
                None => requested,
            }
        };
        #[cfg(not(feature = "lss-slave"))]
        let id = requested;
        self.reset(id);
        self.emcy.reset(&*dict);
        let Some(id) = id else { return };
        self.dirty.0 = 0xFF;
        self.reload(&*dict, now);
        self.state = Some(NmtState::PreOperational);
        out(one_byte(id.error_control(), NmtState::BootUp.to_u8()));
        self.error_control.start(now);
        self.sync.start(now);
    }

    /// Reads the parameters marked dirty again.
    fn reload<D: ObjectDictionary + ?Sized>(&mut self, dict: &D, now: Instant) {
        let d = self.dirty.0;
        self.dirty.0 = 0;
        if d & Dirty::HEARTBEAT != 0 {
            self.error_control.load_heartbeat(dict, now);
        }
        if d & Dirty::CONSUMERS != 0 {
            self.error_control.load_consumers(dict);
        }
        if d & Dirty::GUARDING != 0 {
            self.error_control.load_guarding(dict);
        }
        if d & Dirty::SYNC != 0 {
            self.sync.load(dict, now);
        }
        if d & Dirty::EMCY != 0 {
            self.emcy.load(dict);
        }
        if d & Dirty::PDO != 0 {
            self.pdo.load(dict, d & Dirty::RESTART != 0);
        }
    }

    fn set_state(&mut self, s: NmtState, ev: &mut Events) {
        if self.state != Some(s) {
            if s == NmtState::Operational {
                self.pdo.restart();
            }
            self.state = Some(s);
            ev.state = Some(s);
        }
    }

    fn view<'a, D: ObjectDictionary + ?Sized>(
        dict: &'a mut D,
        emcy: &'a mut emcy::Emcy,
        dirty: &'a mut Dirty,
        pdo: &pdo::PdoEngine<R, T>,
        state: Option<NmtState>,
    ) -> View<'a, D> {
        // Mappings of valid PDOs are locked in operational only: in pre-operational no PDO
        // runs, so a remap cannot put a half-written mapping on the bus, and devices whose
        // file makes the COB-ID read-only (the LinMot E1200's) can still be remapped.
        let locked = if state == Some(NmtState::Operational) { pdo.valid() } else { [0; 2] };
        View { dict, emcy, dirty, written: false, storage: None, locked }
    }

    /// [`Node::handle`] once its sender keeps the frames it refuses.
    fn handle_in<D: ObjectDictionary + ?Sized>(
        &mut self,
        dict: &mut D,
        frame: &CanFrame,
        now: Instant,
        out: &mut impl FnMut(CanFrame),
    ) -> Events {
        let mut ev = self.pending(dict, now, out);
        #[cfg(feature = "lss-slave")]
        if frame.is_data(crate::lss::REQUEST_ID.raw()) {
            // LSS runs in every NMT state, and while a node without node-ID initialises.
            self.lss_in(frame, out, &mut ev);
            return ev;
        }
        let Some(state) = self.state else { return ev };
        if frame.is_data(0) {
            self.nmt(frame, &mut ev);
            return ev;
        }
        #[cfg(feature = "guarding")]
        if let Some(own) = self.node_id.map(NodeId::error_control)
            && frame.remote
            && !frame.extended
            && frame.id == own.raw()
        {
            let (byte, was_lost) = self.error_control.guard_request(state, now);
            out(one_byte(own, byte));
            if was_lost {
                self.clear_heartbeat_error(now, out);
            }
            return ev;
        }
        if !frame.remote && !frame.extended && (0x701..=0x77F).contains(&frame.id) {
            let was_lost = self.error_control.any_lost();
            self.error_control.heartbeat_in(frame, now, &mut ev);
            if was_lost {
                self.clear_heartbeat_error(now, out);
            }
            return ev;
        }
        if state == NmtState::Stopped {
            return ev;
        }
        if let Some(counter) = self.sync.received(frame) {
            self.sync_in(dict, counter, now, out, &mut ev);
            return ev;
        }
        if frame.is_data(self.sdo.request_id().raw()) {
            let mut view = Self::view(dict, &mut self.emcy, &mut self.dirty, &self.pdo, self.state);
            // A block upload's whole sub-block goes out at once.
            self.sdo.handle_into(&mut view, frame, now, out);
            ev.sdo_written = view.written;
            ev.storage = view.storage;
            if self.dirty.0 != 0 {
                self.reload(&*dict, now);
            }
            return ev;
        }
        if state == NmtState::Operational {
            let mut view = Self::view(dict, &mut self.emcy, &mut self.dirty, &self.pdo, self.state);
            if let Some(o) = self.pdo.receive(&mut view, frame, now, out) {
                ev.merge(o);
                if let Some(code) = o.length_emcy {
                    self.emcy.raise(EmcyCode(code), [0; 5], true, now, out);
                }
            }
        }
        ev
    }

    fn nmt(&mut self, frame: &CanFrame, ev: &mut Events) {
        let [cs, target, ..] = frame.data;
        if frame.len < 2 || (target != 0 && Some(target) != self.node_id.map(NodeId::get)) {
            return;
        }
        match NmtCommand::from_u8(cs) {
            Some(NmtCommand::Start) => self.set_state(NmtState::Operational, ev),
            Some(NmtCommand::Stop) => self.set_state(NmtState::Stopped, ev),
            Some(NmtCommand::EnterPreOperational) => self.set_state(NmtState::PreOperational, ev),
            Some(c @ (NmtCommand::ResetNode | NmtCommand::ResetCommunication)) => {
                let r = if c == NmtCommand::ResetNode { Reset::Node } else { Reset::Communication };
                self.state = None;
                self.pending_reset = Some(r);
                ev.reset = Some(r);
            }
            None => {}
        }
    }

    /// Clears EMCY 0x8130 once no watched heartbeat and no life guarding is lost.
    fn clear_heartbeat_error(&mut self, now: Instant, out: &mut impl FnMut(CanFrame)) {
        if !self.error_control.any_lost() {
            self.clear_emcy_in(HEARTBEAT_ERROR, now, out);
        }
    }

    fn sync_in<D: ObjectDictionary + ?Sized>(
        &mut self,
        dict: &mut D,
        counter: Option<u8>,
        now: Instant,
        out: &mut impl FnMut(CanFrame),
        ev: &mut Events,
    ) {
        ev.sync = Some(counter);
        if self.state == Some(NmtState::Operational) {
            let mut view = Self::view(dict, &mut self.emcy, &mut self.dirty, &self.pdo, self.state);
            let o = self.pdo.sync(&mut view, counter, now, out);
            ev.merge(o);
        }
    }

    /// Runs a reset that `handle` reported.
    fn pending<D: ObjectDictionary + ?Sized>(
        &mut self,
        dict: &mut D,
        now: Instant,
        out: &mut impl FnMut(CanFrame),
    ) -> Events {
        let mut ev = Events::default();
        if self.pending_reset.take().is_some() {
            self.start_in(dict, now, out);
            ev.state = self.state;
        }
        ev
    }

    /// [`Node::poll`] once its sender keeps the frames it refuses.
    fn poll_in<D: ObjectDictionary + ?Sized>(
        &mut self,
        dict: &mut D,
        now: Instant,
        out: &mut impl FnMut(CanFrame),
    ) -> Events {
        let mut ev = self.pending(dict, now, out);
        let (Some(state), Some(id)) = (self.state, self.node_id) else { return ev };
        if self.dirty.0 != 0 {
            self.reload(&*dict, now);
        }
        let newly_lost = self.error_control.poll(id.error_control(), state, now, out, &mut ev);
        // A lost heartbeat or life guarding is EMCY 0x8130 (CiA 301 table 21, "life guard
        // error or heartbeat error"; CANopenNode's CO_EM_HEARTBEAT_CONSUMER), the node's
        // number in the first manufacturer byte (0 for life guarding); cleared when every
        // watched heartbeat is back.
        // Only the consumers lost now: this runs on every poll, and a loop over all 128
        // node-IDs cost an idle pass about 7,000 instructions (tests/no-std/qemu.py).
        for i in 0..MAX_HB_CONSUMERS {
            if newly_lost >> i & 1 != 0 {
                let node = self.error_control.consumer_node(i);
                self.raise_emcy_in(HEARTBEAT_ERROR, [node, 0, 0, 0, 0], now, out);
            }
        }
        if ev.life_guarding_lost {
            self.raise_emcy_in(HEARTBEAT_ERROR, [0; 5], now, out);
        }
        if state == NmtState::Stopped {
            return ev;
        }
        #[cfg(feature = "sync-producer")]
        if let Some(counter) = self.sync.produce(now, out) {
            self.sync_in(dict, counter, now, out, &mut ev);
        }
        self.emcy.poll(now, out);
        if state == NmtState::Operational {
            let view = Self::view(dict, &mut self.emcy, &mut self.dirty, &self.pdo, self.state);
            let o = self.pdo.poll(&view, now, out);
            ev.merge(o);
        }
        // Segments still due of a block upload's sub-block, or the abort of a transfer that
        // timed out (the abort ends the transfer, so this stops).
        while let Some(f) = self.sdo.poll(now) {
            out(f);
        }
        ev
    }

    /// The latest time the next [`Node::poll`] is due (µs), for a caller that sleeps: the
    /// heartbeat, the SYNC producer, a queued EMCY, TPDO timers, a consumer's or the life
    /// guarding's timeout. `None` when no timer runs.
    pub fn next_deadline(&self) -> Option<Instant> {
        let pdo =
            (self.state == Some(NmtState::Operational)).then(|| self.pdo.next_deadline()).flatten();
        [
            self.error_control.next_deadline(),
            self.sync.next_deadline(),
            pdo,
            self.emcy.next_deadline(),
        ]
        .into_iter()
        .flatten()
        .min()
    }

    /// [`Node::raise_emcy`] once its sender keeps the frames it refuses.
    fn raise_emcy_in(
        &mut self,
        code: EmcyCode,
        manufacturer: [u8; 5],
        now: Instant,
        out: &mut impl FnMut(CanFrame),
    ) {
        let send = matches!(self.state, Some(NmtState::Operational | NmtState::PreOperational));
        self.emcy.raise(code, manufacturer, send, now, out);
    }

    /// [`Node::clear_emcy`] once its sender keeps the frames it refuses.
    fn clear_emcy_in(
        &mut self,
        code: EmcyCode,
        now: Instant,
        out: &mut impl FnMut(CanFrame),
    ) -> bool {
        let send = matches!(self.state, Some(NmtState::Operational | NmtState::PreOperational));
        self.emcy.clear(code, send, now, out)
    }

    /// Asks for TPDO `n` (1-based) to be sent: at once (after its inhibit time) for an
    /// event-driven TPDO at the next [`Node::poll`], at the next SYNC for type 0. Returns
    /// `false` for a PDO number the node does not serve.
    pub fn trigger_tpdo(&mut self, n: u16) -> bool {
        self.pdo.trigger(n)
    }

    /// The parameters were changed by the application, not over SDO: read them all again.
    pub fn reload_parameters<D: ObjectDictionary + ?Sized>(&mut self, dict: &D, now: Instant) {
        self.dirty.0 = !Dirty::RESTART;
        self.reload(dict, now);
    }
}
