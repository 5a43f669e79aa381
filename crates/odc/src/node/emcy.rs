//! The EMCY producer of a [`Node`](super::Node): active errors, the error register (0x1001),
//! the pre-defined error field (0x1003) and the inhibit time (0x1015).
//!
//! The node keeps the register and the history itself and serves them to SDO reads of
//! 0x1001 and 0x1003 (when the dictionary has those objects): they are read-only over SDO, so
//! the dictionary's write path, which checks access, cannot store them (CANopenNode serves
//! 0x1003 from its EMCY object the same way).

use crate::SdoAbort;
use crate::can::CanFrame;
use crate::emcy::{EmcyCode, EmcyFrame, ErrorRegister};
use crate::slave::ObjectDictionary;
use crate::time::{Duration, Instant};

/// Errors that can be active at once; a further one is still sent and recorded, and sets its
/// register bit, but clearing it cannot be told from the others.
pub const MAX_ACTIVE: usize = 8;
/// Entries of the error history kept (0x1003 sub 1–8); fewer when the dictionary's 0x1003
/// has fewer sub-indexes.
pub const MAX_HISTORY: usize = 8;
/// EMCY frames waiting for the inhibit time to pass; when full, the oldest waiting one is
/// replaced and [`Node::emcy_overflowed`](super::Node::emcy_overflowed) says so.
pub const QUEUE: usize = 4;

#[derive(Clone, Debug)]
pub(super) struct Emcy {
    cob_id: u32,
    inhibit: Duration,
    active: [Option<EmcyCode>; MAX_ACTIVE],
    /// Register bits of errors that did not fit `active`.
    sticky: ErrorRegister,
    history: [u32; MAX_HISTORY],
    history_len: usize,
    /// How many entries the dictionary's 0x1003 has (0: no 0x1003).
    history_cap: usize,
    has_register: bool,
    /// The register the application set ([`Emcy::set_register`]): sent and read instead of
    /// the bits of the active errors.
    app_register: Option<ErrorRegister>,
    /// A ring: `queued` payloads from `head` on (indexes modulo [`QUEUE`], so no bounds
    /// check and no memmove on the frame path).
    queue: [[u8; 8]; QUEUE],
    head: usize,
    queued: usize,
    last_sent: Option<Instant>,
    overflowed: bool,
}

impl Emcy {
    pub(super) fn new() -> Self {
        Self {
            cob_id: 1 << 31,
            inhibit: Duration::ZERO,
            active: [None; MAX_ACTIVE],
            sticky: ErrorRegister::NONE,
            history: [0; MAX_HISTORY],
            history_len: 0,
            history_cap: 0,
            has_register: false,
            app_register: None,
            queue: [[0; 8]; QUEUE],
            head: 0,
            queued: 0,
            last_sent: None,
            overflowed: false,
        }
    }

    /// Reset communication: no active error, empty history, parameters from `dict`.
    /// The application's register stays: it is the device's, not communication's.
    pub(super) fn reset<D: ObjectDictionary + ?Sized>(&mut self, dict: &D) {
        *self = Self { app_register: self.app_register, ..Self::new() };
        self.has_register = dict.read(0x1001, 0, &mut [0u8; 4]).is_ok();
        self.history_cap = (1..=MAX_HISTORY as u8)
            .take_while(|&s| {
                !matches!(
                    dict.read(0x1003, s, &mut [0u8; 8]),
                    Err(SdoAbort::NoSuchObject | SdoAbort::NoSuchSub)
                )
            })
            .count();
        self.load(dict);
    }

    /// Reads 0x1014 and 0x1015 again.
    pub(super) fn load<D: ObjectDictionary + ?Sized>(&mut self, dict: &D) {
        self.cob_id = super::params::get_u32(dict, 0x1014, 0).unwrap_or(1 << 31);
        self.inhibit = Duration::from_micros(
            u64::from(super::params::get_u16(dict, 0x1015, 0).unwrap_or(0)) * 100,
        );
    }

    /// The error register: the application's ([`Emcy::set_register`]), else the bits of the
    /// active errors, with the generic bit.
    pub(super) fn register(&self) -> ErrorRegister {
        if let Some(r) = self.app_register {
            return r;
        }
        self.active.iter().flatten().fold(self.sticky, |r, c| r.with_error(c.register_bit()))
    }

    /// The application takes the error register over (`Some`), or gives it back to the
    /// node (`None`).
    pub(super) fn set_register(&mut self, register: Option<ErrorRegister>) {
        self.app_register = register;
    }

    /// The history, newest first.
    pub(super) fn history(&self) -> &[u32] {
        self.history.get(..self.history_len).unwrap_or(&[])
    }

    pub(super) fn overflowed(&self) -> bool {
        self.overflowed
    }

    fn push(&mut self, code: EmcyCode, info: [u8; 5]) {
        if self.history_cap == 0 {
            return;
        }
        let cap = self.history_cap.min(MAX_HISTORY);
        // Entries past `cap` are never read: shifting all of them keeps the indexes constant.
        for i in (1..MAX_HISTORY).rev() {
            self.history[i] = self.history[i - 1];
        }
        // 0x1003 entry: error code in bits 0–15, additional information in bits 16–31.
        self.history[0] =
            u32::from(code.0) | u32::from(u16::from_le_bytes([info[0], info[1]])) << 16;
        self.history_len = (self.history_len + 1).min(cap);
    }

    /// Records and sends (or queues) an error.
    pub(super) fn raise(
        &mut self,
        code: EmcyCode,
        info: [u8; 5],
        send: bool,
        now: Instant,
        out: &mut impl FnMut(CanFrame),
    ) {
        if !self.active.contains(&Some(code)) {
            match self.active.iter_mut().find(|a| a.is_none()) {
                Some(slot) => *slot = Some(code),
                None => self.sticky = self.sticky.with_error(code.register_bit()),
            }
        }
        self.push(code, info);
        if send {
            let f = EmcyFrame { code, register: self.register(), manufacturer: info };
            self.enqueue(f.encode(), now, out);
        }
    }

    /// Clears an active error; sends "error reset" (0x0000) with the remaining register.
    /// Returns whether the error was active.
    pub(super) fn clear(
        &mut self,
        code: EmcyCode,
        send: bool,
        now: Instant,
        out: &mut impl FnMut(CanFrame),
    ) -> bool {
        let Some(slot) = self.active.iter_mut().find(|a| **a == Some(code)) else { return false };
        *slot = None;
        if self.active.iter().all(Option::is_none) {
            self.sticky = ErrorRegister::NONE;
        }
        if send {
            let f = EmcyFrame::new(EmcyCode::NO_ERROR, self.register());
            self.enqueue(f.encode(), now, out);
        }
        true
    }

    /// Writing 0 to 0x1003:0 empties the history (CiA 301 7.5.2.3); any other value is refused.
    pub(super) fn write_history_count(&mut self, data: &[u8]) -> Result<(), SdoAbort> {
        match data {
            [0, ..] if data.iter().all(|&b| b == 0) => {
                self.history_len = 0;
                Ok(())
            }
            [] => Err(SdoAbort::TooShort),
            _ => Err(SdoAbort::InvalidValue),
        }
    }

    /// An SDO read the node answers itself: 0x1001 and 0x1003. `None` for anything else.
    pub(super) fn read(
        &self,
        index: u16,
        sub: u8,
        buf: &mut [u8],
    ) -> Option<Result<usize, SdoAbort>> {
        let put = |buf: &mut [u8], bytes: &[u8]| {
            buf.get_mut(..bytes.len())
                .map(|d| {
                    crate::bits::copy_bytes(d, bytes);
                    bytes.len()
                })
                .ok_or(SdoAbort::TooShort)
        };
        match (index, sub) {
            (0x1001, 0) if self.has_register => Some(put(buf, &[self.register().0])),
            (0x1003, 0) if self.history_cap > 0 => Some(put(buf, &[self.history_len as u8])),
            (0x1003, s) if usize::from(s) <= self.history_cap => {
                let v = self.history.get(usize::from(s) - 1).copied().unwrap_or(0);
                let v = if usize::from(s) <= self.history_len { v } else { 0 };
                Some(put(buf, &v.to_le_bytes()))
            }
            _ => None,
        }
    }

    fn enqueue(&mut self, payload: [u8; 8], now: Instant, out: &mut impl FnMut(CanFrame)) {
        if self.cob_id & (1 << 31) != 0 {
            return;
        }
        if self.queued == 0 && !self.inhibited(now) {
            self.transmit(payload, now, out);
            return;
        }
        if self.queued >= QUEUE {
            // Full: the oldest waiting one gives way.
            self.head = (self.head + 1) % QUEUE;
            self.queued = QUEUE - 1;
            self.overflowed = true;
        }
        self.queue[(self.head + self.queued) % QUEUE] = payload;
        self.queued += 1;
    }

    fn inhibited(&self, now: Instant) -> bool {
        self.last_sent.is_some_and(|t| now < t.saturating_add(self.inhibit))
    }

    fn transmit(&mut self, payload: [u8; 8], now: Instant, out: &mut impl FnMut(CanFrame)) {
        out(CanFrame::standard(crate::can::StdId::masked(self.cob_id), payload));
        self.last_sent = Some(now);
    }

    /// Sends the next queued EMCY once the inhibit time has passed.
    pub(super) fn poll(&mut self, now: Instant, out: &mut impl FnMut(CanFrame)) {
        if self.queued > 0 && !self.inhibited(now) {
            let payload = self.queue[self.head % QUEUE];
            self.head = (self.head + 1) % QUEUE;
            self.queued -= 1;
            self.transmit(payload, now, out);
        }
    }

    /// When the next queued EMCY may go.
    pub(super) fn next_deadline(&self) -> Option<Instant> {
        (self.queued > 0)
            .then(|| self.last_sent.map_or(Instant::ZERO, |t| t.saturating_add(self.inhibit)))
    }
}
