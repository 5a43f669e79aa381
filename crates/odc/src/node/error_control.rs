//! Error control of a [`Node`](super::Node) (CiA 301 7.2.8.3): the heartbeat producer
//! (0x1017), the heartbeat consumers (0x1016) and, with the feature `guarding`, node guarding
//! and life guarding (0x100C, 0x100D).

use super::params::{get_u8, get_u16, get_u32};
use super::{Events, MAX_HB_CONSUMERS};
use crate::can::{CanFrame, StdId};
use crate::nmt::NmtState;
use crate::slave::ObjectDictionary;
use crate::time::{Duration, Instant};

/// Bit `node` (0–127) of a set of nodes, as [`Events::heartbeat_lost`] holds them. Not
/// inlined: a variable shift of a `u128` is about 40 bytes of Thumb code at every use.
#[inline(never)]
pub(super) fn node_bit(node: u8) -> u128 {
    1u128 << (node & 0x7F)
}

/// Whether `node` is in `set`.
#[inline(never)]
pub(super) fn has_node(set: u128, node: u8) -> bool {
    set & node_bit(node) != 0
}

// `ErrorControl::poll` reports lost consumers as the bits of a `u8`.
const _: () = assert!(MAX_HB_CONSUMERS <= 8);

#[derive(Clone, Copy, Debug, Default)]
struct Consumer {
    node: u8,
    time: Duration,
    /// When its last heartbeat came; `None` until the first (watching starts then).
    last: Option<Instant>,
}

/// Node guarding: the answer's toggle bit and the life time the master's requests keep.
#[cfg(feature = "guarding")]
#[derive(Clone, Copy, Debug)]
struct Guarding {
    toggle: bool,
    life_time: Duration,
    last: Option<Instant>,
    lost: bool,
}

/// The heartbeat producer and consumers and node guarding of one node.
#[derive(Clone, Debug)]
pub(super) struct ErrorControl {
    heartbeat: Duration,
    next_heartbeat: Instant,
    consumers: [Consumer; MAX_HB_CONSUMERS],
    /// Bit n: the heartbeat of node n is lost.
    lost: u128,
    #[cfg(feature = "guarding")]
    guarding: Guarding,
}

impl ErrorControl {
    pub(super) const fn new() -> Self {
        Self {
            heartbeat: Duration::ZERO,
            next_heartbeat: Instant::ZERO,
            consumers: [Consumer { node: 0, time: Duration::ZERO, last: None }; MAX_HB_CONSUMERS],
            lost: 0,
            #[cfg(feature = "guarding")]
            guarding: Guarding {
                toggle: false,
                life_time: Duration::ZERO,
                last: None,
                lost: false,
            },
        }
    }

    /// Back to [`ErrorControl::new`], in place.
    pub(super) fn reset(&mut self) {
        self.heartbeat = Duration::ZERO;
        self.next_heartbeat = Instant::ZERO;
        self.consumers = [Consumer::default(); MAX_HB_CONSUMERS];
        self.lost = 0;
        #[cfg(feature = "guarding")]
        {
            self.guarding =
                Guarding { toggle: false, life_time: Duration::ZERO, last: None, lost: false };
        }
    }

    /// The first heartbeat is one period after the boot-up.
    pub(super) fn start(&mut self, now: Instant) {
        self.next_heartbeat = now.saturating_add(self.heartbeat);
    }

    /// Reads the producer heartbeat time (0x1017, ms) again; the period restarts now.
    pub(super) fn load_heartbeat<D: ObjectDictionary + ?Sized>(&mut self, dict: &D, now: Instant) {
        self.heartbeat = Duration::from_millis(u64::from(get_u16(dict, 0x1017, 0).unwrap_or(0)));
        self.next_heartbeat = now.saturating_add(self.heartbeat);
    }

    /// Reads the consumer heartbeat times (0x1016) again; entries that did not change keep
    /// watching.
    pub(super) fn load_consumers<D: ObjectDictionary + ?Sized>(&mut self, dict: &D) {
        let count = get_u8(dict, 0x1016, 0).unwrap_or(0);
        let mut fresh = [Consumer::default(); MAX_HB_CONSUMERS];
        for (c, sub) in fresh.iter_mut().zip(1..=count) {
            let v = get_u32(dict, 0x1016, sub).unwrap_or(0);
            let node = (v >> 16) as u8;
            // Node 0 or over 127, or time 0: the entry is not used (CiA 301 7.5.2.14).
            let used = (1..=127).contains(&node);
            let time =
                if used { Duration::from_millis(u64::from(v & 0xFFFF)) } else { Duration::ZERO };
            let old = self.consumers.iter().find(|o| o.node == node && o.time == time);
            *c = Consumer { node, time, last: old.and_then(|o| o.last) };
        }
        self.consumers = fresh;
    }

    /// Reads guard time (0x100C, ms) × life time factor (0x100D) again.
    #[cfg_attr(not(feature = "guarding"), allow(clippy::unused_self, unused_variables))]
    pub(super) fn load_guarding<D: ObjectDictionary + ?Sized>(&mut self, dict: &D) {
        #[cfg(feature = "guarding")]
        {
            let guard_ms = u64::from(get_u16(dict, 0x100C, 0).unwrap_or(0));
            let factor = u64::from(get_u8(dict, 0x100D, 0).unwrap_or(0));
            self.guarding.life_time = Duration::from_millis(guard_ms * factor);
        }
    }

    /// A node-guarding request (RTR on 0x700 + node-ID): the answer, state and toggle bit, in
    /// every state (CiA 301 7.2.8.3.1), and whether life guarding was lost until now.
    #[cfg(feature = "guarding")]
    pub(super) fn guard_request(&mut self, state: NmtState, now: Instant) -> (u8, bool) {
        let g = &mut self.guarding;
        let byte = state.guarding_byte(g.toggle);
        g.toggle = !g.toggle;
        g.last = Some(now);
        (byte, core::mem::replace(&mut g.lost, false))
    }

    /// Whether a watched heartbeat or the life guarding is lost (EMCY 0x8130 active).
    pub(super) fn any_lost(&self) -> bool {
        #[cfg(feature = "guarding")]
        if self.guarding.lost {
            return true;
        }
        self.lost != 0
    }

    /// A heartbeat of another node (0x701–0x77F, one byte).
    pub(super) fn heartbeat_in(&mut self, frame: &CanFrame, now: Instant, ev: &mut Events) {
        let node = (frame.id & 0x7F) as u8;
        if frame.len != 1 {
            return;
        }
        for c in self.consumers.iter_mut().filter(|c| c.node == node && !c.time.is_zero()) {
            if c.last.is_none() || has_node(self.lost, node) {
                ev.heartbeat_started |= node_bit(node);
            }
            c.last = Some(now);
            self.lost &= !node_bit(node);
        }
    }

    /// The heartbeat, when due (`state` in it), and the timeouts of the consumers and of
    /// life guarding, reported in `ev`. Returns the consumers (bit n: `consumers[n]`) whose
    /// node was lost now, one bit per node, for the node's EMCY: a loop over them is shorter
    /// than one over the bits of a `u128` on a 32-bit core.
    pub(super) fn poll(
        &mut self,
        own_id: StdId,
        state: NmtState,
        now: Instant,
        out: &mut impl FnMut(CanFrame),
        ev: &mut Events,
    ) -> u8 {
        let mut newly = 0;
        if !self.heartbeat.is_zero() && now >= self.next_heartbeat {
            out(super::one_byte(own_id, state.to_u8()));
            // Keep the period; after a long gap (a stalled caller), start again from now.
            self.next_heartbeat = self.next_heartbeat.saturating_add(self.heartbeat).max(now);
        }
        for (i, c) in self.consumers.iter().enumerate() {
            if let Some(last) = c.last
                && !c.time.is_zero()
                && now > last.saturating_add(c.time)
                && !has_node(self.lost, c.node)
            {
                self.lost |= node_bit(c.node);
                ev.heartbeat_lost |= node_bit(c.node);
                newly |= 1 << i;
            }
        }
        #[cfg(feature = "guarding")]
        if let Some(last) = self.guarding.last
            && !self.guarding.life_time.is_zero()
            && !self.guarding.lost
            && now > last.saturating_add(self.guarding.life_time)
        {
            self.guarding.lost = true;
            ev.life_guarding_lost = true;
        }
        newly
    }

    /// The node that consumer `i` watches (0 for none).
    pub(super) fn consumer_node(&self, i: usize) -> u8 {
        self.consumers.get(i).map_or(0, |c| c.node)
    }

    /// The next heartbeat, or the first timeout of a consumer or of life guarding.
    pub(super) fn next_deadline(&self) -> Option<Instant> {
        let hb = (!self.heartbeat.is_zero()).then_some(self.next_heartbeat);
        let consumers = self
            .consumers
            .iter()
            .filter(|c| !c.time.is_zero() && !has_node(self.lost, c.node))
            .filter_map(|c| Some(c.last?.saturating_add(c.time) + Duration::MICROSECOND))
            .min();
        #[cfg(feature = "guarding")]
        let guard = self
            .guarding
            .last
            .filter(|_| !self.guarding.life_time.is_zero() && !self.guarding.lost)
            .map(|l| l.saturating_add(self.guarding.life_time) + Duration::MICROSECOND);
        #[cfg(not(feature = "guarding"))]
        let guard = None;
        [hb, consumers, guard].into_iter().flatten().min()
    }
}
