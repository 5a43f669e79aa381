//! The node over the dictionary odc generates from eds/lxm23a.eds (the Schneider Lexium 23A
//! drive): boot-up, SDO, the drive's default PDOs (TPDO 1 = statusword 0x6041 on 0x185,
//! RPDO 1 = controlword 0x6040 on 0x205, from the EDS), a remap over SDO, heartbeat, EMCY.
//! Frames and times as CiA 301 gives them.
#![allow(clippy::unwrap_used, clippy::expect_used, clippy::panic, missing_docs)]

mod lxm23a {
    odc_macros::include_device!("../../eds/lxm23a.eds", role = "slave");
}

use lxm23a::slave::Dictionary;
use odc::can::CanFrame;
use odc::emcy::EmcyCode;
use odc::nmt::NmtState;
use odc::node::{Events, Node};

const MS: u64 = 1000;

struct Drive {
    node: Node<64>,
    od: Dictionary,
    sent: Vec<CanFrame>,
    now: u64,
}

fn data(id: u32, b: &[u8]) -> CanFrame {
    CanFrame::from_slice(id, b).unwrap()
}

impl Drive {
    fn boot() -> Self {
        let mut d = Drive {
            node: Node::new(odc::node_id!(5)),
            od: Dictionary::new(odc::node_id!(5)),
            sent: Vec::new(),
            now: 0,
        };
        d.node.start(&mut d.od, odc::time::Instant::ZERO, &mut |f| d.sent.push(f));
        d
    }

    fn rx(&mut self, f: CanFrame) -> Events {
        let sent = &mut self.sent;
        self.node.handle(&mut self.od, &f, odc::time::Instant::from_micros(self.now), &mut |f| {
            sent.push(f)
        })
    }

    fn run_to(&mut self, ms: u64) -> Events {
        let mut ev = Events::default();
        while self.now < ms * MS {
            self.now += MS;
            let sent = &mut self.sent;
            let e =
                self.node.poll(&mut self.od, odc::time::Instant::from_micros(self.now), &mut |f| {
                    sent.push(f)
                });
            ev.state = e.state.or(ev.state);
            ev.tpdo |= e.tpdo;
        }
        ev
    }

    fn take(&mut self) -> Vec<CanFrame> {
        std::mem::take(&mut self.sent)
    }

    /// Expedited SDO download; the server's answer.
    fn write(&mut self, index: u16, sub: u8, v: &[u8]) -> [u8; 8] {
        let [lo, hi] = index.to_le_bytes();
        let mut req = [0x23 | (4 - v.len() as u8) << 2, lo, hi, sub, 0, 0, 0, 0];
        req[4..4 + v.len()].copy_from_slice(v);
        self.rx(CanFrame::new(0x605, req).unwrap());
        let r = self.sent.pop().unwrap();
        assert_eq!(r.id(), 0x585);
        r.data()
    }

    fn read(&mut self, index: u16, sub: u8) -> [u8; 8] {
        let [lo, hi] = index.to_le_bytes();
        self.rx(CanFrame::new(0x605, [0x40, lo, hi, sub, 0, 0, 0, 0]).unwrap());
        self.sent.pop().unwrap().data()
    }
}

#[test]
fn boots_and_answers_sdo() {
    let mut d = Drive::boot();
    assert_eq!(d.take(), [data(0x705, &[0])]);
    // 0x1000 = 0x04020192, the manual's default for object 1000h.
    assert_eq!(d.read(0x1000, 0), [0x43, 0x00, 0x10, 0x00, 0x92, 0x01, 0x02, 0x04]);
}

#[test]
fn default_pdos_of_the_eds() {
    let mut d = Drive::boot();
    d.od.set(lxm23a::od::STATUSWORD, 0x0237u16.into()).unwrap();
    d.rx(data(0, &[0x01, 5]));
    d.take();
    // TPDO 1 is event-driven (type 255): its data goes out once on entering operational.
    d.run_to(1);
    assert_eq!(d.take(), [data(0x185, &[0x37, 0x02])]);
    d.run_to(10);
    assert_eq!(d.take(), [], "no change, no event timer: nothing");
    d.od.set(lxm23a::od::STATUSWORD, 0x0637u16.into()).unwrap();
    d.run_to(11);
    assert_eq!(d.take(), [data(0x185, &[0x37, 0x06])], "change of the mapped data");
    // RPDO 1 writes the controlword through the dictionary's write path.
    assert_eq!(d.rx(data(0x205, &[0x0F, 0x00])).rpdo, 1);
    assert_eq!(u16::from(d.od.get(lxm23a::od::CONTROLWORD).unwrap()), 0x000F);
    // One byte is shorter than the mapping: EMCY 0x8210, error register bit 4 (communication).
    d.rx(data(0x205, &[0x06]));
    assert_eq!(d.take(), [CanFrame::new(0x85, [0x10, 0x82, 0x11, 0, 0, 0, 0, 0]).unwrap()]);
    assert_eq!(u16::from(d.od.get(lxm23a::od::CONTROLWORD).unwrap()), 0x000F);
    assert_eq!(d.read(0x1001, 0)[4], 0x11);
    assert_eq!(d.read(0x1003, 1)[4..8], [0x10, 0x82, 0, 0]);
}

#[test]
fn remap_type_and_event_timer_over_sdo() {
    let mut d = Drive::boot();
    d.od.set(lxm23a::od::STATUSWORD, 0x0237u16.into()).unwrap();
    d.od.set(lxm23a::od::MODES_OF_OPERATION_DISPLAY, 1i8).unwrap();
    // What python-canopen's pdo.save() sends: disable, type, timer, mapping, enable.
    let ok = [0x60, 0x00, 0x18, 0x01, 0, 0, 0, 0];
    assert_eq!(d.write(0x1800, 1, &0x8000_0185u32.to_le_bytes()), ok);
    assert_eq!(d.write(0x1800, 5, &50u16.to_le_bytes())[0], 0x60);
    assert_eq!(d.write(0x1A00, 0, &[0])[0], 0x60);
    assert_eq!(d.write(0x1A00, 1, &0x6041_0010u32.to_le_bytes())[0], 0x60);
    assert_eq!(d.write(0x1A00, 2, &0x6061_0008u32.to_le_bytes())[0], 0x60);
    assert_eq!(d.write(0x1A00, 0, &[2])[0], 0x60);
    assert_eq!(d.write(0x1800, 1, &0x0000_0185u32.to_le_bytes())[0], 0x60);
    d.rx(data(0, &[0x01, 0]));
    d.take();
    d.run_to(1000);
    let tpdo: Vec<_> = d.take().into_iter().filter(|f| f.id() == 0x185).collect();
    assert!(tpdo.iter().all(|f| f.bytes() == [0x37, 0x02, 0x01]), "{tpdo:?}");
    // Entering operational at 1 ms, then every 50 ms: 1 + 19 in the first second.
    assert_eq!(tpdo.len(), 20);
    // Type 5: one per five SYNCs.
    d.write(0x1800, 1, &0x8000_0185u32.to_le_bytes());
    d.write(0x1800, 2, &[5]);
    d.write(0x1800, 1, &0x0000_0185u32.to_le_bytes());
    for _ in 0..20 {
        d.rx(data(0x80, &[]));
    }
    assert_eq!(d.take().iter().filter(|f| f.id() == 0x185).count(), 4);
}

#[test]
fn heartbeat_nmt_and_emcy() {
    let mut d = Drive::boot();
    d.take();
    assert_eq!(d.write(0x1017, 0, &200u16.to_le_bytes())[0], 0x60);
    d.run_to(1000);
    assert_eq!(d.take(), vec![data(0x705, &[0x7F]); 5]);
    d.rx(data(0, &[0x02, 5]));
    assert_eq!(d.node.state(), NmtState::Stopped);
    d.run_to(1200);
    assert_eq!(d.take(), [data(0x705, &[0x04])]);
    // In stopped no SDO answer and no EMCY, but the error is recorded.
    d.rx(CanFrame::new(0x605, [0x40, 0x00, 0x10, 0x00, 0, 0, 0, 0]).unwrap());
    let mut sent = Vec::new();
    d.node.raise_emcy(
        EmcyCode::DC_LINK_OVER_VOLTAGE,
        [0; 5],
        odc::time::Instant::from_micros(d.now),
        &mut |f| sent.push(f),
    );
    assert_eq!((d.take(), sent.len()), (vec![], 0));
    d.rx(data(0, &[0x80, 5]));
    d.node.raise_emcy(
        EmcyCode::EXCESS_TEMPERATURE_DEVICE,
        [0xAB, 0, 0, 0, 0],
        odc::time::Instant::from_micros(d.now),
        &mut |f| sent.push(f),
    );
    // Voltage (bit 2) and temperature (bit 3) with the generic bit.
    assert_eq!(sent, [CanFrame::new(0x85, [0x10, 0x42, 0x0D, 0xAB, 0, 0, 0, 0]).unwrap()]);
    assert_eq!(d.read(0x1003, 0)[4], 2);
    // Reset communication: the heartbeat written over SDO goes with the new dictionary.
    assert!(d.rx(data(0, &[0x82, 5])).reset.is_some());
    d.od = Dictionary::new(odc::node_id!(5));
    d.run_to(2000);
    assert_eq!(d.take(), [data(0x705, &[0])]);
    assert_eq!(d.read(0x1003, 0)[4], 0);
}

/// LSS (CiA 305) on the generated dictionary: the node's LSS address is the EDS's 0x1018
/// (vendor 0x000001DD, product 0x00006000, revision 0x02000001, no serial number: 0); a node-ID
/// configured in stopped takes effect at NMT reset communication, where the application builds
/// the dictionary's defaults for the new node-ID: boot-up on 0x709, SDO on 0x609, and the
/// EDS's TPDO 1 COB-ID `$NODEID+0x180` now 0x189.
#[test]
fn lss_address_from_the_eds_and_a_new_node_id() {
    let mut d = Drive {
        node: Node::new(odc::node_id!(5)).with_lss(None, 0),
        od: Dictionary::new(odc::node_id!(5)),
        sent: Vec::new(),
        now: 0,
    };
    d.node.start(&mut d.od, odc::time::Instant::ZERO, &mut |f| d.sent.push(f));
    assert_eq!(d.take(), [data(0x705, &[0])]);
    d.rx(data(0, &[0x02, 5]));
    let lss = |b: &[u8]| {
        let mut f = [0u8; 8];
        f[..b.len()].copy_from_slice(b);
        CanFrame::new(0x7E5, f).unwrap()
    };
    d.rx(lss(&[0x04, 1]));
    for (cs, want) in [(0x5A, 0x0000_01DDu32), (0x5B, 0x0000_6000), (0x5C, 0x0200_0001), (0x5D, 0)]
    {
        d.rx(lss(&[cs]));
        let mut answer = [cs, 0, 0, 0, 0, 0, 0, 0];
        answer[1..5].copy_from_slice(&want.to_le_bytes());
        assert_eq!(d.take(), [CanFrame::new(0x7E4, answer).unwrap()]);
    }
    d.rx(lss(&[0x11, 9]));
    assert_eq!(d.take(), [CanFrame::new(0x7E4, [0x11, 0, 0, 0, 0, 0, 0, 0]).unwrap()]);
    d.rx(lss(&[0x04, 0]));
    assert!(d.rx(data(0, &[0x82, 5])).reset.is_some());
    d.od = Dictionary::new(d.node.next_node_id());
    d.run_to(1);
    assert_eq!(d.take(), [data(0x709, &[0])]);
    d.rx(CanFrame::new(0x609, [0x40, 0x00, 0x18, 0x01, 0, 0, 0, 0]).unwrap());
    assert_eq!(
        d.take(),
        [CanFrame::new(0x589, [0x43, 0x00, 0x18, 0x01, 0x89, 0x01, 0, 0]).unwrap()]
    );
}
