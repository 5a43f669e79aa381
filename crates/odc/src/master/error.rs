//! Why a master operation failed.

use std::fmt;

use super::lss;
use crate::cob::{CobId, NodeId};
use crate::plan::SdoWrite;
use crate::sdo::SdoError;

/// Why a master operation failed.
#[derive(Debug)]
pub enum Error<E> {
    /// The bus failed.
    Bus(E),
    /// An SDO transfer failed: the server's abort or this client's (timeout, protocol).
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
        /// What was waited for.
        what: &'static str,
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
    /// A CiA 402 job failed (fault, timeout, mode refused, …).
    Drive(crate::cia402::DriverError),
    /// A node-ID outside 1..=127, or an argument the protocol cannot carry.
    Invalid(&'static str),
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
            Self::Timeout { what } => write!(f, "timeout: no {what}"),
            Self::Pdo { cob_id, reason } => {
                write!(f, "PDO 0x{:03X} does not pack: {reason:?}", cob_id.can_id())
            }
            Self::Unpack { cob_id, reason } => {
                write!(f, "PDO 0x{:03X} does not unpack: {reason:?}", cob_id.can_id())
            }
            Self::Lss(e) => write!(f, "LSS: {e}"),
            Self::Drive(e) => write!(f, "CiA 402: {e}"),
            Self::Invalid(what) => f.write_str(what),
        }
    }
}

impl<E: fmt::Debug + fmt::Display> core::error::Error for Error<E> {}
