//! The PDO engine of a [`Node`](super::Node): transmit and receive PDOs that follow the
//! *current* communication (0x1400/0x1800 + n) and mapping (0x1600/0x1A00 + n) objects of the
//! dictionary.
//!
//! The communication parameters are cached (`PdoEngine::load`) and re-read when the node
//! sees an SDO write into 0x1400–0x1BFF and at reset communication. The mapping is read from
//! the dictionary each time a PDO is packed or unpacked, so a remap over SDO (disable the
//! PDO, write sub 0 = 0, the entries, sub 0 = count, enable) takes effect with no copy to keep
//! in step. Values go through [`ObjectDictionary::read`] and [`ObjectDictionary::write`]: an
//! RPDO runs the dictionary's write path (limits, hooks) as an SDO download does.
//!
//! Bounded, no heap: `R` receive and `T` transmit PDOs (the node's const parameters), each
//! with at most [`MAX_MAPPED`] mapping entries (CiA 301 allows 64, one per bit of 8 bytes).

use crate::bits::{load_le_u64, mask};
use crate::can::CanFrame;
use crate::slave::ObjectDictionary;
use crate::time::{Duration, Instant};
use crate::{MappingEntry, SdoAbort};

use super::params::{get_u8, get_u16, get_u32};

/// Mapping entries a PDO may have (CiA 301: sub 0 of a mapping object is 0–64).
pub const MAX_MAPPED: u8 = 64;

/// COB-ID bit 31: the PDO does not exist / is not valid.
const INVALID: u32 = 1 << 31;
/// COB-ID bit 30: no RTR allowed on this TPDO.
const NO_RTR: u32 = 1 << 30;
/// COB-ID bit 29: 29-bit CAN-ID.
const FRAME_29: u32 = 1 << 29;

/// Which PDO, 1-based as in the object names ("RPDO 1" is 0x1400/0x1600).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum PdoId {
    /// Receive PDO n.
    Rx(u16),
    /// Transmit PDO n.
    Tx(u16),
}

/// A PDO that could not be packed or applied: its mapping names a missing or too long
/// object, maps more than 64 bits, or the dictionary refused an RPDO value.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct PdoError {
    /// The PDO.
    pub pdo: PdoId,
    /// What the dictionary answered (or [`SdoAbort::PdoLengthExceeded`] for a mapping of
    /// more than 64 bits).
    pub abort: SdoAbort,
}

/// What the engine did in one call, for the node's events.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub(super) struct Outcome {
    /// Bit n-1: RPDO n was written into the dictionary.
    pub rpdo: u32,
    /// Bit n-1: TPDO n was sent.
    pub tpdo: u32,
    /// The last error.
    pub error: Option<PdoError>,
    /// An RPDO of the wrong length: the EMCY code to raise (0x8210 shorter, 0x8220 longer).
    pub length_emcy: Option<u16>,
}

impl Outcome {
    fn bit(n: usize) -> u32 {
        u32::try_from(n).ok().and_then(|n| 1u32.checked_shl(n)).unwrap_or(0)
    }
}

/// A packed PDO: its bytes as a little-endian word, in two halves, and its length. A word
/// compares in a few instructions where 8 bytes took a loop ("did the mapped data change"
/// runs at every poll of an event-driven TPDO), and goes to and from the dictionary without
/// copies (`tests/slave-size`, canopennode image: 22,235 B flash with bytes, 22,133 B with
/// this, RAM 1,592 and 1,688 B). One `u64` saves a few bytes of code more (26 B) but aligns
/// the PDO state to 8 bytes: 96 B more RAM for 4 + 4 PDOs, 192 B for a `Node<64>`'s 8 + 8.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
struct Data {
    word: [u32; 2],
    len: u8,
}

impl Data {
    fn new(word: u64, len: u8) -> Self {
        Self { word: [word as u32, (word >> 32) as u32], len }
    }

    /// The bytes as one little-endian word.
    fn word(&self) -> u64 {
        u64::from(self.word[0]) | u64::from(self.word[1]) << 32
    }
}

#[derive(Clone, Copy, Debug, Default)]
struct Rpdo {
    /// Valid (exists and COB-ID bit 31 clear).
    valid: bool,
    cob_id: u32,
    ttype: u8,
    /// Data of a synchronous RPDO waiting for the next SYNC.
    pending: Option<Data>,
}

#[derive(Clone, Copy, Debug, Default)]
struct Tpdo {
    valid: bool,
    cob_id: u32,
    ttype: u8,
    /// Inhibit time in µs (sub 3 is in 100 µs).
    inhibit: Duration,
    /// Event timer in µs (sub 5 is in ms); 0 = off.
    event: Duration,
    /// SYNC start value (sub 6); 0 = none.
    sync_start: u8,
    /// SYNCs since the last synchronous transmission.
    syncs: u8,
    /// Waiting for the SYNC counter to reach `sync_start`.
    waiting_start: bool,
    /// The application asked for a transmission (or the data changed).
    triggered: bool,
    /// When the last PDO went out.
    last_sent: Option<Instant>,
    /// When the event timer last started: the time it was due when it caused the PDO (so
    /// a late poll does not stretch the period), else the time the PDO went out.
    timer_from: Instant,
    /// What it carried, to detect a change of the mapped data.
    last: Option<Data>,
    /// Data sampled at the last SYNC (type 252).
    sampled: Option<Data>,
}

impl Tpdo {
    fn is_event(&self) -> bool {
        self.ttype >= 254
    }

    fn inhibited(&self, now: Instant) -> bool {
        self.last_sent.is_some_and(|t| now < t.saturating_add(self.inhibit))
    }
}

fn can_id(cob_id: u32) -> u32 {
    if cob_id & FRAME_29 != 0 { cob_id & 0x1FFF_FFFF } else { cob_id & 0x7FF }
}

fn frame(cob_id: u32, data: &Data) -> Option<CanFrame> {
    let bytes = data.word().to_le_bytes();
    let bytes = bytes.get(..usize::from(data.len))?;
    if cob_id & FRAME_29 != 0 {
        CanFrame::extended(can_id(cob_id), bytes)
    } else {
        CanFrame::from_slice(can_id(cob_id), bytes)
    }
}

/// The mapping entries of mapping object `index`: sub 0, then each entry.
fn entries<D: ObjectDictionary + ?Sized>(
    dict: &D,
    index: u16,
) -> Result<impl Iterator<Item = Result<MappingEntry, SdoAbort>> + '_, SdoAbort> {
    let count = get_u8(dict, index, 0).ok_or(SdoAbort::NoSuchObject)?.min(MAX_MAPPED);
    Ok((1..=count).map(move |sub| {
        get_u32(dict, index, sub).map(MappingEntry::from_u32).ok_or(SdoAbort::NoSuchSub)
    }))
}

/// The total length in bits of the mapping in object `index`.
pub(super) fn mapped_bits<D: ObjectDictionary + ?Sized>(
    dict: &D,
    index: u16,
) -> Result<u32, SdoAbort> {
    let mut bits = 0u32;
    for e in entries(dict, index)? {
        bits += u32::from(e?.bits);
    }
    Ok(bits)
}

/// Packs the objects that mapping object `index` names.
fn pack<D: ObjectDictionary + ?Sized>(dict: &D, index: u16) -> Result<Data, SdoAbort> {
    let mut word = 0u64;
    let mut at = 0usize;
    for e in entries(dict, index)? {
        let e = e?;
        let bits = u32::from(e.bits);
        if at + e.bits as usize > 64 {
            return Err(SdoAbort::PdoLengthExceeded);
        }
        if !e.is_dummy() {
            let mut buf = [0u8; 8];
            let n = dict.read(e.index, e.sub, &mut buf)?;
            if n * 8 < e.bits as usize {
                return Err(SdoAbort::LengthMismatch);
            }
            // A PDO is at most 64 bits (checked above): the frame is one word, no bit loop.
            word |= (load_le_u64(&buf) & mask(bits)).checked_shl(at as u32).unwrap_or(0);
        }
        at += e.bits as usize;
    }
    Ok(Data::new(word, at.div_ceil(8) as u8))
}

/// Writes the bytes of a received PDO (`word`: a frame is at most 8 bytes, one word; bits
/// past its end are 0) into the objects that mapping object `index` names, skipping dummy
/// entries. Each value keeps the bytes of its object past the mapped bits.
fn unpack<D: ObjectDictionary + ?Sized>(
    dict: &mut D,
    index: u16,
    word: u64,
) -> Result<(), SdoAbort> {
    let count = get_u8(dict, index, 0).ok_or(SdoAbort::NoSuchObject)?.min(MAX_MAPPED);
    let mut at = 0usize;
    for sub in 1..=count {
        let e = get_u32(dict, index, sub).map(MappingEntry::from_u32).ok_or(SdoAbort::NoSuchSub)?;
        let bits = u32::from(e.bits);
        if !e.is_dummy() {
            let mut buf = [0u8; 8];
            let n = dict.read(e.index, e.sub, &mut buf)?;
            let value = word.checked_shr(at as u32).unwrap_or(0) & mask(bits);
            // The object's bytes past the mapped bits stay as they were.
            buf = (load_le_u64(&buf) & !mask(bits) | value).to_le_bytes();
            dict.write(
                e.index,
                e.sub,
                buf.get(..n.max(usize::from(e.bits).div_ceil(8))).unwrap_or(&buf),
            )?;
        }
        at += e.bits as usize;
    }
    Ok(())
}

/// The PDOs of a node: `R` receive and `T` transmit PDOs.
#[derive(Clone, Debug)]
pub(super) struct PdoEngine<const R: usize, const T: usize> {
    rx: [Rpdo; R],
    tx: [Tpdo; T],
}

impl<const R: usize, const T: usize> PdoEngine<R, T> {
    pub(super) fn new() -> Self {
        Self { rx: [Rpdo::default(); R], tx: [Tpdo::default(); T] }
    }

    /// Reads the communication parameters again. A PDO whose parameters changed starts
    /// afresh (as on entering operational); the others keep their timers and last data.
    ///
    /// A PDO exists when its COB-ID's bit 31 is clear and its mapping has objects: sub-index 0
    /// of the mapping object at 0 disables the mapping (CiA 301 7.5.2.36), and a PDO without
    /// one is not sent or received (as CANopenNode's `CO_PDO.c` makes it invalid).
    ///
    /// `restart`: every PDO starts afresh (a reset: the node's start clears them this way
    /// rather than build a new engine on the stack).
    pub(super) fn load<D: ObjectDictionary + ?Sized>(&mut self, dict: &D, restart: bool) {
        let exists = |cob_id: u32, mapping: u16| {
            cob_id & INVALID == 0 && get_u8(dict, mapping, 0).is_some_and(|n| n > 0)
        };
        for (i, r) in self.rx.iter_mut().enumerate() {
            let index = 0x1400 + i as u16;
            let cob_id = get_u32(dict, index, 1).unwrap_or(INVALID);
            let ttype = get_u8(dict, index, 2).unwrap_or(255);
            let valid = exists(cob_id, 0x1600 + i as u16);
            if restart || (r.cob_id, r.ttype, r.valid) != (cob_id, ttype, valid) {
                *r = Rpdo { valid, cob_id, ttype, pending: None };
            }
        }
        for (i, t) in self.tx.iter_mut().enumerate() {
            let index = 0x1800 + i as u16;
            let cob_id = get_u32(dict, index, 1).unwrap_or(INVALID);
            let sync_start = get_u8(dict, index, 6).unwrap_or(0);
            let fresh = Tpdo {
                valid: exists(cob_id, 0x1A00 + i as u16),
                cob_id,
                ttype: get_u8(dict, index, 2).unwrap_or(255),
                inhibit: Duration::from_micros(
                    u64::from(get_u16(dict, index, 3).unwrap_or(0)) * 100,
                ),
                event: Duration::from_millis(u64::from(get_u16(dict, index, 5).unwrap_or(0))),
                sync_start,
                waiting_start: sync_start != 0,
                ..Tpdo::default()
            };
            let same = (t.valid, t.cob_id, t.ttype, t.inhibit, t.event, t.sync_start)
                == (
                    fresh.valid,
                    fresh.cob_id,
                    fresh.ttype,
                    fresh.inhibit,
                    fresh.event,
                    fresh.sync_start,
                );
            if restart || !same {
                *t = fresh;
            }
        }
    }

    /// Which PDOs are valid: bit n of word 0 for TPDO n+1, of word 1 for RPDO n+1. Not
    /// inlined: its 64-bit shifts were copied into every place the node makes a `View`.
    #[inline(never)]
    pub(super) fn valid(&self) -> [u64; 2] {
        let bits = |it: &mut dyn Iterator<Item = bool>| {
            it.take(64).enumerate().fold(0u64, |acc, (i, v)| acc | u64::from(v) << i)
        };
        [bits(&mut self.tx.iter().map(|t| t.valid)), bits(&mut self.rx.iter().map(|r| r.valid))]
    }

    /// Entering operational: event-driven TPDOs send their data once, synchronous ones count
    /// SYNCs from zero.
    pub(super) fn restart(&mut self) {
        for t in &mut self.tx {
            t.syncs = 0;
            t.waiting_start = t.sync_start != 0;
            t.last = None;
            t.sampled = None;
            t.last_sent = None;
            t.triggered = false;
        }
        for r in &mut self.rx {
            r.pending = None;
        }
    }

    /// The application asks for TPDO `n` (1-based): sent at once for event-driven types
    /// (after the inhibit time), at the next SYNC for type 0.
    pub(super) fn trigger(&mut self, n: u16) -> bool {
        match usize::from(n).checked_sub(1).and_then(|i| self.tx.get_mut(i)) {
            Some(t) => {
                t.triggered = true;
                true
            }
            None => false,
        }
    }

    fn send(
        t: &mut Tpdo,
        i: usize,
        data: Data,
        now: Instant,
        out: &mut impl FnMut(CanFrame),
        o: &mut Outcome,
    ) {
        if let Some(f) = frame(t.cob_id, &data) {
            out(f);
            o.tpdo |= Outcome::bit(i);
        }
        t.last = Some(data);
        t.last_sent = Some(now);
        t.timer_from = now;
        t.triggered = false;
    }

    /// A SYNC: synchronous TPDOs go out, synchronous RPDOs received since the last SYNC are
    /// written. `counter` is the SYNC counter when the SYNC carries one.
    pub(super) fn sync<D: ObjectDictionary + ?Sized>(
        &mut self,
        dict: &mut D,
        counter: Option<u8>,
        now: Instant,
        out: &mut impl FnMut(CanFrame),
    ) -> Outcome {
        let mut o = Outcome::default();
        for (i, r) in self.rx.iter_mut().enumerate() {
            if let Some(data) = r.pending.take() {
                match unpack(dict, 0x1600 + i as u16, data.word()) {
                    Ok(()) => o.rpdo |= Outcome::bit(i),
                    Err(abort) => o.error = Some(PdoError { pdo: PdoId::Rx(i as u16 + 1), abort }),
                }
            }
        }
        for (i, t) in self.tx.iter_mut().enumerate() {
            if !t.valid || t.ttype > 240 && t.ttype != 252 {
                continue;
            }
            let map = 0x1A00 + i as u16;
            let due = match t.ttype {
                0 => {
                    // Acyclic synchronous: at the SYNC after a trigger or a change of the data.
                    match pack(dict, map) {
                        Ok(d) if t.triggered || t.last != Some(d) => Some(Ok(d)),
                        Ok(_) => None,
                        Err(e) => Some(Err(e)),
                    }
                }
                252 => {
                    match pack(dict, map) {
                        Ok(d) => t.sampled = Some(d),
                        Err(abort) => {
                            o.error = Some(PdoError { pdo: PdoId::Tx(i as u16 + 1), abort })
                        }
                    }
                    None
                }
                n => {
                    if t.waiting_start {
                        // CiA 301: with a SYNC counter, the first transmission is at the SYNC
                        // whose counter equals the start value.
                        match counter {
                            Some(c) if c == t.sync_start => t.waiting_start = false,
                            Some(_) => continue,
                            None => t.waiting_start = false,
                        }
                        t.syncs = n - 1;
                    }
                    t.syncs = t.syncs.saturating_add(1);
                    if t.syncs >= n {
                        t.syncs = 0;
                        Some(pack(dict, map))
                    } else {
                        None
                    }
                }
            };
            match due {
                Some(Ok(d)) => Self::send(t, i, d, now, out, &mut o),
                Some(Err(abort)) => {
                    o.error = Some(PdoError { pdo: PdoId::Tx(i as u16 + 1), abort })
                }
                None => {}
            }
        }
        o
    }

    /// A received frame: an RPDO (data frame on its COB-ID) or an RTR for a TPDO. Returns
    /// `None` when the frame is for no PDO.
    pub(super) fn receive<D: ObjectDictionary + ?Sized>(
        &mut self,
        dict: &mut D,
        f: &CanFrame,
        now: Instant,
        out: &mut impl FnMut(CanFrame),
    ) -> Option<Outcome> {
        let mut o = Outcome::default();
        let matches =
            |cob_id: u32| can_id(cob_id) == f.id && (cob_id & FRAME_29 != 0) == f.extended;
        if f.remote {
            let (i, t) = self
                .tx
                .iter_mut()
                .enumerate()
                .find(|(_, t)| t.valid && t.cob_id & NO_RTR == 0 && matches(t.cob_id))?;
            let data = match t.sampled {
                Some(d) if t.ttype == 252 => Ok(d),
                _ => pack(dict, 0x1A00 + i as u16),
            };
            match data {
                Ok(d) => Self::send(t, i, d, now, out, &mut o),
                Err(abort) => o.error = Some(PdoError { pdo: PdoId::Tx(i as u16 + 1), abort }),
            }
            return Some(o);
        }
        let (i, r) = self.rx.iter_mut().enumerate().find(|(_, r)| r.valid && matches(r.cob_id))?;
        let map = 0x1600 + i as u16;
        let needed = match mapped_bits(dict, map) {
            Ok(bits) => bits.div_ceil(8),
            Err(abort) => {
                o.error = Some(PdoError { pdo: PdoId::Rx(i as u16 + 1), abort });
                return Some(o);
            }
        };
        let len = u32::from(f.len);
        if len < needed {
            // CiA 301: a PDO shorter than its mapping is not processed (EMCY 0x8210).
            o.length_emcy = Some(0x8210);
            return Some(o);
        }
        if len > needed {
            // Longer: the mapped bytes are used, the rest ignored, EMCY 0x8220.
            o.length_emcy = Some(0x8220);
        }
        let data = Data::new(load_le_u64(f.bytes()), f.len.min(8));
        if r.ttype <= 240 {
            r.pending = Some(data);
        } else {
            match unpack(dict, map, data.word()) {
                Ok(()) => o.rpdo |= Outcome::bit(i),
                Err(abort) => o.error = Some(PdoError { pdo: PdoId::Rx(i as u16 + 1), abort }),
            }
        }
        Some(o)
    }

    /// Timers and events of the event-driven TPDOs: a trigger or a change of the mapped data
    /// (sent once the inhibit time has passed), the event timer.
    pub(super) fn poll<D: ObjectDictionary + ?Sized>(
        &mut self,
        dict: &D,
        now: Instant,
        out: &mut impl FnMut(CanFrame),
    ) -> Outcome {
        let mut o = Outcome::default();
        for (i, t) in self.tx.iter_mut().enumerate() {
            if !t.valid || !t.is_event() || t.inhibited(now) {
                continue;
            }
            let due = t.timer_from.saturating_add(t.event);
            let timer = !t.event.is_zero() && t.last_sent.is_some() && now >= due;
            match pack(dict, 0x1A00 + i as u16) {
                Ok(d) if t.triggered || timer || t.last != Some(d) => {
                    let by_timer = timer && !t.triggered && t.last == Some(d);
                    Self::send(t, i, d, now, out, &mut o);
                    if by_timer && now < due.saturating_add(t.event) {
                        t.timer_from = due;
                    }
                }
                Ok(_) => {}
                Err(abort) => {
                    // Reported once per reload, not at every poll.
                    t.valid = false;
                    o.error = Some(PdoError { pdo: PdoId::Tx(i as u16 + 1), abort });
                }
            }
        }
        o
    }

    /// The earliest time a TPDO timer (event timer, inhibit time) runs out, for a caller
    /// that sleeps between polls.
    pub(super) fn next_deadline(&self) -> Option<Instant> {
        self.tx
            .iter()
            .filter(|t| t.valid && t.is_event())
            .filter_map(|t| {
                let sent = t.last_sent?;
                let inhibit = sent.saturating_add(t.inhibit);
                let event = (!t.event.is_zero()).then(|| t.timer_from.saturating_add(t.event));
                Some(if t.triggered { inhibit } else { event?.max(inhibit) })
            })
            .min()
    }
}
