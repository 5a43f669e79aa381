//! [`Esc`](super::subdevice::Esc) over SPI (feature `esc-spi`): the PDI adapters a firmware
//! puts between [`SubDevice`](super::subdevice::SubDevice) and its EtherCAT slave controller,
//! on any `embedded-hal` 1.0 [`SpiDevice`](embedded_hal::spi::SpiDevice) (the HAL's SPI
//! peripheral with its chip-select pin).
//!
//! - [`beckhoff::EscSpi`]: the SPI slave PDI of Beckhoff's ESCs (ET1100, ET1200, the ESC IP
//!   cores): address/command phases with the AL event request shifted out, read termination;
//! - [`lan9252::Lan9252`]: Microchip's LAN9252, whose ESC registers sit behind its own SPI
//!   instructions and system registers (indirect CSR access, process RAM FIFOs).
//!
//! Each is tested against an emulation of its chip on odc-sim's ESC
//! (`crates/odc-sim/tests/it/ethercat_spi.rs`), frames checked against the datasheets' tables.

pub mod beckhoff;
pub mod lan9252;
