//! The LSS slave (`odc::lss::LssSlave`) fed arbitrary frames, against a model of CiA 305
//! written here: which request is served in which state, and what the answer and the event
//! are. Checked after every frame:
//! - answers go on 0x7E4, as 8-byte data frames, and only where CiA 305 has one: the
//!   configuration services (configure node-ID and bit timing, activate, store, inquire)
//!   only in configuration state; switch state selective only in waiting state, after the
//!   four parts of the slave's own address in order; identify remote slave after the six
//!   steps whose ranges hold the address; identify non-configured and fastscan only from a
//!   slave without node-ID (fastscan in waiting state, bit by bit);
//! - the state, the active and pending node-ID and bit timing are the model's, and an NMT
//!   reset communication makes the pending node-ID active;
//! - other COB-IDs, remote, extended and short frames change nothing and get no answer.
#![no_main]

use arbitrary::{Arbitrary, Unstructured};
use libfuzzer_sys::fuzz_target;
use odc::can::CanFrame;
use odc::cob::NodeId;
use odc::lss::{Identity, LssEvent, LssSlave, LssState};

/// The calls into the runtime, in one place: only these know its frame and node-ID types
/// (the harness names a node-ID by its byte, 0xFF for none, as CiA 305 does).
fn lss_new(identity: Identity, node: u8, bit_timing: u8) -> LssSlave {
    // Any byte: 1-127 is a node-ID, every other one none (the model's reading too).
    LssSlave::new(identity, NodeId::new(node), bit_timing)
}

fn lss_handle(s: &mut LssSlave, f: &CanFrame) -> (Option<CanFrame>, Option<LssEvent>) {
    s.handle(f)
}

fn lss_reset_communication(s: &mut LssSlave) -> Option<u8> {
    s.reset_communication().map(NodeId::get)
}

/// (state, active node-ID, pending node-ID, bit timing, pending bit timing).
fn lss_status(s: &LssSlave) -> (LssState, Option<u8>, Option<u8>, u8, u8) {
    (
        s.state(),
        s.node_id().map(NodeId::get),
        s.pending_node_id().map(NodeId::get),
        s.bit_timing(),
        s.pending_bit_timing(),
    )
}

/// The node-ID an event carries: `None` for 0xFF; the model gives no other byte.
fn event_id(id: u8) -> Option<NodeId> {
    (id != UNCONF).then(|| NodeId::new(id).expect("the model's node-IDs are 1-127 or 0xFF"))
}

fn frame(id: u32, b: &[u8]) -> CanFrame {
    CanFrame::from_slice(id, b).expect("11 bits and at most 8 bytes, by construction")
}

const UNCONF: u8 = 0xFF;

/// CiA 305's slave, as the harness expects it to behave.
#[derive(Debug)]
struct Model {
    id: [u32; 4],
    configuration: bool,
    active: u8,
    pending: u8,
    bit_timing: u8,
    pending_bit_timing: u8,
    bit_timings: u16,
    storage: bool,
    /// Switch-state-selective requests received in waiting state since the last state change.
    selective: Vec<(u8, u32)>,
    /// Identify-remote-slave requests since the last state change or answer.
    identify: Vec<(u8, u32)>,
    /// The part fastscan compares next.
    fastscan: u8,
}

fn ans(b: [u8; 8]) -> Option<CanFrame> {
    Some(CanFrame::new(0x7E4, b).expect("an 11-bit identifier"))
}

fn number(b: &[u8; 8]) -> u32 {
    u32::from_le_bytes([b[1], b[2], b[3], b[4]])
}

impl Model {
    fn enter(&mut self, configuration: bool) -> Option<LssEvent> {
        let changed = self.configuration != configuration;
        self.configuration = configuration;
        self.selective.clear();
        self.identify.clear();
        let s = if configuration { LssState::Configuration } else { LssState::Waiting };
        changed.then_some(LssEvent::State(s))
    }

    fn unconfigured(&self) -> bool {
        self.active == UNCONF && self.pending == UNCONF
    }

    /// The answer and event CiA 305 calls for.
    fn request(&mut self, b: [u8; 8]) -> (Option<CanFrame>, Option<LssEvent>) {
        let cs = b[0];
        let n = number(&b);
        match cs {
            0x04 if b[1] <= 1 => {
                let to_config = b[1] == 1;
                let reset = self.configuration
                    && !to_config
                    && self.active == UNCONF
                    && self.pending != UNCONF;
                let e = self.enter(to_config);
                (None, if reset { Some(LssEvent::ResetCommunication) } else { e })
            }
            0x40..=0x43 if !self.configuration => {
                self.selective.push((cs, n));
                let want = [
                    (0x40, self.id[0]),
                    (0x41, self.id[1]),
                    (0x42, self.id[2]),
                    (0x43, self.id[3]),
                ];
                if self.selective.ends_with(&want) {
                    let e = self.enter(true);
                    (ans([0x44, 0, 0, 0, 0, 0, 0, 0]), e)
                } else {
                    (None, None)
                }
            }
            0x46..=0x4B => {
                self.identify.push((cs, n));
                let k = self.identify.len();
                let [v, p, r, s] = self.id;
                let hit = k >= 6 && {
                    let l = &self.identify[k - 6..];
                    l.iter().map(|x| x.0).eq(0x46..=0x4B)
                        && l[0].1 == v
                        && l[1].1 == p
                        && r >= l[2].1
                        && r <= l[3].1
                        && s >= l[4].1
                        && s <= l[5].1
                };
                if hit {
                    self.identify.clear();
                    (ans([0x4F, 0, 0, 0, 0, 0, 0, 0]), None)
                } else {
                    (None, None)
                }
            }
            0x4C if self.unconfigured() => (ans([0x50, 0, 0, 0, 0, 0, 0, 0]), None),
            0x51 if !self.configuration && self.unconfigured() => {
                let (bit, sub, next) = (b[5], b[6], b[7]);
                if bit == 0x80 {
                    self.fastscan = 0;
                    return (ans([0x4F, 0, 0, 0, 0, 0, 0, 0]), None);
                }
                if sub > 3 || bit > 31 || next > 3 || sub != self.fastscan {
                    return (None, None);
                }
                let mask = u32::MAX << bit;
                if (self.id[usize::from(sub)] ^ n) & mask != 0 {
                    return (None, None);
                }
                let mut e = None;
                if bit == 0 {
                    if next < sub {
                        self.fastscan = 0;
                        e = self.enter(true);
                    } else {
                        self.fastscan = next;
                    }
                }
                (ans([0x4F, 0, 0, 0, 0, 0, 0, 0]), e)
            }
            _ if !self.configuration => (None, None),
            0x11 => {
                let id = b[1];
                if id == UNCONF || (1..=127).contains(&id) {
                    self.pending = id;
                    let e = LssEvent::NodeIdConfigured(event_id(id));
                    (ans([0x11, 0, 0, 0, 0, 0, 0, 0]), Some(e))
                } else {
                    (ans([0x11, 1, 0, 0, 0, 0, 0, 0]), None)
                }
            }
            0x13 => {
                let (table, index) = (b[1], b[2]);
                if table == 0 && index < 16 && self.bit_timings >> index & 1 == 1 {
                    self.pending_bit_timing = index;
                    (ans([0x13, 0, 0, 0, 0, 0, 0, 0]), Some(LssEvent::BitTimingConfigured(index)))
                } else {
                    (ans([0x13, 1, 0, 0, 0, 0, 0, 0]), None)
                }
            }
            0x15 => {
                self.bit_timing = self.pending_bit_timing;
                (
                    None,
                    Some(LssEvent::ActivateBitTiming {
                        delay_ms: u16::from_le_bytes([b[1], b[2]]),
                    }),
                )
            }
            0x17 if self.storage => {
                let node_id = event_id(self.pending);
                (None, Some(LssEvent::Store { node_id, bit_timing: self.pending_bit_timing }))
            }
            0x17 => (ans([0x17, 1, 0, 0, 0, 0, 0, 0]), None),
            0x5A..=0x5D => {
                let v = self.id[usize::from(cs - 0x5A)].to_le_bytes();
                (ans([cs, v[0], v[1], v[2], v[3], 0, 0, 0]), None)
            }
            0x5E => (ans([0x5E, self.active, 0, 0, 0, 0, 0, 0]), None),
            _ => (None, None),
        }
    }
}

fn same(s: &LssSlave, m: &Model) {
    let state = if m.configuration { LssState::Configuration } else { LssState::Waiting };
    let opt = |v: u8| (v != UNCONF).then_some(v);
    assert_eq!(
        lss_status(s),
        (state, opt(m.active), opt(m.pending), m.bit_timing, m.pending_bit_timing),
        "slave and CiA 305 model differ: {m:?}"
    );
}

fn run(u: &mut Unstructured<'_>) -> arbitrary::Result<()> {
    // Small numbers often, so the fuzzer can hit the address.
    let part = |u: &mut Unstructured<'_>| -> arbitrary::Result<u32> {
        Ok(if u.ratio(1, 2)? { u32::from(u8::arbitrary(u)? & 7) } else { u32::arbitrary(u)? })
    };
    let id = [part(u)?, part(u)?, part(u)?, part(u)?];
    let node: u8 = if u.ratio(1, 2)? { UNCONF } else { u8::arbitrary(u)? };
    let bit_timing = u.int_in_range(0..=9)?;
    let mut slave = lss_new(Identity::new(id[0], id[1], id[2], id[3]), node, bit_timing);
    let mut m = Model {
        id,
        configuration: false,
        active: if (1..=127).contains(&node) { node } else { UNCONF },
        pending: 0,
        bit_timing,
        pending_bit_timing: bit_timing,
        bit_timings: 0b1_1101_1111,
        storage: false,
        selective: Vec::new(),
        identify: Vec::new(),
        fastscan: 0,
    };
    m.pending = m.active;
    if u.ratio(1, 2)? {
        m.bit_timings = u16::arbitrary(u)?;
        slave = slave.with_bit_timings(m.bit_timings);
    }
    if bool::arbitrary(u)? {
        m.storage = true;
        slave = slave.with_storage();
    }
    same(&slave, &m);
    while !u.is_empty() {
        match u.int_in_range(0..=9u8)? {
            0..=6 => {
                let mut b = [0u8; 8];
                u.fill_buffer(&mut b)?;
                if u.ratio(3, 4)? {
                    b[0] = *u.choose(&[
                        0x04, 0x40, 0x41, 0x42, 0x43, 0x11, 0x13, 0x15, 0x17, 0x46, 0x47, 0x48,
                        0x49, 0x4A, 0x4B, 0x4C, 0x51, 0x5A, 0x5B, 0x5C, 0x5D, 0x5E,
                    ])?;
                }
                if u.ratio(1, 2)? {
                    // A part of the address, or one next to it.
                    let v =
                        id[usize::from(b[0] & 3)].wrapping_add(u32::from(b[5] % 3)).wrapping_sub(1);
                    b[1..5].copy_from_slice(&v.to_le_bytes());
                }
                if b[0] == 0x04 || b[0] == 0x13 {
                    b[1] &= 1;
                }
                let want = m.request(b);
                let got = lss_handle(&mut slave, &frame(0x7E5, &b));
                assert_eq!(got, want, "request {b:02X?}");
                if let Some(a) = got.0 {
                    assert!(
                        a.id() == 0x7E4 && a.len() == 8 && !a.is_remote() && !a.is_extended(),
                        "{a:?}"
                    );
                }
            }
            7 => {
                // Not an LSS request: nothing happens.
                let mut b = [0u8; 8];
                u.fill_buffer(&mut b)?;
                b[0] = *u.choose(&[0x04, 0x11, 0x4C, 0x51, 0x5E, b[0]])?;
                let len = u.int_in_range(0..=8)?;
                let f = match u.int_in_range(0..=3u8)? {
                    0 => CanFrame::remote(0x7E5, len as u8).expect("11 bits, 0-8"),
                    1 => CanFrame::extended(0x7E5, &b).expect("8 bytes"),
                    2 => frame(0x7E5, &b[..len.min(7)]),
                    _ => frame(*u.choose(&[0x7E4, 0x7E6, 0x000, 0x605])?, &b),
                };
                assert_eq!(lss_handle(&mut slave, &f), (None, None), "{f:?}");
            }
            8 => {
                // NMT reset communication: the pending node-ID becomes active.
                m.active = m.pending;
                let now = lss_reset_communication(&mut slave);
                assert_eq!(now, (m.active != UNCONF).then_some(m.active));
            }
            _ => {
                // A whole fastscan, as a master runs it: finds the address of an unconfigured
                // slave in waiting state, and nothing otherwise.
                let candidate = !m.configuration && m.unconfigured();
                let found = fastscan(&mut slave, &mut m);
                assert_eq!(found, candidate.then_some(id), "fastscan");
                if candidate {
                    assert_eq!(slave.state(), LssState::Configuration);
                }
            }
        }
        same(&slave, &m);
    }
    Ok(())
}

/// CiA 305's fastscan from the master's side; each request also goes through the model.
fn fastscan(s: &mut LssSlave, m: &mut Model) -> Option<[u32; 4]> {
    let mut ask = |n: u32, bit: u8, sub: u8, next: u8| {
        let v = n.to_le_bytes();
        let b = [0x51, v[0], v[1], v[2], v[3], bit, sub, next];
        let want = m.request(b);
        let got = lss_handle(s, &frame(0x7E5, &b));
        assert_eq!(got, want, "fastscan {b:02X?}");
        got.0.is_some()
    };
    if !ask(0, 0x80, 0, 0) {
        return None;
    }
    let mut id = [0u32; 4];
    for sub in 0..4u8 {
        let k = usize::from(sub);
        for bit in (0..32u8).rev() {
            if !ask(id[k], bit, sub, sub) {
                id[k] |= 1 << bit;
            }
        }
        if !ask(id[k], 0, sub, (sub + 1) & 3) {
            return None;
        }
    }
    Some(id)
}

fuzz_target!(|data: &[u8]| {
    let _ = run(&mut Unstructured::new(data));
});
