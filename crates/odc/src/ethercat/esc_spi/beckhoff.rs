//! The SPI slave interface of Beckhoff's ESCs (ET1100 / ET1200 / EtherCAT IP core
//! datasheets, section II, "SPI Slave Interface").
//!
//! An access is one chip-select frame: an address/command phase, then data. With 2-byte
//! addressing the phase carries address bits 12:0 and a 3-bit command; addresses above
//! 0x1FFF take a third byte (command "address extension" in the second byte, the real
//! command and address bits 15:13 in the third). While the master shifts the address phase
//! out, the ESC shifts the AL event request register (0x0220, 0x0221, 0x0222) in: the
//! adapter keeps it ([`EscSpi::last_al_event`]) and answers [`Esc::al_event`] with one such
//! phase (a NOP), without a register read and its side effects.
//!
//! Reads use "read with wait state byte" (0x03): a 0xFF byte after the address phase gives
//! the ESC its read time at any SPI clock. In the data phase the master sends 0x00 for each
//! byte but the last, and 0xFF (read termination) for the last: an ESC prefetches, and
//! without the termination it would read past the end (and a mailbox's last byte has side
//! effects).

use embedded_hal::spi::{Operation, SpiDevice};

use crate::ethercat::subdevice::Esc;

/// The commands (CMD0 in the second byte, CMD1 in the third with address extension).
pub mod command {
    /// No operation.
    pub const NOP: u8 = 0b000;
    /// Read.
    pub const READ: u8 = 0b010;
    /// Read with wait state byte.
    pub const READ_WAIT: u8 = 0b011;
    /// Write.
    pub const WRITE: u8 = 0b100;
    /// Address extension: a third address/command byte follows.
    pub const ADDRESS_EXTENSION: u8 = 0b110;
}

/// The byte the master sends after a READ_WAIT address phase.
pub const WAIT_STATE: u8 = 0xFF;
/// The byte the master sends with the last byte of a read.
pub const READ_TERMINATION: u8 = 0xFF;
/// The byte the master sends with every other byte of a read.
pub const READ_NEXT: u8 = 0x00;

/// The address/command phase of `command` at `addr`: 2 bytes for addresses up to 0x1FFF,
/// else 3 (address extension); returns the bytes and how many are used.
pub fn address_phase(addr: u16, command: u8) -> ([u8; 3], usize) {
    let [a12_5, _] = (addr >> 5).to_le_bytes();
    let [a4_0, _] = (addr & 0x1F).to_le_bytes();
    let cmd = command & 0x07;
    if addr <= 0x1FFF {
        ([a12_5, a4_0 << 3 | cmd, 0], 2)
    } else {
        let [a15_13, _] = (addr >> 13).to_le_bytes();
        // Byte 2: A[15:13], CMD1[2:0], two reserved bits sent as 0.
        ([a12_5, a4_0 << 3 | command::ADDRESS_EXTENSION, a15_13 << 5 | cmd << 2], 3)
    }
}

/// A Beckhoff ESC on an SPI device.
#[derive(Debug)]
pub struct EscSpi<S> {
    spi: S,
    al_event: u32,
}

impl<S: SpiDevice> EscSpi<S> {
    /// The ESC behind `spi` (SPI mode as the ESC's SII configures its PDI).
    pub fn new(spi: S) -> Self {
        Self { spi, al_event: 0 }
    }

    /// The SPI device back.
    pub fn release(self) -> S {
        self.spi
    }

    /// The AL event request bytes the last access's address phase delivered (bits 0–15, or
    /// 0–23 after an access with address extension).
    pub fn last_al_event(&self) -> u32 {
        self.al_event
    }

    fn keep_event(&mut self, event: [u8; 3]) {
        self.al_event = u32::from_le_bytes([event[0], event[1], event[2], 0]);
    }
}

impl<S: SpiDevice> Esc for EscSpi<S> {
    type Error = S::Error;

    fn read(&mut self, addr: u16, buf: &mut [u8]) -> Result<(), Self::Error> {
        if buf.is_empty() {
            return Ok(());
        }
        // 0x00 for every byte, 0xFF for the last: sent as the data phase is read in place.
        buf.fill(READ_NEXT);
        if let Some(last) = buf.last_mut() {
            *last = READ_TERMINATION;
        }
        let (phase, n) = address_phase(addr, command::READ_WAIT);
        let mut event = [0u8; 3];
        self.spi.transaction(&mut [
            Operation::Transfer(
                event.get_mut(..n).unwrap_or(&mut []),
                phase.get(..n).unwrap_or(&[]),
            ),
            Operation::Write(&[WAIT_STATE]),
            Operation::TransferInPlace(buf),
        ])?;
        self.keep_event(event);
        Ok(())
    }

    fn write(&mut self, addr: u16, data: &[u8]) -> Result<(), Self::Error> {
        if data.is_empty() {
            return Ok(());
        }
        let (phase, n) = address_phase(addr, command::WRITE);
        let mut event = [0u8; 3];
        self.spi.transaction(&mut [
            Operation::Transfer(
                event.get_mut(..n).unwrap_or(&mut []),
                phase.get(..n).unwrap_or(&[]),
            ),
            Operation::Write(data),
        ])?;
        self.keep_event(event);
        Ok(())
    }

    /// A NOP with address extension: its three address bytes shift out 0x0220–0x0222 (AL
    /// control, DC, SYNC, SM activation, EEPROM, watchdog and the 16 sync managers' events).
    fn al_event(&mut self) -> Result<u32, Self::Error> {
        let phase = [0, command::ADDRESS_EXTENSION, command::NOP << 2];
        let mut event = [0u8; 3];
        self.spi.transaction(&mut [Operation::Transfer(&mut event, &phase)])?;
        self.keep_event(event);
        Ok(self.al_event)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// ET1100 datasheet section II, "Address modes": 2-byte addressing is A[12:5], then
    /// A[4:0] with CMD0; 3-byte addressing puts 0b110 in CMD0 and A[15:13], CMD1 and two
    /// reserved zero bits in the third byte.
    #[test]
    fn address_phases() {
        // 0x0130 = 0b0_0001_0011_0000: A[12:5] = 0b0000_1001, A[4:0] = 0b10000.
        assert_eq!(address_phase(0x0130, command::READ_WAIT), ([0x09, 0b1000_0011, 0], 2));
        assert_eq!(address_phase(0x1FFF, command::WRITE), ([0xFF, 0b1111_1100, 0], 2));
        // 0x2001: A[15:13] = 0b001, A[12:5] = 0, A[4:0] = 0b00001.
        assert_eq!(address_phase(0x2001, command::READ), ([0x00, 0b0000_1110, 0b0010_1000], 3));
        assert_eq!(address_phase(0x2000, command::NOP), ([0x00, 0x06, 0x20], 3));
    }
}
