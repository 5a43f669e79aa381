//! NMT master, heartbeat consumer, the events of the bus and the SYNC producer.

use super::{Error, Event, Master, SyncProducer, Waited, frame};
use crate::can::CanFrame;
use crate::cob::{CobId, NodeId};
use crate::emcy::EmcyFrame;
use crate::nmt::{NmtCommand, NmtState};
use crate::time::{Duration, Instant};
use crate::transport::Bus;

impl<B: Bus> Master<B> {
    // ---- NMT -----------------------------------------------------------------------------

    /// An NMT command to `node`.
    ///
    /// # Errors
    ///
    /// The bus error.
    pub fn nmt(&mut self, command: NmtCommand, node: NodeId) -> Result<(), Error<B::Error>> {
        self.send(&frame(0, &command.frame(Some(node)))?)
    }

    /// An NMT command to every node (node-ID byte 0).
    ///
    /// # Errors
    ///
    /// The bus error.
    pub fn nmt_all(&mut self, command: NmtCommand) -> Result<(), Error<B::Error>> {
        self.send(&frame(0, &command.frame(None))?)
    }

    /// The state `node` last reported (boot-up counts as pre-operational); `None` before it
    /// said anything.
    pub fn state(&self, node: NodeId) -> Option<NmtState> {
        self.nodes.get(&node).and_then(|w| w.state)
    }

    /// Consumes `node`'s heartbeat: when none comes for `timeout`, [`Master::poll`] gives
    /// [`Event::HeartbeatLost`] once, until it comes back.
    pub fn watch_heartbeat(&mut self, node: NodeId, timeout: Duration) {
        let now = self.now();
        let w = self.nodes.entry(node).or_default();
        w.timeout = Some(timeout);
        w.last_seen = now;
        w.lost = false;
    }

    /// Waits for `node`'s boot-up message.
    ///
    /// # Errors
    ///
    /// [`Error::Timeout`] when none comes in time, or the bus error.
    pub fn wait_boot_up(&mut self, node: NodeId) -> Result<(), Error<B::Error>> {
        let id = node.error_control().raw();
        let since = self.now();
        let deadline = since + self.timeout;
        let boot = |f: &CanFrame| f.is_data(id) && f.bytes() == [0];
        match self.link.take(deadline, boot).map_err(Error::Bus)? {
            Some(f) => {
                self.note(&f);
                Ok(())
            }
            None => Err(self.timeout_error(Some(node), Waited::BootUp, since)),
        }
    }

    /// Waits until `node` reports `state` (by heartbeat); the frames in between are kept.
    ///
    /// # Errors
    ///
    /// [`Error::Timeout`], or the bus error.
    pub fn wait_state(&mut self, node: NodeId, state: NmtState) -> Result<(), Error<B::Error>> {
        let id = node.error_control().raw();
        let since = self.now();
        let deadline = since + self.timeout;
        let want = |f: &CanFrame| {
            f.is_data(id) && f.bytes().first().and_then(|b| NmtState::from_u8(*b)) == Some(state)
        };
        match self.link.take(deadline, want).map_err(Error::Bus)? {
            Some(f) => {
                self.note(&f);
                Ok(())
            }
            None => {
                // The heartbeats seen meanwhile (queued) still tell the node's last state.
                let pending: std::vec::Vec<CanFrame> = self.link.pending.iter().copied().collect();
                for f in pending.iter().filter(|f| f.is_data(id)) {
                    if let Some(s) = f.bytes().first().and_then(|b| NmtState::from_u8(*b))
                        && s != NmtState::BootUp
                    {
                        self.nodes.entry(node).or_default().state = Some(s);
                    }
                }
                Err(self.timeout_error(Some(node), Waited::State(state), since))
            }
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
        let now = self.link.bus.now();
        let event = match id {
            0x080 => Event::Sync { counter: f.bytes().first().copied() },
            0x081..=0x0FF => match (NodeId::of_emcy(id), EmcyFrame::decode(f.bytes())) {
                (Some(node), Ok(emcy)) => Event::Emcy { node, emcy },
                _ => Event::Other(*f),
            },
            0x181..=0x57F => Event::Pdo { cob_id: CobId::of_frame(f), frame: *f },
            0x701..=0x77F => {
                let Some(node) = NodeId::of_error_control(id) else {
                    return Some(Event::Other(*f));
                };
                let Some(state) = f.bytes().first().and_then(|b| NmtState::from_u8(*b)) else {
                    return Some(Event::Other(*f));
                };
                self.guard_answer(node, f, now);
                let w = self.nodes.entry(node).or_default();
                w.last_seen = now;
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

    /// The next event, waiting until `deadline` at the latest: queued frames first, then
    /// lost heartbeats, then the bus. Also sends the SYNCs that fall due meanwhile. Repeated
    /// heartbeats of an unchanged state are not events (they update the node's watch).
    ///
    /// # Errors
    ///
    /// The bus error.
    pub fn poll(&mut self, deadline: Instant) -> Result<Option<Event>, Error<B::Error>> {
        loop {
            if let Some(f) = self.link.pending.pop_front() {
                match self.note(&f) {
                    Some(event) => return Ok(Some(event)),
                    None => continue,
                }
            }
            let now = self.now();
            if let Some(node) = self.lost_node(now) {
                return Ok(Some(Event::HeartbeatLost { node }));
            }
            if let Some(event) = self.guard_due(now)? {
                return Ok(Some(event));
            }
            self.sync_due(now)?;
            if now >= deadline {
                return Ok(None);
            }
            // Wake for the next SYNC or heartbeat deadline, whichever is first.
            let wake = [
                self.sync.map(|s| s.next),
                self.next_heartbeat_deadline(),
                self.next_guard_deadline(),
            ]
            .into_iter()
            .flatten()
            .fold(deadline, Instant::min);
            if let Some(f) = self.link.receive(wake.max(now)).map_err(Error::Bus)? {
                self.link.pending.push_back(f);
            }
        }
    }

    fn lost_node(&mut self, now: Instant) -> Option<NodeId> {
        for (node, w) in &mut self.nodes {
            if let Some(t) = w.timeout
                && !w.lost
                && now > w.last_seen + t
            {
                w.lost = true;
                return Some(*node);
            }
        }
        None
    }

    fn next_heartbeat_deadline(&self) -> Option<Instant> {
        self.nodes
            .values()
            .filter(|w| !w.lost)
            .filter_map(|w| w.timeout.map(|t| w.last_seen + t + Duration::MICROSECOND))
            .min()
    }

    fn sync_due(&mut self, now: Instant) -> Result<(), Error<B::Error>> {
        if let Some(s) = self.sync
            && now >= s.next
        {
            // One SYNC per call, on the period's grid (a late poll does not send a burst).
            let next = (s.next + s.period).max(now + Duration::MICROSECOND);
            self.sync = Some(SyncProducer { period: s.period, next });
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

    /// Makes [`Master::poll`] send a SYNC every `period` (none with `None` or zero).
    pub fn set_sync_period(&mut self, period: Option<Duration>) {
        let now = self.now();
        self.sync = period
            .filter(|p| !p.is_zero())
            .map(|period| SyncProducer { period, next: now + period });
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
}
