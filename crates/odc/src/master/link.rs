//! The master's bus: frames not yet handed out are queued, every frame is shown to an
//! observer, and the SDO client sees only its responses.

use std::boxed::Box;
use std::collections::{BTreeMap, VecDeque};

use crate::can::CanFrame;
use crate::cob::{self, Function, NodeId};
use crate::time::Instant;
use crate::transport::Bus;

/// Which way a frame went, for an observer.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Dir {
    /// Sent by the master.
    Sent,
    /// Received from the bus.
    Received,
}

pub(super) type Observer = Box<dyn FnMut(Dir, &CanFrame) + Send>;

/// The bus with the frames not yet handed out, and an observer of every frame.
pub(super) struct Link<B> {
    pub(super) bus: B,
    pub(super) pending: VecDeque<CanFrame>,
    pub(super) observer: Option<Observer>,
    /// The SDO response CAN-ID the current transfer waits for.
    pub(super) sdo_response: Option<u32>,
    /// When each node was last heard: any frame it sends (boot-up, heartbeat, EMCY, TPDO,
    /// SDO response), so a timeout can tell a silent node from an absent one.
    pub(super) heard: BTreeMap<NodeId, Instant>,
}

/// The node that sent `frame`, by CiA 301's predefined connection set: only the functions a
/// node transmits (a request to it is no sign of life).
fn sender(frame: &CanFrame) -> Option<NodeId> {
    if frame.is_extended() || frame.is_remote() {
        return None;
    }
    match cob::classify(u16::try_from(frame.id()).ok()?)? {
        (Function::Emcy | Function::Tpdo(_) | Function::SdoTx | Function::Heartbeat, node) => node,
        _ => None,
    }
}

impl<B: Bus> Link<B> {
    pub(super) fn send(&mut self, frame: &CanFrame) -> Result<(), B::Error> {
        if let Some(o) = &mut self.observer {
            o(Dir::Sent, frame);
        }
        self.bus.send(frame)
    }

    /// The next frame from the bus (not the queue), waiting until `deadline`.
    pub(super) fn receive(&mut self, deadline: Instant) -> Result<Option<CanFrame>, B::Error> {
        let frame = self.bus.recv(deadline)?;
        if let Some(f) = &frame {
            if let Some(node) = sender(f) {
                let now = self.bus.now();
                self.heard.insert(node, now);
            }
            if let Some(o) = &mut self.observer {
                o(Dir::Received, f);
            }
        }
        Ok(frame)
    }

    /// The first frame (queued first) that `want` accepts, waiting until `deadline`; the
    /// others received meanwhile are queued.
    pub(super) fn take(
        &mut self,
        deadline: Instant,
        want: impl Fn(&CanFrame) -> bool,
    ) -> Result<Option<CanFrame>, B::Error> {
        if let Some(pos) = self.pending.iter().position(&want) {
            return Ok(self.pending.remove(pos));
        }
        loop {
            match self.receive(deadline)? {
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

    fn recv(&mut self, deadline: Instant) -> Result<Option<CanFrame>, B::Error> {
        let id = self.sdo_response;
        self.take(deadline, |f| Some(f.id) == id && !f.extended && !f.remote)
    }

    fn now(&mut self) -> Instant {
        self.bus.now()
    }
}
