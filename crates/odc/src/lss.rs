//! LSS, layer setting services (CiA 305): a master sets a node's node-ID and bit timing over
//! the bus, identified by its LSS address (the four numbers of 0x1018).
//!
//! - [`frame`]: the codec of both directions, [`Request`] (master → slave, CAN-ID 0x7E5) and
//!   [`Response`] (slave → master, 0x7E4), for a slave here and a master later;
//! - [`LssSlave`]: the slave's state machine, `no_std` and heap-free. It answers frames and
//!   tells the node what to do ([`LssEvent`]); the node owns the node-ID, the CAN controller and
//!   the non-volatile storage.

pub mod frame;
mod slave;

pub use frame::{Request, Response};
#[cfg(feature = "lss-slave")]
pub use slave::LssSlave;
pub use slave::{Identity, LssEvent, LssState, StoreResult};

use crate::can::StdId;

/// CAN-ID of LSS requests, master → slave.
pub const REQUEST_ID: StdId = StdId::masked(0x7E5);
/// CAN-ID of LSS responses, slave → master.
pub const RESPONSE_ID: StdId = StdId::masked(0x7E4);
/// The node-ID of a slave that has none ("unconfigured", CiA 305).
pub use crate::cob::UNCONFIGURED;
