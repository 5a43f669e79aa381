//! The SII EEPROM interface, registers 0x0500–0x050F (ETG.1000.4 §6.4, the ESC datasheets'
//! "SII EEPROM interface"), over the image `odc_sii::write` made from the ESI.
//!
//! 0x0502 control/status: bit 0 write enable, bit 6 read size (1: 8 bytes), bit 7 address
//! algorithm (1: 2 address bytes, EEPROMs over 16 Kibit), bits 8–10 command (read 1, write
//! 2, reload 4), bit 11 checksum error, bit 13 command error, bit 14 write enable error,
//! bit 15 busy. 0x0504 is the word address, 0x0508 the data. The simulated EEPROM answers at
//! once: busy is never seen set.

use super::registers as reg;

const WRITE_ENABLE: u16 = 0x0001;
const READ_8_BYTES: u16 = 0x0040;
const TWO_ADDRESS_BYTES: u16 = 0x0080;
const READ: u16 = 0x0100;
const WRITE: u16 = 0x0200;
const RELOAD: u16 = 0x0400;
const CHECKSUM_ERROR: u16 = 0x0800;
const COMMAND_ERROR: u16 = 0x2000;
const WRITE_ENABLE_ERROR: u16 = 0x4000;

/// The EEPROM behind the interface.
#[derive(Debug)]
pub struct SiiPort {
    image: Vec<u8>,
}

impl SiiPort {
    /// An EEPROM holding `image`.
    pub fn new(image: Vec<u8>) -> Self {
        Self { image }
    }

    /// The image (as written since: the master may write words).
    pub fn image(&self) -> &[u8] {
        &self.image
    }

    fn word(&self, w: usize) -> u16 {
        match self.image.get(2 * w..2 * w + 2) {
            Some(&[lo, hi]) => u16::from_le_bytes([lo, hi]),
            // Past the image: an erased EEPROM.
            _ => 0xFFFF,
        }
    }

    /// Whether the info area's checksum (word 7, CRC-8 of bytes 0–13) holds: the ESC loads
    /// the PDI configuration only then, and sets DL status bit 0.
    pub fn loaded(&self) -> bool {
        self.image.get(..14).is_some_and(|b| u16::from(odc_sii::crc8(b)) == self.word(7) & 0xFF)
    }

    /// What the ESC loads at power-on: PDI control (word 0), PDI configuration (word 1) and
    /// the station alias (word 4); zeros when the checksum fails.
    pub fn power_on_words(&self) -> (u16, u16, u16) {
        match self.loaded() {
            true => (self.word(0), self.word(1), self.word(4)),
            false => (0, 0, 0),
        }
    }

    /// The control register's value between commands.
    pub fn control_idle(&self) -> u16 {
        let wide = if self.image.len() > 2048 { TWO_ADDRESS_BYTES } else { 0 };
        let crc = if self.loaded() { 0 } else { CHECKSUM_ERROR };
        READ_8_BYTES | wide | crc
    }

    /// Runs the command just written to 0x0502 (the registers are in `mem`).
    pub fn command(&mut self, mem: &mut [u8]) {
        let at = |a: u16| usize::from(a);
        let get = |mem: &[u8], a: u16| {
            u16::from_le_bytes([
                mem.get(at(a)).copied().unwrap_or(0),
                mem.get(at(a) + 1).copied().unwrap_or(0),
            ])
        };
        let control = get(mem, reg::SII_CONTROL);
        let address = usize::from(get(mem, reg::SII_ADDRESS));
        let mut status = self.control_idle();
        match control & (READ | WRITE | RELOAD) {
            0 => {}
            READ => {
                let data = at(reg::SII_DATA);
                for i in 0..4 {
                    let w = self.word(address + i).to_le_bytes();
                    if let Some(dst) = mem.get_mut(data + 2 * i..data + 2 * i + 2) {
                        dst.copy_from_slice(&w);
                    }
                }
            }
            WRITE if control & WRITE_ENABLE == 0 => status |= WRITE_ENABLE_ERROR,
            WRITE => {
                let data = at(reg::SII_DATA);
                let w =
                    [mem.get(data).copied().unwrap_or(0), mem.get(data + 1).copied().unwrap_or(0)];
                match self.image.get_mut(2 * address..2 * address + 2) {
                    Some(dst) => dst.copy_from_slice(&w),
                    None => status |= COMMAND_ERROR,
                }
            }
            // Reload: the ESC takes the alias again (read by the master at 0x0012).
            RELOAD => {
                let alias = self.power_on_words().2.to_le_bytes();
                if let Some(dst) = mem.get_mut(at(reg::STATION_ALIAS)..at(reg::STATION_ALIAS) + 2) {
                    dst.copy_from_slice(&alias);
                }
            }
            // More than one command at once.
            _ => status |= COMMAND_ERROR,
        }
        if let Some(dst) = mem.get_mut(at(reg::SII_CONTROL)..at(reg::SII_CONTROL) + 2) {
            dst.copy_from_slice(&status.to_le_bytes());
        }
    }
}
