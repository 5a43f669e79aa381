//! A simulated CiA 402 drive: the firmware a drive maker writes with odc, on a channel bus.
//!
//! The generated slave dictionary, the runtime's [`Node`] (NMT, SDO server, PDOs as the
//! dictionary maps them, heartbeat, EMCY) and its CiA 402 [`Drive`](cia402::Drive) (the state
//! machine on each new controlword, the statusword, modes of operation display, and a
//! profile-position axis that moves at the profile velocity by one SYNC period per SYNC) over
//! the dictionary, which implements [`DriveObjects`] itself. What is left here is the loop.

use std::time::{Duration, Instant};

use odc::can::CanFrame;
use odc::cia402::{self, DriveObjects};
use odc::nmt::NmtState;
use odc::node::Node;
use odc::slave::ObjectDictionary;

use crate::bus::{Closed, Port};

/// The simulated drive.
pub struct Drive<D> {
    od: D,
    node: Node<64>,
    drive: cia402::Drive,
    cycle_ms: u32,
    start: Instant,
}

impl<D: ObjectDictionary + DriveObjects> Drive<D> {
    /// A drive with node id `node` around `od`, moving by `cycle_ms` of profile velocity per
    /// SYNC.
    pub fn new(od: D, node: odc::cob::NodeId, cycle_ms: u32) -> Self {
        let (node, drive) = (Node::new(node), cia402::Drive::new());
        Drive { od, node, drive, cycle_ms, start: Instant::now() }
    }

    /// Runs on `port` until the other end closes the bus; returns the dictionary as the drive
    /// left it.
    ///
    /// # Errors
    ///
    /// [`Closed`] only if the bus closes before the boot-up message is out.
    pub fn run(mut self, port: &Port) -> Result<D, Closed> {
        for frame in self.boot() {
            port.send(frame)?;
        }
        loop {
            let frames = match port.recv_timeout(Duration::from_millis(1)) {
                Ok(Some(frame)) => self.handle(&frame),
                Ok(None) => self.poll(),
                Err(Closed) => return Ok(self.od),
            };
            for out in frames {
                if port.send(out).is_err() {
                    return Ok(self.od);
                }
            }
        }
    }

    fn now_us(&self) -> u64 {
        u64::try_from(self.start.elapsed().as_micros()).unwrap_or(u64::MAX)
    }

    /// Initialisation: the drive leaves "not ready to switch on" by itself (transition 1),
    /// the node enters pre-operational and sends its boot-up message.
    pub fn boot(&mut self) -> Vec<CanFrame> {
        self.drive = cia402::Drive::new();
        self.drive.start(&mut self.od);
        let mut out = Vec::new();
        let now = self.now_us();
        self.node.start(&mut self.od, odc::time::Instant::from_micros(now), &mut |f| out.push(f));
        out
    }

    /// The frames the drive sends in answer to `frame`. On SYNC the axis moves first, so that
    /// the synchronous TPDOs the node sends for it carry the new position.
    pub fn handle(&mut self, frame: &CanFrame) -> Vec<CanFrame> {
        if frame.is_data(u32::from(odc::cob::SYNC)) && self.node.state() == NmtState::Operational {
            self.drive.step(&mut self.od, odc::time::Duration::from_millis(self.cycle_ms.into()));
            self.drive.update(&mut self.od);
        }
        let mut out = Vec::new();
        let now = self.now_us();
        let events =
            self.node.handle(&mut self.od, frame, odc::time::Instant::from_micros(now), &mut |f| {
                out.push(f)
            });
        if events.reset.is_some() {
            // The values stay as they are (the examples need no restored defaults).
            return self.boot();
        }
        self.drive.update(&mut self.od);
        out.extend(self.poll());
        out
    }

    /// The node's timers, and the event-driven TPDOs whose data the drive changed.
    fn poll(&mut self) -> Vec<CanFrame> {
        let mut out = Vec::new();
        let now = self.now_us();
        self.node.poll(&mut self.od, odc::time::Instant::from_micros(now), &mut |f| out.push(f));
        out
    }

    /// The dictionary, as the drive keeps it.
    pub fn dictionary(&self) -> &D {
        &self.od
    }
}
