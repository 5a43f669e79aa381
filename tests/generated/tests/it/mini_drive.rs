//! The generated code of `mini-drive.eds`, exercised: descriptors, PDO bytes, the slave
//! dictionary's abort codes, the master plan.

use odc::cia402::{Controlword, State, Statusword};
use odc::plan::SdoWrite;
use odc::{Access, DataType, DefaultValue, ObjectAddr, Pdo, SdoAbort};
use odc_tests_generated::mini_drive::{cia402, master, od, pdo, slave};

#[test]
fn descriptors() {
    assert_eq!(od::CONTROLWORD.addr, ObjectAddr::new(0x6040, 0));
    assert_eq!(od::CONTROLWORD.data_type(), DataType::Unsigned16);
    assert_eq!(od::CONTROLWORD.access, Access::Rww);
    const { assert!(od::CONTROLWORD.pdo_mappable) };
    assert_eq!(od::TARGET_POSITION.low, Some(-100_000));
    assert_eq!(od::TARGET_POSITION.high, Some(100_000));
    assert_eq!(od::identity_object::VENDOR_ID.addr, ObjectAddr::new(0x1018, 1));
    assert_eq!(od::identity_object::VENDOR_ID.default, Some(DefaultValue::Value(0x1DD)));
    assert_eq!(od::COB_ID_EMCY.default, Some(DefaultValue::NodeIdPlus(0x80)));
    assert_eq!(od::MANUFACTURER_DEVICE_NAME.data_type(), DataType::VisibleString);
    assert_eq!(od::SCALE_FACTOR.default, Some(DefaultValue::Value(1.5f32)));
}

#[test]
fn rpdo_bytes() {
    // 0x6040 (16 bits), an 8-bit dummy, 0x607A (32 bits): 7 bytes, little-endian.
    let rx = pdo::Rpdo1 { controlword: Controlword::ENABLE_OPERATION, target_position: -2 };
    let bytes = rx.pack().expect("fits");
    assert_eq!(bytes.as_ref(), &[0x0F, 0x00, 0x00, 0xFE, 0xFF, 0xFF, 0xFF]);
    assert_eq!(pdo::Rpdo1::unpack(&[0x0F, 0x00, 0xAA, 0xFE, 0xFF, 0xFF, 0xFF]), Ok(rx));
    assert_eq!(<pdo::Rpdo1 as Pdo>::LEN, 7);
    assert_eq!(pdo::Rpdo1::MAPPING_VALUES, [0x6040_0010, 0x0005_0008, 0x607A_0020]);
    assert_eq!(pdo::Rpdo1::cob_id(odc::node_id!(5)), 0x205);
    assert_eq!(pdo::Rpdo1::TRANSMISSION_TYPE, 255);
}

#[test]
fn tpdo_bytes() {
    let bytes = [0x37, 0x02, 0x08, 0x10, 0x27, 0x00, 0x00];
    let tx = pdo::Tpdo1::unpack(&bytes).expect("7 bytes");
    assert_eq!(tx.statusword, Statusword(0x0237));
    assert_eq!(tx.statusword.state(), Some(State::OperationEnabled));
    assert_eq!(tx.modes_of_operation_display, 8);
    assert_eq!(tx.position_actual_value, 10_000);
    assert_eq!(tx.pack().expect("fits").as_ref(), &bytes);
    assert_eq!(
        cia402::Mode::from_i8(tx.modes_of_operation_display),
        Some(cia402::Mode::CyclicSyncPosition)
    );
    assert_eq!(pdo::Tpdo1::cob_id(odc::node_id!(0x7F)), 0x1FF);
}

#[test]
fn modes_follow_0x6502() {
    // 0x6502 default 0x80: csp only.
    assert_eq!(cia402::Mode::ALL, [cia402::Mode::CyclicSyncPosition]);
    assert_eq!(cia402::Mode::from_i8(1), None);
    assert_eq!(i8::from(cia402::Mode::CyclicSyncPosition), 8);
}

#[test]
fn slave_reads_and_writes() {
    let mut d = slave::Dictionary::new(odc::node_id!(5));
    assert_eq!(d.get(od::COB_ID_EMCY), Ok(0x85));
    let mut buf = [0u8; 8];
    assert_eq!(d.read(0x1018, 1, &mut buf), Ok(4));
    assert_eq!(&buf[..4], &[0xDD, 0x01, 0, 0]);
    assert_eq!(d.read(0x1008, 0, &mut buf), Ok(3));
    assert_eq!(&buf[..3], b"MD1");
    assert_eq!(d.write(0x6040, 0, &[0x06, 0x00]), Ok(()));
    assert_eq!(d.get(od::CONTROLWORD), Ok(Controlword::SHUTDOWN));
    // Abort codes.
    let code = |r: Result<(), SdoAbort>| r.err().map(SdoAbort::to_u32);
    assert_eq!(code(d.write(0x1000, 0, &[0; 4])), Some(0x0601_0002));
    assert_eq!(code(d.write(0x3000, 0, &[0])), Some(0x0602_0000));
    assert_eq!(code(d.write(0x1018, 7, &[0; 4])), Some(0x0609_0011));
    assert_eq!(code(d.write(0x6040, 0, &[0])), Some(0x0607_0013));
    assert_eq!(code(d.write(0x6040, 0, &[0; 3])), Some(0x0607_0012));
    assert_eq!(code(d.write(0x607A, 0, &200_000i32.to_le_bytes())), Some(0x0609_0031));
    assert_eq!(code(d.write(0x607A, 0, &(-200_000i32).to_le_bytes())), Some(0x0609_0032));
    assert_eq!(d.write(0x607A, 0, &1000i32.to_le_bytes()), Ok(()));
    assert_eq!(d.get(od::TARGET_POSITION), Ok(1000));
    assert_eq!(d.read(0x9999, 0, &mut buf), Err(SdoAbort::NoSuchObject));
}

#[test]
fn dictionaries_compare_field_by_field() {
    let mut a = slave::Dictionary::new(odc::node_id!(5));
    let b = slave::Dictionary::new(odc::node_id!(5));
    assert_eq!(a, b);
    // $NODEID+0x80 differs between nodes.
    assert_ne!(a, slave::Dictionary::new(odc::node_id!(6)));
    assert_eq!(a.write(0x607A, 0, &1000i32.to_le_bytes()), Ok(()));
    assert_ne!(a, b);
    let target = b.get(od::TARGET_POSITION).unwrap();
    assert_eq!(a.write(0x607A, 0, &target.to_le_bytes()), Ok(()));
    assert_eq!(a, b);
}

#[test]
fn write_hook_sees_and_vetoes() {
    struct Hook(Vec<ObjectAddr>);
    impl odc::slave::WriteHook for Hook {
        fn before_write(&mut self, addr: ObjectAddr, _: &[u8]) -> Result<(), SdoAbort> {
            if addr.index == 0x6060 { Err(SdoAbort::DeviceState) } else { Ok(()) }
        }
        fn after_write(&mut self, addr: ObjectAddr) {
            self.0.push(addr);
        }
    }
    let mut d = slave::Dictionary::new(odc::node_id!(1));
    let mut hook = Hook(Vec::new());
    assert_eq!(d.write_with(0x6040, 0, &[0x0F, 0], &mut hook), Ok(()));
    assert_eq!(d.write_with(0x6060, 0, &[8], &mut hook), Err(SdoAbort::DeviceState));
    assert_eq!(d.get(od::MODES_OF_OPERATION), Ok(1));
    assert_eq!(hook.0, [ObjectAddr::new(0x6040, 0)]);
    let generic: &mut dyn odc::slave::ObjectDictionary = &mut d;
    assert_eq!(generic.write(0x6040, 0, &[0x07, 0]), Ok(()));
}

#[test]
fn master_plan_follows_cia301() {
    let w = master::rpdo1(odc::node_id!(5));
    assert_eq!(
        w,
        [
            SdoWrite::u32(0x1400, 1, 0x8000_0205),
            SdoWrite::u8(0x1600, 0, 0),
            SdoWrite::u32(0x1600, 1, 0x6040_0010),
            SdoWrite::u32(0x1600, 2, 0x0005_0008),
            SdoWrite::u32(0x1600, 3, 0x607A_0020),
            SdoWrite::u8(0x1600, 0, 3),
            SdoWrite::u8(0x1400, 2, 255),
            SdoWrite::u32(0x1400, 1, 0x205),
        ]
    );
    let t = master::tpdo1(odc::node_id!(5));
    assert_eq!(t.first(), Some(&SdoWrite::u32(0x1800, 1, 0x8000_0185)));
    assert!(t.contains(&SdoWrite::u16(0x1800, 3, 100)));
    assert_eq!(t.last(), Some(&SdoWrite::u32(0x1800, 1, 0x185)));
    let plan = master::plan(odc::node_id!(5));
    assert_eq!(plan.len(), w.len() + t.len());
    assert_eq!(plan[..w.len()], w);
    assert_eq!(SdoWrite::u16(1, 2, 0x1234).to_le_bytes(), ([0x34, 0x12, 0, 0], 2));
}

/// CiA 301 data types DOMAIN and UNICODE_STRING: DOMAIN (0x1F50:01, program data, CiA 302-3) and UNICODE_STRING (0x2001)
/// entries are in the generated dictionary. The UNICODE_STRING holds the file's default
/// ("Ax", UTF-16LE) in the bytes its default takes; the DOMAIN's data goes to the
/// application's `WriteHook::write_domain`, and a dictionary without one refuses it
/// (0x08000020) instead of dropping it.
#[test]
fn domain_and_unicode_entries_are_served() {
    use odc::{Domain, UnicodeString};
    let _: odc::Entry<Domain> = od::program_data::PROGRAM_NUMBER_1;
    let _: odc::Entry<UnicodeString<4>> = od::AXIS_LABEL;
    let mut d = slave::Dictionary::new(odc::node_id!(5));
    let mut buf = [0u8; 8];
    assert_eq!(d.read(0x2001, 0, &mut buf), Ok(4));
    assert_eq!(buf[..4], [0x41, 0, 0x78, 0]);
    assert_eq!(d.write(0x2001, 0, &[0x42, 0]), Ok(()));
    assert_eq!(d.read(0x2001, 0, &mut buf), Ok(2));
    // Longer than the file's default (4 bytes): 0x06070012.
    assert_eq!(d.write(0x2001, 0, &[0x42, 0, 0x43, 0, 0x44, 0]), Err(SdoAbort::TooLong));
    assert_eq!(d.read(0x1F50, 1, &mut buf), Err(SdoAbort::ReadOfWriteOnly));
    assert_eq!(d.write(0x1F50, 1, &[1, 2, 3]), Err(SdoAbort::DataTransfer));

    struct Program(Vec<u8>);
    impl odc::slave::WriteHook for Program {
        fn write_domain(&mut self, addr: ObjectAddr, data: &[u8]) -> Result<(), SdoAbort> {
            assert_eq!(addr, ObjectAddr::new(0x1F50, 1));
            self.0.extend_from_slice(data);
            Ok(())
        }
    }
    let mut program = Program(Vec::new());
    let image: Vec<u8> = (0..200u8).collect();
    assert_eq!(d.write_with(0x1F50, 1, &image, &mut program), Ok(()));
    assert_eq!(program.0, image);
}

/// CiA 306 `LSS_Supported=0` in the file: the generated flag says the device has no LSS.
#[test]
fn lss_follows_the_file() {
    const { assert!(!slave::LSS_SUPPORTED) };
}
