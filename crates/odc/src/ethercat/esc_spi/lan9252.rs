//! Microchip's LAN9252 on SPI (LAN9252 datasheet DS00001909: "SPI/SQI Slave" for the
//! instructions, "EtherCAT CSR and Process Data RAM Access" for the indirect access).
//!
//! The LAN9252's SPI reaches its own system registers (32 bits each, little endian) with the
//! instructions READ (0x03), FAST READ (0x0B, one dummy byte after the address) and WRITE
//! (0x02), a 16-bit address sent high byte first. The ESC's registers (0x0000–0x0FFF) lie
//! behind two of them: a command in ECAT_CSR_CMD (0x0304: busy, read/write, size 1/2/4,
//! address) moves 1, 2 or 4 bytes through ECAT_CSR_DATA (0x0300), and the adapter polls the
//! busy bit. The process RAM (0x1000 up) streams through FIFOs: an address and length in
//! ECAT_PRAM_RD/WR_ADDR_LEN (0x0308/0x0310), a start in ECAT_PRAM_RD/WR_CMD (0x030C/0x0314),
//! whose count field says how many 32-bit words the FIFO holds (read) or has room for
//! (write), the data through the FIFO ports at 0x0000 (read) and 0x0020 (write). The first
//! word carries the data from byte `address & 3` on.
//!
//! Bursts stay within the 32 bytes of a FIFO port (every address there is the port), so the
//! adapter needs no assumption on the chip's address increment.

use embedded_hal::spi::{Operation, SpiDevice};

use crate::ethercat::subdevice::Esc;

/// SPI instructions.
pub mod instruction {
    /// Read (with an address).
    pub const READ: u8 = 0x03;
    /// Fast read: the address, then one dummy byte.
    pub const FAST_READ: u8 = 0x0B;
    /// Write.
    pub const WRITE: u8 = 0x02;
}

/// System registers.
pub mod register {
    /// Process RAM read data FIFO (0x0000–0x001F).
    pub const PRAM_READ_FIFO: u16 = 0x0000;
    /// Process RAM write data FIFO (0x0020–0x003F).
    pub const PRAM_WRITE_FIFO: u16 = 0x0020;
    /// Chip ID and revision.
    pub const ID_REV: u16 = 0x0050;
    /// Byte order test: reads 0x8765_4321.
    pub const BYTE_TEST: u16 = 0x0064;
    /// Hardware configuration: bit 27 device ready.
    pub const HW_CFG: u16 = 0x0074;
    /// EtherCAT CSR interface data.
    pub const ECAT_CSR_DATA: u16 = 0x0300;
    /// EtherCAT CSR interface command.
    pub const ECAT_CSR_CMD: u16 = 0x0304;
    /// Process RAM read address and length.
    pub const ECAT_PRAM_RD_ADDR_LEN: u16 = 0x0308;
    /// Process RAM read command.
    pub const ECAT_PRAM_RD_CMD: u16 = 0x030C;
    /// Process RAM write address and length.
    pub const ECAT_PRAM_WR_ADDR_LEN: u16 = 0x0310;
    /// Process RAM write command.
    pub const ECAT_PRAM_WR_CMD: u16 = 0x0314;
}

/// BYTE_TEST's value.
pub const BYTE_TEST_VALUE: u32 = 0x8765_4321;
/// HW_CFG: the device is ready.
pub const HW_CFG_READY: u32 = 1 << 27;
/// ECAT_CSR_CMD: busy (write 1 to start).
pub const CSR_BUSY: u32 = 1 << 31;
/// ECAT_CSR_CMD: read (1) or write (0).
pub const CSR_READ: u32 = 1 << 30;
/// ECAT_PRAM_*_CMD: busy (write 1 to start).
pub const PRAM_BUSY: u32 = 1 << 31;
/// ECAT_PRAM_*_CMD: abort.
pub const PRAM_ABORT: u32 = 1 << 30;
/// ECAT_PRAM_*_CMD: data available (read) or space available (write).
pub const PRAM_AVAILABLE: u32 = 1;
/// The first address of the process RAM: below it the ESC's registers.
pub const PROCESS_RAM: u16 = 0x1000;
/// Words in a FIFO port's address range.
const PORT_WORDS: usize = 8;

/// What an access fails with.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Error<E> {
    /// The SPI transfer's.
    Spi(E),
    /// A command's busy bit (or the FIFO's count) did not come within the poll limit.
    Busy,
}

impl<E: core::fmt::Debug> core::fmt::Display for Error<E> {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        match self {
            Self::Spi(e) => write!(f, "SPI: {e:?}"),
            Self::Busy => f.write_str("LAN9252 command still busy after the poll limit"),
        }
    }
}

impl<E: core::fmt::Debug> core::error::Error for Error<E> {}

/// The firmware's side of a process RAM transfer: the buffer read into, or the data written.
enum Ram<'a> {
    Read(&'a mut [u8]),
    Write(&'a [u8]),
}

/// A LAN9252 on an SPI device.
#[derive(Debug)]
pub struct Lan9252<S> {
    spi: S,
    polls: u32,
}

impl<S: SpiDevice> Lan9252<S> {
    /// The LAN9252 behind `spi` (SPI mode 0 or 3), polling a command at most 1,000 times.
    pub fn new(spi: S) -> Self {
        Self { spi, polls: 1000 }
    }

    /// At most `polls` reads of a command register before [`Error::Busy`].
    #[must_use]
    pub fn with_poll_limit(mut self, polls: u32) -> Self {
        self.polls = polls.max(1);
        self
    }

    /// The SPI device back.
    pub fn release(self) -> S {
        self.spi
    }

    /// Whether the chip answers (BYTE_TEST reads its pattern) and is ready (HW_CFG bit 27):
    /// what a firmware waits for after reset before any other access.
    ///
    /// # Errors
    ///
    /// The SPI transfer's.
    pub fn ready(&mut self) -> Result<bool, Error<S::Error>> {
        Ok(self.read_register(register::BYTE_TEST)? == BYTE_TEST_VALUE
            && self.read_register(register::HW_CFG)? & HW_CFG_READY != 0)
    }

    /// A system register (FAST READ, one dummy byte).
    ///
    /// # Errors
    ///
    /// The SPI transfer's.
    pub fn read_register(&mut self, addr: u16) -> Result<u32, Error<S::Error>> {
        let mut word = [0u8; 4];
        self.read_words(addr, &mut word)?;
        Ok(u32::from_le_bytes(word))
    }

    /// Writes a system register.
    ///
    /// # Errors
    ///
    /// The SPI transfer's.
    pub fn write_register(&mut self, addr: u16, value: u32) -> Result<(), Error<S::Error>> {
        self.write_words(addr, &value.to_le_bytes())
    }

    /// One FAST READ of `buf.len()` bytes from `addr`.
    fn read_words(&mut self, addr: u16, buf: &mut [u8]) -> Result<(), Error<S::Error>> {
        let [hi, lo] = addr.to_be_bytes();
        let header = [instruction::FAST_READ, hi, lo, 0];
        self.spi
            .transaction(&mut [Operation::Write(&header), Operation::Read(buf)])
            .map_err(Error::Spi)
    }

    /// One WRITE of `data` at `addr`.
    fn write_words(&mut self, addr: u16, data: &[u8]) -> Result<(), Error<S::Error>> {
        let [hi, lo] = addr.to_be_bytes();
        let header = [instruction::WRITE, hi, lo];
        self.spi
            .transaction(&mut [Operation::Write(&header), Operation::Write(data)])
            .map_err(Error::Spi)
    }

    /// Reads `reg` until `done` says so, at most the poll limit; returns the last value.
    fn poll(&mut self, reg: u16, done: impl Fn(u32) -> bool) -> Result<u32, Error<S::Error>> {
        for _ in 0..self.polls {
            let v = self.read_register(reg)?;
            if done(v) {
                return Ok(v);
            }
        }
        Err(Error::Busy)
    }

    /// One indirect access of 1, 2 or 4 bytes to the ESC's registers; `data` in and out.
    fn csr(&mut self, addr: u16, data: &mut [u8], read: bool) -> Result<(), Error<S::Error>> {
        let size = u32::try_from(data.len()).unwrap_or(0) & 0x7;
        // The 1, 2 or 4 bytes as the low bytes of the data register, little-endian (shifts,
        // not slice copies: no `memcpy` call for 4 bytes).
        if !read {
            let word = data.iter().rev().fold(0u32, |w, &b| w << 8 | u32::from(b));
            self.write_register(register::ECAT_CSR_DATA, word)?;
        }
        let direction = if read { CSR_READ } else { 0 };
        let command = CSR_BUSY | direction | size << 16 | u32::from(addr);
        self.write_register(register::ECAT_CSR_CMD, command)?;
        self.poll(register::ECAT_CSR_CMD, |v| v & CSR_BUSY == 0)?;
        if read {
            let value = self.read_register(register::ECAT_CSR_DATA)?;
            for (k, d) in data.iter_mut().enumerate() {
                *d = (value >> (8 * (k % 4))) as u8;
            }
        }
        Ok(())
    }

    /// The ESC's registers in accesses the chip takes: 4 bytes at an address that is a
    /// multiple of 4, 2 at a multiple of 2, else 1 (the datasheet's table of CSR address
    /// against size).
    fn registers(&mut self, addr: u16, data: &mut [u8], read: bool) -> Result<(), Error<S::Error>> {
        let mut at = addr;
        let mut rest = data;
        while !rest.is_empty() {
            let size = match (at % 4, at % 2, rest.len()) {
                (0, _, 4..) => 4,
                (_, 0, 2..) => 2,
                _ => 1,
            };
            // `size` is at most `rest.len()` (not empty): always `Some`.
            let Some((chunk, tail)) = rest.split_at_mut_checked(size) else { break };
            self.csr(at, chunk, read)?;
            at = at.wrapping_add(u16::try_from(size).unwrap_or(1));
            rest = tail;
        }
        Ok(())
    }

    /// Starts a process RAM command: `addr_len` then `cmd`.
    fn start(
        &mut self,
        addr_len: u16,
        cmd: u16,
        addr: u16,
        len: usize,
    ) -> Result<(), Error<S::Error>> {
        let len = u32::try_from(len).unwrap_or(u32::MAX) & 0xFFFF;
        self.write_register(addr_len, len << 16 | u32::from(addr))?;
        self.write_register(cmd, PRAM_BUSY)
    }

    /// A process RAM transfer through the read or the write FIFO: one loop for both
    /// directions (the firmware links it once).
    fn ram(&mut self, addr: u16, mut io: Ram<'_>) -> Result<(), Error<S::Error>> {
        use register::{
            ECAT_PRAM_RD_ADDR_LEN, ECAT_PRAM_RD_CMD, ECAT_PRAM_WR_ADDR_LEN, ECAT_PRAM_WR_CMD,
        };
        let (len, addr_len, cmd_reg) = match &io {
            Ram::Read(buf) => (buf.len(), ECAT_PRAM_RD_ADDR_LEN, ECAT_PRAM_RD_CMD),
            Ram::Write(data) => (data.len(), ECAT_PRAM_WR_ADDR_LEN, ECAT_PRAM_WR_CMD),
        };
        let lead = usize::from(addr & 3);
        let total = (lead + len).div_ceil(4);
        self.start(addr_len, cmd_reg, addr, len)?;
        let mut done = 0usize;
        while done < total {
            // The count field: words the read FIFO holds, or the write FIFO has room for.
            let cmd = self.poll(cmd_reg, |v| v & PRAM_AVAILABLE != 0)?;
            let available = usize::try_from(cmd >> 8 & 0x1F).unwrap_or(0).max(1);
            let n = available.min(total - done).min(PORT_WORDS);
            let mut words = [0u8; 4 * PORT_WORDS];
            let words = words.get_mut(..4 * n).unwrap_or(&mut []);
            // The stream's byte k is the data's byte k - lead.
            let pos = |k: usize| (4 * done + k).checked_sub(lead);
            match &mut io {
                Ram::Read(buf) => {
                    self.read_words(register::PRAM_READ_FIFO, words)?;
                    for (k, &b) in words.iter().enumerate() {
                        if let Some(dst) = pos(k).and_then(|p| buf.get_mut(p)) {
                            *dst = b;
                        }
                    }
                }
                Ram::Write(data) => {
                    for (k, w) in words.iter_mut().enumerate() {
                        *w = pos(k).and_then(|p| data.get(p)).copied().unwrap_or(0);
                    }
                    self.write_words(register::PRAM_WRITE_FIFO, words)?;
                }
            }
            done += n;
        }
        Ok(())
    }
}

impl<S: SpiDevice> Esc for Lan9252<S> {
    type Error = Error<S::Error>;

    fn read(&mut self, addr: u16, buf: &mut [u8]) -> Result<(), Self::Error> {
        // Registers below the process RAM, the rest through the read FIFO.
        let split = usize::from(PROCESS_RAM.saturating_sub(addr)).min(buf.len());
        let (regs, ram) = buf.split_at_mut(split);
        if !regs.is_empty() {
            self.registers(addr, regs, true)?;
        }
        if !ram.is_empty() {
            self.ram(addr.max(PROCESS_RAM), Ram::Read(ram))?;
        }
        Ok(())
    }

    fn write(&mut self, addr: u16, data: &[u8]) -> Result<(), Self::Error> {
        let split = usize::from(PROCESS_RAM.saturating_sub(addr)).min(data.len());
        let (regs, ram) = data.split_at(split);
        let mut chunk = [0u8; 4];
        let mut at = addr;
        for part in regs.chunks(4) {
            // `registers` takes a mutable buffer (it serves reads too): a copy per 4 bytes.
            let c = chunk.get_mut(..part.len()).unwrap_or(&mut []);
            c.copy_from_slice(part);
            self.registers(at, c, false)?;
            at = at.wrapping_add(u16::try_from(part.len()).unwrap_or(4));
        }
        if !ram.is_empty() {
            self.ram(addr.max(PROCESS_RAM), Ram::Write(ram))?;
        }
        Ok(())
    }
}
