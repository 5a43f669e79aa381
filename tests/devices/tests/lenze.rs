//! The worked examples of the Lenze E94AYCCA manual (`shared/seeds/lenze-e94aycca-canopen-
//! manual.txt`, chapters 7–10), rebuilt from the code generated from `eds/lenze-e94aycca.eds`
//! and the odc runtime. Codes are addressed through the generated Lenze scheme
//! (`lenze::C00061`, …), so the examples also check the code → index rule.
//!
//! Count (18 frames or frame parts printed): 18 reproduced.
//! - 7.2.2 NMT "start remote node" to all nodes (1): reproduced.
//! - 9.2.2 code → index bytes of C00011 (1 partial frame, bytes 2–4): reproduced.
//! - 9.2.3 scaled value 123.45 × 100 (1 partial frame, bytes 5–8): reproduced.
//! - 9.2.4 error code 0x06040041 in bytes 5–8 (1 partial frame): reproduced.
//! - 9.3.1 read C00061, node 5 (2), 9.3.2 write C00088, node 2 (2), 9.3.3 segmented read of
//!   C00099, node 12 (6): reproduced with odc's client and server. The manual says "User data
//!   are displayed in the Motorola format"; every example is little-endian (Intel), and so is
//!   CiA 301: the examples are trusted.
//! - 10.1.3 node guarding of node 2: the RTR request on 0x702 (1) and the response with state
//!   5 (1), answered by odc's `node::Node` (and the next answer with the toggle bit set).
//! - 10.2.3 heartbeat of node 1 (1): the identifier 0x701 is printed, the data byte is the
//!   producer's state; sent by odc's node, operational (5), every 10 ms.
//! - 10.3 EMCY (1): reproduced with the Lenze layout (byte 4 reserved, bytes 5–8 the Lenze
//!   error number, little-endian, in the runtime's 5-byte manufacturer field).
//!
//! The two bit-packed configuration values of chapter 10 are rebuilt as well: the node
//! guarding entry 0x050203E8 (C13386: life time factor 5, node 2, guard time 1000 ms) and the
//! heartbeat consumer entry 0x0001000F (C13385: node 1, 15 ms). The heartbeat example says
//! "every 10 seconds" and sets 10 ms; the values (10 ms < 15 ms consumer time) are trusted.

mod common;

use common::{Bench, assert_same, printed};
use odc::SdoAbort;
use odc::can::CanFrame;
use odc::cob::{Function, NodeId};
use odc::emcy::{EmcyCode, EmcyFrame, ErrorRegister};
use odc::nmt::{NmtCommand, heartbeat_consumer_entry};
use odc::node::Node;
use odc::sdo::frame::{Request, Response};
use odc_tests_devices::lenze_e94aycca::{lenze, od, slave};

fn bench(node: u8) -> Bench<slave::Dictionary> {
    Bench::new(node, slave::Dictionary::new(node))
}

/// 7.2.2: "Identifier: 0x00, User data: 0x0100 (NMT command Start Remote Node to all nodes)".
#[test]
fn nmt_start_all() {
    let mut b = bench(1);
    b.nmt_all(NmtCommand::Start);
    assert_same(&b.wire.log, &[printed("0 / 01 00")]);
}

/// 9.2.2: C00011 is index 24575 − 11 = 0x5FF4, subindex 0; the telegram's bytes 2–4 are
/// `0xF4 0x5F 0x00`.
#[test]
fn code_to_index() {
    let addr = lenze::code(11).expect("C00011 is a code");
    assert_eq!(addr, lenze::C00011.addr);
    let request = Request::InitiateUpload(addr).encode();
    assert_eq!(request[1..4], [0xF4, 0x5F, 0x00]);
    // The other codes of the chapter: C00061 = 0x5FC2, C00088 = 0x5FA7, C00099 = 0x5F9C.
    assert_eq!(lenze::code(61).map(|a| a.index), Some(24514));
    assert_eq!(lenze::code(88).map(|a| a.index), Some(24487));
    assert_eq!(lenze::code(99).map(|a| a.index), Some(24476));
}

/// 9.2.3: a code with scaling factor 100 and format U32 carrying 123.45: 12345 = 0x3039,
/// data bytes `0x39 0x30 0x00 0x00`.
#[test]
fn scaled_value() {
    let raw = (123.45f64 * 100.0).round() as u32;
    assert_eq!(raw, 12345);
    let request = Request::InitiateDownload(
        lenze::C00011.addr,
        odc::sdo::frame::Init::expedited(&raw.to_le_bytes()).expect("4 bytes"),
    )
    .encode();
    assert_eq!(request[4..8], [0x39, 0x30, 0x00, 0x00]);
}

/// 9.2.4: the error code 0x06040041 ("object not mapped to PDO") in bytes 5–8: `0x41 0x00
/// 0x04 0x06`, command 0x80.
#[test]
fn error_response_bytes() {
    let abort = Response::Abort(lenze::C00011.addr, SdoAbort::NotMappable).encode();
    assert_eq!(abort[0], 0x80);
    assert_eq!(abort[4..8], [0x41, 0x00, 0x04, 0x06]);
    // And a real one from the server: C00061 is read-only.
    let mut b = bench(5);
    let e = b.client.write(&mut b.wire, &lenze::C00061, 1).expect_err("read-only");
    assert_eq!(e.abort(), Some(SdoAbort::WriteOfReadOnly));
}

/// 9.3.1: read the heatsink temperature C00061 (INTEGER32, factor 1) of node 5: 43 °C.
#[test]
fn read_parameter() {
    let mut b = bench(5);
    // The device measures 43 °C.
    b.wire.od.set(lenze::C00061, 43).unwrap();
    assert_eq!(b.read(&lenze::C00061), 43);
    assert_same(
        &b.wire.log,
        &[printed("605 / 40 C2 5F 00 00 00 00 00"), printed("585 / 43 C2 5F 00 2B 00 00 00")],
    );
}

/// 9.3.2: write the rated motor current C00088 = 10.2 A (U32, display factor 1/10) to node 2.
#[test]
fn write_parameter() {
    let mut b = bench(2);
    let raw = (10.2f64 * 10.0).round() as u32;
    b.write(&lenze::C00088, raw);
    assert_eq!(b.wire.od.get(lenze::C00088), Ok(102));
    assert_same(
        &b.wire.log,
        &[printed("602 / 23 A7 5F 00 66 00 00 00"), printed("582 / 60 A7 5F 00 00 00 00 00")],
    );
}

/// 9.3.3: read the firmware version C00099 (11 ASCII characters) of node 12 as a "block
/// parameter" (CiA 301 segmented upload).
#[test]
fn read_block_parameter() {
    let mut b = bench(12);
    let version = b.read(&lenze::C00099);
    assert_eq!(version.as_str(), "01.00.00.00");
    assert_same(
        &b.wire.log,
        &[
            printed("60C / 40 9C 5F 00 00 00 00 00"),
            printed("58C / 41 9C 5F 00 0B 00 00 00"),
            printed("60C / 60 00 00 00 00 00 00 00"),
            printed("58C / 00 30 31 2E 30 30 2E 30"),
            printed("60C / 70 00 00 00 00 00 00 00"),
            printed("58C / 17 30 2E 30 30 00 00 00"),
        ],
    );
}

/// 10.1.3: node guarding of node 2 by node 1: guard time 1000 ms, life time factor 5. The
/// master's RTR on 1792 + 2 = 0x702 and the answers of odc's node (node 2, operational): state
/// 5 with the toggle bit 0 in the first answer, 1 in the second (0x85, 10.1.1: "the toggle
/// bit must change its value with each response").
#[test]
fn node_guarding() {
    // The entry of C13386/n: life time factor (bits 31..24), node (23..16), guard time (15..0).
    let entry = 5u32 << 24 | heartbeat_consumer_entry(2, 1000);
    assert_eq!(entry, 0x0502_03E8);
    let mut master = bench(1);
    master.write(&lenze::C13386_1, entry);
    // The slave: guard time and life time factor in 0x100C/0x100D, which its node reads.
    let mut od = slave::Dictionary::new(2);
    od.set(od::GUARD_TIME, 1000).expect("0x100C");
    od.set(od::LIFE_TIME_FACTOR, 5).expect("0x100D");
    let mut node: Node<64> = Node::new(2);
    let mut wire = Vec::new();
    node.start(&mut od, 0, &mut |f| wire.push(f));
    let start = CanFrame::from_slice(0x000, &[NmtCommand::Start as u8, 2]).expect("NMT");
    node.handle(&mut od, &start, 1_000, &mut |f| wire.push(f));
    wire.clear();
    let id = Function::Heartbeat.can_id(NodeId::new(2).expect("node 2")).expect("per node");
    let rtr = CanFrame::remote(u32::from(id), 1);
    for at_ms in [1_000, 2_000] {
        wire.push(rtr);
        node.handle(&mut od, &rtr, at_ms * 1_000, &mut |f| wire.push(f));
    }
    assert_same(
        &wire,
        &[printed("702 RTR"), printed("702 / 05"), printed("702 RTR"), printed("702 / 85")],
    );
}

/// 10.2.3: node 1 produces a heartbeat every 10 ms; node 2 consumes it with 15 ms. odc's
/// node 1, operational, with 0x1017 = 10 ms, sends 0x701 with its state (5) every 10 ms.
#[test]
fn heartbeat() {
    let entry = heartbeat_consumer_entry(1, 15);
    assert_eq!(entry, 0x0001_000F);
    let mut consumer = bench(2);
    consumer.write(&lenze::C13385_1, entry);
    let mut od = slave::Dictionary::new(1);
    od.set(od::PRODUCER_HEARTBEAT_TIME, 10).expect("0x1017");
    let mut node: Node<64> = Node::new(1);
    let mut wire = Vec::new();
    node.start(&mut od, 0, &mut |f| wire.push(f));
    let start = CanFrame::from_slice(0x000, &[NmtCommand::Start as u8, 0]).expect("NMT");
    node.handle(&mut od, &start, 0, &mut |f| wire.push(f));
    wire.clear();
    for ms in 1..=20 {
        node.poll(&mut od, ms * 1_000, &mut |f| wire.push(f));
    }
    assert_same(&wire, &[printed("701 / 05"), printed("701 / 05")]);
}

/// 10.3: the EMCY "generic error" with Lenze error 0x007B001B (encoder wire breakage).
#[test]
fn emcy() {
    let lenze_error = 0x007B_001Bu32.to_le_bytes();
    let emcy = EmcyFrame {
        manufacturer: [0, lenze_error[0], lenze_error[1], lenze_error[2], lenze_error[3]],
        ..EmcyFrame::new(EmcyCode(0x1000), ErrorRegister::GENERIC)
    };
    let cob_id = odc::slave::initial(&od::COB_ID_EMCY, 1, 0);
    let frame = CanFrame::new(cob_id, emcy.encode());
    assert_eq!(frame.id, 0x81);
    assert_eq!(frame.data, [0x00, 0x10, 0x01, 0x00, 0x1B, 0x00, 0x7B, 0x00]);
    // The matching "error-free" message: code 0, register 0, error number 0.
    let cleared = EmcyFrame::new(EmcyCode(0), ErrorRegister::NONE).encode();
    assert_eq!(cleared, [0; 8]);
}
