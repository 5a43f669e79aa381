//! The bench of the figures of network services (NMT, node guarding, heartbeat, EMCY, PDO
//! mapping): odc's `master::Master` and one device run by odc's `node::Node` on a generated
//! slave dictionary, on one wire that logs every frame in the order it goes on the bus.
//!
//! Time is simulated: each reading of the clock is one millisecond later, and the node is
//! polled then (its heartbeat, event-driven TPDOs, EMCY inhibit time run as on a device).
#![allow(clippy::unwrap_used, clippy::expect_used, dead_code)] // test helpers; not every test uses all

use std::collections::VecDeque;

use odc::can::CanFrame;
use odc::master::Master;
use odc::node::Node;
use odc::slave::ObjectDictionary;
use odc::transport::Bus;

/// The node of the bench: 4 RPDOs and 4 TPDOs, as both Schneider drives have.
pub type DriveNode = Node<64, 4, 4>;

/// The wire with the device on it.
pub struct NodeWire<D> {
    /// The device's CANopen node.
    pub node: DriveNode,
    /// The device's dictionary.
    pub od: D,
    /// Every frame, both directions, in bus order.
    pub log: Vec<CanFrame>,
    inbox: VecDeque<CanFrame>,
    now_us: u64,
}

impl<D: ObjectDictionary> NodeWire<D> {
    /// Node `node_id` on dictionary `od`, powered on: its boot-up message is the first frame
    /// of the log.
    pub fn new(node_id: odc::cob::NodeId, od: D) -> Self {
        let mut wire = NodeWire {
            node: Node::new(node_id),
            od,
            log: Vec::new(),
            inbox: VecDeque::new(),
            now_us: 0,
        };
        let (node, od, log, inbox) = (&mut wire.node, &mut wire.od, &mut wire.log, &mut wire.inbox);
        node.start(od, odc::time::Instant::ZERO, &mut |f| {
            log.push(f);
            inbox.push_back(f);
        });
        wire
    }

    /// Lets `ms` milliseconds pass, the node polled every millisecond.
    pub fn advance(&mut self, ms: u64) {
        for _ in 0..ms {
            self.tick();
        }
    }

    fn tick(&mut self) {
        self.now_us += 1_000;
        let (node, od, log, inbox) = (&mut self.node, &mut self.od, &mut self.log, &mut self.inbox);
        node.poll(od, odc::time::Instant::from_micros(self.now_us), &mut |f| {
            log.push(f);
            inbox.push_back(f);
        });
    }

    /// The current time in µs (for the node's own calls, such as `raise_emcy`).
    pub fn now_us(&self) -> u64 {
        self.now_us
    }

    /// The device raises an error (`Node::raise_emcy`): its EMCY goes on the wire.
    pub fn raise_emcy(&mut self, code: odc::emcy::EmcyCode, manufacturer: [u8; 5]) {
        let (node, log, inbox) = (&mut self.node, &mut self.log, &mut self.inbox);
        node.raise_emcy(
            code,
            manufacturer,
            odc::time::Instant::from_micros(self.now_us),
            &mut |f| {
                log.push(f);
                inbox.push_back(f);
            },
        );
    }

    /// The logged frames with CAN-ID `id` (data and remote).
    pub fn frames(&self, id: u32) -> Vec<CanFrame> {
        self.frames_of(&[id])
    }

    /// The logged frames with any of the CAN-IDs `ids`, in bus order.
    pub fn frames_of(&self, ids: &[u32]) -> Vec<CanFrame> {
        self.log.iter().filter(|f| ids.contains(&f.id()) && !f.is_extended()).copied().collect()
    }
}

impl<D: ObjectDictionary> Bus for NodeWire<D> {
    type Error = std::convert::Infallible;

    fn send(&mut self, frame: &CanFrame) -> Result<(), Self::Error> {
        self.log.push(*frame);
        let (node, od, log, inbox) = (&mut self.node, &mut self.od, &mut self.log, &mut self.inbox);
        node.handle(od, frame, odc::time::Instant::from_micros(self.now_us), &mut |f| {
            log.push(f);
            inbox.push_back(f);
        });
        Ok(())
    }

    fn recv(&mut self, _deadline: odc::time::Instant) -> Result<Option<CanFrame>, Self::Error> {
        Ok(self.inbox.pop_front())
    }

    fn now(&mut self) -> odc::time::Instant {
        self.tick();
        odc::time::Instant::from_micros(self.now_us)
    }
}

/// odc's master on a wire with node `node_id` (booted) on dictionary `od`.
pub fn master<D: ObjectDictionary>(node_id: odc::cob::NodeId, od: D) -> Master<NodeWire<D>> {
    Master::new(NodeWire::new(node_id, od)).with_timeout(odc::time::Duration::from_millis(50))
}

/// The heartbeat frames of node `node_id` on `od`, boot-up first: its producer heartbeat time
/// (`time`, 1017h) written to `period_ms` by odc's master, the node started, `ms` milliseconds
/// on.
pub fn heartbeats<D: ObjectDictionary>(
    node_id: odc::cob::NodeId,
    od: D,
    time: &odc::Entry<u16>,
    period_ms: u16,
    ms: u64,
) -> Vec<CanFrame> {
    use odc::cob::Function;
    let mut m = master(node_id, od);
    m.write(node_id, time, period_ms).unwrap();
    m.nmt(odc::nmt::NmtCommand::Start, node_id).unwrap();
    m.bus_mut().advance(ms);
    let id = Function::Heartbeat.can_id(node_id).unwrap();
    m.bus_mut().frames(u32::from(id))
}
