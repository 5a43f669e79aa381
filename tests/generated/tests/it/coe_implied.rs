//! The generated slave dictionary of a CoE device whose ESI dictionary leaves out 0x1C00,
//! 0x1C12/0x1C13 and the mapping objects (`crates/odc-esi/tests/fixtures/coe_implied.xml`):
//! firmware made from it answers what SOEM's `config_map` and ethercrab read over CoE. The
//! requests are CiA 301 SDO frames, the SDO layer CoE carries unchanged (ETG.1000.6 §5.6.2);
//! the expected bytes are worked out by hand from the ESI's `Sm` and PDO elements.
#![allow(clippy::unwrap_used, clippy::expect_used, clippy::panic)]

use odc::can::CanFrame;
use odc::sdo::Server;
use odc::time::Instant;
use odc_tests_generated::coe_implied::slave;

const NODE: odc::cob::NodeId = odc::node_id!(1);

/// The answer of the generated dictionary to an expedited upload request of `index:sub`.
fn upload(od: &mut slave::Dictionary, index: u16, sub: u8) -> [u8; 8] {
    let mut server = Server::<64>::new(NODE);
    let [lo, hi] = index.to_le_bytes();
    let req = CanFrame::new(0x601, [0x40, lo, hi, sub, 0, 0, 0, 0]).unwrap();
    let resp = server.handle(od, &req, Instant::ZERO).unwrap();
    resp.bytes().try_into().unwrap()
}

#[test]
fn assignment_mapping_and_sm_types_are_served() {
    let mut od = slave::Dictionary::new(NODE);
    // 0x1C13:01 = 0x1A00 (TxPdo Sm="3"), 2 bytes expedited (0x4B); 0x1C13:02 = 0x1A02 (its
    // Mandatory TxPdo without Sm); count 2.
    assert_eq!(upload(&mut od, 0x1C13, 1), [0x4B, 0x13, 0x1C, 0x01, 0x00, 0x1A, 0, 0]);
    assert_eq!(upload(&mut od, 0x1C13, 2), [0x4B, 0x13, 0x1C, 0x02, 0x02, 0x1A, 0, 0]);
    assert_eq!(upload(&mut od, 0x1C13, 0), [0x4F, 0x13, 0x1C, 0x00, 2, 0, 0, 0]);
    // 0x1C12:01 = 0x1600 (RxPdo Sm="2").
    assert_eq!(upload(&mut od, 0x1C12, 1), [0x4B, 0x12, 0x1C, 0x01, 0x00, 0x16, 0, 0]);
    // 0x1600:01 = 0x7000:01, 16 bits: 0x70000110, 4 bytes (0x43).
    assert_eq!(upload(&mut od, 0x1600, 1), [0x43, 0x00, 0x16, 0x01, 0x10, 0x01, 0x00, 0x70]);
    // 0x1C00:03 = 3 (SM 2 Outputs), 0x1C00:04 = 4 (SM 3 Inputs).
    assert_eq!(upload(&mut od, 0x1C00, 3), [0x4F, 0x00, 0x1C, 0x03, 3, 0, 0, 0]);
    assert_eq!(upload(&mut od, 0x1C00, 4), [0x4F, 0x00, 0x1C, 0x04, 4, 0, 0, 0]);
    // No assignment object beyond the ESI's sync managers: abort 0x06020000.
    assert_eq!(upload(&mut od, 0x1C14, 0), [0x80, 0x14, 0x1C, 0x00, 0x00, 0x00, 0x02, 0x06]);
}

#[test]
fn synthesised_objects_are_read_only() {
    let mut od = slave::Dictionary::new(NODE);
    assert_eq!(od.write(0x1C13, 1, &[0x01, 0x1A]), Err(odc::SdoAbort::WriteOfReadOnly));
    let mut buf = [0u8; 2];
    assert_eq!(od.read(0x1C13, 1, &mut buf), Ok(2));
    assert_eq!(buf, [0x00, 0x1A]);
}
