//! The SPI slave PDI of Beckhoff's ESCs (ET1100/ET1200/IP core datasheets, section II, "SPI
//! Slave Interface"), as the ESC decodes a frame: the address/command phase (2 bytes, or 3
//! with address extension) while the AL event request register shifts out, the wait state
//! byte of READ_WAIT, data read with 0x00 on MOSI until the 0xFF of read termination, data
//! written.

use embedded_hal::spi::{ErrorType, Operation, SpiDevice};
use odc::ethercat::subdevice::Esc as _;

use super::{ChipError, clock};
use crate::ethercat::esc::Pdi;

/// A Beckhoff ESC's SPI slave interface on the emulated ESC.
#[derive(Debug)]
pub struct EscSpiChip<'a> {
    pdi: Pdi<'a>,
}

impl<'a> EscSpiChip<'a> {
    /// The SPI slave interface of the ESC behind `pdi`.
    pub fn new(pdi: Pdi<'a>) -> Self {
        Self { pdi }
    }
}

/// Where a frame is.
enum Phase {
    /// Address/command bytes so far.
    Address { bytes: [u8; 3], n: usize },
    /// READ_WAIT: the wait state byte comes next.
    Wait { addr: u16 },
    /// Reading at `addr`; `terminated` once the 0xFF came.
    Read { addr: u16, terminated: bool },
    /// Writing at `addr`.
    Write { addr: u16 },
    /// A NOP: the rest of the frame is ignored.
    Nop,
}

const NOP: u8 = 0b000;
const READ: u8 = 0b010;
const READ_WAIT: u8 = 0b011;
const WRITE: u8 = 0b100;
const ADDRESS_EXTENSION: u8 = 0b110;

impl EscSpiChip<'_> {
    fn start(command: u8, addr: u16) -> Result<Phase, ChipError> {
        match command {
            NOP => Ok(Phase::Nop),
            READ => Ok(Phase::Read { addr, terminated: false }),
            READ_WAIT => Ok(Phase::Wait { addr }),
            WRITE => Ok(Phase::Write { addr }),
            _ => Err(ChipError("reserved SPI command")),
        }
    }

    /// One byte of the frame: MOSI in, MISO out.
    fn byte(&mut self, phase: &mut Phase, event: [u8; 4], mosi: u8) -> Result<u8, ChipError> {
        match phase {
            Phase::Address { bytes, n } => {
                let miso = event.get(*n).copied().unwrap_or(0);
                if let Some(b) = bytes.get_mut(*n) {
                    *b = mosi;
                }
                *n += 1;
                let low = u16::from(bytes[0]) << 5 | u16::from(bytes[1] >> 3);
                match (*n, bytes[1] & 0x07) {
                    (2, ADDRESS_EXTENSION) => {}
                    (2, command) => *phase = Self::start(command, low)?,
                    (3, _) => {
                        if bytes[2] & 0x03 != 0 {
                            return Err(ChipError("reserved bits of the third address byte set"));
                        }
                        let addr = low | u16::from(bytes[2] >> 5) << 13;
                        let command = bytes[2] >> 2 & 0x07;
                        if command == ADDRESS_EXTENSION {
                            return Err(ChipError("address extension in the third byte"));
                        }
                        *phase = Self::start(command, addr)?;
                    }
                    _ => {}
                }
                Ok(miso)
            }
            Phase::Wait { addr } => {
                if mosi != 0xFF {
                    return Err(ChipError("wait state byte is not 0xFF"));
                }
                *phase = Phase::Read { addr: *addr, terminated: false };
                Ok(0xFF)
            }
            Phase::Read { addr, terminated } => {
                if *terminated {
                    return Err(ChipError("read data after the read termination byte"));
                }
                match mosi {
                    0xFF => *terminated = true,
                    0x00 => {}
                    _ => return Err(ChipError("read data byte neither 0x00 nor 0xFF")),
                }
                let mut b = [0u8];
                let Ok(()) = self.pdi.read(*addr, &mut b);
                *addr = addr.wrapping_add(1);
                Ok(b[0])
            }
            Phase::Write { addr } => {
                let Ok(()) = self.pdi.write(*addr, &[mosi]);
                *addr = addr.wrapping_add(1);
                Ok(0)
            }
            Phase::Nop => Ok(0),
        }
    }
}

impl ErrorType for EscSpiChip<'_> {
    type Error = ChipError;
}

impl SpiDevice for EscSpiChip<'_> {
    fn transaction(&mut self, operations: &mut [Operation<'_, u8>]) -> Result<(), ChipError> {
        // The AL event request as the frame starts shifts out with the address phase.
        let event = self.pdi.0.al_event().to_le_bytes();
        let mut phase = Phase::Address { bytes: [0; 3], n: 0 };
        clock(operations, |mosi| self.byte(&mut phase, event, mosi))?;
        match phase {
            Phase::Address { .. } => Err(ChipError("frame ended in the address phase")),
            Phase::Wait { .. } => Err(ChipError("frame ended before the wait state byte")),
            Phase::Read { terminated: false, .. } => {
                Err(ChipError("read ended without the read termination byte 0xFF"))
            }
            _ => Ok(()),
        }
    }
}
