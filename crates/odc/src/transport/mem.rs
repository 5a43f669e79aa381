//! An in-memory CAN bus: several ports on one bus, every frame sent by one port reaches all
//! the others (not the sender, as on a real bus where a controller does not receive its own
//! frames). For tests and simulation: a node and a master in one process, or several nodes.
//!
//! ```
//! use odc::can::CanFrame;
//! use odc::transport::{Bus, mem::MemBus};
//!
//! let bus = MemBus::new();
//! let (mut a, mut b, mut c) = (bus.port(), bus.port(), bus.port());
//! a.send(&CanFrame::from_slice(0x701, &[0]).unwrap())?;
//! let now = b.now();
//! assert_eq!(b.recv(now)?.map(|f| f.id()), Some(0x701));
//! assert_eq!(c.try_recv()?.map(|f| f.id()), Some(0x701));
//! assert_eq!(a.try_recv()?, None); // not to the sender
//! # Ok::<(), odc::transport::mem::Closed>(())
//! ```

use std::collections::VecDeque;
use std::sync::{Arc, Condvar, Mutex, MutexGuard, PoisonError};
use std::time::Instant as StdInstant;
use std::vec::Vec;

use super::Bus;
use crate::can::CanFrame;
use crate::time::Instant;

/// The bus can no longer be used: a thread panicked while it held the bus.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Closed;

impl core::fmt::Display for Closed {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        f.write_str("the in-memory CAN bus is poisoned")
    }
}

impl core::error::Error for Closed {}

impl<T> From<PoisonError<T>> for Closed {
    fn from(_: PoisonError<T>) -> Self {
        Closed
    }
}

#[derive(Debug, Default)]
struct Shared {
    /// One receive queue per port, by port number; `None` once the port was dropped.
    queues: Vec<Option<VecDeque<CanFrame>>>,
}

#[derive(Debug)]
struct Inner {
    shared: Mutex<Shared>,
    arrived: Condvar,
    start: StdInstant,
}

/// The bus: makes ports. Cloning it gives another handle on the same bus.
#[derive(Clone, Debug)]
pub struct MemBus(Arc<Inner>);

impl Default for MemBus {
    fn default() -> Self {
        Self::new()
    }
}

impl MemBus {
    /// An empty bus; its clock (`now` of every port) starts now.
    pub fn new() -> Self {
        Self(Arc::new(Inner {
            shared: Mutex::new(Shared::default()),
            arrived: Condvar::new(),
            start: StdInstant::now(),
        }))
    }

    /// A new port: it receives every frame sent by another port from now on.
    pub fn port(&self) -> MemPort {
        let mut s = self.0.shared.lock().unwrap_or_else(PoisonError::into_inner);
        s.queues.push(Some(VecDeque::new()));
        MemPort { bus: self.0.clone(), me: s.queues.len() - 1 }
    }
}

/// One port of a [`MemBus`]: a [`Bus`] whose frames reach every other port.
#[derive(Debug)]
pub struct MemPort {
    bus: Arc<Inner>,
    me: usize,
}

impl MemPort {
    fn lock(&self) -> Result<MutexGuard<'_, Shared>, Closed> {
        Ok(self.bus.shared.lock()?)
    }

    /// The next received frame if one is waiting, without waiting.
    ///
    /// # Errors
    ///
    /// [`Closed`] when the bus is poisoned.
    pub fn try_recv(&mut self) -> Result<Option<CanFrame>, Closed> {
        let mut s = self.lock()?;
        Ok(s.queues.get_mut(self.me).and_then(Option::as_mut).and_then(VecDeque::pop_front))
    }

    fn elapsed(&self) -> Instant {
        Instant::since(self.bus.start)
    }
}

impl Drop for MemPort {
    fn drop(&mut self) {
        let mut s = self.bus.shared.lock().unwrap_or_else(PoisonError::into_inner);
        if let Some(q) = s.queues.get_mut(self.me) {
            *q = None;
        }
    }
}

impl Bus for MemPort {
    type Error = Closed;

    fn send(&mut self, frame: &CanFrame) -> Result<(), Closed> {
        let mut s = self.lock()?;
        for (i, q) in s.queues.iter_mut().enumerate() {
            if let (true, Some(q)) = (i != self.me, q) {
                q.push_back(*frame);
            }
        }
        drop(s);
        self.bus.arrived.notify_all();
        Ok(())
    }

    fn recv(&mut self, deadline: Instant) -> Result<Option<CanFrame>, Closed> {
        let mut s = self.lock()?;
        loop {
            if let Some(f) =
                s.queues.get_mut(self.me).and_then(Option::as_mut).and_then(VecDeque::pop_front)
            {
                return Ok(Some(f));
            }
            let now = self.elapsed();
            if now >= deadline {
                return Ok(None);
            }
            s = self.bus.arrived.wait_timeout(s, (deadline - now).into())?.0;
        }
    }

    fn now(&mut self) -> Instant {
        self.elapsed()
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::time::Duration;

    #[test]
    fn every_other_port_receives() {
        let bus = MemBus::new();
        let mut ports: Vec<MemPort> = (0..4).map(|_| bus.port()).collect();
        let f = CanFrame::from_slice(0x181, &[1, 2]).unwrap();
        ports[1].send(&f).unwrap();
        for (i, p) in ports.iter_mut().enumerate() {
            let got = p.try_recv().unwrap();
            assert_eq!(got, (i != 1).then_some(f), "port {i}");
            assert_eq!(p.try_recv().unwrap(), None);
        }
        // A dropped port no longer queues.
        let dropped = ports.pop();
        drop(dropped);
        ports[0].send(&f).unwrap();
        assert_eq!(ports[2].try_recv().unwrap(), Some(f));
    }

    #[test]
    fn recv_waits_for_another_thread_and_times_out() {
        let bus = MemBus::new();
        let mut rx = bus.port();
        let mut tx = bus.port();
        let t = std::thread::spawn(move || {
            std::thread::sleep(std::time::Duration::from_millis(20));
            tx.send(&CanFrame::remote(0x705, 1).unwrap()).unwrap();
        });
        let start = rx.now();
        let got = rx.recv(start + Duration::from_secs(2)).unwrap();
        assert_eq!(got, Some(CanFrame::remote(0x705, 1).unwrap()));
        t.join().unwrap();
        let before = rx.now();
        assert_eq!(rx.recv(before + Duration::from_millis(30)).unwrap(), None);
        assert!(rx.now() >= before + Duration::from_millis(30));
    }
}
