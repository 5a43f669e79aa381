//! [`SimDevice`]: a device file as a node on a bus. Frames in, frames out, and a timer tick;
//! no I/O of its own, so any transport (the [`VirtualBus`](crate::VirtualBus), SocketCAN)
//! can carry it.
//!
//! MERGE: until the node runtime (`odc::node::Node`, helper A) is merged, this is the
//! minimum of a node: NMT commands (start, stop, pre-operational, reset node and reset
//! communication, each reset with a new boot-up message), the SDO server in pre-operational
//! and operational. [`SimDevice::handle`] and [`SimDevice::poll`] are the two call sites the
//! node takes over (`Node::handle` and `Node::poll`; `Node::start` for the boot-up).

use odc::can::CanFrame;
use odc::cia402::{DeviceControl, Drive};
use odc::nmt::{NmtCommand, NmtState};
use odc::sdo::Server;
use odc_model::Device;

use crate::ModelDictionary;

/// The SDO transfer buffer: larger than any value of the files served (a segmented upload of
/// a longer value is refused with "out of memory").
pub const SDO_BUFFER: usize = 4096;

/// A simulated device: a [`ModelDictionary`] served on node `node_id`, with a CiA 402 drive
/// when the file is one.
#[derive(Debug)]
pub struct SimDevice {
    node_id: u8,
    od: ModelDictionary,
    sdo: Server<SDO_BUFFER>,
    nmt: NmtState,
    drive: Option<Drive>,
    last_tick_ms: u64,
}

impl SimDevice {
    /// The device of `device` on node `node_id` (1–127), in initialisation: call
    /// [`SimDevice::start`] for its boot-up.
    pub fn new(device: &Device, node_id: u8) -> Self {
        let od = ModelDictionary::new(device, node_id);
        let drive = od.is_drive().then(Drive::new);
        Self {
            node_id,
            od,
            sdo: Server::new(node_id),
            nmt: NmtState::BootUp,
            drive,
            last_tick_ms: 0,
        }
    }

    /// The node-ID.
    pub fn node_id(&self) -> u8 {
        self.node_id
    }

    /// The NMT state.
    pub fn nmt_state(&self) -> NmtState {
        self.nmt
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
        self.sdo = Server::new(self.node_id);
        self.nmt = NmtState::PreOperational;
        self.last_tick_ms = now_ms;
        if let Some(drive) = &mut self.drive {
            // 0x605A quick stop option code (INTEGER16), as the dictionary holds it now;
            // CiA 402's default 2 without it.
            let option = self.od.get::<i16>(0x605A, 0).unwrap_or(2);
            let control = DeviceControl::new().with_quick_stop_option(option);
            *drive = Drive::new().with_control(control);
            drive.start(&mut self.od);
        }
        if let Some(boot_up) =
            CanFrame::from_slice(0x700 + u32::from(self.node_id), &[NmtState::BootUp.to_u8()])
        {
            out(boot_up);
        }
    }

    /// Frame in, frames out. MERGE: `Node::handle`.
    pub fn handle(&mut self, frame: &CanFrame, now_ms: u64, out: &mut impl FnMut(CanFrame)) {
        if frame.id == u32::from(odc::cob::NMT) {
            if let [cs, node] = *frame.bytes()
                && (node == 0 || node == self.node_id)
            {
                match NmtCommand::from_u8(cs) {
                    Some(NmtCommand::Start) => self.nmt = NmtState::Operational,
                    Some(NmtCommand::Stop) => self.nmt = NmtState::Stopped,
                    Some(NmtCommand::EnterPreOperational) => self.nmt = NmtState::PreOperational,
                    Some(NmtCommand::ResetNode) => {
                        self.od.reset(self.node_id);
                        self.start(now_ms, out);
                    }
                    Some(NmtCommand::ResetCommunication) => {
                        self.od.reset_communication(self.node_id);
                        self.start(now_ms, out);
                    }
                    None => {}
                }
            }
            return;
        }
        if frame.id == self.sdo.request_id() && self.nmt.sdo_allowed() {
            if let Some(answer) = self.sdo.handle(&mut self.od, frame, now_ms) {
                out(answer);
            }
            if let Some(drive) = &mut self.drive {
                drive.update(&mut self.od);
            }
        }
    }

    /// The timer tick: SDO timeouts, the drive's motion. MERGE: `Node::poll`.
    pub fn poll(&mut self, now_ms: u64, out: &mut impl FnMut(CanFrame)) {
        if let Some(abort) = self.sdo.poll(now_ms) {
            out(abort);
        }
        let dt = now_ms.saturating_sub(self.last_tick_ms);
        self.last_tick_ms = now_ms;
        if let Some(drive) = &mut self.drive {
            drive.step(&mut self.od, u32::try_from(dt).unwrap_or(u32::MAX));
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
    mut stop: impl FnMut() -> bool,
) -> Result<(), B::Error> {
    let mut out = Vec::new();
    device.start(bus.now_ms(), &mut |f| out.push(f));
    let mut next_tick = bus.now_ms() + tick_ms;
    while !stop() {
        for f in out.drain(..) {
            bus.send(&f)?;
        }
        if let Some(frame) = bus.recv(next_tick)? {
            let now = bus.now_ms();
            device.handle(&frame, now, &mut |f| out.push(f));
        }
        let now = bus.now_ms();
        if now >= next_tick {
            device.poll(now, &mut |f| out.push(f));
            next_tick = now + tick_ms;
        }
    }
    for f in out.drain(..) {
        bus.send(&f)?;
    }
    Ok(())
}
