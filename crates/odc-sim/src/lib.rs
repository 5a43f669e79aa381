//! Device simulation for odc: any device file becomes a live device to test a master against.
//!
//! - [`ModelDictionary`]: the object dictionary of a device, built from its model at run time
//!   with the semantics of the generated `slave::Dictionary` (so a file needs no build step
//!   to be served);
//! - [`SimDevice`]: the dictionary as a node (boot-up, NMT, SDO server); CiA 402 drives run
//!   [`odc::cia402::Drive`] over it (the state machine and a simple axis);
//! - [`VirtualBus`]: a CAN bus over TCP on which every client is a node, with the devices on
//!   it (`odc simulate --tcp`, and `--socketcand` for socketcand's protocol, [`socketcand`]);
//!   [`nodes`]: several devices on one bus.
//!
//! - [`ethercat`]: an emulated EtherCAT SubDevice (ESC, SII, AL state machine, CoE, process
//!   data) built from an ESI device, and a [`Chain`](ethercat::Chain) of them that a master's
//!   frames pass through.
//!
//! A crate of its own because simulation is std-only and model-driven, unlike the `no_std`
//! runtime.
#![cfg_attr(not(test), deny(clippy::unwrap_used, clippy::expect_used, clippy::panic))]

mod bus;
mod device;
mod dictionary;
pub mod ethercat;
#[cfg(target_os = "linux")]
mod ethernet;
pub mod nodes;
pub mod socketcand;
mod value;

pub use bus::{StopHandle, TICK, VirtualBus};
pub use device::{SDO_BUFFER, SimDevice, run_all_on_bus, run_on_bus};
pub use dictionary::ModelDictionary;
#[cfg(target_os = "linux")]
pub use ethernet::{ETHERTYPE_ETHERCAT, EthernetEndpoint, Served};
