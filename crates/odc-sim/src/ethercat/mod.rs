//! A simulated EtherCAT SubDevice: an emulated EtherCAT slave controller (ESC) around the
//! [`ModelDictionary`](crate::ModelDictionary) and the SII image of an ESI device, so that
//! any master can be tested against a device made from the ESI it will ship with.
//!
//! Hand-written because no maintained Rust crate emulates an ESC: the EtherCAT crates are
//! masters (ethercrab, SOEM bindings) or SubDevice stacks for real ESC chips, which need the
//! chip. What is emulated is what a master sees:
//!
//! - [`frame`]: the frame and datagram codec;
//! - [`esc`]: the address space and the execution of the 14 datagram commands, with the
//!   working counter and the position auto-increment; [`registers`] the register map;
//! - [`sii`]: the EEPROM interface over `odc_sii::write`'s image; [`dc`]: distributed
//!   clocks as far as a master's set-up reads and writes them;
//! - [`info`]: the descriptions SDO Information serves, from the model;
//! - [`SubDevice`] runs the firmware stack (or, for an ESC without a microcontroller, whose
//!   SII sets device emulation, none: AL status follows AL control and the fixed PDOs stand
//!   for its I/O pins), [`odc::ethercat::subdevice`] (AL state machine,
//!   mailbox with CoE, process data), on the emulated ESC through its PDI ([`esc::Pdi`]),
//!   with a CiA 402 drive when the device is one; [`Chain`]
//!   runs a frame through several in a line; `EthercrabLink` (feature `ethercrab`) wires
//!   a chain to an ethercrab master in the same process;
//! - [`spi`]: the SPI side of two ESC chips (Beckhoff's SPI PDI, the LAN9252) for odc's SPI
//!   adapters; [`SubDevice::with_pdi`] runs the firmware stack through one.
//!
//! Simplifications, each visible to a master only in timing: an ESC answers at once (the
//! SII is never busy, a mailbox reply is ready when the request is written), process data
//! sync managers have one buffer, and a DC clock takes the reference's time at the first
//! comparison instead of through a control loop. FMMUs map bits (a master may pack devices
//! of fewer than 8 bits into shared bytes). Not
//! emulated: the mailbox repeat request (SM activate bit 1), the watchdogs' expiry, SYNC
//! pulses and latches, EoE/FoE/SoE (answered with the mailbox error "unsupported protocol").

mod chain;
pub mod dc;
mod device;
pub mod esc;
pub mod frame;
pub mod info;
#[cfg(feature = "ethercrab")]
mod link;
pub mod registers;
pub mod sii;
pub mod spi;

pub use chain::{Chain, HOP_NS};
pub use device::SubDevice;
#[cfg(feature = "ethercrab")]
pub use link::{Carried, EthercrabLink};
