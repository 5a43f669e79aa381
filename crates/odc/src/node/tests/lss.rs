//! The node's LSS slave. Frames as CiA 305 gives them: requests on 0x7E5, answers on 0x7E4,
//! command specifiers 0x04 switch state global, 0x11 configure node-ID, 0x13 configure bit
//! timing, 0x15 activate bit timing, 0x17 store, 0x4C/0x50 identify non-configured slave,
//! 0x5A inquire vendor-ID, 0x5E inquire node-ID.

use super::*;
use crate::lss::{Identity, LssState, StoreResult};

const ADDRESS: Identity = Identity::new(0x0000_0123, 0x0000_0456, 0x0001_0002, 0x0ABC_DEF0);

fn req(b: &[u8]) -> CanFrame {
    let mut d = [0u8; 8];
    d[..b.len()].copy_from_slice(b);
    CanFrame::new(0x7E5, d).unwrap()
}

fn ans(b: &[u8]) -> CanFrame {
    let mut d = [0u8; 8];
    d[..b.len()].copy_from_slice(b);
    CanFrame::new(0x7E4, d).unwrap()
}

/// The bench's dictionary with the LSS address in 0x1018.
fn dict_with_identity() -> Dict {
    let mut d = Dict::new();
    d.add(0x1018, 0, &[4], false);
    for (s, v) in
        [(1, ADDRESS.vendor), (2, ADDRESS.product), (3, ADDRESS.revision), (4, ADDRESS.serial)]
    {
        d.add(0x1018, s, &v.to_le_bytes(), false);
    }
    d
}

fn bench(node: Node<32, 4, 4>, dict: Dict) -> Bench {
    let mut b = Bench { node, dict, sent: Vec::new(), now: 0 };
    b.node.start(&mut b.dict, crate::time::Instant::ZERO, &mut |f| b.sent.push(f));
    b
}

#[test]
fn configured_node_id_boots_at_the_next_reset_communication() {
    let mut b = bench(Node::new(NODE).with_lss(Some(ADDRESS), 0), Dict::new());
    assert_eq!(b.take(), [data(0x705, &[0])]);
    // LSS runs in stopped too.
    b.nmt(0x02);
    assert_eq!(b.node.state(), NmtState::Stopped);
    assert_eq!(b.rx(req(&[0x04, 1])).lss, Some(LssEvent::State(LssState::Configuration)));
    let ev = b.rx(req(&[0x11, 0x20]));
    assert_eq!(ev.lss, Some(LssEvent::NodeIdConfigured(NodeId::new(0x20))));
    assert_eq!(b.take(), [ans(&[0x11, 0])]);
    // Still node 5 until the reset: inquire node-ID says 5, SDO stays on 0x605.
    b.rx(req(&[0x5E]));
    assert_eq!(b.take(), [ans(&[0x5E, 5])]);
    assert_eq!(b.rx(req(&[0x04, 0])).reset, None);
    assert_eq!(b.node.next_node_id(), NodeId::new(0x20));
    // NMT reset communication: boot-up at the new node-ID, SDO on 0x620/0x5A0.
    assert_eq!(b.nmt(0x82).reset, Some(Reset::Communication));
    assert_eq!(b.take(), []);
    b.run_to(1);
    assert_eq!(b.take(), [data(0x720, &[0])]);
    assert_eq!((b.node.node_id(), b.node.state()), (NodeId::new(0x20), NmtState::PreOperational));
    b.rx(CanFrame::new(0x620, [0x40, 0x00, 0x10, 0x00, 0, 0, 0, 0]).unwrap());
    assert_eq!(
        b.take(),
        [CanFrame::new(0x5A0, [0x43, 0x00, 0x10, 0x00, 0x91, 0x01, 0, 0]).unwrap()]
    );
    // Inquiries are served in configuration state.
    b.rx(req(&[0x04, 1]));
    b.rx(req(&[0x5E]));
    assert_eq!(b.take(), [ans(&[0x5E, 0x20])]);
}

/// CiA 305: a node without node-ID stays in initialisation, sends no boot-up and serves no
/// NMT, until LSS configures a node-ID and switches it to waiting: then it resets its
/// communication and boots at that node-ID. Its address comes from 0x1018.
#[test]
fn unconfigured_node_waits_for_lss() {
    let node = Node::unconfigured().with_lss(None, 0);
    let mut b = bench(node, dict_with_identity());
    b.rx(data(0, &[0x01, 0]));
    b.run_to(50);
    assert_eq!(b.take(), []);
    assert_eq!(b.node.state(), NmtState::BootUp);
    b.rx(req(&[0x4C]));
    assert_eq!(b.take(), [ans(&[0x50])]);
    b.rx(req(&[0x04, 1]));
    b.rx(req(&[0x5A]));
    assert_eq!(b.take(), [ans(&[0x5A, 0x23, 0x01, 0, 0])]);
    b.rx(req(&[0x11, 0x21]));
    assert_eq!(b.take(), [ans(&[0x11, 0])]);
    let ev = b.rx(req(&[0x04, 0]));
    assert_eq!(
        (ev.lss, ev.reset),
        (Some(LssEvent::ResetCommunication), Some(Reset::Communication))
    );
    assert_eq!(b.node.next_node_id(), NodeId::new(0x21));
    let ev = b.run_to(51);
    assert_eq!(ev.state, Some(NmtState::PreOperational));
    assert_eq!(b.take(), [data(0x721, &[0])]);
    // NMT is served now.
    b.rx(data(0, &[0x01, 0x21]));
    assert_eq!(b.node.state(), NmtState::Operational);
}

#[test]
fn store_is_the_applications_and_bit_timing_an_event() {
    // Without storage the slave answers "not supported" (error 1) itself.
    let mut b = bench(Node::new(NODE).with_lss(Some(ADDRESS), 0), Dict::new());
    b.take();
    b.rx(req(&[0x04, 1]));
    assert_eq!(b.rx(req(&[0x17])).lss, None);
    assert_eq!(b.take(), [ans(&[0x17, 1])]);
    assert!(b.node.lss_store_response(StoreResult::Stored, &mut |_| {}));

    let mut b = bench(Node::new(NODE).with_lss(Some(ADDRESS), 0).with_lss_storage(), Dict::new());
    b.take();
    b.rx(req(&[0x04, 1]));
    // Configure bit timing: table 0, index 4 (125 kbit/s).
    assert_eq!(b.rx(req(&[0x13, 0, 4])).lss, Some(LssEvent::BitTimingConfigured(4)));
    assert_eq!(b.take(), [ans(&[0x13, 0])]);
    let ev = b.rx(req(&[0x17]));
    assert_eq!(ev.lss, Some(LssEvent::Store { node_id: Some(NODE), bit_timing: 4 }));
    assert_eq!(b.take(), []);
    let sent = &mut b.sent;
    assert!(b.node.lss_store_response(StoreResult::Stored, &mut |f| sent.push(f)));
    assert_eq!(b.take(), [ans(&[0x17, 0])]);
    // Activate bit timing with a 200 ms switch delay (little-endian in bytes 1-2).
    let ev = b.rx(req(&[0x15, 200, 0]));
    assert_eq!(ev.lss, Some(LssEvent::ActivateBitTiming { delay_ms: 200 }));
    assert_eq!(b.node.lss().map(|l| l.bit_timing()), Some(4));
    assert_eq!(b.take(), []);
}

#[test]
fn a_node_without_lss_ignores_0x7e5_and_the_store_call() {
    let mut b = Bench::new();
    b.take();
    assert_eq!(b.rx(req(&[0x04, 1])), Events::default());
    b.rx(req(&[0x5E]));
    assert_eq!(b.take(), []);
    assert!(!b.node.lss_store_response(StoreResult::Stored, &mut |_| {}));
}
