//! Microchip's LAN9252 on SPI (datasheet DS00001909), as far as a firmware's PDI driver
//! uses it: the SPI instructions READ (0x03), FAST READ (0x0B, one dummy byte) and WRITE
//! (0x02) on 32-bit little-endian system registers; BYTE_TEST, HW_CFG and ID_REV; the
//! indirect access to the ESC's registers (ECAT_CSR_CMD/DATA, 1, 2 or 4 bytes at an address
//! aligned to the size); the process RAM through the read and write FIFOs (ECAT_PRAM_RD/WR
//! ADDR_LEN and CMD, data at 0x0000 and 0x0020, the first word from byte `address & 3`).
//!
//! A command runs at once, but its busy bit (or FIFO count) reads as not done for the first
//! `busy_reads` polls, so a driver that does not poll is caught. The FIFOs hold 16 words, as
//! the chip's do: a driver must follow the count field.

use std::collections::VecDeque;

use embedded_hal::spi::{ErrorType, Operation, SpiDevice};
use odc::ethercat::subdevice::Esc as _;

use super::{ChipError, clock};
use crate::ethercat::esc::Pdi;

const READ: u8 = 0x03;
const FAST_READ: u8 = 0x0B;
const WRITE: u8 = 0x02;

const ID_REV: u16 = 0x0050;
const BYTE_TEST: u16 = 0x0064;
const HW_CFG: u16 = 0x0074;
const CSR_DATA: u16 = 0x0300;
const CSR_CMD: u16 = 0x0304;
const PRAM_RD_ADDR_LEN: u16 = 0x0308;
const PRAM_RD_CMD: u16 = 0x030C;
const PRAM_WR_ADDR_LEN: u16 = 0x0310;
const PRAM_WR_CMD: u16 = 0x0314;

const BUSY: u32 = 1 << 31;
const CSR_READ: u32 = 1 << 30;
const PRAM_ABORT: u32 = 1 << 30;
/// Words a FIFO holds.
const FIFO_WORDS: usize = 16;

/// A process RAM transfer in progress.
#[derive(Debug, Default)]
struct Pram {
    active: bool,
    addr: u16,
    len: usize,
    /// Read: the words still to be taken; write: the words received.
    words: VecDeque<u32>,
    /// Write: words still expected.
    expected: usize,
}

/// A LAN9252 on the emulated ESC.
#[derive(Debug)]
pub struct Lan9252Chip<'a> {
    pdi: Pdi<'a>,
    csr_data: u32,
    csr_cmd: u32,
    rd_addr_len: u32,
    wr_addr_len: u32,
    rd: Pram,
    wr: Pram,
    busy_reads: u32,
    /// Polls left before the current command reads as done.
    pending: u32,
}

/// Where a frame is.
enum Phase {
    Instruction,
    Address { instruction: u8, hi: Option<u8> },
    Dummy { addr: u16 },
    Read { addr: u16, word: Option<[u8; 4]> },
    Write { addr: u16, word: [u8; 4], n: usize },
}

impl<'a> Lan9252Chip<'a> {
    /// The LAN9252 around the ESC behind `pdi`; a command reads as busy once.
    pub fn new(pdi: Pdi<'a>) -> Self {
        Self {
            pdi,
            csr_data: 0,
            csr_cmd: 0,
            rd_addr_len: 0,
            wr_addr_len: 0,
            rd: Pram::default(),
            wr: Pram::default(),
            busy_reads: 1,
            pending: 0,
        }
    }

    /// A command reads as busy for `n` polls.
    #[must_use]
    pub fn with_busy_reads(mut self, n: u32) -> Self {
        self.busy_reads = n;
        self
    }

    /// A system register as the SPI reads it.
    fn read_register(&mut self, addr: u16) -> Result<u32, ChipError> {
        Ok(match addr {
            0x0000..=0x001F => {
                if !self.rd.active || self.pending > 0 {
                    return Err(ChipError("read FIFO read while it holds no data"));
                }
                let w = self.rd.words.pop_front().ok_or(ChipError("read FIFO underrun"))?;
                self.rd.active = !self.rd.words.is_empty();
                w
            }
            ID_REV => 0x9252_0001,
            BYTE_TEST => 0x8765_4321,
            HW_CFG => 1 << 27,
            CSR_DATA => self.csr_data,
            CSR_CMD => self.poll(self.csr_cmd & !BUSY, self.csr_cmd),
            PRAM_RD_ADDR_LEN => self.rd_addr_len,
            PRAM_WR_ADDR_LEN => self.wr_addr_len,
            PRAM_RD_CMD => {
                let n = self.rd.words.len().min(FIFO_WORDS);
                let busy = if self.rd.active { BUSY } else { 0 };
                let ready = u32::try_from(n).unwrap_or(0) << 8 | u32::from(n > 0);
                self.poll(busy | ready, BUSY)
            }
            PRAM_WR_CMD => {
                let room = self.wr.expected.saturating_sub(self.wr.words.len()).min(FIFO_WORDS);
                let busy = if self.wr.active { BUSY } else { 0 };
                let ready = u32::try_from(room).unwrap_or(0) << 8 | u32::from(room > 0);
                self.poll(busy | ready, BUSY)
            }
            _ => 0,
        })
    }

    /// `done`, or while polls are pending `busy` (busy, no count, nothing available).
    fn poll(&mut self, done: u32, busy: u32) -> u32 {
        if self.pending > 0 {
            self.pending -= 1;
            return busy;
        }
        done
    }

    fn write_register(&mut self, addr: u16, v: u32) -> Result<(), ChipError> {
        match addr {
            0x0020..=0x003F => self.fifo_write(v)?,
            CSR_DATA => self.csr_data = v,
            CSR_CMD => self.csr(v)?,
            PRAM_RD_ADDR_LEN => self.rd_addr_len = v,
            PRAM_WR_ADDR_LEN => self.wr_addr_len = v,
            PRAM_RD_CMD => self.pram_read(v)?,
            PRAM_WR_CMD => self.pram_write(v)?,
            _ => {}
        }
        Ok(())
    }

    /// ECAT_CSR_CMD: bit 31 start, bit 30 read, bits 18:16 size, bits 15:0 address.
    fn csr(&mut self, v: u32) -> Result<(), ChipError> {
        if v & BUSY == 0 {
            return Ok(());
        }
        let size = usize::try_from(v >> 16 & 0x07).unwrap_or(0);
        let addr = u16::try_from(v & 0xFFFF).unwrap_or(0);
        if !matches!(size, 1 | 2 | 4) {
            return Err(ChipError("CSR size other than 1, 2 or 4"));
        }
        if usize::from(addr) % size != 0 {
            return Err(ChipError("CSR address not aligned to its size"));
        }
        if addr >= 0x1000 {
            return Err(ChipError("CSR access to the process RAM"));
        }
        let mut word = self.csr_data.to_le_bytes();
        let bytes = word.get_mut(..size).ok_or(ChipError("CSR size"))?;
        if v & CSR_READ != 0 {
            let Ok(()) = self.pdi.read(addr, bytes);
            word.get_mut(size..).into_iter().flatten().for_each(|b| *b = 0);
            self.csr_data = u32::from_le_bytes(word);
        } else {
            let Ok(()) = self.pdi.write(addr, bytes);
        }
        self.csr_cmd = v;
        self.pending = self.busy_reads;
        Ok(())
    }

    fn pram_read(&mut self, v: u32) -> Result<(), ChipError> {
        if v & PRAM_ABORT != 0 {
            self.rd = Pram::default();
            return Ok(());
        }
        if v & BUSY == 0 {
            return Ok(());
        }
        let (addr, len) = addr_len(self.rd_addr_len)?;
        let lead = usize::from(addr & 3);
        let mut bytes = vec![0u8; (lead + len).div_ceil(4) * 4];
        // The ESC's side effects (a mailbox emptied) as the chip fetches the data.
        let Ok(()) = self.pdi.read(addr, bytes.get_mut(lead..lead + len).unwrap_or(&mut []));
        let words =
            bytes.chunks_exact(4).map(|c| u32::from_le_bytes([c[0], c[1], c[2], c[3]])).collect();
        self.rd = Pram { active: true, addr, len, words, expected: 0 };
        self.pending = self.busy_reads;
        Ok(())
    }

    fn pram_write(&mut self, v: u32) -> Result<(), ChipError> {
        if v & PRAM_ABORT != 0 {
            self.wr = Pram::default();
            return Ok(());
        }
        if v & BUSY == 0 {
            return Ok(());
        }
        let (addr, len) = addr_len(self.wr_addr_len)?;
        let expected = (usize::from(addr & 3) + len).div_ceil(4);
        self.wr = Pram { active: true, addr, len, words: VecDeque::new(), expected };
        self.pending = self.busy_reads;
        Ok(())
    }

    fn fifo_write(&mut self, v: u32) -> Result<(), ChipError> {
        if !self.wr.active || self.pending > 0 {
            return Err(ChipError("write FIFO written without space available"));
        }
        if self.wr.words.len() >= self.wr.expected {
            return Err(ChipError("write FIFO overrun"));
        }
        self.wr.words.push_back(v);
        if self.wr.words.len() == self.wr.expected {
            let bytes: Vec<u8> = self.wr.words.iter().flat_map(|w| w.to_le_bytes()).collect();
            let lead = usize::from(self.wr.addr & 3);
            let data = bytes.get(lead..lead + self.wr.len).unwrap_or(&[]);
            let Ok(()) = self.pdi.write(self.wr.addr, data);
            self.wr = Pram::default();
        }
        Ok(())
    }

    /// One byte of the frame: MOSI in, MISO out.
    fn byte(&mut self, phase: &mut Phase, mosi: u8) -> Result<u8, ChipError> {
        match phase {
            Phase::Instruction => {
                if !matches!(mosi, READ | FAST_READ | WRITE) {
                    return Err(ChipError("SPI instruction not emulated"));
                }
                *phase = Phase::Address { instruction: mosi, hi: None };
            }
            Phase::Address { instruction, hi: None } => {
                *phase = Phase::Address { instruction: *instruction, hi: Some(mosi) };
            }
            Phase::Address { instruction, hi: Some(hi) } => {
                // Bits 15:14 select the address mode; the register is bits 13:0.
                let addr = u16::from_be_bytes([*hi & 0x3F, mosi]);
                *phase = match *instruction {
                    FAST_READ => Phase::Dummy { addr },
                    READ => Phase::Read { addr, word: None },
                    _ => Phase::Write { addr, word: [0; 4], n: 0 },
                };
            }
            Phase::Dummy { addr } => *phase = Phase::Read { addr: *addr, word: None },
            Phase::Read { addr, word } => {
                // A register is fetched as its first byte is clocked out.
                let current = match word {
                    Some(w) if *addr & 3 != 0 => *w,
                    _ => self.read_register(*addr & !3)?.to_le_bytes(),
                };
                *word = Some(current);
                let b = current.get(usize::from(*addr & 3)).copied().unwrap_or(0);
                *addr = addr.wrapping_add(1);
                return Ok(b);
            }
            Phase::Write { addr, word, n } => {
                if let Some(w) = word.get_mut(usize::from(*addr & 3)) {
                    *w = mosi;
                }
                *n += 1;
                if *addr & 3 == 3 {
                    self.write_register(*addr & !3, u32::from_le_bytes(*word))?;
                    *n = 0;
                }
                *addr = addr.wrapping_add(1);
            }
        }
        Ok(0)
    }
}

/// ECAT_PRAM_*_ADDR_LEN: bits 31:16 length, bits 15:0 address (in the process RAM).
fn addr_len(v: u32) -> Result<(u16, usize), ChipError> {
    let addr = u16::try_from(v & 0xFFFF).unwrap_or(0);
    let len = usize::try_from(v >> 16).unwrap_or(0);
    if addr < 0x1000 || usize::from(addr) + len > crate::ethercat::registers::MEMORY {
        return Err(ChipError("process RAM FIFO address outside the process RAM"));
    }
    if len == 0 {
        return Err(ChipError("process RAM FIFO length 0"));
    }
    Ok((addr, len))
}

impl ErrorType for Lan9252Chip<'_> {
    type Error = ChipError;
}

impl SpiDevice for Lan9252Chip<'_> {
    fn transaction(&mut self, operations: &mut [Operation<'_, u8>]) -> Result<(), ChipError> {
        let mut phase = Phase::Instruction;
        clock(operations, |mosi| self.byte(&mut phase, mosi))?;
        match phase {
            Phase::Instruction | Phase::Read { .. } => Ok(()),
            Phase::Write { n: 0, .. } => Ok(()),
            Phase::Write { .. } => Err(ChipError("write ended within a register")),
            Phase::Address { .. } | Phase::Dummy { .. } => {
                Err(ChipError("frame ended before its data"))
            }
        }
    }
}
