//! The node against a small hand-written dictionary. Expected frames and times are CiA 301's:
//! boot-up 0x700+id with one byte 0; heartbeat states 0x04/0x05/0x7F; guarding answer with the
//! toggle in bit 7, 0 first; EMCY on 0x80+id as code (LE), register, 5 bytes; PDO transmission
//! types as in CiA 301 table 71.

extern crate std;
use std::{vec, vec::Vec};

use super::*;
use crate::SdoAbort;

#[cfg(feature = "lss-slave")]
mod lss;
mod tx;

const ID: u8 = 5;
const NODE: NodeId = crate::node_id!(ID);
const MS: u64 = 1000;

/// One entry: address, value bytes (their length is the type's), writable.
struct Obj {
    index: u16,
    sub: u8,
    value: Vec<u8>,
    writable: bool,
}

/// A dictionary with the communication objects a node uses and three application objects
/// (0x2000 u16, 0x2001 u8, 0x2002 u32).
struct Dict {
    objs: Vec<Obj>,
    writes: Vec<(u16, u8)>,
}

impl Dict {
    fn new() -> Self {
        let mut d = Dict { objs: Vec::new(), writes: Vec::new() };
        let rw = true;
        d.add(0x1000, 0, &0x0000_0191u32.to_le_bytes(), false);
        d.add(0x1001, 0, &[0], false);
        d.add(0x1003, 0, &[0], rw);
        for s in 1..=4 {
            d.add(0x1003, s, &[0; 4], false);
        }
        d.add(0x1005, 0, &0x80u32.to_le_bytes(), rw);
        d.add(0x1006, 0, &0u32.to_le_bytes(), rw);
        d.add(0x100C, 0, &0u16.to_le_bytes(), rw);
        d.add(0x100D, 0, &[0], rw);
        // Store / restore all parameters: capability "on command" (bit 0).
        d.add(0x1010, 0, &[1], false);
        d.add(0x1010, 1, &1u32.to_le_bytes(), rw);
        d.add(0x1011, 0, &[1], false);
        d.add(0x1011, 1, &1u32.to_le_bytes(), rw);
        d.add(0x1014, 0, &(0x80u32 + u32::from(ID)).to_le_bytes(), false);
        d.add(0x1015, 0, &0u16.to_le_bytes(), rw);
        d.add(0x1016, 0, &[2], false);
        d.add(0x1016, 1, &0u32.to_le_bytes(), rw);
        d.add(0x1016, 2, &0u32.to_le_bytes(), rw);
        d.add(0x1017, 0, &0u16.to_le_bytes(), rw);
        d.add(0x1019, 0, &[0], rw);
        // RPDO 1: 0x2000 (16 bits), a dummy byte (0x0005 = UNSIGNED8), 0x2001 (8 bits).
        d.add(0x1400, 1, &(0x200u32 + u32::from(ID)).to_le_bytes(), rw);
        d.add(0x1400, 2, &[255], rw);
        d.add(0x1600, 0, &[3], rw);
        d.add(0x1600, 1, &0x2000_0010u32.to_le_bytes(), rw);
        d.add(0x1600, 2, &0x0005_0008u32.to_le_bytes(), rw);
        d.add(0x1600, 3, &0x2001_0008u32.to_le_bytes(), rw);
        for s in 4..=8 {
            d.add(0x1600, s, &[0; 4], rw);
        }
        // TPDO 1: 0x2000 (16 bits); TPDO 2: 0x2002 (32 bits), 0x1001 (8 bits).
        for (n, maps) in [(0u16, &[0x2000_0010u32][..]), (1, &[0x2002_0020, 0x1001_0008][..])] {
            let cob = 0x180 + 0x100 * u32::from(n) + u32::from(ID);
            d.add(0x1800 + n, 1, &cob.to_le_bytes(), rw);
            d.add(0x1800 + n, 2, &[255], rw);
            d.add(0x1800 + n, 3, &0u16.to_le_bytes(), rw);
            d.add(0x1800 + n, 5, &0u16.to_le_bytes(), rw);
            d.add(0x1800 + n, 6, &[0], rw);
            d.add(0x1A00 + n, 0, &[maps.len() as u8], rw);
            for s in 1..=8u8 {
                let v = maps.get(usize::from(s) - 1).copied().unwrap_or(0);
                d.add(0x1A00 + n, s, &v.to_le_bytes(), rw);
            }
        }
        d.add(0x2000, 0, &[0; 2], rw);
        d.add(0x2001, 0, &[0], rw);
        d.add(0x2002, 0, &[0; 4], rw);
        // A drive's modes: 0x6060, and 0x6502 announcing profile position (bit 0) and
        // homing (bit 5).
        d.add(0x6060, 0, &[0], rw);
        d.add(0x6502, 0, &0x21u32.to_le_bytes(), false);
        d
    }

    fn add(&mut self, index: u16, sub: u8, value: &[u8], writable: bool) {
        self.objs.push(Obj { index, sub, value: value.to_vec(), writable });
    }

    fn find(&self, index: u16, sub: u8) -> Result<usize, SdoAbort> {
        match self.objs.iter().position(|o| (o.index, o.sub) == (index, sub)) {
            Some(p) => Ok(p),
            None if self.objs.iter().any(|o| o.index == index) => Err(SdoAbort::NoSuchSub),
            None => Err(SdoAbort::NoSuchObject),
        }
    }

    /// Firmware-side store, no access check.
    fn set(&mut self, index: u16, sub: u8, value: &[u8]) {
        let p = self.find(index, sub).unwrap();
        self.objs[p].value = value.to_vec();
    }

    fn get(&self, index: u16, sub: u8) -> Vec<u8> {
        self.objs[self.find(index, sub).unwrap()].value.clone()
    }
}

impl ObjectDictionary for Dict {
    fn read(&self, index: u16, sub: u8, buf: &mut [u8]) -> Result<usize, SdoAbort> {
        let v = &self.objs[self.find(index, sub)?].value;
        buf.get_mut(..v.len()).ok_or(SdoAbort::TooShort)?.copy_from_slice(v);
        Ok(v.len())
    }

    fn write(&mut self, index: u16, sub: u8, data: &[u8]) -> Result<(), SdoAbort> {
        let p = self.find(index, sub)?;
        let o = &mut self.objs[p];
        if !o.writable {
            return Err(SdoAbort::WriteOfReadOnly);
        }
        if data.len() != o.value.len() {
            return Err(SdoAbort::LengthMismatch);
        }
        o.value = data.to_vec();
        self.writes.push((index, sub));
        Ok(())
    }

    fn access(&self, index: u16, sub: u8) -> Option<crate::Access> {
        let o = &self.objs[self.find(index, sub).ok()?];
        Some(if o.writable { crate::Access::Rw } else { crate::Access::Ro })
    }

    /// As a file would say: 0x1000 is not mappable, read-only entries only into TPDOs.
    fn pdo_mappable(&self, index: u16, sub: u8, tx: bool) -> Result<u32, SdoAbort> {
        let o = &self.objs[self.find(index, sub)?];
        if index == 0x1000 || !tx && !o.writable {
            return Err(SdoAbort::NotMappable);
        }
        Ok(o.value.len() as u32 * 8)
    }
}

/// A node on a dictionary, with the frames it sent.
struct Bench {
    node: Node<32, 4, 4>,
    dict: Dict,
    sent: Vec<CanFrame>,
    now: u64,
}

fn data(id: u32, bytes: &[u8]) -> CanFrame {
    CanFrame::from_slice(id, bytes).unwrap()
}

impl Bench {
    fn new() -> Self {
        Self::with(Dict::new())
    }

    fn with(dict: Dict) -> Self {
        let mut b = Bench { node: Node::new(NODE), dict, sent: Vec::new(), now: 0 };
        b.node.start(&mut b.dict, crate::time::Instant::ZERO, &mut |f| b.sent.push(f));
        b
    }

    fn rx(&mut self, f: CanFrame) -> Events {
        let sent = &mut self.sent;
        self.node.handle(
            &mut self.dict,
            &f,
            crate::time::Instant::from_micros(self.now),
            &mut |f| sent.push(f),
        )
    }

    fn nmt(&mut self, cs: u8) -> Events {
        self.rx(data(0, &[cs, ID]))
    }

    /// Polls every millisecond until `until_ms`; the events of all polls.
    fn run_to(&mut self, until_ms: u64) -> Events {
        let mut ev = Events::default();
        while self.now < until_ms * MS {
            self.now += MS;
            let sent = &mut self.sent;
            ev.absorb(self.node.poll(
                &mut self.dict,
                crate::time::Instant::from_micros(self.now),
                &mut |f| sent.push(f),
            ));
        }
        ev
    }

    fn take(&mut self) -> Vec<CanFrame> {
        core::mem::take(&mut self.sent)
    }

    fn sdo_write(&mut self, index: u16, sub: u8, value: &[u8]) -> [u8; 8] {
        let n = value.len() as u8;
        let [lo, hi] = index.to_le_bytes();
        let mut req = [0x23 | (4 - n) << 2, lo, hi, sub, 0, 0, 0, 0];
        req[4..4 + value.len()].copy_from_slice(value);
        self.rx(CanFrame::new(0x600 + u32::from(ID), req).unwrap());
        let reply = self.sent.pop().expect("an SDO answer");
        assert_eq!(reply.id, 0x580 + u32::from(ID));
        reply.data
    }

    fn sdo_read(&mut self, index: u16, sub: u8) -> [u8; 8] {
        let [lo, hi] = index.to_le_bytes();
        self.rx(CanFrame::new(0x600 + u32::from(ID), [0x40, lo, hi, sub, 0, 0, 0, 0]).unwrap());
        let reply = self.sent.pop().expect("an SDO answer");
        assert_eq!(reply.id, 0x580 + u32::from(ID));
        reply.data
    }
}

fn ids(frames: &[CanFrame]) -> Vec<u32> {
    frames.iter().map(|f| f.id).collect()
}

#[test]
fn boot_up_then_nmt_states_decide_the_services() {
    let mut b = Bench::new();
    assert_eq!(b.take(), [data(0x705, &[0x00])]);
    assert_eq!(b.node.state(), NmtState::PreOperational);
    // Pre-operational: SDO yes, PDO no.
    assert_eq!(b.sdo_read(0x1000, 0)[..4], [0x43, 0x00, 0x10, 0x00]);
    b.rx(data(0x205, &[1, 2, 0, 3]));
    assert_eq!(b.dict.get(0x2000, 0), [0, 0]);
    // Operational: the RPDO is written.
    assert_eq!(b.nmt(0x01).state, Some(NmtState::Operational));
    b.take();
    let ev = b.rx(data(0x205, &[1, 2, 0, 3]));
    assert_eq!(ev.rpdo, 1);
    assert_eq!((b.dict.get(0x2000, 0), b.dict.get(0x2001, 0)), (vec![1, 2], vec![3]));
    // Stopped: no SDO answer, no PDO; NMT still works.
    assert_eq!(b.nmt(0x02).state, Some(NmtState::Stopped));
    b.rx(CanFrame::new(0x605, [0x40, 0x00, 0x10, 0x00, 0, 0, 0, 0]).unwrap());
    b.rx(data(0x205, &[9, 9, 0, 9]));
    assert_eq!(b.take(), []);
    assert_eq!(b.dict.get(0x2000, 0), [1, 2]);
    assert_eq!(b.nmt(0x80).state, Some(NmtState::PreOperational));
    // A command for another node is not for this one; node 0 is every node.
    assert_eq!(b.rx(data(0, &[0x01, 6])).state, None);
    assert_eq!(b.rx(data(0, &[0x01, 0])).state, Some(NmtState::Operational));
}

#[test]
fn reset_is_reported_and_the_next_poll_boots_again() {
    let mut b = Bench::new();
    b.nmt(0x01);
    b.take();
    let ev = b.nmt(0x81);
    assert_eq!(ev.reset, Some(Reset::Node));
    assert_eq!(b.node.state(), NmtState::BootUp);
    // The application restores its defaults here; then the node boots.
    let ev = b.run_to(1);
    assert_eq!(ev.state, Some(NmtState::PreOperational));
    assert_eq!(b.take(), [data(0x705, &[0])]);
    assert_eq!(b.nmt(0x82).reset, Some(Reset::Communication));
    b.node.set_node_id(crate::node_id!(9));
    b.run_to(2);
    assert_eq!(b.take(), [data(0x709, &[0])]);
    assert_eq!(b.node.node_id(), NodeId::new(9));
}

#[test]
fn heartbeat_period_from_0x1017_written_over_sdo() {
    let mut b = Bench::new();
    b.take();
    assert_eq!(b.run_to(500), Events::default());
    assert_eq!(b.take(), [], "0x1017 = 0: no heartbeat");
    assert_eq!(b.sdo_write(0x1017, 0, &100u16.to_le_bytes())[0], 0x60);
    b.run_to(1000);
    let hb = b.take();
    assert_eq!(hb, vec![data(0x705, &[0x7F]); 5], "every 100 ms from the write at 500 ms");
    b.nmt(0x01);
    b.run_to(1100);
    let hb: Vec<_> = b.take().into_iter().filter(|f| f.id == 0x705).collect();
    assert_eq!(hb, [data(0x705, &[0x05])]);
    b.nmt(0x02);
    b.run_to(1200);
    assert_eq!(b.take(), [data(0x705, &[0x04])], "heartbeat runs in stopped");
}

#[test]
fn heartbeat_consumer_reports_a_loss_once() {
    let mut b = Bench::new();
    b.sdo_write(
        0x1016,
        1,
        &crate::nmt::heartbeat_consumer_entry(crate::node_id!(3), 50).to_le_bytes(),
    );
    assert_eq!(b.run_to(200).heartbeat_lost, 0, "not watched before its first heartbeat");
    let ev = b.rx(data(0x703, &[0x05]));
    assert_eq!(ev.heartbeat_started, 1 << 3);
    assert_eq!(b.run_to(250).heartbeat_lost, 0, "50 ms exactly is in time");
    assert_eq!(b.run_to(251).heartbeat_lost, 1 << 3);
    assert_eq!(b.run_to(400).heartbeat_lost, 0, "once per loss");
    b.now = 400 * MS;
    assert_eq!(b.rx(data(0x703, &[0x05])).heartbeat_started, 1 << 3);
    assert_eq!(b.run_to(451).heartbeat_lost, 1 << 3);
}

/// A lost heartbeat is EMCY 0x8130 ("life guard error or heartbeat error", CiA 301 table 21)
/// with the error register's communication bit, the node's number in the first manufacturer
/// byte; its return sends the "error reset" EMCY (code 0).
#[test]
fn heartbeat_loss_raises_emcy_8130_and_its_return_clears_it() {
    let mut b = Bench::new();
    b.sdo_write(
        0x1016,
        1,
        &crate::nmt::heartbeat_consumer_entry(crate::node_id!(3), 50).to_le_bytes(),
    );
    b.rx(data(0x703, &[0x05]));
    b.take();
    b.run_to(251);
    let emcy: Vec<CanFrame> = b.take().into_iter().filter(|f| f.id == 0x85).collect();
    assert_eq!(emcy, [data(0x85, &[0x30, 0x81, 0x11, 3, 0, 0, 0, 0])]);
    b.now = 300 * MS;
    b.rx(data(0x703, &[0x05]));
    let emcy: Vec<CanFrame> = b.take().into_iter().filter(|f| f.id == 0x85).collect();
    assert_eq!(emcy, [data(0x85, &[0, 0, 0, 0, 0, 0, 0, 0])]);
}

#[test]
fn node_guarding_answers_with_the_toggle_and_detects_life_loss() {
    let mut b = Bench::new();
    b.take();
    b.rx(CanFrame::remote(0x705, 1).unwrap());
    b.rx(CanFrame::remote(0x705, 1).unwrap());
    b.nmt(0x01);
    b.rx(CanFrame::remote(0x705, 1).unwrap());
    assert_eq!(b.take(), [data(0x705, &[0x7F]), data(0x705, &[0xFF]), data(0x705, &[0x05])]);
    // Guard time 100 ms, life time factor 3: 300 ms without a request is a loss.
    b.sdo_write(0x100C, 0, &100u16.to_le_bytes());
    b.sdo_write(0x100D, 0, &[3]);
    b.rx(CanFrame::remote(0x705, 1).unwrap());
    assert_eq!(b.take(), [data(0x705, &[0x85])]);
    assert!(!b.run_to(300).life_guarding_lost);
    assert!(b.run_to(301).life_guarding_lost);
    assert!(!b.run_to(1000).life_guarding_lost, "once per loss");
}

#[test]
fn synchronous_tpdos_every_nth_sync_and_acyclic_on_change() {
    let mut b = Bench::new();
    b.dict.set(0x1800, 2, &[1]); // TPDO 1: every SYNC
    b.dict.set(0x1801, 2, &[5]); // TPDO 2: every 5th
    b.node.reload_parameters(&b.dict, crate::time::Instant::ZERO);
    b.nmt(0x01);
    b.dict.set(0x2000, 0, &[0x34, 0x12]);
    b.take();
    for _ in 0..10 {
        b.rx(data(0x80, &[]));
    }
    let f = b.take();
    assert_eq!(f.iter().filter(|f| f.id == 0x185).count(), 10);
    assert_eq!(f.iter().filter(|f| f.id == 0x285).count(), 2);
    assert_eq!(f[0], data(0x185, &[0x34, 0x12]));
    assert_eq!(ids(&f[..6]), [0x185, 0x185, 0x185, 0x185, 0x185, 0x285], "the 5th SYNC");
    // Type 0: at the SYNC after a change (the first SYNC counts as one).
    b.dict.set(0x1800, 2, &[0]);
    b.node.reload_parameters(&b.dict, crate::time::Instant::ZERO);
    b.nmt(0x80);
    b.nmt(0x01);
    b.rx(data(0x80, &[]));
    b.rx(data(0x80, &[]));
    b.dict.set(0x2000, 0, &[1, 0]);
    b.rx(data(0x80, &[]));
    b.node.trigger_tpdo(1);
    b.rx(data(0x80, &[]));
    let t1: Vec<_> = b.take().into_iter().filter(|f| f.id == 0x185).collect();
    assert_eq!(t1, [data(0x185, &[0x34, 0x12]), data(0x185, &[1, 0]), data(0x185, &[1, 0])]);
}

#[test]
fn sync_start_value_with_a_sync_counter() {
    let mut b = Bench::new();
    b.dict.set(0x1019, 0, &[10]);
    b.dict.set(0x1800, 2, &[2]);
    b.dict.set(0x1800, 6, &[3]);
    b.node.reload_parameters(&b.dict, crate::time::Instant::ZERO);
    b.nmt(0x01);
    b.take();
    let mut at = Vec::new();
    for c in 1..=8u8 {
        b.rx(data(0x80, &[c]));
        if b.take().iter().any(|f| f.id == 0x185) {
            at.push(c);
        }
    }
    assert_eq!(at, [3, 5, 7], "first at counter = start value 3, then every 2nd");
}

#[test]
fn event_driven_tpdo_timer_inhibit_and_change() {
    let mut b = Bench::new();
    b.dict.set(0x1800, 5, &50u16.to_le_bytes()); // event timer 50 ms
    b.dict.set(0x1801, 1, &(0x8000_0285u32).to_le_bytes()); // TPDO 2 off
    b.node.reload_parameters(&b.dict, crate::time::Instant::ZERO);
    b.nmt(0x01);
    b.take();
    b.run_to(1000);
    let n = b.take().len();
    // Sent on entering operational (at the first poll, 1 ms), then every 50 ms: 1 + 19.
    assert_eq!(n, 20);
    // Inhibit time 10 ms (100 × 100 µs): a change 1 ms after a PDO waits 9 ms more.
    b.dict.set(0x1800, 3, &100u16.to_le_bytes());
    b.dict.set(0x1800, 5, &0u16.to_le_bytes());
    b.node.reload_parameters(&b.dict, crate::time::Instant::from_micros(b.now));
    b.nmt(0x80);
    b.nmt(0x01);
    b.run_to(1001);
    assert_eq!(b.take().len(), 1);
    b.dict.set(0x2000, 0, &[7, 0]);
    let mut times = Vec::new();
    for _ in 0..30 {
        b.run_to(b.now / MS + 1);
        if !b.take().is_empty() {
            times.push(b.now / MS);
        }
        if b.now == 1013 * MS {
            b.dict.set(0x2000, 0, &[8, 0]);
        }
    }
    assert_eq!(times, [1011, 1021]);
}

#[test]
fn rtr_tpdos_252_samples_at_sync_253_on_request() {
    let mut b = Bench::new();
    b.dict.set(0x1800, 2, &[252]);
    b.dict.set(0x1801, 2, &[253]);
    b.node.reload_parameters(&b.dict, crate::time::Instant::ZERO);
    b.nmt(0x01);
    b.dict.set(0x2000, 0, &[1, 0]);
    b.rx(data(0x80, &[]));
    b.dict.set(0x2000, 0, &[2, 0]);
    b.dict.set(0x2002, 0, &[1, 2, 3, 4]);
    b.run_to(100);
    b.take();
    b.rx(CanFrame::remote(0x185, 2).unwrap());
    b.rx(CanFrame::remote(0x285, 5).unwrap());
    assert_eq!(b.take(), [data(0x185, &[1, 0]), data(0x285, &[1, 2, 3, 4, 0])]);
    // COB-ID bit 30: no RTR.
    b.dict.set(0x1801, 1, &(0x4000_0285u32).to_le_bytes());
    b.node.reload_parameters(&b.dict, crate::time::Instant::ZERO);
    b.rx(CanFrame::remote(0x285, 5).unwrap());
    assert_eq!(b.take(), []);
}

#[test]
fn rpdo_length_errors_raise_emcy_and_dummy_entries_are_skipped() {
    let mut b = Bench::new();
    b.nmt(0x01);
    b.take();
    let ev = b.rx(data(0x205, &[1, 2, 3]));
    assert_eq!(ev.rpdo, 0);
    assert_eq!(b.take(), [CanFrame::new(0x85, [0x10, 0x82, 0x11, 0, 0, 0, 0, 0]).unwrap()]);
    assert_eq!(b.dict.get(0x2000, 0), [0, 0]);
    let ev = b.rx(data(0x205, &[1, 2, 0xEE, 4, 5]));
    assert_eq!(ev.rpdo, 1);
    assert_eq!(b.take(), [CanFrame::new(0x85, [0x20, 0x82, 0x11, 0, 0, 0, 0, 0]).unwrap()]);
    assert_eq!((b.dict.get(0x2000, 0), b.dict.get(0x2001, 0)), (vec![1, 2], vec![4]));
    assert!(!b.dict.writes.iter().any(|w| w.0 == 0x0005), "no write to the dummy");
    assert_eq!(b.node.error_history(), [0x8220, 0x8210]);
}

#[test]
fn synchronous_rpdo_applies_at_the_next_sync() {
    let mut b = Bench::new();
    b.dict.set(0x1400, 2, &[1]);
    b.node.reload_parameters(&b.dict, crate::time::Instant::ZERO);
    b.nmt(0x01);
    assert_eq!(b.rx(data(0x205, &[1, 2, 0, 3])).rpdo, 0);
    assert_eq!(b.dict.get(0x2000, 0), [0, 0]);
    assert_eq!(b.rx(data(0x80, &[])).rpdo, 1);
    assert_eq!(b.dict.get(0x2000, 0), [1, 2]);
}

#[test]
fn emcy_register_history_and_inhibit() {
    let mut b = Bench::new();
    b.take();
    let mut sent = Vec::new();
    b.node.raise_emcy(
        crate::emcy::EmcyCode(0x2310),
        [1, 2, 3, 4, 5],
        crate::time::Instant::ZERO,
        &mut |f| sent.push(f),
    );
    assert_eq!(sent, [CanFrame::new(0x85, [0x10, 0x23, 0x03, 1, 2, 3, 4, 5]).unwrap()]);
    assert_eq!(b.sdo_read(0x1001, 0)[4], 0x03);
    assert_eq!(b.sdo_read(0x1003, 0)[4], 1);
    assert_eq!(b.sdo_read(0x1003, 1)[4..8], [0x10, 0x23, 0x01, 0x02]);
    // Inhibit 10 ms: the next EMCY waits.
    b.sdo_write(0x1015, 0, &100u16.to_le_bytes());
    sent.clear();
    b.node.raise_emcy(
        crate::emcy::EmcyCode(0x3210),
        [0; 5],
        crate::time::Instant::from_micros(20 * MS),
        &mut |f| sent.push(f),
    );
    assert_eq!(sent.len(), 1, "20 ms after the last one");
    sent.clear();
    b.node.clear_emcy(
        crate::emcy::EmcyCode(0x2310),
        crate::time::Instant::from_micros(21 * MS),
        &mut |f| sent.push(f),
    );
    assert_eq!(sent, [], "inhibited until 30 ms");
    b.take();
    b.now = 21 * MS;
    b.run_to(29);
    assert_eq!(b.take(), []);
    b.run_to(30);
    assert_eq!(b.take(), [data(0x85, &[0, 0, 0x05, 0, 0, 0, 0, 0])], "error reset, voltage left");
    assert_eq!(b.sdo_read(0x1003, 0)[4], 2);
    assert_eq!(b.sdo_read(0x1003, 1)[4..6], [0x10, 0x32]);
    // Writing 0 to 0x1003:0 clears the history; anything else is refused (0x06090030).
    assert_eq!(b.sdo_write(0x1003, 0, &[1]), [0x80, 0x03, 0x10, 0x00, 0x30, 0x00, 0x09, 0x06]);
    assert_eq!(b.sdo_write(0x1003, 0, &[0])[0], 0x60);
    assert_eq!(b.sdo_read(0x1003, 0)[4], 0);
    assert_eq!(b.node.error_register(), ErrorRegister(0x05));
}

#[test]
fn remap_over_sdo_changes_the_tpdo() {
    let mut b = Bench::new();
    b.dict.set(0x2000, 0, &[0xAA, 0xBB]);
    b.dict.set(0x2001, 0, &[0xCC]);
    b.nmt(0x01);
    b.run_to(1);
    assert!(b.take().contains(&data(0x185, &[0xAA, 0xBB])));
    // While TPDO 1 is valid its mapping cannot change (0x06010000).
    assert_eq!(b.sdo_write(0x1A00, 0, &[0]), [0x80, 0x00, 0x1A, 0x00, 0x00, 0x00, 0x01, 0x06]);
    b.sdo_write(0x1800, 1, &0x8000_0185u32.to_le_bytes());
    b.sdo_write(0x1A00, 0, &[0]);
    b.sdo_write(0x1A00, 1, &0x2001_0008u32.to_le_bytes());
    b.sdo_write(0x1A00, 2, &0x2000_0010u32.to_le_bytes());
    b.sdo_write(0x1A00, 0, &[2]);
    b.sdo_write(0x1800, 1, &0x0000_0185u32.to_le_bytes());
    b.take();
    b.run_to(2);
    assert_eq!(b.take(), [data(0x185, &[0xCC, 0xAA, 0xBB])]);
    // More than 64 bits: 0x06040042.
    b.sdo_write(0x1800, 1, &0x8000_0185u32.to_le_bytes());
    for s in 1..=3 {
        b.sdo_write(0x1A00, s, &0x2002_0020u32.to_le_bytes());
    }
    assert_eq!(b.sdo_write(0x1A00, 0, &[3]), [0x80, 0x00, 0x1A, 0x00, 0x42, 0x00, 0x04, 0x06]);
}

/// The abort in an SDO answer.
fn abort_code(reply: [u8; 8]) -> u32 {
    assert_eq!(reply[0], 0x80, "an abort: {reply:02X?}");
    u32::from_le_bytes([reply[4], reply[5], reply[6], reply[7]])
}

/// CiA 301 §7.5.2.36 (RPDO mapping) and §7.5.2.38 (TPDO mapping): the write of an entry
/// naming an object the device does not have is refused with 0x06020000, of one that may
/// not be mapped (or with more bits than the object has) with 0x06040041; enabling a
/// mapping (sub 0) checks its entries the same way, and 0x06040042 for more than 64 bits.
#[test]
fn mapping_entries_are_checked_when_written() {
    let mut b = Bench::new();
    b.take();
    // Pre-operational, TPDO 1 disabled for the remap.
    b.sdo_write(0x1800, 1, &0x8000_0185u32.to_le_bytes());
    assert_eq!(b.sdo_write(0x1A00, 0, &[0])[0], 0x60);
    let entry = |b: &mut Bench, map: u16, v: u32| abort_code(b.sdo_write(map, 1, &v.to_le_bytes()));
    assert_eq!(entry(&mut b, 0x1A00, 0x3000_0010), 0x0602_0000, "no object 0x3000");
    assert_eq!(entry(&mut b, 0x1A00, 0x2000_0910), 0x0602_0000, "no sub 9 of 0x2000");
    assert_eq!(entry(&mut b, 0x1A00, 0x1000_0020), 0x0604_0041, "0x1000 not mappable");
    assert_eq!(entry(&mut b, 0x1A00, 0x2000_0020), 0x0604_0041, "32 bits of a 16-bit object");
    assert_eq!(entry(&mut b, 0x1A00, 0x2000_0000), 0x0604_0041, "no bits");
    assert_eq!(b.sdo_write(0x1600, 0, &[0])[0], 0x60);
    assert_eq!(entry(&mut b, 0x1600, 0x1001_0008), 0x0604_0041, "read-only into an RPDO");
    // Refused writes leave the entries as they were.
    assert_eq!(b.dict.get(0x1A00, 1), 0x2000_0010u32.to_le_bytes());
    // A good entry, a dummy in an RPDO, and 0 (an unused entry) are accepted.
    assert_eq!(b.sdo_write(0x1A00, 1, &0x2002_0020u32.to_le_bytes())[0], 0x60);
    assert_eq!(b.sdo_write(0x1600, 1, &0x0006_0010u32.to_le_bytes())[0], 0x60);
    assert_eq!(b.sdo_write(0x1A00, 2, &0u32.to_le_bytes())[0], 0x60);
    // Sub 0 counts an entry the firmware left bad: refused when the mapping is enabled.
    b.dict.set(0x1A00, 2, &0x1000_0020u32.to_le_bytes());
    assert_eq!(abort_code(b.sdo_write(0x1A00, 0, &[2])), 0x0604_0041);
    b.dict.set(0x1A00, 2, &0x4000_0008u32.to_le_bytes());
    assert_eq!(abort_code(b.sdo_write(0x1A00, 0, &[2])), 0x0602_0000);
    b.dict.set(0x1A00, 2, &0x2002_0020u32.to_le_bytes());
    b.dict.set(0x1A00, 3, &0x2001_0008u32.to_le_bytes());
    assert_eq!(abort_code(b.sdo_write(0x1A00, 0, &[3])), 0x0604_0042, "72 bits");
    assert_eq!(b.sdo_write(0x1A00, 0, &[2])[0], 0x60);
    assert_eq!(abort_code(b.sdo_write(0x1A00, 0, &[65])), 0x0604_0042, "65 entries");
}

#[test]
fn sync_producer_with_counter() {
    let mut b = Bench::new();
    b.dict.set(0x1800, 2, &[1]);
    b.dict.set(0x1019, 0, &[3]);
    b.dict.set(0x1006, 0, &10_000u32.to_le_bytes()); // 10 ms
    b.node.reload_parameters(&b.dict, crate::time::Instant::ZERO);
    b.take();
    // Bit 30 of 0x1005 makes the node the SYNC producer.
    b.sdo_write(0x1005, 0, &0x4000_0080u32.to_le_bytes());
    b.nmt(0x01);
    b.run_to(40);
    let f = b.take();
    let syncs: Vec<_> = f.iter().filter(|f| f.id == 0x80).map(|f| f.bytes().to_vec()).collect();
    assert_eq!(syncs, [vec![1], vec![2], vec![3], vec![1]]);
    assert_eq!(f.iter().filter(|f| f.id == 0x185).count(), 4, "its own SYNC drives its TPDOs");
}

#[test]
fn extended_and_remote_frames_are_not_data() {
    let mut b = Bench::new();
    b.nmt(0x01);
    b.take();
    // An extended frame with the NMT or RPDO id, an RTR on the SDO id: nothing.
    b.rx(CanFrame::extended(0, &[0x02, ID]).unwrap());
    b.rx(CanFrame::extended(0x205, &[1, 2, 0, 3]).unwrap());
    b.rx(CanFrame::remote(0x605, 8).unwrap());
    assert_eq!(b.node.state(), NmtState::Operational);
    assert_eq!(b.dict.get(0x2000, 0), [0, 0]);
    assert_eq!(b.take(), []);
}

#[test]
fn event_timer_keeps_its_period_when_polls_are_late() {
    let mut b = Bench::new();
    b.dict.set(0x1800, 5, &50u16.to_le_bytes());
    b.dict.set(0x1801, 1, &(0x8000_0285u32).to_le_bytes());
    b.node.reload_parameters(&b.dict, crate::time::Instant::ZERO);
    b.nmt(0x01);
    b.take();
    // A caller that polls every 7 ms: the PDOs still come every 50 ms on average.
    let mut times = Vec::new();
    while b.now < 1001 * MS {
        b.now += 7 * MS;
        let sent = &mut b.sent;
        b.node.poll(&mut b.dict, crate::time::Instant::from_micros(b.now), &mut |f| sent.push(f));
        if !b.take().is_empty() {
            times.push(b.now / MS);
        }
    }
    assert_eq!(times.len(), 20, "{times:?}");
    assert_eq!(&times[..3], [7, 63, 112]);
}

#[test]
fn a_valid_pdo_can_be_remapped_in_pre_operational() {
    let mut b = Bench::new();
    // TPDO 1 is valid; in pre-operational no PDO runs, so its mapping may change.
    assert_eq!(b.sdo_write(0x1A00, 0, &[0])[0], 0x60);
    assert_eq!(b.sdo_write(0x1A00, 1, &0x2001_0008u32.to_le_bytes())[0], 0x60);
    assert_eq!(b.sdo_write(0x1A00, 0, &[1])[0], 0x60);
    b.dict.set(0x2001, 0, &[0x42]);
    b.nmt(0x01);
    b.take();
    b.run_to(1);
    assert_eq!(b.take()[0], data(0x185, &[0x42]));
}

#[test]
fn dependent_parameters_are_checked() {
    let mut b = Bench::new();
    // A valid TPDO's CAN-ID cannot change (0x06090030); invalid first, then it can.
    assert_eq!(
        b.sdo_write(0x1800, 1, &0x0000_0190u32.to_le_bytes())[4..],
        [0x30, 0x00, 0x09, 0x06]
    );
    assert_eq!(b.sdo_write(0x1800, 1, &0x8000_0185u32.to_le_bytes())[0], 0x60);
    assert_eq!(b.sdo_write(0x1800, 1, &0x0000_0190u32.to_le_bytes())[0], 0x60);
    // Two consumer entries for node 3 (0x06040043); time 0 makes an entry unused.
    let entry = |n, t| {
        let n = NodeId::new(n).unwrap();
        crate::nmt::heartbeat_consumer_entry(n, t).to_le_bytes()
    };
    assert_eq!(b.sdo_write(0x1016, 1, &entry(3, 100))[0], 0x60);
    assert_eq!(b.sdo_write(0x1016, 2, &entry(3, 200))[4..], [0x43, 0x00, 0x04, 0x06]);
    assert_eq!(b.sdo_write(0x1016, 2, &entry(3, 0))[0], 0x60);
    assert_eq!(b.sdo_write(0x1016, 2, &entry(4, 200))[0], 0x60);
}

/// Found by the `node` fuzz target (a TPDO sent on 0x7FF): a PDO, SYNC or EMCY COB-ID on one
/// of CiA 301's restricted CAN-IDs is refused with 0x06090030, so the node never speaks on
/// the identifiers of NMT, SDO, error control or LSS; an invalid PDO may still hold one, and
/// the edges of the ranges are allowed.
#[test]
fn restricted_can_ids_are_refused() {
    let mut b = Bench::new();
    let invalid_value = [0x30, 0x00, 0x09, 0x06];
    assert_eq!(b.sdo_write(0x1800, 1, &0x8000_07FFu32.to_le_bytes())[0], 0x60);
    for id in [0x7FFu32, 0x000, 0x07F, 0x101, 0x180, 0x585, 0x605, 0x6E0, 0x705, 0x7E4] {
        assert_eq!(b.sdo_write(0x1800, 1, &id.to_le_bytes())[4..], invalid_value, "TPDO {id:#X}");
        assert_eq!(b.sdo_write(0x1400, 1, &id.to_le_bytes())[4..], invalid_value, "RPDO {id:#X}");
        assert_eq!(b.sdo_write(0x1005, 0, &id.to_le_bytes())[4..], invalid_value, "SYNC {id:#X}");
    }
    // 29-bit identifiers are outside the rule; 0x080, 0x100, 0x181, 0x580, 0x680 and 0x6DF
    // are free.
    assert_eq!(b.sdo_write(0x1800, 1, &0x2000_0585u32.to_le_bytes())[0], 0x60);
    for id in [0x100u32, 0x181, 0x580, 0x680, 0x6DF] {
        assert_eq!(b.sdo_write(0x1800, 1, &(id | 1 << 31).to_le_bytes())[0], 0x60, "{id:#X}");
        assert_eq!(b.sdo_write(0x1800, 1, &(id & 0x7FF).to_le_bytes())[0], 0x60, "{id:#X}");
    }
    assert_eq!(b.sdo_write(0x1005, 0, &0x80u32.to_le_bytes())[0], 0x60);
    // EMCY (writable here): refused while valid, taken while invalid.
    b.dict.objs.iter_mut().filter(|o| o.index == 0x1014).for_each(|o| o.writable = true);
    assert_eq!(b.sdo_write(0x1014, 0, &0x705u32.to_le_bytes())[4..], invalid_value);
    assert_eq!(b.sdo_write(0x1014, 0, &0x8000_0705u32.to_le_bytes())[0], 0x60);
    assert_eq!(b.sdo_write(0x1014, 0, &0x85u32.to_le_bytes())[0], 0x60);
}

/// Found by the `node` fuzz target: SYNC COB-ID 0xF6FC0032 (producer, 29-bit flag) was taken,
/// and the node produced its SYNC as an 11-bit frame on 0x032. SYNC and EMCY are 11-bit here:
/// a COB-ID with bit 29 or any of bits 11-28 set is refused (0x06090030).
#[test]
fn sync_and_emcy_cob_ids_are_11_bit() {
    let mut b = Bench::new();
    let invalid_value = [0x30, 0x00, 0x09, 0x06];
    b.dict.objs.iter_mut().filter(|o| o.index == 0x1014).for_each(|o| o.writable = true);
    for cob in [0xF6FC_0032u32, 0x6000_0080, 0x2000_0080, 0x0000_0880, 0x1000_0080] {
        assert_eq!(b.sdo_write(0x1005, 0, &cob.to_le_bytes())[4..], invalid_value, "{cob:#X}");
        assert_eq!(b.sdo_write(0x1014, 0, &cob.to_le_bytes())[4..], invalid_value, "{cob:#X}");
    }
    // A SYNC producer on 0x080 every 10 ms is taken and produces 11-bit frames on 0x080.
    assert_eq!(b.sdo_write(0x1006, 0, &10_000u32.to_le_bytes())[0], 0x60);
    assert_eq!(b.sdo_write(0x1005, 0, &0x4000_0080u32.to_le_bytes())[0], 0x60);
    b.take();
    b.run_to(25);
    assert_eq!(ids(&b.take()), [0x080, 0x080]);
}

/// A read-only COB-ID (a device with fixed identifiers, as the LinMot E1200's EDS says) is
/// refused as read-only (0x06010002), not as a CAN-ID change of a valid PDO (0x06090030):
/// the access check comes first, as in a dictionary without a node.
#[test]
fn read_only_cob_id_is_refused_as_read_only() {
    let mut dict = Dict::new();
    let p = dict.find(0x1800, 1).unwrap();
    dict.objs[p].writable = false;
    let mut b = Bench::with(dict);
    b.take();
    assert_eq!(
        b.sdo_write(0x1800, 1, &0x0000_0190u32.to_le_bytes())[4..],
        [0x02, 0x00, 0x01, 0x06]
    );
}

/// CiA 301 block upload (7.2.4.3.12–16) of a 30-byte string through the node: the whole
/// sub-block (4 full segments and the last one, c bit set, sequence numbers 1–5) answers the
/// one "start upload" request; the end frame carries 2 unused bytes in the last segment and
/// the CRC-16-CCITT of the data (0x13D7 for "A".."^", computed apart with Python's crc_hqx).
#[test]
fn block_upload_sends_whole_sub_blocks() {
    let text: Vec<u8> = (0x41..0x41 + 30).collect();
    let mut dict = Dict::new();
    dict.add(0x2003, 0, &text, false);
    let mut b = Bench::with(dict);
    b.take();
    let sdo = |d: [u8; 8]| CanFrame::new(0x605, d).unwrap();
    let answer = |d: [u8; 8]| CanFrame::new(0x585, d).unwrap();
    // Initiate block upload: ccs 5, CRC supported, blksize 127, pst 0.
    b.rx(sdo([0xA4, 0x03, 0x20, 0x00, 127, 0, 0, 0]));
    assert_eq!(b.take(), [answer([0xC6, 0x03, 0x20, 0x00, 30, 0, 0, 0])]);
    b.rx(sdo([0xA3, 0, 0, 0, 0, 0, 0, 0]));
    let mut expected = Vec::new();
    for (i, chunk) in text.chunks(7).enumerate() {
        let last = i == 4;
        let mut d = [0u8; 8];
        d[0] = (i as u8 + 1) | if last { 0x80 } else { 0 };
        d[1..1 + chunk.len()].copy_from_slice(chunk);
        expected.push(answer(d));
    }
    assert_eq!(b.take(), expected);
    // Nothing is left for poll to send.
    b.run_to(2);
    assert_eq!(b.take(), []);
    // Sub-block confirmed (ackseq 5): end with n = 5 unused bytes and the CRC.
    b.rx(sdo([0xA2, 5, 127, 0, 0, 0, 0, 0]));
    assert_eq!(b.take(), [answer([0xC1 | 5 << 2, 0xD7, 0x13, 0, 0, 0, 0, 0])]);
    b.rx(sdo([0xA1, 0, 0, 0, 0, 0, 0, 0]));
    assert_eq!(b.take(), []);
}

/// A segmented upload the client abandons: poll sends the abort "SDO protocol timed out"
/// (0x05040000) once the server's timeout (1000 ms) has passed.
#[test]
fn poll_aborts_an_sdo_transfer_that_timed_out() {
    let mut dict = Dict::new();
    dict.add(0x2003, 0, &[b'x'; 20], false);
    let mut b = Bench::with(dict);
    b.take();
    b.rx(CanFrame::new(0x605, [0x40, 0x03, 0x20, 0x00, 0, 0, 0, 0]).unwrap());
    assert_eq!(b.take(), [CanFrame::new(0x585, [0x41, 0x03, 0x20, 0x00, 20, 0, 0, 0]).unwrap()]);
    b.run_to(1000);
    assert_eq!(b.take(), []);
    b.run_to(1002);
    assert_eq!(
        b.take(),
        [CanFrame::new(0x585, [0x80, 0x03, 0x20, 0x00, 0x00, 0x00, 0x04, 0x05]).unwrap()]
    );
}

/// A TPDO whose mapping has no objects (0x1A00:00 = 0, mapping disabled) is not sent, as a
/// PDO that does not exist (CANopenNode makes it invalid); with its object mapped it is.
#[test]
fn tpdo_without_mapped_objects_is_not_sent() {
    let mut dict = Dict::new();
    dict.set(0x1A00, 0, &[0]);
    dict.set(0x1800, 2, &[254]);
    let mut b = Bench::with(dict);
    b.nmt(0x01);
    b.take();
    b.run_to(10);
    assert!(b.take().iter().all(|f| f.id != 0x185), "an empty TPDO 1 went out");
    b.sdo_write(0x1A00, 0, &[1]);
    b.run_to(20);
    assert!(b.take().iter().any(|f| f.id == 0x185 && f.len == 2), "TPDO 1 with 0x2000");
}

/// CiA 301 object descriptions of 0x1010 (store parameters) and 0x1011 (restore default
/// parameters): only the signatures "save" (0x65766173) and "load" (0x64616F6C) are
/// accepted, anything else is refused with 0x08000020; a read still gives the capability.
#[test]
fn store_and_restore_need_their_signatures() {
    let mut b = Bench::new();
    b.take();
    let save = u32::from_le_bytes(*b"save");
    assert_eq!(save, 0x6576_6173);
    let load = u32::from_le_bytes(*b"load");
    assert_eq!(abort_code(b.sdo_write(0x1010, 1, &1u32.to_le_bytes())), 0x0800_0020);
    assert_eq!(abort_code(b.sdo_write(0x1010, 1, &load.to_le_bytes())), 0x0800_0020);
    assert_eq!(abort_code(b.sdo_write(0x1011, 1, &save.to_le_bytes())), 0x0800_0020);
    assert_eq!(abort_code(b.sdo_write(0x1010, 2, &save.to_le_bytes())), 0x0609_0011);
    let [lo, hi] = 0x1010u16.to_le_bytes();
    let ev = b.rx(CanFrame::new(0x605, [0x23, lo, hi, 1, b's', b'a', b'v', b'e']).unwrap());
    assert_eq!(b.take(), [data(0x585, &[0x60, lo, hi, 1, 0, 0, 0, 0])]);
    assert_eq!(ev.storage, Some(Storage::Save(1)));
    assert_eq!(b.sdo_read(0x1010, 1)[4..8], 1u32.to_le_bytes(), "the capability stays");
    let [lo, hi] = 0x1011u16.to_le_bytes();
    let ev = b.rx(CanFrame::new(0x605, [0x23, lo, hi, 1, b'l', b'o', b'a', b'd']).unwrap());
    assert_eq!(ev.storage, Some(Storage::Restore(1)));
    assert_eq!(b.dict.writes, []);
}

/// CiA 301 object 0x1001 (error register) and the EMCY message (byte 2, the error
/// register): the register is the device's. The application sets it; EMCY frames and 0x1001
/// carry it, over a reset communication too, until it gives it back to the node.
#[test]
fn the_application_sets_the_error_register() {
    let mut b = Bench::new();
    b.take();
    let mut sent = Vec::new();
    let at = crate::time::Instant::ZERO;
    b.node.set_error_register(Some(ErrorRegister(0x01)));
    b.node.raise_emcy(crate::emcy::EmcyCode(0x3100), [0; 5], at, &mut |f| sent.push(f));
    assert_eq!(sent, [data(0x85, &[0x00, 0x31, 0x01, 0, 0, 0, 0, 0])], "not 0x05");
    assert_eq!(b.sdo_read(0x1001, 0)[4], 0x01);
    b.nmt(0x82);
    b.run_to(1);
    assert_eq!(b.node.error_register(), ErrorRegister(0x01), "kept over reset communication");
    b.node.set_error_register(None);
    sent.clear();
    b.node.raise_emcy(crate::emcy::EmcyCode(0x3100), [0; 5], at, &mut |f| sent.push(f));
    assert_eq!(sent[0].data[2], 0x05, "the node's again: generic and voltage");
}

/// CiA 402-2 objects 0x6060 (modes of operation) and 0x6502 (supported drive modes): a
/// mode 0x6502 does not list is refused with 0x06090030; listed ones, 0 and the
/// manufacturer's negative modes are written.
#[test]
fn modes_of_operation_follow_0x6502() {
    let mut b = Bench::new();
    b.take();
    for (mode, ok) in
        [(1i8, true), (6, true), (0, true), (-1, true), (3, false), (8, false), (5, false)]
    {
        let reply = b.sdo_write(0x6060, 0, &[mode as u8]);
        if ok {
            assert_eq!(reply[0], 0x60, "mode {mode}");
            assert_eq!(b.dict.get(0x6060, 0), [mode as u8]);
        } else {
            assert_eq!(abort_code(reply), 0x0609_0030, "mode {mode}");
        }
    }
}
