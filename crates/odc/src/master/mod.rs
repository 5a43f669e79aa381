//! The controller side of a CANopen network: one [`Master`] over any [`Bus`] (the transports
//! of [`crate::transport`]: SocketCAN, embedded-can HALs, TCP, in-memory).
//!
//! - NMT master: commands to one node or all; each node's state as its boot-up, heartbeat or
//!   guarding answer last said; a heartbeat consumer that makes a lost node an event; node
//!   guarding (remote frames, toggle bit, life-guarding loss as an event);
//! - SYNC producer (with the CiA 301 counter when asked for);
//! - SDO client for every node (expedited, segmented; block transfer with
//!   [`Master::upload_block`]), typed by generated descriptors;
//! - PDO exchange with generated structs: send an RPDO struct, receive a TPDO struct by COB-ID;
//! - execution of generated configuration plans;
//! - EMCY consumer: the code, its CiA 301/402 meaning and the error register;
//! - LSS master ([`lss`]);
//! - a CiA 402 drive on PDOs and SYNC, with the runtime's driver ([`axis`]).
//!
//! Blocking and single-threaded, like the SDO client it is built on. A frame that arrives
//! while the master waits for something else is kept, in order, and handed out later by
//! [`Master::poll`] or the next wait that wants it: nothing is dropped. Timeouts and errors
//! are values, never panics. `std` only (it keeps queues); firmware uses [`crate::node`].
//!
//! ```
//! use odc::master::{Event, Master};
//! use odc::nmt::{NmtCommand, NmtState};
//! use odc::transport::{Bus, mem::MemBus};
//! use odc::can::CanFrame;
//! use odc::time::Duration;
//!
//! let bus = MemBus::new();
//! let (mut device, port) = (bus.port(), bus.port());
//! let mut master = Master::new(port).with_timeout(Duration::from_millis(100));
//! // A device says it booted, and later that it is operational.
//! device.send(&CanFrame::from_slice(0x705, &[0x00]).unwrap()).unwrap();
//! let node = odc::node_id!(5);
//! master.wait_boot_up(node)?;
//! assert_eq!(master.state(node), Some(NmtState::PreOperational));
//! master.nmt(NmtCommand::Start, node)?;
//! device.send(&CanFrame::from_slice(0x705, &[0x05]).unwrap()).unwrap();
//! let deadline = master.now() + Duration::from_millis(100);
//! assert_eq!(master.poll(deadline)?, Some(Event::State { node, state: NmtState::Operational }));
//! # Ok::<(), odc::master::Error<odc::transport::mem::Closed>>(())
//! ```

pub mod axis;
mod error;
mod guard;
mod link;
pub mod lss;
mod nmt;
mod sdo;

use std::boxed::Box;
use std::collections::{BTreeMap, VecDeque};
use std::vec::Vec;

use crate::Pdo;
use crate::can::CanFrame;
use crate::cob::{CobId, NodeId};
use crate::emcy::EmcyFrame;
use crate::nmt::NmtState;
use crate::plan::SdoWrite;
use crate::sdo::Client;
use crate::time::{Duration, Instant};
use crate::transport::Bus;

/// Bytes of the largest SDO value the master transfers (segmented or block).
pub const SDO_BUFFER: usize = 4096;

/// Default time the master waits for an answer (1 s, as [`crate::sdo::DEFAULT_TIMEOUT`]).
pub const DEFAULT_TIMEOUT: Duration = Duration::from_secs(1);

/// Something that happened on the bus.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Event {
    /// A node sent its boot-up message (it is now pre-operational).
    BootUp {
        /// The node.
        node: NodeId,
    },
    /// A node's heartbeat or guarding answer reported a state other than the last one.
    State {
        /// The node.
        node: NodeId,
        /// Its state.
        state: NmtState,
    },
    /// A node watched with [`Master::watch_heartbeat`] missed its heartbeat time.
    HeartbeatLost {
        /// The node.
        node: NodeId,
    },
    /// A node guarded with [`Master::guard`] gave no valid answer (toggle bit alternating)
    /// within its life time.
    GuardingLost {
        /// The node.
        node: NodeId,
    },
    /// An emergency message (`EmcyCode`'s `Display` gives its CiA 301/402 meaning).
    Emcy {
        /// The node.
        node: NodeId,
        /// Code, error register, manufacturer bytes.
        emcy: EmcyFrame,
    },
    /// A PDO (an 11-bit data frame on 0x181–0x57F).
    Pdo {
        /// Its COB-ID (11-bit, valid).
        cob_id: CobId,
        /// The frame.
        frame: CanFrame,
    },
    /// A SYNC from another producer.
    Sync {
        /// Its counter, when it has one.
        counter: Option<u8>,
    },
    /// Any other frame (SDO of other clients, TIME, LSS, extended or remote frames, ...).
    Other(CanFrame),
}

pub use error::{Error, Waited};
pub use guard::GuardStatus;
pub use link::Dir;
use link::Link;

/// What the master knows of one node.
#[derive(Clone, Copy, Debug, Default)]
struct Watch {
    state: Option<NmtState>,
    /// Heartbeat consumer time, when watched.
    timeout: Option<Duration>,
    last_seen: Instant,
    lost: bool,
}

/// The SYNC producer.
#[derive(Clone, Copy, Debug)]
struct SyncProducer {
    period: Duration,
    next: Instant,
}

/// A CANopen master over a bus.
pub struct Master<B: Bus> {
    link: Link<B>,
    timeout: Duration,
    clients: BTreeMap<NodeId, Box<Client<SDO_BUFFER>>>,
    nodes: BTreeMap<NodeId, Watch>,
    guards: BTreeMap<NodeId, guard::Guard>,
    sync: Option<SyncProducer>,
    /// The SYNC counter's overflow value (0x1019), when SYNCs carry a counter.
    sync_overflow: Option<u8>,
    sync_counter: u8,
}

impl<B: Bus> Master<B> {
    /// A master on `bus`, waiting [`DEFAULT_TIMEOUT`] for answers.
    pub fn new(bus: B) -> Self {
        Master {
            link: Link {
                bus,
                pending: VecDeque::new(),
                observer: None,
                sdo_response: None,
                heard: BTreeMap::new(),
            },
            timeout: DEFAULT_TIMEOUT,
            clients: BTreeMap::new(),
            nodes: BTreeMap::new(),
            guards: BTreeMap::new(),
            sync: None,
            sync_overflow: None,
            sync_counter: 1,
        }
    }

    /// The same master with another answer timeout (SDO responses, boot-up, PDOs).
    pub fn with_timeout(mut self, timeout: Duration) -> Self {
        self.timeout = timeout;
        self.clients.clear();
        self
    }

    /// Calls `observer` with every frame sent and received (a bus log, a monitor).
    pub fn observe(&mut self, observer: impl FnMut(Dir, &CanFrame) + Send + 'static) {
        self.link.observer = Some(Box::new(observer));
    }

    /// The bus.
    pub fn bus_mut(&mut self) -> &mut B {
        &mut self.link.bus
    }

    /// The bus's clock.
    pub fn now(&mut self) -> Instant {
        self.link.bus.now()
    }

    /// The answer timeout (SDO responses, boot-up, PDOs).
    pub fn timeout(&self) -> Duration {
        self.timeout
    }

    /// When `node` was last heard: the last frame it sent (boot-up, heartbeat, EMCY, TPDO,
    /// SDO response) that the master received; `None` if none yet.
    pub fn last_heard(&self, node: NodeId) -> Option<Instant> {
        self.link.heard.get(&node).copied()
    }

    /// The timeout error of a wait for `what` from `node` that began at `since`: whether the
    /// node was heard meanwhile, and its last reported state.
    fn timeout_error(&self, node: Option<NodeId>, what: Waited, since: Instant) -> Error<B::Error> {
        let heard = node.and_then(|n| self.last_heard(n)).is_some_and(|t| t >= since);
        let state = node.and_then(|n| self.state(n));
        Error::Timeout { node, what, waited: self.timeout, heard, state }
    }

    /// Sends a frame as it is.
    ///
    /// # Errors
    ///
    /// The bus error.
    pub fn send(&mut self, frame: &CanFrame) -> Result<(), Error<B::Error>> {
        self.link.send(frame).map_err(Error::Bus)
    }

    // ---- PDO -----------------------------------------------------------------------------

    /// Sends an RPDO: the struct's bytes on `cob_id`'s identifier, 11- or 29-bit as its bit
    /// 29 says (bit 31, "not valid", and bit 30 do not change the frame).
    ///
    /// # Errors
    ///
    /// A value that does not fit its field, or the bus error.
    pub fn send_pdo<P: Pdo>(&mut self, cob_id: CobId, pdo: &P) -> Result<(), Error<B::Error>> {
        let bytes = pdo.pack().map_err(|reason| Error::Pdo { cob_id, reason })?;
        let frame =
            cob_id.frame(bytes.as_ref()).ok_or(Error::Invalid("a PDO of more than 8 bytes"))?;
        self.send(&frame)
    }

    /// The next TPDO on `cob_id` (a data frame of its identifier and format), unpacked
    /// (queued ones first).
    ///
    /// # Errors
    ///
    /// [`Error::Timeout`], a frame that does not unpack into `P`, or the bus error.
    pub fn recv_pdo<P: Pdo>(&mut self, cob_id: CobId) -> Result<P, Error<B::Error>> {
        let frame = self.recv_frame(cob_id)?;
        P::unpack(frame.bytes()).map_err(|reason| Error::Unpack { cob_id, reason })
    }

    /// The next data frame on `cob_id` (queued ones first), as it is: for process data
    /// without a struct, or a vendor protocol.
    ///
    /// # Errors
    ///
    /// [`Error::Timeout`], or the bus error.
    pub fn recv_frame(&mut self, cob_id: CobId) -> Result<CanFrame, Error<B::Error>> {
        let since = self.now();
        let deadline = since + self.timeout;
        match self.link.take(deadline, |f| cob_id.matches(f)).map_err(Error::Bus)? {
            Some(f) => Ok(f),
            None => {
                let node = match cob_id.is_extended() {
                    true => None,
                    false => u16::try_from(cob_id.can_id())
                        .ok()
                        .and_then(crate::cob::classify)
                        .and_then(|(_, n)| n),
                };
                Err(self.timeout_error(node, Waited::Frame(cob_id), since))
            }
        }
    }

    /// The LSS master (CiA 305) on this master's bus.
    pub fn lss(&mut self) -> lss::LssMaster<'_, B> {
        lss::LssMaster::new(self)
    }
}

/// The CiA 301 writes that give a PDO a mapping of the application's choice (for a device
/// whose file has no default mapping, or another one): invalidate the COB-ID (bit 31), clear
/// the mapping, write `P::MAPPING`, set the count and the transmission type, validate the
/// COB-ID (CiA 301 7.5.2.36), by the one procedure, [`PdoConfig`](crate::plan::PdoConfig).
/// Run it with [`Master::execute`].
pub fn mapping_plan<P: Pdo>(
    comm_index: u16,
    mapping_index: u16,
    cob_id: CobId,
    transmission_type: u8,
) -> Vec<SdoWrite> {
    let mapping: Vec<u32> = P::MAPPING.iter().map(|e| e.to_u32()).collect();
    crate::plan::PdoConfig::new(mapping_index, &mapping)
        .with_comm(comm_index, true)
        .with_transmission_type(transmission_type)
        .to_vec(cob_id.0)
}

/// A data frame of at most 8 bytes.
fn frame<E>(id: u32, data: &[u8]) -> Result<CanFrame, Error<E>> {
    CanFrame::from_slice(id, data).ok_or(Error::Invalid("a frame of more than 8 bytes"))
}
