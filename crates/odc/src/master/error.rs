//! Why a master operation failed. Every error prints (Display) which node and what was asked
//! or waited for, so a command-line tool shows it as it is.

use std::fmt;

use super::lss;
use crate::cob::{CobId, NodeId};
use crate::nmt::NmtState;
use crate::plan::SdoWrite;
use crate::sdo::SdoError;
use crate::time::Duration;

/// Why a master operation failed.
///
/// `Debug` prints the same text as `Display`: a program whose `main` returns
/// `Result<(), Box<dyn Error>>` shows its error with `Debug`, and it should read
/// "timeout: nothing at all from node 5 …", not a dump of this enum.
pub enum Error<E> {
    /// The bus failed.
    Bus(E),
    /// An SDO transfer failed: the server's abort, or this client's for a protocol error (a
    /// response that never came is [`Error::Timeout`]).
    Sdo {
        /// The node.
        node: NodeId,
        /// Object index.
        index: u16,
        /// Sub-index.
        sub: u8,
        /// Why.
        error: SdoError<E>,
    },
    /// A write of a configuration plan failed.
    Plan {
        /// The node.
        node: NodeId,
        /// Position of the write in the plan.
        step: usize,
        /// The write.
        write: SdoWrite,
        /// Why.
        error: SdoError<E>,
    },
    /// Nothing came in time.
    Timeout {
        /// The node waited for, when the answer is one node's.
        node: Option<NodeId>,
        /// What was waited for.
        what: Waited,
        /// How long.
        waited: Duration,
        /// Whether a frame from `node` came during the wait (a heartbeat, an EMCY, a PDO, …):
        /// the node is alive but did not give this answer. `false`: nothing at all from it
        /// (absent, another node-ID, another bit rate, or no heartbeat configured).
        heard: bool,
        /// The NMT state `node` last reported, if any.
        state: Option<NmtState>,
    },
    /// A PDO struct does not pack, or a received PDO does not unpack into it.
    Pdo {
        /// The PDO's COB-ID.
        cob_id: CobId,
        /// What the layout engine said.
        reason: crate::PackError,
    },
    /// A received PDO does not unpack into the struct asked for.
    Unpack {
        /// The PDO's COB-ID.
        cob_id: CobId,
        /// What the layout engine said.
        reason: crate::UnpackError,
    },
    /// An LSS service failed.
    Lss(lss::LssError),
    /// A CiA 402 job of the drive at `node` failed (fault, timeout, mode refused, …).
    Drive {
        /// The drive.
        node: NodeId,
        /// Why.
        error: crate::cia402::DriverError,
    },
    /// A node-ID outside 1..=127, or an argument the protocol cannot carry.
    Invalid(&'static str),
}

/// What a master waited for when it timed out.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Waited {
    /// The boot-up message (0x700 + node-ID, byte 0).
    BootUp,
    /// A heartbeat reporting this state.
    State(NmtState),
    /// The SDO server's response for this object.
    Sdo {
        /// Object index.
        index: u16,
        /// Sub-index.
        sub: u8,
    },
    /// A data frame (a PDO) on this COB-ID.
    Frame(CobId),
}

impl fmt::Display for Waited {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Self::BootUp => f.write_str("boot-up message"),
            Self::State(s) => write!(f, "heartbeat reporting {s}"),
            Self::Sdo { index, sub } => write!(f, "SDO response for 0x{index:04X}:{sub:02X}"),
            Self::Frame(c) if c.is_extended() => write!(f, "frame on 0x{:08X}", c.can_id()),
            Self::Frame(c) => write!(f, "frame on 0x{:03X}", c.can_id()),
        }
    }
}

impl<E: fmt::Display> fmt::Display for Error<E> {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Self::Bus(e) => write!(f, "bus error: {e}"),
            Self::Sdo { node, index, sub, error } => {
                write!(f, "SDO to node {node}, 0x{index:04X}:{sub:02X}: {error}")
            }
            Self::Plan { node, step, write, error } => write!(
                f,
                "write {step} of the plan for node {node} (0x{:04X}:{:02X}): {error}",
                write.index, write.sub
            ),
            Self::Timeout { node: None, what, waited, .. } => {
                write!(f, "timeout: no {what} within {waited}")
            }
            Self::Timeout { node: Some(node), what, waited, heard: false, .. } => write!(
                f,
                "timeout: nothing at all from node {node} within {waited} (waiting for the {what}): \
                 is it on the bus, with this node-ID and bit rate?"
            ),
            Self::Timeout { node: Some(node), what, waited, heard: true, state } => {
                write!(
                    f,
                    "timeout: node {node} is alive (its frames arrive) but sent no {what} within {waited}"
                )?;
                match (what, state) {
                    // CiA 301 §7.3.2.2: no SDO in the stopped state.
                    (Waited::Sdo { .. }, Some(NmtState::Stopped)) => {
                        f.write_str("; it reports NMT state stopped, where it serves no SDO")
                    }
                    (_, Some(s)) => write!(f, "; its last NMT state: {s}"),
                    (_, None) => Ok(()),
                }
            }
            Self::Pdo { cob_id, reason } => {
                write!(f, "PDO 0x{:03X} does not pack: {reason}", cob_id.can_id())
            }
            Self::Unpack { cob_id, reason } => {
                write!(f, "PDO 0x{:03X} does not unpack: {reason}", cob_id.can_id())
            }
            Self::Lss(e) => write!(f, "LSS: {e}"),
            Self::Drive { node, error } => write!(f, "CiA 402 drive at node {node}: {error}"),
            Self::Invalid(what) => f.write_str(what),
        }
    }
}

impl<E: fmt::Display> fmt::Debug for Error<E> {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        fmt::Display::fmt(self, f)
    }
}

impl<E: fmt::Display> core::error::Error for Error<E> {}
