//! The CiA 402 words are typed in generated code: the program of issue 14 §3 compiles against
//! the code of `eds/lxm23a.eds`, and the typed fields pack to the bytes of the `u16` they
//! stand for.

use odc::cia402::{Controlword, State, Statusword};
use odc::{DataType, DefaultValue, Pdo};
use odc_tests_generated::lxm23a;

#[test]
fn the_obvious_program_compiles_and_packs() {
    use lxm23a::{od, pdo};
    let rx = pdo::Rpdo2 { controlword: Controlword::ENABLE_OPERATION, target_position: 1000 };
    let tx = pdo::Tpdo2::default();
    let _: Statusword = tx.statusword;
    let _: odc::Entry<Controlword> = od::CONTROLWORD;
    let _: u16 = Controlword::SHUTDOWN.into();

    // Controlword 0x000F little-endian, then the target position 1000 (0x3E8) as an INTEGER32.
    let bytes = rx.pack().expect("6 bytes");
    assert_eq!(bytes.as_ref(), &[0x0F, 0x00, 0xE8, 0x03, 0x00, 0x00]);
    assert_eq!(pdo::Rpdo2::unpack(bytes.as_ref()), Ok(rx));
    assert_eq!(pdo::Rpdo2::MAPPING_VALUES, [0x6040_0010, 0x607A_0020]);
}

#[test]
fn statusword_fields_decode_the_state() {
    let tx = lxm23a::pdo::Tpdo2::unpack(&[0x37, 0x06, 0x10, 0x27, 0x00, 0x00]).expect("6 bytes");
    assert_eq!(tx.statusword, Statusword(0x0637));
    assert_eq!(tx.statusword.state(), Some(State::OperationEnabled));
    assert!(tx.statusword.target_reached());
    assert_eq!(tx.position_actual_value, 10_000);
}

#[test]
fn descriptors_keep_the_wire_type() {
    use lxm23a::od;
    // UNSIGNED16 on the wire and in the SDO encoding; the default typed too.
    assert_eq!(od::CONTROLWORD.data_type(), DataType::Unsigned16);
    assert_eq!(od::STATUSWORD.data_type(), DataType::Unsigned16);
    assert_eq!(od::CONTROLWORD.default, Some(DefaultValue::Value(Controlword(0))));
    assert_eq!(od::CONTROLWORD.decode_download(&[0x06, 0x00]), Ok(Controlword::SHUTDOWN));
    let mut buf = [0u8; 2];
    assert_eq!(od::STATUSWORD.encode_upload(&Statusword(0x0250), &mut buf), Ok(2));
    assert_eq!(buf, [0x50, 0x02]);
}

#[test]
fn the_slave_stores_typed_words() {
    let mut d = lxm23a::slave::Dictionary::new(odc::node_id!(1));
    assert_eq!(d.write(0x6040, 0, &[0x0F, 0x00]), Ok(()));
    assert_eq!(d.get(lxm23a::od::CONTROLWORD), Ok(Controlword::ENABLE_OPERATION));
    assert_eq!(d.set(lxm23a::od::STATUSWORD, State::OperationEnabled.statusword()), Ok(()));
    let mut buf = [0u8; 2];
    assert_eq!(d.read(0x6041, 0, &mut buf), Ok(2));
    assert_eq!(u16::from_le_bytes(buf), 0x0027);
}
