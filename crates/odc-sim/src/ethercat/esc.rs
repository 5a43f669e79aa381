//! The ESC: its address space and the execution of a datagram as it passes (ETG.1000.4
//! §5.4–5.5): addressing (position with auto-increment, station address, broadcast, logical
//! through the FMMUs), the read, write and read-write semantics, and the working counter.
//!
//! Working counter (ETG.1000.4 Table 7): a device that reads adds 1, one that writes adds 1,
//! and for the read-write commands (APRW, FPRW, BRW, LRW) a read adds 1 and a write 2. ARMW
//! and FRMW: the addressed device reads (1), every other one writes (1). An access the sync
//! managers refuse (a full write mailbox, an empty read mailbox) does nothing and adds 0.
//!
//! What the application (the device's firmware) does with what was written is not here: the
//! ESC raises the AL event request register (0x0220) as a real one does, and the firmware
//! stack reads it and the rest through [`Pdi`], the application side of the ESC.

use super::dc::Clock;
use super::frame::{Command, Datagram};
use super::registers::{self as reg, MEMORY, ecat_writable};
use super::sii::SiiPort;

/// A sync manager's registers (0x0800 + 8n) and its status bit "mailbox full": the same
/// layout the device stack reads.
pub use odc::ethercat::subdevice::al::{SM_FULL, SmRegs};

/// The process memory a sync manager covers.
fn sm_range(sm: &SmRegs) -> core::ops::Range<usize> {
    usize::from(sm.start)..usize::from(sm.start) + usize::from(sm.len)
}

/// The ESC of one device: 4 KiB of registers and the process RAM.
#[derive(Debug)]
pub struct Esc {
    mem: Vec<u8>,
    pub(super) sii: SiiPort,
    pub(super) clock: Clock,
}

/// Where the frame meets this device: the times its ports see it (the simulation's ns).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct Passing {
    /// When it arrives at port 0.
    pub arrival_ns: u64,
    /// When it comes back through port 1 (`None`: port 1 closed, the end of the line).
    pub port1_ns: Option<u64>,
}

impl Esc {
    /// An ESC at power-on with the EEPROM `image` loaded; `clock_base_ns` is where its
    /// local clock stands when the simulation's starts.
    pub fn new(image: Vec<u8>, clock_base_ns: u64, downstream: bool) -> Self {
        let mut esc = Self {
            mem: vec![0; MEMORY],
            sii: SiiPort::new(image),
            clock: Clock::new(clock_base_ns),
        };
        esc.power_on(downstream);
        esc
    }

    /// The ESC with `kib` KiB of process RAM (1 to [`reg::MAX_RAM_KIB`]) instead of the
    /// default [`reg::RAM_KIB`], as it powers on: register 0x0006 says the size, and the
    /// memory behind the sync managers and FMMUs ends there (an access beyond it is not
    /// counted in the working counter).
    #[must_use]
    pub fn with_ram_kib(mut self, kib: u8) -> Self {
        let kib = kib.clamp(1, reg::MAX_RAM_KIB);
        self.mem.resize(usize::from(reg::PROCESS_RAM) + usize::from(kib) * 1024, 0);
        self.set_u8(reg::RAM_SIZE, kib);
        self
    }

    /// The process RAM in KiB (register 0x0006).
    pub fn ram_kib(&self) -> u8 {
        self.u8(reg::RAM_SIZE)
    }

    fn power_on(&mut self, downstream: bool) {
        self.mem.fill(0);
        self.set_u8(reg::TYPE, 0x11);
        self.set_u8(reg::FMMU_COUNT, reg::FMMUS);
        self.set_u8(reg::SM_COUNT, reg::SMS);
        self.set_u8(reg::RAM_SIZE, reg::RAM_KIB);
        // Ports 0 and 1 MII (0b11 each), 2 and 3 not implemented.
        self.set_u8(reg::PORT_DESCRIPTOR, 0x0F);
        // Distributed clocks (bit 2), 64-bit system time (bit 3).
        self.set_u16(reg::FEATURES, 0x000C);
        // Links on port 0 and, with a device after it, on port 1 (bits 4, 5); communication
        // on port 0 (bit 9), on port 1 (bit 11) or port 1's loop closed (bit 10).
        let dl = if downstream { 0x0A30 } else { 0x0610 };
        // Bit 0: the PDI is operational (the EEPROM was loaded).
        self.set_u16(reg::DL_STATUS, dl | u16::from(self.sii.loaded()));
        // AL status INIT.
        self.set_u16(reg::AL_STATUS, 0x0001);
        // Watchdogs as the ESC datasheets give them after reset: divider 2498 (100 µs),
        // 1000 × 100 µs = 100 ms for PDI and process data.
        self.set_u16(reg::WATCHDOG_DIVIDER, 0x09C2);
        self.set_u16(reg::WATCHDOG_PDI, 0x03E8);
        self.set_u16(reg::WATCHDOG_PD, 0x03E8);
        // Bit 0: the process data watchdog has not expired (the simulation does not run it).
        self.set_u16(reg::WATCHDOG_STATUS, 0x0001);
        let (pdi_control, pdi_config, alias) = self.sii.power_on_words();
        self.set_u16(reg::PDI_CONTROL, pdi_control);
        self.set_u16(reg::PDI_CONFIG, pdi_config);
        self.set_u16(reg::STATION_ALIAS, alias);
        self.set_u16(reg::SII_CONTROL, self.sii.control_idle());
    }

    /// The byte at `addr` (0 outside the memory).
    pub fn u8(&self, addr: u16) -> u8 {
        self.mem.get(usize::from(addr)).copied().unwrap_or(0)
    }

    /// The little-endian u16 at `addr`.
    pub fn u16(&self, addr: u16) -> u16 {
        u16::from_le_bytes([self.u8(addr), self.u8(addr.wrapping_add(1))])
    }

    /// The little-endian u32 at `addr`.
    pub fn u32(&self, addr: u16) -> u32 {
        u32::from(self.u16(addr)) | u32::from(self.u16(addr.wrapping_add(2))) << 16
    }

    /// Sets a byte (the ESC's or the application's side: no write protection).
    pub fn set_u8(&mut self, addr: u16, v: u8) {
        if let Some(b) = self.mem.get_mut(usize::from(addr)) {
            *b = v;
        }
    }

    /// Sets a little-endian u16.
    pub fn set_u16(&mut self, addr: u16, v: u16) {
        self.set_bytes(addr, &v.to_le_bytes());
    }

    /// Sets bytes from `addr`.
    pub fn set_bytes(&mut self, addr: u16, v: &[u8]) {
        let at = usize::from(addr);
        if let Some(dst) = self.mem.get_mut(at..at + v.len()) {
            dst.copy_from_slice(v);
        }
    }

    /// The bytes `len` from `addr` (empty outside the memory).
    pub fn bytes(&self, addr: u16, len: usize) -> &[u8] {
        let at = usize::from(addr);
        self.mem.get(at..at + len).unwrap_or(&[])
    }

    /// The registers of sync manager `n`.
    pub fn sm(&self, n: u8) -> SmRegs {
        let at = usize::from(reg::SM) + 8 * usize::from(n);
        let r = match self.mem.get(at..at + 8) {
            Some(&[a, b, c, d, e, f, g, h]) => [a, b, c, d, e, f, g, h],
            _ => [0; 8],
        };
        SmRegs::from_bytes(r)
    }

    /// Sets the status byte of sync manager `n`.
    pub fn set_sm_status(&mut self, n: u8, status: u8) {
        self.set_u8(reg::SM + 8 * u16::from(n) + 5, status);
    }

    /// Sets the PDI control byte of sync manager `n` (bit 0: deactivated by the application).
    pub fn set_sm_pdi_control(&mut self, n: u8, v: u8) {
        self.set_u8(reg::SM + 8 * u16::from(n) + 7, v);
    }

    /// Device emulation (ESC configuration 0x0141 bit 0, loaded from the SII's word 0, as
    /// the ESC datasheets define it): an ESC without a microcontroller (a digital I/O PDI)
    /// sets AL status to the state written to AL control itself.
    pub fn device_emulation(&self) -> bool {
        self.u8(reg::PDI_CONTROL + 1) & 0x01 != 0
    }

    /// The AL event request register (0x0220): bit 0 AL control written, bit 8 + n an event
    /// of sync manager n.
    pub fn al_event(&self) -> u32 {
        self.u32(reg::AL_EVENT)
    }

    fn raise(&mut self, bit: u32) {
        let ev = self.u32(reg::AL_EVENT) | 1 << bit;
        self.set_bytes(reg::AL_EVENT, &ev.to_le_bytes());
    }

    fn clear(&mut self, bit: u32) {
        let ev = self.u32(reg::AL_EVENT) & !(1 << bit);
        self.set_bytes(reg::AL_EVENT, &ev.to_le_bytes());
    }

    /// Executes `d` as this device (the frame passing it `at`), and updates its working
    /// counter and address field.
    pub fn execute(&mut self, d: &mut Datagram<'_>, at: &Passing) {
        let Some(cmd) = d.command() else { return };
        let here = d.adp() == 0;
        let me = d.adp() == self.u16(reg::STATION_ADDRESS);
        let ado = d.ado();
        let wkc = match cmd {
            Command::Nop => 0,
            Command::Aprd if here => self.read(ado, d.data, false, at),
            Command::Apwr if here => self.write(ado, d.data, at),
            Command::Aprw if here => self.read_write(ado, d.data, at),
            Command::Fprd if me => self.read(ado, d.data, false, at),
            Command::Fpwr if me => self.write(ado, d.data, at),
            Command::Fprw if me => self.read_write(ado, d.data, at),
            Command::Brd => self.read(ado, d.data, true, at),
            Command::Bwr => self.write(ado, d.data, at),
            Command::Brw => {
                let incoming = d.data.to_vec();
                let r = self.read(ado, d.data, true, at);
                r + 2 * self.write(ado, &incoming, at)
            }
            Command::Armw if here => self.read(ado, d.data, false, at),
            Command::Armw => self.write(ado, d.data, at),
            Command::Frmw if me => self.read(ado, d.data, false, at),
            Command::Frmw => self.write(ado, d.data, at),
            Command::Lrd | Command::Lwr | Command::Lrw => self.logical(cmd, d.logical(), d.data),
            _ => 0,
        };
        if matches!(
            cmd,
            Command::Aprd
                | Command::Apwr
                | Command::Aprw
                | Command::Armw
                | Command::Brd
                | Command::Bwr
                | Command::Brw
        ) {
            d.set_adp(d.adp().wrapping_add(1));
        }
        d.add_wkc(wkc);
    }

    fn read_write(&mut self, ado: u16, data: &mut [u8], at: &Passing) -> u16 {
        let incoming = data.to_vec();
        let r = self.read(ado, data, false, at);
        if r == 0 {
            return 0;
        }
        r + 2 * self.write(ado, &incoming, at)
    }

    /// Whether the sync managers allow the master this access, and which mailbox it
    /// completes.
    fn sm_check(&self, range: core::ops::Range<usize>, write: bool) -> Option<Option<u8>> {
        let mut completes = None;
        for n in 0..reg::SMS {
            let sm = self.sm(n);
            let area = sm_range(&sm);
            if sm.activate & 1 == 0 || area.is_empty() {
                continue;
            }
            let overlaps = range.start < area.end && area.start < range.end;
            if !overlaps {
                continue;
            }
            // Deactivated by the application (process data outside SAFE-OP and OP).
            if sm.pdi_control & 1 != 0 {
                return None;
            }
            if sm.is_mailbox() {
                let full = sm.status & SM_FULL != 0;
                if write != sm.master_writes() || (write && full) || (!write && !full) {
                    return None;
                }
                if range.contains(&(area.end - 1)) {
                    completes = Some(n);
                }
            } else if write && !sm.master_writes() {
                // An input area the master writes to: the ESC ignores it.
                return None;
            }
        }
        Some(completes)
    }

    /// A physical read into `data` (ORed into it for a broadcast); 1 if done, else 0.
    fn read(&mut self, ado: u16, data: &mut [u8], or: bool, at: &Passing) -> u16 {
        let start = usize::from(ado);
        let range = start..start + data.len();
        let Some(completes) = self.sm_check(range.clone(), false) else { return 0 };
        self.clock.refresh(&mut self.mem, range.clone(), at);
        for (i, d) in data.iter_mut().enumerate() {
            let v = self.mem.get(start + i).copied().unwrap_or(0);
            *d = if or { *d | v } else { v };
        }
        if let Some(n) = completes {
            let status = self.sm(n).status & !SM_FULL;
            self.set_sm_status(n, status);
            self.raise(8 + u32::from(n));
        }
        1
    }

    /// A physical write of `data`; 1 if done, else 0.
    fn write(&mut self, ado: u16, data: &[u8], at: &Passing) -> u16 {
        let start = usize::from(ado);
        let range = start..start + data.len();
        let Some(completes) = self.sm_check(range.clone(), true) else { return 0 };
        let before: Vec<u8> = (0..reg::SMS).map(|n| self.sm(n).activate).collect();
        for (i, &v) in data.iter().enumerate() {
            let Ok(addr) = u16::try_from(start + i) else { break };
            if ecat_writable(addr) {
                self.set_u8(addr, v);
            }
        }
        let touches = |a: u16, len: usize| {
            let a = usize::from(a);
            range.start < a + len && a < range.end
        };
        if touches(reg::AL_CONTROL, 2) {
            if self.device_emulation() {
                // AL status follows AL control (the state; the acknowledge bit is not an
                // error indication). A microcontroller behind the ESC still gets the event.
                let state = self.u8(reg::AL_CONTROL) & 0x0F;
                self.set_u16(reg::AL_STATUS, u16::from(state));
            }
            self.raise(0);
        }
        if touches(reg::SII_CONTROL, 2) {
            self.sii.command(&mut self.mem);
        }
        if touches(reg::DC_RECEIVE_TIME_PORT0, 1) {
            self.clock.latch(&mut self.mem, at);
        }
        if range.start <= usize::from(reg::DC_SYSTEM_TIME)
            && range.end >= usize::from(reg::DC_SYSTEM_TIME) + 4
        {
            let off = usize::from(reg::DC_SYSTEM_TIME) - range.start;
            let mut v = [0u8; 8];
            for (i, b) in v.iter_mut().enumerate() {
                *b = data.get(off + i).copied().unwrap_or(0);
            }
            let wide = range.end >= usize::from(reg::DC_SYSTEM_TIME) + 8;
            if !wide {
                v[4..].fill(0);
            }
            self.clock.compare(&mut self.mem, u64::from_le_bytes(v), wide, at);
        }
        // Enabling or disabling a sync manager resets its mailbox state.
        for (n, was) in (0..reg::SMS).zip(before) {
            if (self.sm(n).activate ^ was) & 1 != 0 {
                self.set_sm_status(n, 0);
            }
        }
        if let Some(n) = completes {
            let status = self.sm(n).status | SM_FULL;
            self.set_sm_status(n, status);
            self.raise(8 + u32::from(n));
        }
        1
    }

    /// A logical command through the FMMUs (ETG.1000.4 §6.6), at bit granularity: an FMMU
    /// maps the logical bits from its start bit of its first byte to its stop bit of its last
    /// onto the physical bits from its physical start bit, so that a master may pack devices
    /// with fewer than 8 bits into shared bytes (SOEM does); the bits of a shared byte that
    /// the FMMU does not map are neither read nor written.
    fn logical(&mut self, cmd: Command, addr: u32, data: &mut [u8]) -> u16 {
        let (mut read, mut written) = (false, false);
        let end = u64::from(addr) + data.len() as u64;
        for n in 0..u16::from(reg::FMMUS) {
            let f = reg::FMMU + 16 * n;
            if self.u8(f + 12) & 1 == 0 {
                continue;
            }
            let l_start = u64::from(self.u32(f));
            let l_len = u64::from(self.u16(f + 4));
            let (start_bit, stop_bit) = (self.u8(f + 6) & 7, self.u8(f + 7) & 7);
            let phys_bit = self.u8(f + 10) & 7;
            let kind = self.u8(f + 11);
            let write = kind & 0x02 != 0 && matches!(cmd, Command::Lwr | Command::Lrw);
            let read_it = kind & 0x01 != 0 && matches!(cmd, Command::Lrd | Command::Lrw);
            if l_len == 0 || !(write || read_it) {
                continue;
            }
            // The mapped logical bits [first, last] and the datagram's bits, overlapped.
            let first = l_start * 8 + u64::from(start_bit);
            let last = (l_start + l_len - 1) * 8 + u64::from(stop_bit);
            let (lo, hi) = (first.max(u64::from(addr) * 8), (last + 1).min(end * 8));
            if lo >= hi {
                continue;
            }
            let p_first = u64::from(self.u16(f + 8)) * 8 + u64::from(phys_bit) + (lo - first);
            let p_last = p_first + (hi - lo) - 1;
            let (Ok(p_lo), Ok(p_hi)) = (usize::try_from(p_first / 8), usize::try_from(p_last / 8))
            else {
                continue;
            };
            let range = p_lo..p_hi + 1;
            if p_hi >= self.mem.len() {
                continue;
            }
            let whole = lo % 8 == 0 && hi % 8 == 0 && p_first % 8 == 0;
            let d0 = lo - u64::from(addr) * 8;
            if write && self.sm_check(range.clone(), true).is_some() {
                if whole {
                    let (from, n) = ((d0 / 8) as usize, range.len());
                    if let (Some(dst), Some(src)) =
                        (self.mem.get_mut(range.clone()), data.get(from..from + n))
                    {
                        dst.copy_from_slice(src);
                    }
                } else {
                    for i in 0..hi - lo {
                        let v = bit(data, d0 + i);
                        set_bit(&mut self.mem, p_first + i, v);
                    }
                }
                written = true;
            }
            if read_it && self.sm_check(range.clone(), false).is_some() {
                if whole {
                    let (to, n) = ((d0 / 8) as usize, range.len());
                    if let (Some(src), Some(dst)) = (self.mem.get(range), data.get_mut(to..to + n))
                    {
                        dst.copy_from_slice(src);
                    }
                } else {
                    for i in 0..hi - lo {
                        let v = bit(&self.mem, p_first + i);
                        set_bit(data, d0 + i, v);
                    }
                }
                read = true;
            }
        }
        match cmd {
            Command::Lrw => u16::from(read) + 2 * u16::from(written),
            _ => u16::from(read || written),
        }
    }
}

fn overlap(a: &core::ops::Range<usize>, b: &core::ops::Range<usize>) -> bool {
    a.start < b.end && b.start < a.end
}

/// Bit `i` of `b` (LSB first), false outside it.
fn bit(b: &[u8], i: u64) -> bool {
    usize::try_from(i / 8).ok().and_then(|k| b.get(k)).is_some_and(|x| x >> (i % 8) & 1 != 0)
}

fn set_bit(b: &mut [u8], i: u64, v: bool) {
    if let Some(x) = usize::try_from(i / 8).ok().and_then(|k| b.get_mut(k)) {
        let m = 1u8 << (i % 8);
        *x = if v { *x | m } else { *x & !m };
    }
}

/// The ESC as the device's firmware sees it through its PDI: no write protection, and the
/// side effects a real ESC has on the application's accesses (ESC datasheets section II,
/// sync manager and AL event request): reading the last byte of a mailbox the master writes
/// empties it, writing the last byte of one the master reads fills it, reading AL control
/// clears its event, reading a sync manager's status or buffer clears that sync manager's.
#[derive(Debug)]
pub struct Pdi<'a>(pub &'a mut Esc);

impl Pdi<'_> {
    fn touched(&mut self, addr: u16, len: usize, write: bool) {
        let range = usize::from(addr)..usize::from(addr) + len;
        // Registers other than AL control and the sync managers' have no side effect.
        let sms = usize::from(reg::SM)..usize::from(reg::SM) + 8 * usize::from(reg::SMS);
        let registers = range.end <= usize::from(reg::PROCESS_RAM);
        if registers && !range.contains(&usize::from(reg::AL_CONTROL)) && !overlap(&range, &sms) {
            return;
        }
        let covers = |a: u16| range.contains(&usize::from(a));
        if !write && covers(reg::AL_CONTROL) {
            self.0.clear(0);
        }
        // Events are raised for mailboxes only; a buffered sync manager's access has no side
        // effect once no event is pending (the cyclic path).
        let pending = self.0.al_event() != 0;
        for n in 0..reg::SMS {
            let at = reg::SM + 8 * u16::from(n);
            let mailbox = self.0.u8(at + 4) & 0x03 == 0x02;
            if !mailbox && !pending {
                continue;
            }
            if !write && covers(at + 5) {
                self.0.clear(8 + u32::from(n));
            }
            let sm = self.0.sm(n);
            let area = sm_range(&sm);
            if area.is_empty() || sm.activate & 1 == 0 {
                continue;
            }
            if overlap(&range, &area) {
                self.0.clear(8 + u32::from(n));
            }
            if !mailbox || !range.contains(&(area.end - 1)) {
                continue;
            }
            if !write && sm.master_writes() {
                self.0.set_sm_status(n, sm.status & !SM_FULL);
            } else if write && !sm.master_writes() {
                self.0.set_sm_status(n, sm.status | SM_FULL);
            }
        }
    }
}

impl odc::ethercat::subdevice::Esc for Pdi<'_> {
    type Error = core::convert::Infallible;

    fn read(&mut self, addr: u16, buf: &mut [u8]) -> Result<(), Self::Error> {
        let at = usize::from(addr);
        match self.0.mem.get(at..at + buf.len()) {
            Some(src) => buf.copy_from_slice(src),
            None => buf.fill(0),
        }
        self.touched(addr, buf.len(), false);
        Ok(())
    }

    fn write(&mut self, addr: u16, data: &[u8]) -> Result<(), Self::Error> {
        self.0.set_bytes(addr, data);
        self.touched(addr, data.len(), true);
        Ok(())
    }

    fn al_event(&mut self) -> Result<u32, Self::Error> {
        Ok(self.0.al_event())
    }
}
