//! [`SimDevice`]: a device file as a node on a bus. Frames in, frames out, and a timer tick;
//! no I/O of its own, so any transport (the [`VirtualBus`](crate::VirtualBus), SocketCAN)
//! can carry it.
//!
//! The node is the runtime's [`Node`] over a [`ModelDictionary`]: the same NMT, heartbeat,
//! node guarding, SYNC, PDO engine (following remaps), EMCY, SDO server (with block transfer)
//! and, for a file with `LSS_Supported=1`, LSS slave as generated firmware runs. What a
//! simulation adds: the resets of the dictionary the node asks for, and a CiA 402 drive
//! (state machine and axis) updated after every frame and tick, so RPDO and SDO controlwords
//! both move it.

use odc::can::CanFrame;
use odc::cia402::{DeviceControl, Drive};
use odc::cob::NodeId;
use odc::nmt::NmtState;
use odc::node::{Events, Node, Reset};
use odc_model::Device;

use crate::ModelDictionary;

/// The SDO transfer buffer: larger than any value of the files served (a segmented upload of
/// a longer value is refused with "out of memory").
pub const SDO_BUFFER: usize = 4096;

/// Receive and transmit PDOs the simulated node serves: more than any device of the corpus
/// configures at once (CiA 301 allows 512 of each; those past this are ignored).
pub const MAX_PDOS: usize = 64;

/// The node of a simulation.
type SimNode = Node<SDO_BUFFER, MAX_PDOS, MAX_PDOS>;

/// A simulated device: a [`ModelDictionary`] served by a [`Node`], with a CiA 402 drive when
/// the file is one.
#[derive(Debug)]
pub struct SimDevice {
    node: SimNode,
    od: ModelDictionary,
    drive: Option<Drive>,
    last_tick_ms: u64,
}

impl SimDevice {
    /// The device of `device` on node `node_id` (1–127), in initialisation: call
    /// [`SimDevice::start`] for its boot-up. `None`: a device without node-ID (CiA 305's
    /// 0xFF, as drives without address switches come), silent until an LSS master finds it
    /// (fastscan) and gives it one, then boots at the next reset communication.
    pub fn new(device: &Device, node_id: impl Into<Option<NodeId>>) -> Self {
        let node_id = node_id.into();
        let od = ModelDictionary::new(device, node_id);
        let drive = od.is_drive().then(Drive::new);
        // LSS with the identity of 0x1018 (read at start), bit timing 0 (1 Mbit/s; CiA 305),
        // when the file says `LSS_Supported=1` (absent means no, CiA 306): a device whose
        // file says 0 does not answer on 0x7E5. A device started without node-ID gets it
        // anyway: LSS is its only way to one.
        let lss = device.device_info.lss_supported.as_ref().is_some_and(|v| v.value);
        let node = match node_id {
            Some(id) => Node::new(id),
            None => Node::unconfigured(),
        };
        let node = match lss || node_id.is_none() {
            true => node.with_lss(None, 0),
            false => node,
        };
        Self { node, od, drive, last_tick_ms: 0 }
    }

    /// The node-ID (LSS may have changed it).
    pub fn node_id(&self) -> Option<NodeId> {
        self.node.node_id()
    }

    /// The NMT state.
    pub fn nmt_state(&self) -> NmtState {
        self.node.state()
    }

    /// The dictionary.
    pub fn dictionary(&self) -> &ModelDictionary {
        &self.od
    }

    /// Whether it runs a CiA 402 drive.
    pub fn is_drive(&self) -> bool {
        self.drive.is_some()
    }

    /// Initialisation: the boot-up message (0x700 + node-ID, one byte 0), then
    /// pre-operational; a drive leaves "not ready to switch on".
    pub fn start(&mut self, now_ms: u64, out: &mut impl FnMut(CanFrame)) {
        self.last_tick_ms = now_ms;
        self.restart_drive();
        self.node.start(&mut self.od, odc::time::Instant::from_millis(now_ms), out);
    }

    /// A drive as after power-on, with the quick stop option code (0x605A, INTEGER16) the
    /// dictionary holds now (CiA 402's default 2 without it).
    fn restart_drive(&mut self) {
        if let Some(drive) = &mut self.drive {
            let option = self.od.get::<i16>(0x605A, 0).unwrap_or(2);
            let control = DeviceControl::new().with_quick_stop_option(option);
            *drive = Drive::new().with_control(control);
            drive.start(&mut self.od);
        }
    }

    /// Frame in, frames out.
    pub fn handle(&mut self, frame: &CanFrame, now_ms: u64, out: &mut impl FnMut(CanFrame)) {
        let events =
            self.node.handle(&mut self.od, frame, odc::time::Instant::from_millis(now_ms), out);
        self.after(&events, now_ms, out);
    }

    /// The timer tick: the node's timers (heartbeat, event timers, guarding, SDO timeouts)
    /// and the drive's motion.
    pub fn poll(&mut self, now_ms: u64, out: &mut impl FnMut(CanFrame)) {
        let events = self.node.poll(&mut self.od, odc::time::Instant::from_millis(now_ms), out);
        self.after(&events, now_ms, out);
        let dt = now_ms.saturating_sub(self.last_tick_ms);
        self.last_tick_ms = now_ms;
        if let Some(drive) = &mut self.drive {
            drive.step(&mut self.od, odc::time::Duration::from_millis(dt));
        }
    }

    /// What the application of a node does with its events: a reset restores the dictionary
    /// (reset node all of it and the drive, reset communication 0x1000–0x1FFF, CiA 301
    /// §7.3.2.2.1), then the node boots at once (boot-up) instead of at the next tick. Any
    /// frame may have moved the controlword.
    fn after(&mut self, events: &Events, now_ms: u64, out: &mut impl FnMut(CanFrame)) {
        if let Some(reset) = events.reset {
            match reset {
                // At the node-ID the node boots with (a new one LSS configured).
                Reset::Node => {
                    self.od.reset(self.node.next_node_id());
                    self.restart_drive();
                }
                // The drive's state is the application's, not communication's: it stays.
                Reset::Communication => self.od.reset_communication(self.node.next_node_id()),
            }
            self.node.start(&mut self.od, odc::time::Instant::from_millis(now_ms), out);
        }
        if let Some(drive) = &mut self.drive {
            if events.sdo_written || events.rpdo != 0 {
                // The quick stop option code (0x605A) as the dictionary holds it now: a
                // master may change it at any time (CiA 402-2 6.5.2).
                let option = self.od.get::<i16>(0x605A, 0).unwrap_or(2);
                *drive = drive.with_control(drive.control().with_quick_stop_option(option));
            }
            // A lost heartbeat (0x1016) or life guarding: what the abort connection option
            // code (0x6007, CiA 402-2 6.5.1) commands (1 fault, 2 disable voltage, 3 quick
            // stop); a drive without 0x6007 takes no action.
            if (events.heartbeat_lost != 0 || events.life_guarding_lost)
                && let Ok(code) = self.od.get::<i16>(0x6007, 0)
            {
                drive.connection_lost(&mut self.od, code);
            }
            drive.update(&mut self.od);
        }
    }
}

/// Runs `device` on any [`Bus`](odc::sdo::Bus) (a SocketCAN interface, one end of a TCP
/// link) until `stop` returns true or the bus fails: the boot-up, then each received frame
/// through [`SimDevice::handle`] and a [`SimDevice::poll`] every `tick_ms`.
///
/// # Errors
///
/// The bus's, on a send or receive.
pub fn run_on_bus<B: odc::sdo::Bus>(
    bus: &mut B,
    device: &mut SimDevice,
    tick_ms: u64,
    stop: impl FnMut() -> bool,
) -> Result<(), B::Error> {
    run_all_on_bus(bus, std::slice::from_mut(device), tick_ms, stop)
}

/// Runs `devices` on any [`Bus`](odc::sdo::Bus) as [`run_on_bus`] runs one: the bus carries
/// their frames out, and each device also receives the frames of the others
/// ([`crate::nodes`]), which one interface does not hand back to the process that sent them.
///
/// # Errors
///
/// The bus's, on a send or receive.
pub fn run_all_on_bus<B: odc::sdo::Bus>(
    bus: &mut B,
    devices: &mut [SimDevice],
    tick_ms: u64,
    mut stop: impl FnMut() -> bool,
) -> Result<(), B::Error> {
    let mut out = Vec::new();
    // The device's tick counts in ms; the bus's clock is an `Instant`.
    let now_ms = |bus: &mut B| bus.now().as_millis();
    crate::nodes::start_all(devices, now_ms(bus), &mut |f| out.push(f));
    let mut next_tick = now_ms(bus) + tick_ms;
    while !stop() {
        for f in out.drain(..) {
            bus.send(&f)?;
        }
        if let Some(frame) = bus.recv(odc::time::Instant::from_millis(next_tick))? {
            let now = now_ms(bus);
            crate::nodes::handle_all(devices, &frame, now, &mut |f| out.push(f));
        }
        let now = now_ms(bus);
        if now >= next_tick {
            crate::nodes::poll_all(devices, now, &mut |f| out.push(f));
            next_tick = now + tick_ms;
        }
    }
    for f in out.drain(..) {
        bus.send(&f)?;
    }
    Ok(())
}
