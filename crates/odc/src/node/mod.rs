//! A CANopen node (CiA 301 slave) over any [`ObjectDictionary`]: NMT, boot-up, heartbeat
//! producer and consumer, node guarding, SYNC, the PDO engine, EMCY, the SDO server (with
//! block transfer) and, with [`Node::with_lss`], the LSS slave (CiA 305).
//!
//! `no_std`, no heap, no threads: the caller feeds every received frame to [`Node::handle`],
//! calls [`Node::poll`] often enough for its timers (heartbeat, event timers, inhibit times,
//! guarding; every millisecond is plenty, [`Node::next_deadline`] says when it must), and
//! passes a monotonic time in microseconds; the node's frames go to the `out` closure (a CAN
//! driver's transmit queue). `out` may refuse a frame by returning `Err` ([`Sent`]): the node
//! keeps up to [`TX_QUEUE`] refused frames in order and offers them first at its next call,
//! and counts the ones that did not fit ([`Node::tx_lost`]). The node reads its parameters from the dictionary (0x1005,
//! 0x1006, 0x100C, 0x100D, 0x1014–0x1017, 0x1019, the PDO objects) and reads them again after
//! an SDO write to them, so a master configures it as any CANopen device.
//!
//! ```
//! # mod lxm23a { odc_macros::include_device!("../../eds/lxm23a.eds", role = "slave"); }
//! use odc::can::CanFrame;
//! use odc::nmt::NmtState;
//! use odc::node::Node;
//!
//! let mut od = lxm23a::slave::Dictionary::new(odc::node_id!(5));
//! let mut node: Node<64> = Node::new(odc::node_id!(5));
//! let mut sent = Vec::new();
//! node.start(&mut od, 0, &mut |f| sent.push(f));
//! assert_eq!(sent, [CanFrame::from_slice(0x705, &[0x00]).unwrap()]); // boot-up
//! // NMT "start remote node" for every node: operational.
//! let start = CanFrame::from_slice(0x000, &[0x01, 0]).unwrap();
//! let events = node.handle(&mut od, &start, 1_000, &mut |f| sent.push(f));
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
mod lss;
use lss::LssSetup;
pub mod pdo;
mod tx;
pub use tx::{Sent, TX_QUEUE};
#[cfg(test)]
mod tests;

use crate::SdoAbort;
use crate::can::{CanFrame, StdId};
use crate::cob::NodeId;
use crate::emcy::{EmcyCode, ErrorRegister};
use crate::lss::{LssEvent, LssSlave};
use crate::nmt::{NmtCommand, NmtState};
use crate::sdo::Server;
use crate::slave::ObjectDictionary;

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

/// Reads up to 4 bytes of `index:sub` as a little-endian number; `None` when the dictionary
/// has no such entry or cannot read it.
fn get_u32<D: ObjectDictionary + ?Sized>(dict: &D, index: u16, sub: u8) -> Option<u32> {
    let mut buf = [0u8; 8];
    let n = dict.read(index, sub, &mut buf).ok()?;
    let mut le = [0u8; 4];
    for (d, s) in le.iter_mut().zip(buf.iter().take(n)) {
        *d = *s;
    }
    Some(u32::from_le_bytes(le))
}

fn get_u16<D: ObjectDictionary + ?Sized>(dict: &D, index: u16, sub: u8) -> Option<u16> {
    get_u32(dict, index, sub).map(|v| v as u16)
}

fn get_u8<D: ObjectDictionary + ?Sized>(dict: &D, index: u16, sub: u8) -> Option<u8> {
    get_u32(dict, index, sub).map(|v| v as u8)
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
    }
}

/// Communication objects written since the node last read them.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
struct Dirty(u8);

impl Dirty {
    const HEARTBEAT: u8 = 1;
    const CONSUMERS: u8 = 2;
    const GUARDING: u8 = 4;
    const SYNC: u8 = 8;
    const EMCY: u8 = 16;
    const PDO: u8 = 32;

    fn of(index: u16) -> u8 {
        match index {
            0x1017 => Self::HEARTBEAT,
            0x1016 => Self::CONSUMERS,
            0x100C | 0x100D => Self::GUARDING,
            0x1005 | 0x1006 | 0x1019 => Self::SYNC,
            0x1014 | 0x1015 => Self::EMCY,
            0x1400..=0x1BFF => Self::PDO,
            _ => 0,
        }
    }
}

impl<D: ObjectDictionary + ?Sized> View<'_, D> {
    /// CiA 301's rules for values of communication objects that depend on other values.
    fn check_parameter(&self, index: u16, sub: u8, data: &[u8]) -> Result<(), SdoAbort> {
        let new = || {
            let mut le = [0u8; 4];
            for (d, s) in le.iter_mut().zip(data) {
                *d = *s;
            }
            u32::from_le_bytes(le)
        };
        match (index, sub) {
            // A PDO's CAN-ID may change only while it is invalid (CiA 301 7.5.2.35/37:
            // 0x06090030 otherwise).
            (0x1400..=0x15FF | 0x1800..=0x19FF, 1) => {
                let old = get_u32(&*self.dict, index, 1);
                let valid = |c: u32| c & (1 << 31) == 0;
                if let Some(old) = old
                    && valid(old)
                    && valid(new())
                    && old & 0x3FFF_FFFF != new() & 0x3FFF_FFFF
                {
                    return Err(SdoAbort::InvalidValue);
                }
            }
            // Two heartbeat consumer entries for one node (CiA 301 7.5.2.14: 0x06040043).
            (0x1016, s) if s > 0 => {
                let node = new() >> 16 & 0xFF;
                let time = new() & 0xFFFF;
                let count = get_u8(&*self.dict, 0x1016, 0).unwrap_or(0);
                let clash = (1..=count).filter(|&o| o != s).any(|o| {
                    get_u32(&*self.dict, 0x1016, o)
                        .is_some_and(|v| v >> 16 & 0xFF == node && v & 0xFFFF != 0)
                });
                if time != 0 && node != 0 && clash {
                    return Err(SdoAbort::ParameterIncompatible);
                }
            }
            _ => {}
        }
        Ok(())
    }
}

/// The dictionary as the SDO server and the PDO engine see it: the node answers 0x1001 and
/// 0x1003 itself, and notes writes to the communication objects.
struct View<'a, D: ?Sized> {
    dict: &'a mut D,
    emcy: &'a mut emcy::Emcy,
    dirty: &'a mut Dirty,
    written: bool,
    /// The mappings of these PDOs may not change (CiA 301 7.5.2.36: only while the PDO is
    /// invalid): bit n of word 0 for TPDO n+1, of word 1 for RPDO n+1.
    locked: [u64; 2],
}

impl<D: ObjectDictionary + ?Sized> ObjectDictionary for View<'_, D> {
    fn read(&self, index: u16, sub: u8, buf: &mut [u8]) -> Result<usize, SdoAbort> {
        match self.emcy.read(index, sub, buf) {
            Some(r) => r,
            None => self.dict.read(index, sub, buf),
        }
    }

    fn access(&self, index: u16, sub: u8) -> Option<crate::Access> {
        self.dict.access(index, sub)
    }

    fn write(&mut self, index: u16, sub: u8, data: &[u8]) -> Result<(), SdoAbort> {
        if (index, sub) == (0x1003, 0) && self.emcy.read(0x1003, 0, &mut [0]).is_some() {
            return self.emcy.write_history_count(data);
        }
        // Access first, as the dictionary would refuse it (a read-only COB-ID: 0x06010002).
        if self.dict.access(index, sub).is_some_and(|a| !a.writable()) {
            return Err(SdoAbort::WriteOfReadOnly);
        }
        self.check_parameter(index, sub, data)?;
        if let Some((word, n)) = match index {
            0x1600..=0x17FF => Some((1, index - 0x1600)),
            0x1A00..=0x1BFF => Some((0, index - 0x1A00)),
            _ => None,
        } && n < 64
            && self.locked[word] >> n & 1 == 1
        {
            // CiA 301: a mapping may only change while its PDO is invalid (COB-ID bit 31).
            return Err(SdoAbort::UnsupportedAccess);
        }
        if matches!(index, 0x1600..=0x17FF | 0x1A00..=0x1BFF)
            && sub == 0
            && data.first().is_some_and(|&c| c > 0)
        {
            // The mapping enabled: at most 64 bits (CiA 301 abort 0x06040042).
            let count = data.first().copied().unwrap_or(0);
            let mut bits = 0u32;
            for s in 1..=count.min(pdo::MAX_MAPPED) {
                bits += get_u32(&*self.dict, index, s).map_or(0, |e| e & 0xFF);
            }
            if bits > 64 || count > pdo::MAX_MAPPED {
                return Err(SdoAbort::PdoLengthExceeded);
            }
        }
        self.dict.write(index, sub, data)?;
        self.dirty.0 |= Dirty::of(index);
        self.written = true;
        Ok(())
    }
}

#[derive(Clone, Copy, Debug, Default)]
struct Consumer {
    node: u8,
    time_us: u64,
    /// When its last heartbeat came; `None` until the first (watching starts then).
    last_us: Option<u64>,
}

/// A CANopen node: NMT slave, heartbeat, node guarding, SYNC, PDOs, EMCY and the SDO server,
/// over a dictionary the caller passes to each call.
///
/// `N`: bytes of the SDO server's buffer (the largest value of a segmented transfer); `R`
/// and `T`: receive and transmit PDOs served (0x1400/0x1800 onward; 8 each by default, the
/// devices in `eds/` have 4). Every buffer is inside the node: `Node<64>` is 1456 bytes on
/// x86_64, `Node<64, 4, 4>` 1104 (measured with `size_of`, LSS slave and the transmit queue
/// of [`TX_QUEUE`] frames included; the SDO buffer is `N` of them); `Node<32, 4, 4>` was 976
/// bytes on thumbv7em (`tests/slave-size`) before the 72-byte transmit queue.
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
    // Heartbeat producer.
    heartbeat_us: u64,
    next_heartbeat_us: u64,
    // Heartbeat consumers.
    consumers: [Consumer; MAX_HB_CONSUMERS],
    lost: u128,
    // Node guarding.
    toggle: bool,
    life_time_us: u64,
    last_guard_us: Option<u64>,
    guard_lost: bool,
    // SYNC.
    sync_cob_id: u32,
    sync_period_us: u64,
    sync_overflow: u8,
    sync_counter: u8,
    next_sync_us: u64,
    emcy: emcy::Emcy,
    pdo: pdo::PdoEngine<R, T>,
    // LSS slave: what to build at the first start, then the slave (kept across resets).
    lss_setup: Option<LssSetup>,
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
            heartbeat_us: 0,
            next_heartbeat_us: 0,
            consumers: [Consumer::default(); MAX_HB_CONSUMERS],
            lost: 0,
            toggle: false,
            life_time_us: 0,
            last_guard_us: None,
            guard_lost: false,
            sync_cob_id: 0x80,
            sync_period_us: 0,
            sync_overflow: 0,
            sync_counter: 0,
            next_sync_us: 0,
            emcy: emcy::Emcy::new(),
            pdo: pdo::PdoEngine::new(),
            lss_setup: None,
            lss: None,
            tx: tx::TxQueue::default(),
        }
    }

    /// The node id; `None` while it has none (LSS, CiA 305).
    pub fn node_id(&self) -> Option<NodeId> {
        self.node_id
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
        now_us: u64,
        out: &mut impl FnMut(CanFrame),
    ) {
        let requested = self.next_node_id.take().or(self.node_id);
        let setup = self.lss_setup;
        let mut lss = self.lss.take();
        if lss.is_none()
            && let Some(s) = setup
        {
            lss = Some(s.slave(&*dict, requested));
        }
        let id = match lss.as_mut() {
            Some(l) => l.reset_communication(),
            None => requested,
        };
        *self = Self::with_id(id);
        self.lss_setup = setup;
        self.lss = lss;
        let Some(id) = id else { return };
        self.emcy.reset(&*dict);
        self.dirty.0 = 0xFF;
        self.reload(&*dict, now_us);
        self.pdo.load(&*dict);
        self.state = Some(NmtState::PreOperational);
        out(one_byte(id.error_control(), NmtState::BootUp.to_u8()));
        self.next_heartbeat_us = now_us.saturating_add(self.heartbeat_us);
        self.next_sync_us = now_us.saturating_add(self.sync_period_us);
    }

    /// Reads the parameters marked dirty again.
    fn reload<D: ObjectDictionary + ?Sized>(&mut self, dict: &D, now_us: u64) {
        let d = self.dirty.0;
        self.dirty.0 = 0;
        if d & Dirty::HEARTBEAT != 0 {
            self.heartbeat_us = u64::from(get_u16(dict, 0x1017, 0).unwrap_or(0)) * 1000;
            self.next_heartbeat_us = now_us.saturating_add(self.heartbeat_us);
        }
        if d & Dirty::CONSUMERS != 0 {
            let count = get_u8(dict, 0x1016, 0).unwrap_or(0);
            let mut fresh = [Consumer::default(); MAX_HB_CONSUMERS];
            for (c, sub) in fresh.iter_mut().zip(1..=count) {
                let v = get_u32(dict, 0x1016, sub).unwrap_or(0);
                let node = (v >> 16) as u8;
                // Node 0 or over 127, or time 0: the entry is not used (CiA 301 7.5.2.14).
                let used = (1..=127).contains(&node);
                let time_us = if used { u64::from(v & 0xFFFF) * 1000 } else { 0 };
                // An entry that did not change keeps watching.
                let old = self.consumers.iter().find(|o| o.node == node && o.time_us == time_us);
                *c = Consumer { node, time_us, last_us: old.and_then(|o| o.last_us) };
            }
            self.consumers = fresh;
        }
        if d & Dirty::GUARDING != 0 {
            let guard_ms = u64::from(get_u16(dict, 0x100C, 0).unwrap_or(0));
            let factor = u64::from(get_u8(dict, 0x100D, 0).unwrap_or(0));
            self.life_time_us = guard_ms * factor * 1000;
        }
        if d & Dirty::SYNC != 0 {
            let cob = get_u32(dict, 0x1005, 0).unwrap_or(0x80);
            let was_producer = self.sync_producer();
            self.sync_cob_id = cob;
            self.sync_period_us = u64::from(get_u32(dict, 0x1006, 0).unwrap_or(0));
            self.sync_overflow = get_u8(dict, 0x1019, 0).unwrap_or(0);
            if !was_producer && self.sync_producer() {
                self.sync_counter = 0;
                self.next_sync_us = now_us.saturating_add(self.sync_period_us);
            }
        }
        if d & Dirty::EMCY != 0 {
            self.emcy.load(dict);
        }
        if d & Dirty::PDO != 0 {
            self.pdo.load(dict);
        }
    }

    fn sync_producer(&self) -> bool {
        self.sync_cob_id & (1 << 30) != 0 && self.sync_period_us != 0
    }

    fn sync_id(&self) -> StdId {
        StdId::masked(self.sync_cob_id)
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
        View { dict, emcy, dirty, written: false, locked }
    }

    /// [`Node::handle`] once its sender keeps the frames it refuses.
    fn handle_in<D: ObjectDictionary + ?Sized>(
        &mut self,
        dict: &mut D,
        frame: &CanFrame,
        now_us: u64,
        out: &mut impl FnMut(CanFrame),
    ) -> Events {
        let mut ev = self.pending(dict, now_us, out);
        if frame.is_data(crate::lss::REQUEST_ID.raw()) {
            // LSS runs in every NMT state, and while a node without node-ID initialises.
            self.lss_in(frame, out, &mut ev);
            return ev;
        }
        let (Some(state), Some(id)) = (self.state, self.node_id) else { return ev };
        let own_ec = id.error_control();
        if frame.is_data(0) {
            self.nmt(frame, &mut ev);
            return ev;
        }
        if frame.remote && !frame.extended && frame.id == own_ec.raw() {
            // Node guarding: state and toggle bit, in every state (CiA 301 7.2.8.3.1).
            let byte = state.guarding_byte(self.toggle);
            self.toggle = !self.toggle;
            self.last_guard_us = Some(now_us);
            let was_lost = core::mem::replace(&mut self.guard_lost, false);
            out(one_byte(own_ec, byte));
            if was_lost {
                self.clear_heartbeat_error(now_us, out);
            }
            return ev;
        }
        if !frame.remote && !frame.extended && (0x701..=0x77F).contains(&frame.id) {
            let was_lost = self.lost != 0;
            self.heartbeat_in(frame, now_us, &mut ev);
            if was_lost {
                self.clear_heartbeat_error(now_us, out);
            }
            return ev;
        }
        if state == NmtState::Stopped {
            return ev;
        }
        if frame.is_data(self.sync_id().raw()) && self.sync_cob_id & (1 << 29) == 0 {
            let counter = frame.bytes().first().copied().filter(|_| self.sync_overflow > 1);
            self.sync_in(dict, counter, now_us, out, &mut ev);
            return ev;
        }
        if frame.is_data(self.sdo.request_id().raw()) {
            let mut view = Self::view(dict, &mut self.emcy, &mut self.dirty, &self.pdo, self.state);
            // A block upload's whole sub-block goes out at once.
            self.sdo.handle_into(&mut view, frame, now_us / 1000, out);
            ev.sdo_written = view.written;
            if self.dirty.0 != 0 {
                self.reload(&*dict, now_us);
            }
            return ev;
        }
        if state == NmtState::Operational {
            let mut view = Self::view(dict, &mut self.emcy, &mut self.dirty, &self.pdo, self.state);
            if let Some(o) = self.pdo.receive(&mut view, frame, now_us, out) {
                ev.merge(o);
                if let Some(code) = o.length_emcy {
                    self.emcy.raise(EmcyCode(code), [0; 5], true, now_us, out);
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
    fn clear_heartbeat_error(&mut self, now_us: u64, out: &mut impl FnMut(CanFrame)) {
        if self.lost == 0 && !self.guard_lost {
            self.clear_emcy_in(HEARTBEAT_ERROR, now_us, out);
        }
    }

    fn heartbeat_in(&mut self, frame: &CanFrame, now_us: u64, ev: &mut Events) {
        let node = (frame.id - 0x700) as u8;
        if frame.len != 1 {
            return;
        }
        for c in self.consumers.iter_mut().filter(|c| c.node == node && c.time_us != 0) {
            if c.last_us.is_none() || self.lost >> node & 1 == 1 {
                ev.heartbeat_started |= 1 << node;
            }
            c.last_us = Some(now_us);
            self.lost &= !(1u128 << node);
        }
    }

    fn sync_in<D: ObjectDictionary + ?Sized>(
        &mut self,
        dict: &mut D,
        counter: Option<u8>,
        now_us: u64,
        out: &mut impl FnMut(CanFrame),
        ev: &mut Events,
    ) {
        ev.sync = Some(counter);
        if self.state == Some(NmtState::Operational) {
            let mut view = Self::view(dict, &mut self.emcy, &mut self.dirty, &self.pdo, self.state);
            let o = self.pdo.sync(&mut view, counter, now_us, out);
            ev.merge(o);
        }
    }

    /// Runs a reset that `handle` reported.
    fn pending<D: ObjectDictionary + ?Sized>(
        &mut self,
        dict: &mut D,
        now_us: u64,
        out: &mut impl FnMut(CanFrame),
    ) -> Events {
        let mut ev = Events::default();
        if self.pending_reset.take().is_some() {
            self.start_in(dict, now_us, out);
            ev.state = self.state;
        }
        ev
    }

    /// [`Node::poll`] once its sender keeps the frames it refuses.
    fn poll_in<D: ObjectDictionary + ?Sized>(
        &mut self,
        dict: &mut D,
        now_us: u64,
        out: &mut impl FnMut(CanFrame),
    ) -> Events {
        let mut ev = self.pending(dict, now_us, out);
        let (Some(state), Some(id)) = (self.state, self.node_id) else { return ev };
        if self.dirty.0 != 0 {
            self.reload(&*dict, now_us);
        }
        if self.heartbeat_us != 0 && now_us >= self.next_heartbeat_us {
            out(one_byte(id.error_control(), state.to_u8()));
            // Keep the period; after a long gap (a stalled caller), start again from now.
            self.next_heartbeat_us =
                self.next_heartbeat_us.saturating_add(self.heartbeat_us).max(now_us);
        }
        for c in &self.consumers {
            if let Some(last) = c.last_us
                && c.time_us != 0
                && now_us > last.saturating_add(c.time_us)
                && self.lost >> c.node & 1 == 0
            {
                self.lost |= 1 << c.node;
                ev.heartbeat_lost |= 1 << c.node;
            }
        }
        if let Some(last) = self.last_guard_us
            && self.life_time_us != 0
            && !self.guard_lost
            && now_us > last.saturating_add(self.life_time_us)
        {
            self.guard_lost = true;
            ev.life_guarding_lost = true;
        }
        // A lost heartbeat or life guarding is EMCY 0x8130 (CiA 301 table 21, "life guard
        // error or heartbeat error"; CANopenNode's CO_EM_HEARTBEAT_CONSUMER), the node's
        // number in the first manufacturer byte (0 for life guarding); cleared when every
        // watched heartbeat is back.
        for node in (0..128u8).filter(|&n| ev.heartbeat_lost >> n & 1 == 1) {
            self.raise_emcy_in(HEARTBEAT_ERROR, [node, 0, 0, 0, 0], now_us, out);
        }
        if ev.life_guarding_lost {
            self.raise_emcy_in(HEARTBEAT_ERROR, [0; 5], now_us, out);
        }
        if state == NmtState::Stopped {
            return ev;
        }
        if self.sync_producer() && now_us >= self.next_sync_us {
            let counter = (self.sync_overflow > 1).then(|| {
                self.sync_counter =
                    if self.sync_counter >= self.sync_overflow { 1 } else { self.sync_counter + 1 };
                self.sync_counter
            });
            out(match counter {
                Some(c) => one_byte(self.sync_id(), c),
                None => CanFrame::standard_len(self.sync_id(), [0; 8], 0),
            });
            self.next_sync_us = self.next_sync_us.saturating_add(self.sync_period_us).max(now_us);
            let mut sync_ev = Events::default();
            self.sync_in(dict, counter, now_us, out, &mut sync_ev);
            ev.absorb(sync_ev);
        }
        self.emcy.poll(now_us, out);
        if state == NmtState::Operational {
            let view = Self::view(dict, &mut self.emcy, &mut self.dirty, &self.pdo, self.state);
            let o = self.pdo.poll(&view, now_us, out);
            ev.merge(o);
        }
        // Segments still due of a block upload's sub-block, or the abort of a transfer that
        // timed out (the abort ends the transfer, so this stops).
        while let Some(f) = self.sdo.poll(now_us / 1000) {
            out(f);
        }
        ev
    }

    /// The latest time the next [`Node::poll`] is due (µs), for a caller that sleeps: the
    /// heartbeat, the SYNC producer, a queued EMCY, TPDO timers, a consumer's or the life
    /// guarding's timeout. `None` when no timer runs.
    pub fn next_deadline(&self) -> Option<u64> {
        let hb = (self.heartbeat_us != 0).then_some(self.next_heartbeat_us);
        let sync = self.sync_producer().then_some(self.next_sync_us);
        let consumers = self
            .consumers
            .iter()
            .filter(|c| c.time_us != 0 && self.lost >> c.node & 1 == 0)
            .filter_map(|c| Some(c.last_us?.saturating_add(c.time_us) + 1))
            .min();
        let guard = self
            .last_guard_us
            .filter(|_| self.life_time_us != 0 && !self.guard_lost)
            .map(|l| l.saturating_add(self.life_time_us) + 1);
        let pdo =
            (self.state == Some(NmtState::Operational)).then(|| self.pdo.next_deadline()).flatten();
        [hb, sync, consumers, guard, pdo, self.emcy.next_deadline()].into_iter().flatten().min()
    }

    /// [`Node::raise_emcy`] once its sender keeps the frames it refuses.
    fn raise_emcy_in(
        &mut self,
        code: EmcyCode,
        manufacturer: [u8; 5],
        now_us: u64,
        out: &mut impl FnMut(CanFrame),
    ) {
        let send = matches!(self.state, Some(NmtState::Operational | NmtState::PreOperational));
        self.emcy.raise(code, manufacturer, send, now_us, out);
    }

    /// [`Node::clear_emcy`] once its sender keeps the frames it refuses.
    fn clear_emcy_in(
        &mut self,
        code: EmcyCode,
        now_us: u64,
        out: &mut impl FnMut(CanFrame),
    ) -> bool {
        let send = matches!(self.state, Some(NmtState::Operational | NmtState::PreOperational));
        self.emcy.clear(code, send, now_us, out)
    }

    /// Asks for TPDO `n` (1-based) to be sent: at once (after its inhibit time) for an
    /// event-driven TPDO at the next [`Node::poll`], at the next SYNC for type 0. Returns
    /// `false` for a PDO number the node does not serve.
    pub fn trigger_tpdo(&mut self, n: u16) -> bool {
        self.pdo.trigger(n)
    }

    /// The parameters were changed by the application, not over SDO: read them all again.
    pub fn reload_parameters<D: ObjectDictionary + ?Sized>(&mut self, dict: &D, now_us: u64) {
        self.dirty.0 = 0xFF;
        self.reload(dict, now_us);
    }
}
