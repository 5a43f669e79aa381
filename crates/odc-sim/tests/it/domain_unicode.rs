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

/// A DOMAIN with a default in its file (CANopenNode's IO.eds 0x2120:05 and gocanopen's
/// 0x200F have `DefaultValue=0`) holds it after reset node, as the other entries hold theirs:
/// the conformance sweep read it empty.
#[test]
fn a_domain_default_is_its_data_after_reset() {
    let eds = "[DeviceInfo]\nVendorName=t\nProductName=t\n\n\
        [MandatoryObjects]\nSupportedObjects=2\n1=0x1000\n2=0x1001\n\n\
        [OptionalObjects]\nSupportedObjects=0\n\n\
        [ManufacturerObjects]\nSupportedObjects=1\n1=0x2120\n\n\
        [1000]\nParameterName=Device type\nObjectType=0x7\nDataType=0x0007\nAccessType=ro\nDefaultValue=0\nPDOMapping=0\n\n\
        [1001]\nParameterName=Error register\nObjectType=0x7\nDataType=0x0005\nAccessType=ro\nDefaultValue=0\nPDOMapping=0\n\n\
        [2120]\nParameterName=domain\nObjectType=0x7\nDataType=0x000F\nAccessType=rw\nDefaultValue=0\nPDOMapping=0\n";
    let dir = std::env::temp_dir().join(format!("odc-sim-domain-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let path = dir.join("domain.eds");
    std::fs::write(&path, eds).unwrap();
    let loaded = odc_pipeline::load(&path, &odc_pipeline::Options::new()).unwrap();
    let device = loaded.device().unwrap().clone();
    std::fs::remove_dir_all(&dir).unwrap();
    let mut od = ModelDictionary::new(&device, odc::node_id!(5));
    assert_eq!(od.domain(0x2120, 0), Some(&[0u8][..]));
    od.write(0x2120, 0, &[1, 2, 3]).unwrap();
    od.reset(odc::node_id!(5).into());
    let mut buf = [0u8; 8];
    assert_eq!(od.read(0x2120, 0, &mut buf), Ok(1));
    assert_eq!(buf[0], 0);
}

/// A VISIBLE_STRING default with a tab and '€' (as canopensocket's basicDevice.eds 0x2120:07
/// has) is the entry's value, byte for byte, as `VisibleString::from_default` keeps it in
/// generated code; a master's write of the same text is refused, as `VisibleString::decode`
/// refuses it (CiA 301: visible characters only).
#[test]
fn a_string_default_with_a_tab_and_utf8_is_kept() {
    use odc::{ObjValue, VisibleString};
    use odc_model::{
        Access, DataType, Device, Object, ObjectKind, Span, Spanned, SubObject, Value,
    };
    let text = "tab '\t', euro '\u{20AC}'";
    let mut sub = SubObject::new(0, "String", DataType::VisibleString, Access::Rw);
    sub.default = Some(Spanned::new(Value::Text(text.into()), Span::DUMMY));
    let mut object = Object::new(0x2120, "String", ObjectKind::Var, Span::DUMMY);
    object.subs.insert(0, sub);
    let mut device = Device::default();
    device.objects.insert(0x2120, object);
    let mut od = odc_sim::ModelDictionary::new(&device, odc::node_id!(5));
    let mut buf = [0u8; 64];
    let n = od.read(0x2120, 0, &mut buf).unwrap();
    assert_eq!(&buf[..n], text.as_bytes());
    let generated = VisibleString::<32>::from_default(text).unwrap();
    let mut theirs = [0u8; 32];
    assert_eq!(generated.encode(&mut theirs), Ok(text.len()));
    assert_eq!(&theirs[..n], &buf[..n]);
    let want = VisibleString::<32>::decode(text.as_bytes()).map(|_| ());
    assert!(want.is_err());
    assert_eq!(od.write(0x2120, 0, text.as_bytes()), want.map_err(odc::SdoAbort::from));
}
