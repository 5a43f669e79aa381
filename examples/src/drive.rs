//! A simulated CiA 402 drive around an odc-generated slave dictionary: the firmware a drive
//! maker would write, reduced to what the examples need.
//!
//! - NMT: boot-up message, pre-operational, operational on "start", PDOs in operational only;
//! - SDO: odc's [`Server`] on the dictionary;
//! - PDO: RPDOs written into, TPDOs read from the dictionary as its mapping objects say
//!   ([`crate::pdo`]); event-driven TPDOs (types 254, 255) go out when their data changes,
//!   synchronous ones (0–240) on SYNC;
//! - CiA 402: the state machine ([`State::after`] on each new controlword), the statusword,
//!   modes of operation display following modes of operation, and a profile-position axis:
//!   a new set-point (controlword bit 4 rising, absolute or relative by bit 6) is acknowledged
//!   (statusword bit 12) and the axis moves at the profile velocity by one SYNC period per
//!   SYNC until it reaches the target (statusword bit 10).
//!
//! The dictionary's typed fields are the drive's memory; [`Cia402Device`] is the few lines
//! that name them for this generic firmware.

use std::collections::BTreeMap;
use std::time::Duration;

use odc::can::CanFrame;
use odc::cia402::{Controlword, ModeOfOperation, State, Statusword};
use odc::nmt::{NmtCommand, NmtState};
use odc::sdo::Server;
use odc::slave::ObjectDictionary;

use crate::bus::{Closed, Port};
use crate::pdo;

/// The objects the firmware reads and writes directly in a generated `slave::Dictionary`
/// (`get`/`set` with a descriptor of its `od`, which differ in name from one device file to the
/// next).
pub trait Cia402Device: ObjectDictionary {
    /// 0x6040.
    fn controlword(&self) -> Controlword;
    /// 0x6041 (read-only over SDO; the firmware sets it).
    fn set_statusword(&mut self, statusword: Statusword);
    /// 0x6060.
    fn mode_of_operation(&self) -> i8;
    /// 0x6061 (read-only over SDO).
    fn set_mode_of_operation_display(&mut self, mode: i8);
    /// 0x607A.
    fn target_position(&self) -> i32;
    /// 0x6081, in position units per second.
    fn profile_velocity(&self) -> u32;
    /// 0x6064 (read-only over SDO).
    fn set_position_actual_value(&mut self, position: i32);
}

/// The simulated drive.
pub struct Drive<D> {
    od: D,
    node: u8,
    server: Server<64>,
    nmt: NmtState,
    state: State,
    last_controlword: Controlword,
    position: i64,
    target: i64,
    moving: bool,
    acknowledged: bool,
    cycle_ms: i64,
    sent: BTreeMap<u16, Vec<u8>>,
}

impl<D: Cia402Device> Drive<D> {
    /// A drive with node id `node` around `od`, moving by `cycle_ms` of profile velocity per
    /// SYNC.
    pub fn new(od: D, node: u8, cycle_ms: u32) -> Self {
        Drive {
            od,
            node,
            server: Server::new(node),
            nmt: NmtState::BootUp,
            state: State::NotReadyToSwitchOn,
            last_controlword: Controlword::DISABLE_VOLTAGE,
            position: 0,
            target: 0,
            moving: false,
            acknowledged: false,
            cycle_ms: i64::from(cycle_ms),
            sent: BTreeMap::new(),
        }
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
            match port.recv_timeout(Duration::from_secs(1)) {
                Ok(Some(frame)) => {
                    for out in self.handle(&frame) {
                        if port.send(out).is_err() {
                            return Ok(self.od);
                        }
                    }
                }
                Ok(None) => {}
                Err(Closed) => return Ok(self.od),
            }
        }
    }

    /// Initialisation: the drive leaves "not ready to switch on" by itself (transition 1),
    /// enters pre-operational and sends its boot-up message.
    pub fn boot(&mut self) -> Vec<CanFrame> {
        self.state = State::SwitchOnDisabled;
        self.nmt = NmtState::PreOperational;
        self.sent.clear();
        self.update();
        CanFrame::from_slice(0x700 + u32::from(self.node), &[NmtState::BootUp.to_u8()])
            .into_iter()
            .collect()
    }

    /// The frames the drive sends in answer to `frame`.
    pub fn handle(&mut self, frame: &CanFrame) -> Vec<CanFrame> {
        let mut out = Vec::new();
        let sync = frame.id == u32::from(odc::cob::SYNC);
        if frame.id == u32::from(odc::cob::NMT) {
            if let [cs, node] = *frame.bytes()
                && (node == 0 || node == self.node)
            {
                match NmtCommand::from_u8(cs) {
                    Some(NmtCommand::Start) => {
                        self.nmt = NmtState::Operational;
                        // Entering operational, every event-driven TPDO goes out once.
                        self.sent.clear();
                    }
                    Some(NmtCommand::Stop) => self.nmt = NmtState::Stopped,
                    Some(NmtCommand::EnterPreOperational) => self.nmt = NmtState::PreOperational,
                    Some(NmtCommand::ResetNode | NmtCommand::ResetCommunication) => {
                        return self.boot();
                    }
                    None => {}
                }
            }
        } else if sync {
            if self.nmt == NmtState::Operational {
                self.step();
            }
        } else if frame.id == self.server.request_id() {
            if self.nmt.sdo_allowed() {
                out.extend(self.server.handle(&mut self.od, frame, 0));
            }
        } else if self.nmt == NmtState::Operational {
            self.receive_pdo(frame);
        }
        self.update();
        out.extend(self.transmit_pdos(sync));
        out
    }

    fn receive_pdo(&mut self, frame: &CanFrame) {
        for n in 0..4 {
            if pdo::cob_id(&self.od, 0x1400 + n) == Some(frame.id) {
                // A frame the mapping cannot take is dropped, as CiA 301 lets a device do
                // (it would send an EMCY; these examples have none).
                if let Ok(entries) = pdo::mapping(&self.od, 0x1600 + n) {
                    let _ = pdo::receive(&mut self.od, &entries, frame.bytes());
                }
            }
        }
    }

    /// The firmware's reaction to the values the master wrote: the state machine, the mode,
    /// the set-point handshake, and the statusword and actual position it reports.
    fn update(&mut self) {
        let cw = self.od.controlword();
        let last = self.last_controlword;
        if cw != last {
            self.state = self.state.after(cw, cw.bit(7) && !last.bit(7));
            let profile_position = ModeOfOperation::from_i8(self.od.mode_of_operation())
                == ModeOfOperation::ProfilePosition;
            if cw.bit(4)
                && !last.bit(4)
                && self.state == State::OperationEnabled
                && profile_position
            {
                let target = i64::from(self.od.target_position());
                self.target = if cw.bit(6) { self.position + target } else { target };
                self.moving = self.target != self.position;
                self.acknowledged = true;
            }
            if !cw.bit(4) {
                self.acknowledged = false;
            }
            self.last_controlword = cw;
        }
        if self.state != State::OperationEnabled {
            self.moving = false;
        }
        self.od.set_mode_of_operation_display(self.od.mode_of_operation());
        let powered = matches!(
            self.state,
            State::ReadyToSwitchOn
                | State::SwitchedOn
                | State::OperationEnabled
                | State::QuickStopActive
        );
        let sw = self
            .state
            .statusword()
            .with_voltage_enabled(powered)
            .with_remote(true)
            .with_target_reached(!self.moving)
            .with_setpoint_ack(self.acknowledged);
        self.od.set_statusword(sw);
        self.od.set_position_actual_value(i32::try_from(self.position).unwrap_or(i32::MAX));
    }

    /// One SYNC period of motion.
    fn step(&mut self) {
        if !self.moving {
            return;
        }
        let per_cycle = (i64::from(self.od.profile_velocity()) * self.cycle_ms / 1000).max(1);
        let remaining = self.target - self.position;
        self.position += remaining.clamp(-per_cycle, per_cycle);
        self.moving = self.position != self.target;
    }

    fn transmit_pdos(&mut self, sync: bool) -> Vec<CanFrame> {
        let mut out = Vec::new();
        if self.nmt != NmtState::Operational {
            return out;
        }
        for n in 0..4 {
            let comm = 0x1800 + n;
            let Some(id) = pdo::cob_id(&self.od, comm) else { continue };
            let Ok(entries) = pdo::mapping(&self.od, 0x1A00 + n) else { continue };
            if entries.is_empty() {
                continue;
            }
            let Ok(data) = pdo::transmit(&self.od, &entries) else { continue };
            let changed = self.sent.get(&comm) != Some(&data);
            let due = match pdo::transmission_type(&self.od, comm) {
                0 => sync && changed,
                1..=240 => sync,
                254 | 255 => changed,
                _ => false,
            };
            if due && let Some(frame) = CanFrame::from_slice(id, &data) {
                out.push(frame);
                self.sent.insert(comm, data);
            }
        }
        out
    }

    /// The dictionary, as the drive keeps it.
    pub fn dictionary(&self) -> &D {
        &self.od
    }
}
