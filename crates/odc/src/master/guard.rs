//! Node guarding from the master's side (CiA 301 7.2.8.3.1): a remote frame on 0x700 +
//! node-ID every guard time, the answer's toggle bit checked, and a life-guarding loss when
//! no valid answer comes within guard time × life time factor. For devices without heartbeat
//! (the MDrive and Lenze manuals describe guarding from this side).

use std::vec::Vec;

use super::{Error, Event, Master};
use crate::can::CanFrame;
use crate::cob::NodeId;
use crate::nmt::NmtState;
use crate::time::{Duration, Instant};
use crate::transport::Bus;

/// What the master's guarding of one node has seen so far.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct GuardStatus {
    /// Remote frames sent.
    pub requests: u32,
    /// Answers with the toggle bit expected (the first answer after [`Master::guard`] or a
    /// boot-up sets where the toggle starts: 0 after a boot-up, CiA 301 7.2.8.3.1).
    pub answers: u32,
    /// Answers whose toggle bit was not the expected one: not counted as answers, they do not
    /// keep the node alive.
    pub toggle_errors: u32,
    /// The state the last valid answer reported.
    pub state: Option<NmtState>,
    /// Whether the node is lost now (no valid answer within the life time).
    pub lost: bool,
}

/// One guarded node.
#[derive(Clone, Copy, Debug)]
pub(super) struct Guard {
    guard_time: Duration,
    life_time: Duration,
    next_rtr: Instant,
    /// Remote frames sent and not yet answered (more than one when answers come late).
    outstanding: u32,
    /// The toggle bit of the next answer, once known.
    expect: Option<bool>,
    last_valid: Instant,
    status: GuardStatus,
}

impl<B: Bus> Master<B> {
    /// Guards `node`: [`Master::poll`] sends a remote frame on 0x700 + node-ID every
    /// `guard_time`, checks the answers' toggle bit, and gives [`Event::GuardingLost`] once
    /// when no valid answer came for `guard_time × life_time_factor` (until one comes
    /// again). The device's own 0x100C/0x100D are the application's to write (the node
    /// watches the master with them).
    ///
    /// # Errors
    ///
    /// [`Error::Invalid`] for a guard time or life time factor of 0 (guarding off in CiA 301:
    /// call [`Master::unguard`]).
    pub fn guard(
        &mut self,
        node: NodeId,
        guard_time: Duration,
        life_time_factor: u8,
    ) -> Result<(), Error<B::Error>> {
        if guard_time.is_zero() || life_time_factor == 0 {
            return Err(Error::Invalid("guard time and life time factor must not be 0"));
        }
        let now = self.now();
        self.guards.insert(
            node,
            Guard {
                guard_time,
                life_time: guard_time.saturating_mul(u64::from(life_time_factor)),
                next_rtr: now,
                outstanding: 0,
                expect: None,
                last_valid: now,
                status: GuardStatus::default(),
            },
        );
        Ok(())
    }

    /// Stops guarding `node` (the node then loses life guarding, if it watches it).
    pub fn unguard(&mut self, node: NodeId) {
        self.guards.remove(&node);
    }

    /// What guarding `node` has seen, while it is guarded.
    pub fn guarding(&self, node: NodeId) -> Option<GuardStatus> {
        self.guards.get(&node).map(|g| g.status)
    }

    /// A frame on 0x700 + node-ID of a guarded node: a boot-up restarts the toggle at 0; a
    /// one-byte answer to an outstanding request is checked. Returns whether it was a guarding
    /// answer (the caller still records the state it reports).
    pub(super) fn guard_answer(&mut self, node: NodeId, f: &CanFrame, now: Instant) -> bool {
        let Some(g) = self.guards.get_mut(&node) else { return false };
        let [byte] = f.bytes() else { return false };
        if *byte == 0 {
            g.expect = Some(false);
            g.outstanding = 0;
            return false;
        }
        if g.outstanding == 0 {
            // A heartbeat of a node that also beats: not an answer.
            return false;
        }
        g.outstanding -= 1;
        let toggle = byte & 0x80 != 0;
        if g.expect.is_some_and(|t| t != toggle) {
            g.status.toggle_errors += 1;
            return true;
        }
        g.expect = Some(!toggle);
        g.last_valid = now;
        g.status.answers += 1;
        g.status.state = NmtState::from_u8(*byte);
        g.status.lost = false;
        true
    }

    /// Sends the remote frames that fall due and reports a node whose life time ran out.
    pub(super) fn guard_due(&mut self, now: Instant) -> Result<Option<Event>, Error<B::Error>> {
        let mut due = Vec::new();
        let mut lost = None;
        for (node, g) in &mut self.guards {
            if lost.is_none() && !g.status.lost && now > g.last_valid.saturating_add(g.life_time) {
                g.status.lost = true;
                lost = Some(*node);
            }
            if now >= g.next_rtr {
                g.next_rtr = g
                    .next_rtr
                    .saturating_add(g.guard_time)
                    .max(now.saturating_add(Duration::from_micros(1)));
                // An answer older than the life time will not come: at most that many wait.
                let most = u32::try_from(g.life_time.as_micros() / g.guard_time.as_micros())
                    .unwrap_or(u32::MAX);
                g.outstanding = (g.outstanding + 1).min(most.max(1));
                g.status.requests += 1;
                due.push(*node);
            }
        }
        for node in due {
            let rtr = CanFrame::remote(node.error_control().raw(), 1)
                .ok_or(Error::Invalid("a node-ID outside 1..=127"))?;
            self.send(&rtr)?;
        }
        Ok(lost.map(|node| Event::GuardingLost { node }))
    }

    /// The next time guarding needs [`Master::poll`]: a request or a life time's end.
    pub(super) fn next_guard_deadline(&self) -> Option<Instant> {
        self.guards
            .values()
            .flat_map(|g| {
                let end = g.last_valid.saturating_add(g.life_time);
                let life = (!g.status.lost).then(|| end.saturating_add(Duration::from_micros(1)));
                [Some(g.next_rtr), life]
            })
            .flatten()
            .min()
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::transport::mem::MemBus;

    const NODE: NodeId = crate::node_id!(5);

    /// A device that answers every RTR on 0x705 with `answer(n)` for the n-th request.
    fn run(answer: impl Fn(u32) -> Option<u8>, until_ms: u64) -> (Vec<Event>, GuardStatus) {
        let bus = MemBus::new();
        let (mut device, port) = (bus.port(), bus.port());
        let mut master = Master::new(port);
        master.guard(NODE, Duration::from_millis(20), 3).unwrap();
        let start = master.now();
        let mut events = Vec::new();
        let mut n = 0;
        while master.now() < start + Duration::from_millis(until_ms) {
            let deadline = master.now() + Duration::from_millis(5);
            if let Some(e) = master.poll(deadline).unwrap() {
                events.push(e);
            }
            while let Some(f) = device.recv(Instant::from_micros(0)).unwrap() {
                if f.is_remote() && f.id() == 0x705 {
                    if let Some(b) = answer(n) {
                        device.send(&CanFrame::from_slice(0x705, &[b]).unwrap()).unwrap();
                    }
                    n += 1;
                }
            }
        }
        (events, master.guarding(NODE).unwrap())
    }

    #[test]
    fn toggling_answers_keep_the_node() {
        let (events, status) = run(|n| Some(0x7F | if n % 2 == 1 { 0x80 } else { 0 }), 200);
        assert!(!events.iter().any(|e| matches!(e, Event::GuardingLost { .. })), "{events:?}");
        assert!(status.requests >= 8 && status.answers + 1 >= status.requests, "{status:?}");
        assert_eq!(status.toggle_errors, 0);
        assert_eq!(status.state, Some(NmtState::PreOperational));
    }

    #[test]
    fn a_stuck_toggle_is_an_error_and_loses_the_node() {
        let (events, status) = run(|_| Some(0x05), 200);
        assert!(status.toggle_errors >= 5, "{status:?}");
        assert_eq!(status.answers, 1, "only the first answer counts");
        assert!(events.contains(&Event::GuardingLost { node: NODE }), "{events:?}");
        assert!(status.lost);
    }

    #[test]
    fn silence_is_lost_once() {
        let (events, status) = run(|_| None, 200);
        let lost = events.iter().filter(|e| **e == Event::GuardingLost { node: NODE }).count();
        assert_eq!(lost, 1, "{events:?}");
        assert_eq!(status.answers, 0);
    }

    #[test]
    fn late_answers_keep_their_toggle() {
        // Each answer comes one request late: the first request is not answered at once, so
        // two are outstanding when answers start; the toggle still alternates.
        let bus = MemBus::new();
        let (mut device, port) = (bus.port(), bus.port());
        let mut master = Master::new(port);
        master.guard(NODE, Duration::from_millis(20), 3).unwrap();
        let start = master.now();
        let mut n = 0u32;
        let mut pending = false;
        while master.now() < start + Duration::from_millis(200) {
            let deadline = master.now() + Duration::from_millis(5);
            let _ = master.poll(deadline).unwrap();
            while let Some(f) = device.recv(Instant::from_micros(0)).unwrap() {
                if f.is_remote() {
                    if pending {
                        let b = 0x7F | if n % 2 == 1 { 0x80 } else { 0 };
                        device.send(&CanFrame::from_slice(0x705, &[b]).unwrap()).unwrap();
                        n += 1;
                    }
                    pending = true;
                }
            }
        }
        let st = master.guarding(NODE).unwrap();
        assert_eq!(st.toggle_errors, 0, "{st:?}");
        assert!(st.answers >= 7 && !st.lost, "{st:?}");
    }

    #[test]
    fn zero_guard_time_is_refused() {
        let mut master = Master::new(MemBus::new().port());
        assert!(matches!(master.guard(NODE, Duration::from_millis(0), 3), Err(Error::Invalid(_))));
        assert!(matches!(master.guard(NODE, Duration::from_millis(10), 0), Err(Error::Invalid(_))));
    }
}
