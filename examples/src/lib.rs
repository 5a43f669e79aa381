//! Drives on a simulated CAN bus, for the example programs beside this crate
//! (`cargo run --example lxm23a`, `lexium_mdrive`, `servoone`, `linmot`).
//!
//! Each example includes the code odc generates from one device file twice over: the master
//! side (descriptors, PDO structs, the configuration plan) drives the bus, and the slave side
//! (the `no_std` object dictionary) is the heart of a simulated drive on the other end. The
//! two run in two threads and talk through [`bus`], a pair of channels carrying
//! [`odc::can::CanFrame`]s; the master prints every frame.
//!
//! - [`bus`]: the channels, and how a frame is printed;
//! - [`master`]: the controller: NMT, SYNC, PDOs, odc's SDO client, the CiA 402 walk to
//!   "operation enabled" and a profile-position move;
//! - [`drive`]: the simulated CiA 402 drive: NMT, odc's SDO server on the generated dictionary,
//!   PDOs as the dictionary maps them, the state machine and a profile-position axis;
//! - [`pdo`]: reading and writing process data through any [`odc::slave::ObjectDictionary`],
//!   following the mapping objects the master configured.

pub mod bus;
pub mod drive;
pub mod master;
pub mod pdo;

/// What can go wrong in an example: a closed bus, an SDO failure, a missing answer.
pub type Error = Box<dyn std::error::Error + Send + Sync>;
