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
//! - [`drive`]: the simulated CiA 402 drive: the generated dictionary served by the runtime's
//!   `odc::node::Node`, with its `odc::cia402::Drive` (state machine, profile-position axis).
//!   The master stays here until the master runtime of the next issue takes its place.

pub mod bus;
pub mod drive;
pub mod master;

/// What can go wrong in an example: a closed bus, an SDO failure, a missing answer.
pub type Error = Box<dyn std::error::Error + Send + Sync>;
