//! `include_device!` generates what `odc-build` generates (tests/generated) for the same file.

use odc::cia402::Controlword;
use odc::{Access, DataType, DefaultValue, ObjectAddr, Pdo};
use odc_tests_generated::lxm23a as built;
use odc_tests_macros::lxm23a::{od, pdo, slave};

#[test]
fn descriptors() {
    assert_eq!(od::DEVICE_TYPE.addr, ObjectAddr::new(0x1000, 0));
    assert_eq!(od::DEVICE_TYPE.data_type(), DataType::Unsigned32);
    assert_eq!(od::DEVICE_TYPE.access, Access::Ro);
    // The manual's default for object 1000h.
    assert_eq!(od::DEVICE_TYPE.default, Some(DefaultValue::Value(0x0402_0192)));
    assert_eq!(od::DEVICE_TYPE.default, built::od::DEVICE_TYPE.default);
    assert_eq!(od::CONTROLWORD.addr, ObjectAddr::new(0x6040, 0));
    assert_eq!(od::CONTROLWORD.data_type(), DataType::Unsigned16);
    assert_eq!(od::CONTROLWORD.access, built::od::CONTROLWORD.access);
    assert_eq!(od::CONTROLWORD.pdo_mappable, built::od::CONTROLWORD.pdo_mappable);
    assert_eq!(
        od::pre_defined_error_field::NUMBER_OF_ERRORS.high,
        built::od::pre_defined_error_field::NUMBER_OF_ERRORS.high
    );
}

#[test]
fn rpdo2_packs_like_odc_build() {
    assert_eq!(pdo::Rpdo2::MAPPING_VALUES, [0x6040_0010, 0x607A_0020]);
    assert_eq!(pdo::Rpdo2::MAPPING_VALUES, built::pdo::Rpdo2::MAPPING_VALUES);
    assert_eq!(pdo::Rpdo2::cob_id(odc::node_id!(5)), 0x8000_0305);
    assert_eq!(<pdo::Rpdo2 as Pdo>::LEN, 6);
    let rx = pdo::Rpdo2 { controlword: Controlword::ENABLE_OPERATION, target_position: -2 };
    let bytes = rx.pack().expect("fits");
    assert_eq!(bytes.as_ref(), &[0x0F, 0x00, 0xFE, 0xFF, 0xFF, 0xFF]);
    let same =
        built::pdo::Rpdo2 { controlword: Controlword::ENABLE_OPERATION, target_position: -2 };
    assert_eq!(same.pack().expect("fits").as_ref(), bytes.as_ref());
    assert_eq!(pdo::Rpdo2::unpack(bytes.as_ref()), Ok(rx));
}

#[test]
fn slave_reads_the_device_type() {
    let d = slave::Dictionary::new(odc::node_id!(3));
    let mut buf = [0u8; 4];
    assert_eq!(odc::slave::ObjectDictionary::read(&d, 0x1000, 0, &mut buf), Ok(4));
    assert_eq!(u32::from_le_bytes(buf), 0x0402_0192);
}

#[test]
fn esi_device_and_role() {
    // role = "slave": a dictionary, and no master plan module (this would not compile).
    let _ = odc_tests_macros::servoone::slave::Dictionary::new(None);
}
