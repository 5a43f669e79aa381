//! DOMAIN and UNICODE_STRING entries in the simulator (CiA 301 data types DOMAIN 0x000F, UNICODE_STRING 0x000B): served, not
//! dropped. The fixture is the code generation tests' mini drive: 0x1F50:01 "Program
//! number 1" (DOMAIN, wo, as CiA 302-3's program download object) and 0x2001 (UNICODE_STRING,
//! default "Ax").
#![allow(clippy::unwrap_used, clippy::expect_used, clippy::panic)]

use odc::SdoAbort;
use odc::can::CanFrame;
use odc::slave::ObjectDictionary;
use odc_sim::{ModelDictionary, SimDevice};

fn device() -> odc_model::Device {
    let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../odc-codegen/tests/fixtures/mini-drive.eds");
    let loaded = odc_pipeline::load(&path, &odc_pipeline::Options::new()).unwrap();
    loaded.device().unwrap().clone()
}

#[test]
fn the_dictionary_keeps_domains_and_unicode_strings() {
    let mut od = ModelDictionary::new(&device(), odc::node_id!(5));
    let image: Vec<u8> = (0..=255u8).cycle().take(1000).collect();
    assert_eq!(od.domain(0x1F50, 1), None);
    od.write(0x1F50, 1, &image).unwrap();
    assert_eq!(od.domain(0x1F50, 1), Some(&image[..]));
    assert_eq!(od.read(0x1F50, 1, &mut [0; 8]), Err(SdoAbort::ReadOfWriteOnly));
    let mut buf = [0u8; 8];
    assert_eq!(od.read(0x2001, 0, &mut buf), Ok(4));
    assert_eq!(buf[..4], [0x41, 0, 0x78, 0]);
    assert_eq!(od.write(0x2001, 0, &[0x42, 0, 0x43, 0, 0x44, 0]), Err(SdoAbort::TooLong));
    assert_eq!(od.write(0x2001, 0, &[0x42]), Err(SdoAbort::InvalidValue));
    od.reset(odc::node_id!(5).into());
    assert_eq!(od.domain(0x1F50, 1), None, "reset node: the application starts afresh");
}

/// The simulated node answers an SDO download of 0x1F50:01 (expedited, 4 bytes) with the
/// download response, not 0x06090011.
#[test]
fn the_simulated_node_takes_a_program_download() {
    let mut dev = SimDevice::new(&device(), odc::node_id!(5));
    let mut out = Vec::new();
    dev.start(0, &mut |f| out.push(f));
    out.clear();
    let req = CanFrame::new(0x605, [0x23, 0x50, 0x1F, 0x01, 0xDE, 0xAD, 0xBE, 0xEF]).unwrap();
    dev.handle(&req, 1, &mut |f| out.push(f));
    assert_eq!(out, [CanFrame::new(0x585, [0x60, 0x50, 0x1F, 0x01, 0, 0, 0, 0]).unwrap()]);
    assert_eq!(dev.dictionary().domain(0x1F50, 1), Some(&[0xDE, 0xAD, 0xBE, 0xEF][..]));
}
