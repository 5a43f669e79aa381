//! Transmit back-pressure: the node's sender may refuse a frame (a full transmit queue, a
//! driver error). The node keeps up to [`TX_QUEUE`] refused frames, in order, and offers them
//! again, first, at its next call with a sender; a frame that finds the queue full is counted
//! ([`Node::tx_lost`]), never dropped unseen.

use super::{Events, Node};
use crate::can::{CanFrame, StdId};
use crate::emcy::EmcyCode;
use crate::slave::ObjectDictionary;
use crate::time::Instant;

/// Frames the node keeps when its sender refuses them.
pub const TX_QUEUE: usize = 4;

/// What a sender returns for one frame: whether it took it.
///
/// `()` always takes it (a `Vec`, a sender that cannot fail); `Result<(), E>` took it when
/// `Ok` (any `Err`, such as a full transmit mailbox or a bus error, asks the node to keep the
/// frame and offer it again).
pub trait Sent {
    /// Whether the frame was taken.
    fn taken(&self) -> bool;
}

impl Sent for () {
    fn taken(&self) -> bool {
        true
    }
}

impl<E> Sent for Result<(), E> {
    fn taken(&self) -> bool {
        self.is_ok()
    }
}

/// The frames a sender refused, oldest first, and how many were lost to a full queue.
#[derive(Clone, Debug)]
pub(super) struct TxQueue {
    frames: [CanFrame; TX_QUEUE],
    len: u8,
    lost: u32,
}

/// A placeholder for the unused slots (never sent: only `frames[..len]` are).
const EMPTY: CanFrame = CanFrame::standard_len(StdId::masked(0), [0; 8], 0);

impl Default for TxQueue {
    fn default() -> Self {
        Self { frames: [EMPTY; TX_QUEUE], len: 0, lost: 0 }
    }
}

impl TxQueue {
    /// Offers the kept frames again, oldest first, until the sender refuses one. Written
    /// without indexing, so the firmware path links no panic.
    fn flush<S: Sent>(&mut self, out: &mut impl FnMut(CanFrame) -> S) {
        while self.len > 0 {
            let [first, b, c, d] = self.frames;
            if !out(first).taken() {
                break;
            }
            self.frames = [b, c, d, EMPTY];
            self.len -= 1;
        }
    }

    /// Sends `frame` after the kept ones; keeps it when it cannot go now, counts it lost when
    /// the queue is full.
    fn send<S: Sent>(&mut self, frame: CanFrame, out: &mut impl FnMut(CanFrame) -> S) {
        if self.len > 0 {
            self.flush(out);
        }
        if self.len == 0 && out(frame).taken() {
            return;
        }
        match self.frames.get_mut(usize::from(self.len)) {
            Some(slot) => {
                *slot = frame;
                self.len += 1;
            }
            None => self.lost = self.lost.saturating_add(1),
        }
    }
}

impl<const N: usize, const R: usize, const T: usize> Node<N, R, T> {
    /// Runs `f` with a sender that keeps what `out` refuses.
    pub(super) fn with_tx<X, S: Sent>(
        &mut self,
        out: &mut impl FnMut(CanFrame) -> S,
        f: impl FnOnce(&mut Self, &mut dyn FnMut(CanFrame)) -> X,
    ) -> X {
        let mut tx = core::mem::take(&mut self.tx);
        tx.flush(out);
        let x = f(self, &mut |frame| tx.send(frame, out));
        // Frames kept meanwhile were counted into `tx`; the node's own queue was idle.
        self.tx = tx;
        x
    }

    /// Frames the sender refused that wait to be offered again (at most [`TX_QUEUE`]).
    pub fn tx_pending(&self) -> usize {
        usize::from(self.tx.len)
    }

    /// Frames lost because the sender refused them while [`TX_QUEUE`] others waited.
    pub fn tx_lost(&self) -> u32 {
        self.tx.lost
    }

    /// Initialisation → boot-up frame (0x700 + id, one byte 0) → pre-operational. Also what
    /// reset node and reset communication do: every parameter is read again from `dict`
    /// (which the application has set back to its defaults, for [`Node::next_node_id`]), the
    /// error history is emptied. The node-ID an LSS master configured becomes active here;
    /// a node without node-ID (0xFF) stays initialising, without boot-up (CiA 305).
    ///
    /// `out` sends a frame; it may refuse one ([`Sent`]), which the node keeps and offers
    /// again at its next call.
    pub fn start<D: ObjectDictionary + ?Sized, S: Sent>(
        &mut self,
        dict: &mut D,
        now: Instant,
        out: &mut impl FnMut(CanFrame) -> S,
    ) {
        self.with_tx(out, |n, mut o| n.start_in(dict, now, &mut o));
    }

    /// One received frame: NMT, node guarding RTR, heartbeats of other nodes, SYNC, SDO
    /// requests, RPDOs and RTRs of TPDOs. Frames for none of these are ignored.
    pub fn handle<D: ObjectDictionary + ?Sized, S: Sent>(
        &mut self,
        dict: &mut D,
        frame: &CanFrame,
        now: Instant,
        out: &mut impl FnMut(CanFrame) -> S,
    ) -> Events {
        self.with_tx(out, |n, mut o| n.handle_in(dict, frame, now, &mut o))
    }

    /// Timers: heartbeat, heartbeat consumers, life guarding, the SYNC producer, EMCY inhibit,
    /// TPDO event timers and inhibit times, change of the mapped data of event-driven TPDOs,
    /// the SDO timeout. A reset requested by NMT happens here (boot-up).
    /// Frames the sender refused before are offered again first.
    pub fn poll<D: ObjectDictionary + ?Sized, S: Sent>(
        &mut self,
        dict: &mut D,
        now: Instant,
        out: &mut impl FnMut(CanFrame) -> S,
    ) -> Events {
        self.with_tx(out, |n, mut o| n.poll_in(dict, now, &mut o))
    }

    /// Raises an error: sets its bit in the error register, adds it to the history (0x1003)
    /// and sends the EMCY (COB-ID 0x1014; after the inhibit time 0x1015; not in stopped,
    /// where EMCY is not a service).
    pub fn raise_emcy<S: Sent>(
        &mut self,
        code: EmcyCode,
        manufacturer: [u8; 5],
        now: Instant,
        out: &mut impl FnMut(CanFrame) -> S,
    ) {
        self.with_tx(out, |n, mut o| n.raise_emcy_in(code, manufacturer, now, &mut o));
    }

    /// Clears an error raised before; sends the "error reset" EMCY (code 0x0000) with the
    /// error register that remains. Returns whether the error was active.
    pub fn clear_emcy<S: Sent>(
        &mut self,
        code: EmcyCode,
        now: Instant,
        out: &mut impl FnMut(CanFrame) -> S,
    ) -> bool {
        self.with_tx(out, |n, mut o| n.clear_emcy_in(code, now, &mut o))
    }
}
