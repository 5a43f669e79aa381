//! The SPI side of two ESC chips, emulated on the [`Esc`](super::esc::Esc): an
//! `embedded_hal::spi::SpiDevice` that decodes each chip-select frame as the chip would and
//! reads and writes the ESC through its [`Pdi`](super::esc::Pdi), so that odc's SPI adapters
//! (`odc::ethercat::esc_spi`) and the firmware stack above them run against the simulated
//! device. A frame the chip would not understand (a reserved command, a read without its
//! termination byte, a CSR access the LAN9252 does not take) fails the transaction with a
//! [`ChipError`] naming it, where the real chip would misbehave silently.
//!
//! - [`EscSpiChip`]: the SPI slave PDI of Beckhoff's ESCs;
//! - [`Lan9252Chip`]: Microchip's LAN9252 (its SPI instructions, system registers, the
//!   indirect ESC CSR access and the process RAM FIFOs).

mod beckhoff;
mod lan9252;

pub use beckhoff::EscSpiChip;
pub use lan9252::Lan9252Chip;

use embedded_hal::spi::Operation;

/// How a simulated device's firmware stack reaches its ESC.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum PdiPath {
    /// Register and RAM access as a parallel or on-chip PDI gives it.
    #[default]
    Direct,
    /// odc's `EscSpi` adapter on [`EscSpiChip`].
    EscSpi,
    /// odc's `Lan9252` adapter on [`Lan9252Chip`].
    Lan9252,
}

/// A frame the emulated chip refuses: what was wrong with it.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct ChipError(pub &'static str);

impl core::fmt::Display for ChipError {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        f.write_str(self.0)
    }
}

impl std::error::Error for ChipError {}

impl embedded_hal::spi::Error for ChipError {
    fn kind(&self) -> embedded_hal::spi::ErrorKind {
        embedded_hal::spi::ErrorKind::Other
    }
}

/// Clocks the operations of one frame through `byte` (MOSI in, MISO out), in order. MOSI
/// while reading is 0x00, as most SPI peripherals send (embedded-hal leaves it to them).
fn clock<F>(ops: &mut [Operation<'_, u8>], mut byte: F) -> Result<(), ChipError>
where
    F: FnMut(u8) -> Result<u8, ChipError>,
{
    for op in ops {
        match op {
            Operation::Read(buf) => {
                for b in buf.iter_mut() {
                    *b = byte(0x00)?;
                }
            }
            Operation::Write(data) => {
                for &b in data.iter() {
                    byte(b)?;
                }
            }
            Operation::Transfer(read, write) => {
                for k in 0..read.len().max(write.len()) {
                    let miso = byte(write.get(k).copied().unwrap_or(0x00))?;
                    if let Some(r) = read.get_mut(k) {
                        *r = miso;
                    }
                }
            }
            Operation::TransferInPlace(buf) => {
                for b in buf.iter_mut() {
                    *b = byte(*b)?;
                }
            }
            Operation::DelayNs(_) => {}
        }
    }
    Ok(())
}
