//! A simulated CiA 402 drive around an odc-generated slave dictionary: the firmware a drive
//! maker would write, reduced to what the examples need.
//!
//! - NMT: boot-up message, pre-operational, operational on "start", PDOs in operational only;
//! - SDO: odc's [`Server`] on the dictionary;
//! - PDO: RPDOs written into, TPDOs read from the dictionary as its mapping objects say
//!   ([`crate::pdo`]); event-driven TPDOs (types 254, 255) go out when their data changes,
//!   synchronous ones (0–240) on SYNC;
//! - CiA 402: odc's [`Drive`] (the state machine on each new controlword, the statusword,
//!   modes of operation display following modes of operation, and a profile-position axis
//!   that moves at the profile velocity by one SYNC period per SYNC) over the generated
//!   dictionary, which implements [`DriveObjects`] itself.

use std::collections::BTreeMap;
use std::time::Duration;

use odc::can::CanFrame;
use odc::cia402::{self, DriveObjects};
use odc::nmt::{NmtCommand, NmtState};
use odc::sdo::Server;
use odc::slave::ObjectDictionary;

use crate::bus::{Closed, Port};
use crate::pdo;

/// The simulated drive.
pub struct Drive<D> {
    od: D,
    node: u8,
    server: Server<64>,
    nmt: NmtState,
    drive: cia402::Drive,
    cycle_ms: u32,
    sent: BTreeMap<u16, Vec<u8>>,
}

impl<D: ObjectDictionary + DriveObjects> Drive<D> {
    /// A drive with node id `node` around `od`, moving by `cycle_ms` of profile velocity per
    /// SYNC.
    pub fn new(od: D, node: u8, cycle_ms: u32) -> Self {
        Drive {
            od,
            node,
            server: Server::new(node),
            nmt: NmtState::BootUp,
            drive: cia402::Drive::new(),
            cycle_ms,
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
        self.drive = cia402::Drive::new();
        self.drive.start(&mut self.od);
        self.nmt = NmtState::PreOperational;
        self.sent.clear();
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
                self.drive.step(&mut self.od, self.cycle_ms);
            }
        } else if frame.id == self.server.request_id() {
            if self.nmt.sdo_allowed() {
                out.extend(self.server.handle(&mut self.od, frame, 0));
            }
        } else if self.nmt == NmtState::Operational {
            self.receive_pdo(frame);
        }
        self.drive.update(&mut self.od);
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
