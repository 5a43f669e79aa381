//! Distributed clocks, as far as a master's set-up sees them (ETG.1000.4 §9.2, the ESC
//! datasheets' chapter on DC): a free-running local clock per device, the receive times a
//! write to 0x0900 latches, the system time (local time + offset 0x0920) and its
//! comparison with a written system time (0x0910), which the ESC's control loop would
//! settle; here it settles at once (the offset takes the difference), and 0x092C holds the
//! difference seen.

use core::ops::Range;

use super::esc::Passing;
use super::registers as reg;

/// A device's local clock: the simulation's time plus a base of its own (devices power up at
/// different moments).
#[derive(Clone, Copy, Debug)]
pub struct Clock {
    base: u64,
}

impl Clock {
    /// A clock reading `base_ns` when the simulation's reads 0.
    pub fn new(base_ns: u64) -> Self {
        Self { base: base_ns }
    }

    /// The local time at simulation time `t`.
    pub fn local(&self, t: u64) -> u64 {
        t.wrapping_add(self.base)
    }

    fn offset(mem: &[u8]) -> u64 {
        let at = usize::from(reg::DC_SYSTEM_TIME_OFFSET);
        match mem.get(at..at + 8).and_then(|b| <[u8; 8]>::try_from(b).ok()) {
            Some(b) => u64::from_le_bytes(b),
            None => 0,
        }
    }

    fn delay(mem: &[u8]) -> u64 {
        let at = usize::from(reg::DC_SYSTEM_TIME_DELAY);
        match mem.get(at..at + 4).and_then(|b| <[u8; 4]>::try_from(b).ok()) {
            Some(b) => u64::from(u32::from_le_bytes(b)),
            None => 0,
        }
    }

    /// The system time when the frame passes.
    pub fn system_time(&self, mem: &[u8], at: &Passing) -> u64 {
        self.local(at.arrival_ns).wrapping_add(Self::offset(mem))
    }

    /// Before a read of `range`: the system time register holds the time of the read.
    pub fn refresh(&self, mem: &mut [u8], range: Range<usize>, at: &Passing) {
        let st = usize::from(reg::DC_SYSTEM_TIME);
        if range.start < st + 8 && st < range.end {
            let now = self.system_time(mem, at);
            if let Some(dst) = mem.get_mut(st..st + 8) {
                dst.copy_from_slice(&now.to_le_bytes());
            }
        }
    }

    /// A write to 0x0900: the receive times of the ports (local time, 32 bits each) and of
    /// the processing unit (64 bits). A closed port latches nothing (0).
    pub fn latch(&self, mem: &mut [u8], at: &Passing) {
        let p0 = self.local(at.arrival_ns);
        let p1 = at.port1_ns.map_or(0, |t| self.local(t));
        let mut put = |addr: u16, v: &[u8]| {
            let a = usize::from(addr);
            if let Some(dst) = mem.get_mut(a..a + v.len()) {
                dst.copy_from_slice(v);
            }
        };
        put(reg::DC_RECEIVE_TIME_PORT0, &(p0 as u32).to_le_bytes());
        put(reg::DC_RECEIVE_TIME_PORT0 + 4, &(p1 as u32).to_le_bytes());
        put(reg::DC_RECEIVE_TIME_PORT0 + 8, &[0; 8]);
        put(reg::DC_RECEIVE_TIME_EPU, &p0.to_le_bytes());
    }

    /// A written system time (the reference clock's, forwarded by FRMW/ARMW or written by
    /// the master): the difference to the own system time plus the transmission delay goes
    /// to 0x092C (bit 31 set when the own time is smaller) and the offset takes it up.
    /// A 32-bit write compares the low halves.
    pub fn compare(&self, mem: &mut [u8], written: u64, wide: bool, at: &Passing) {
        let received = written.wrapping_add(Self::delay(mem));
        let own = self.system_time(mem, at);
        let diff = match wide {
            true => own.wrapping_sub(received) as i64,
            false => i64::from((own as u32).wrapping_sub(received as u32) as i32),
        };
        let magnitude = (diff.unsigned_abs().min(0x7FFF_FFFF)) as u32;
        let word = if diff < 0 { magnitude | 0x8000_0000 } else { magnitude };
        let offset = Self::offset(mem).wrapping_sub(diff as u64);
        let o = usize::from(reg::DC_SYSTEM_TIME_OFFSET);
        if let Some(dst) = mem.get_mut(o..o + 8) {
            dst.copy_from_slice(&offset.to_le_bytes());
        }
        let d = usize::from(reg::DC_SYSTEM_TIME_DIFFERENCE);
        if let Some(dst) = mem.get_mut(d..d + 4) {
            dst.copy_from_slice(&word.to_le_bytes());
        }
    }
}
