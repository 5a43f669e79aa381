//! The vendor parameter schemes declared in the overlays beside the device files, as generated
//! code offers them: each manual's own examples of its numbering, the typed aliases, and the
//! run-time lookup of what the file says about a computed address.

use odc::{Access, DataType, Entry, ObjectAddr};
use odc_tests_devices::{lenze_e94aycca, linmot_e1200, lxm23a, servoone, servoone_ecat};

fn addr(index: u16, sub: u8) -> Option<ObjectAddr> {
    Some(ObjectAddr::new(index, sub))
}

/// Compile-time proof that an alias has the value type of the file's object.
fn typed<T: odc::ObjValue>(e: Entry<T>) -> Entry<T> {
    e
}

#[test]
fn lxm23a_keypad_parameters() {
    use lxm23a::keypad;
    // Manual ch. 8: "Pa-bc <==> 2aBC, BC is hexadecimal format of bc"; its two examples.
    assert_eq!(keypad::param(3, 5), addr(0x2305, 0));
    assert_eq!(keypad::param(1, 44), addr(0x212C, 0));
    // Reading notes §5: P3-18 = 0x2312, P4-00 = 0x2400.
    assert_eq!(keypad::param(3, 18), addr(0x2312, 0));
    assert_eq!(keypad::index(4, 0), Some(0x2400));
    // bc has two decimal digits, a one.
    assert_eq!(keypad::param(1, 100), None);
    assert_eq!(keypad::param(10, 0), None);
    // Typed as the parameter tables say (P3-05 UINT16, P1-44 INT32), not the generic INTEGER16.
    let node_id: Entry<u16> = typed(keypad::P3_05);
    assert_eq!(node_id.addr, ObjectAddr::new(0x2305, 0));
    let gear: Entry<i32> = typed(keypad::P1_44);
    assert_eq!(gear.addr, ObjectAddr::new(0x212C, 0));
    assert_eq!(
        keypad::lookup(ObjectAddr::new(0x2305, 0)).map(|e| e.data_type),
        Some(DataType::Unsigned16)
    );
    assert_eq!(keypad::ENTRIES.len(), 14);
    assert!(keypad::ENTRIES.windows(2).all(|w| w[0].addr < w[1].addr));
}

#[test]
fn servoone_device_parameters() {
    use servoone::param;
    // Manual 8.2.3: "2000 h + 1C7 h (0455 hex) = 21C7 h".
    assert_eq!(param::p(455), addr(0x21C7, 0));
    // P 455 MOT_FNOM, which 8.2.3 reads and writes: its type is not printed, so the file
    // gives it the 32 bits every SDO value takes (Table 8.3).
    let fnom: Entry<u32> = typed(param::P0455);
    assert_eq!(fnom.addr, ObjectAddr::new(0x21C7, 0));
    assert_eq!(
        param::lookup(ObjectAddr::new(0x21C7, 0)).map(|e| (e.data_type, e.access)),
        Some((DataType::Unsigned32, Access::Rw))
    );
    // Field parameter P 2007 COM_301_EvMask, element [0] EvMsk_TxPdo1L at sub-index 1.
    assert_eq!(param::p_element(2007, 0), addr(0x27D7, 1));
    assert_eq!(param::p_element(2007, 7), addr(0x27D7, 8));
    let mask: Entry<u32> = typed(param::P2007_0);
    assert_eq!(mask.addr, ObjectAddr::new(0x27D7, 1));
    assert_eq!(mask.name, "EvMsk_TxPdo1L [0]");
    // P 3 DV_DeviceAliasName, the string of the segmented-upload example.
    assert_eq!(param::P0003.addr, ObjectAddr::new(0x2003, 0));
    assert_eq!(param::P0003.data_type(), DataType::VisibleString);
    // The manufacturer area ends at 0x5FFF.
    assert_eq!(param::p(0x3FFF), addr(0x5FFF, 0));
    assert_eq!(param::p(0x4000), None);
    // One object dictionary, two buses: the EtherCAT description gets the same scheme.
    assert_eq!(servoone_ecat::param::p(2007), param::p(2007));
    assert_eq!(servoone_ecat::param::P2007_0.addr, param::P2007_0.addr);
}

#[test]
fn lenze_codes() {
    use lenze_e94aycca::lenze;
    // Manual 9.2.2: C00011 is 24575 - 11 = 24564 = 0x5FF4, subindex 0.
    assert_eq!(lenze::code(11), addr(0x5FF4, 0));
    let speed: Entry<u32> = typed(lenze::C00011);
    assert_eq!(speed.addr, ObjectAddr::new(0x5FF4, 0));
    // The codes of the telegram examples: C00061 (0x5FC2, INTEGER32), C00088 (0x5FA7, U32,
    // written), C00099 (0x5F9C, the 11-character firmware version).
    let temperature: Entry<i32> = typed(lenze::C00061);
    assert_eq!(temperature.addr, ObjectAddr::new(0x5FC2, 0));
    assert_eq!(lenze::C00088.addr, ObjectAddr::new(0x5FA7, 0));
    assert_eq!(lenze::C00088.access, Access::Rw);
    assert_eq!(lenze::C00099.addr, ObjectAddr::new(0x5F9C, 0));
    assert_eq!(
        lenze::lookup(ObjectAddr::new(0x5F9C, 0)).map(|e| e.data_type),
        Some(DataType::VisibleString)
    );
    // The slot rule: C13nnn (MXI1) and C14nnn (MXI2) differ by 1000 in the code, so by 0x3E8
    // in the index: C13350 = 0x2BD9, C14350 = 0x27F1.
    assert_eq!(lenze::C13350.addr, ObjectAddr::new(0x2BD9, 0));
    assert_eq!(lenze::C14350.addr, ObjectAddr::new(0x27F1, 0));
    // Subcodes: C13385/1 (heartbeat consumer 1) and C13386/1 (node guarding 1).
    assert_eq!(lenze::code_sub(13385, 1), addr(0x2BB6, 1));
    assert_eq!(lenze::C13385_1.addr, ObjectAddr::new(0x2BB6, 1));
    assert_eq!(lenze::C13386_32.addr, ObjectAddr::new(0x2BB5, 32));
    assert_eq!(lenze::code_sub(13385, 0), None);
    // Codes above 16383 would leave the manufacturer area.
    assert_eq!(lenze::code(16383), addr(0x2000, 0));
    assert_eq!(lenze::code(16384), None);
    // Every alias is a code the file defines: the file names its VARs "Cnnnnn ...".
    for e in &lenze::ENTRIES {
        let code = 0x5FFF - e.addr.index;
        assert_eq!(lenze::index(code), Some(e.addr.index));
        if e.addr.sub == 0 {
            assert!(e.name.starts_with(&format!("C{code:05}")), "{e:?}");
        }
    }
}

#[test]
fn linmot_upids() {
    use linmot_e1200::upid::{self, Op};
    // Manual 6.2.1: index 2000h + UPID, the sub-index chooses the operation; 9.1.3's UPIDs.
    assert_eq!(upid::param(0x1CA4, Op::Ram), addr(0x3CA4, 0x01));
    assert_eq!(upid::param(0x1CA4, Op::Rom), addr(0x3CA4, 0x02));
    assert_eq!(upid::param(0x1CA4, Op::Min), addr(0x3CA4, 0x03));
    assert_eq!(upid::param(0x1CA4, Op::Max), addr(0x3CA4, 0x04));
    assert_eq!(upid::param(0x1CA4, Op::Default), addr(0x3CA4, 0x05));
    assert_eq!(upid::param(0x1CA4, Op::RamRom), addr(0x3CA4, 0x06));
    let voltage: Entry<u16> = typed(upid::U1CA4_RAM);
    assert_eq!(voltage.addr, ObjectAddr::new(0x3CA4, 1));
    let diff: Entry<i16> = typed(upid::U1CA6_RAM);
    assert_eq!(diff.addr, ObjectAddr::new(0x3CA6, 1));
    let velocity: Entry<i32> = typed(upid::U1B91_RAM);
    assert_eq!(velocity.addr, ObjectAddr::new(0x3B91, 1));
    assert_eq!(upid::U1CA4_MIN.access, Access::Ro);
    assert_eq!(upid::U1CA4_RAM_ROM.access, Access::Wo);
    // UPID 0 means "no mapping"; 0x4F01..=0x4F08 are the UPID PDO mapping objects.
    assert_eq!(upid::param(0, Op::Ram), None);
    assert_eq!(upid::param(0x2F01, Op::Ram), None);
    assert_eq!(upid::index(0x2F09), Some(0x4F09));
    assert_eq!(upid::ENTRIES.len(), 18);
}
