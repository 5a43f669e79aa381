//! The worked examples of the LinMot E1200 manual (`shared/seeds/linmot-e1200-canopen-
//! manual.txt`), rebuilt from the code generated from `eds/linmot-e1200.eds` (and its UPID
//! scheme) and the odc runtime.
//!
//! Count (12 frames or frame templates printed with bytes, 4 of them the motion command
//! frames of 7.1): 8 reproduced from generated code, 4 not.
//! - 6.2.1 UPID commands (8 request templates, `yy yy` = 2000h + UPID, `xx` the value): built
//!   with odc's client on the scheme's aliases for UPID 1B91h (SInt32) and compared with the
//!   template's fixed bytes: reproduced. For a 16-bit UPID the template's write command 23h
//!   ("size depends on the UPID") differs from odc's 2Bh (2 bytes, size indicated, CiA 301);
//!   the 32-bit UPID is where both agree. The device answers with 42h (no size); odc's server
//!   indicates the size, and odc's client accepts 42h answers (checked below).
//! - 7.1 homing and motion command (4 RxPDO frames): not reproduced from generated code. The
//!   manual gives the content of RxPDO 1/2 (Control Word, MC Header, MC parameter bytes) but no
//!   object for these built-in items (the file's [Comments] Line5), so the file maps nothing
//!   and the generated `pdo` module is empty. The test spells out the manual's layout in its
//!   own code to show what the frames carry; that is the test's code, not generated code.
//! - 9.1.3 UPIDs in TxPDO 4: values, no frames. The UPID writes to 4F08h sub 1–3 go through
//!   the generated descriptors; the device's mapping entries `4F080110h` (printed garbled as
//!   "ARUSITEn"), `4F080210h`, `4F080320h` are rebuilt from the UPID objects' data types,
//!   which the scheme's aliases give.

mod common;

use common::{Bench, assert_same, printed};
use odc::can::CanFrame;
use odc::sdo::Client;
use odc::sdo::frame::{Init, Response};
use odc::{MappingEntry, ObjectAddr};
use odc_tests_devices::linmot_e1200::{od, slave, upid};

const NODE: u8 = 1;

fn bench() -> Bench<slave::Dictionary> {
    Bench::new(NODE, slave::Dictionary::new(NODE))
}

/// 6.2.1: the UPID command requests, for UPID 1B91h (Difference Velocity, SInt32) at
/// 2000h + 1B91h = 3B91h.
#[test]
fn upid_commands() {
    use upid::Op;
    assert_eq!(upid::param(0x1B91, Op::Ram), Some(ObjectAddr::new(0x3B91, 0x01)));
    let mut b = bench();
    let value = -1234;
    b.read(&upid::U1B91_RAM);
    b.write(&upid::U1B91_RAM, value);
    b.read(&upid::U1B91_ROM);
    b.write(&upid::U1B91_ROM, value);
    b.read(&upid::U1B91_MIN);
    b.read(&upid::U1B91_MAX);
    b.read(&upid::U1B91_DEFAULT);
    b.write(&upid::U1B91_RAM_ROM, value);
    // The templates' fixed bytes (command, index, sub-index) are compared; their `xx` are the
    // value written (compared too) or "-" (not used, zero).
    let v = value.to_le_bytes();
    let write = |sub: u8| {
        let f = CanFrame::new(0x601, [0x23, 0x91, 0x3B, sub, v[0], v[1], v[2], v[3]]);
        let text = format!("601 / {}", f.data.map(|b| format!("{b:02X}")).join(" "));
        printed(Box::leak(text.into_boxed_str()))
    };
    assert_same(
        &b.requests(),
        &[
            printed("601 / 40 91 3B 01 00 00 00 00"),
            write(0x01),
            printed("601 / 40 91 3B 02 00 00 00 00"),
            write(0x02),
            printed("601 / 40 91 3B 03 00 00 00 00"),
            printed("601 / 40 91 3B 04 00 00 00 00"),
            printed("601 / 40 91 3B 05 00 00 00 00"),
            write(0x06),
        ],
    );
}

/// The device answers reads with command 42h (expedited, size not indicated, 4 bytes); odc's
/// client takes the width from the descriptor's type.
#[test]
fn answers_without_size() {
    let mut client = Client::<8>::new(NODE);
    let addr = upid::U1CA4_RAM.addr;
    client.start_upload(addr.index, addr.sub, 0).expect("idle");
    let answer = Response::InitiateUpload(
        addr,
        Init::Expedited { data: [0x34, 0x12, 0, 0], len: 4, sized: false },
    );
    assert_eq!(answer.encode()[0], 0x42);
    let frame = CanFrame::new(0x581, answer.encode());
    assert_eq!(client.handle(&frame, 1), Some(odc::sdo::Step::Done));
    let value: u16 = odc::ObjValue::decode(&client.data()[..2]).expect("2 bytes");
    assert_eq!(value, 0x1234);
}

/// 9.1.3: TxPDO 4 carries X4.4 Analog Voltage (UPID 1CA4h, UInt16), Diff Analog Voltage
/// (1CA6h, SInt16) and Difference Velocity (1B91h, SInt32).
#[test]
fn upids_in_txpdo4() {
    use od::tpdo4_upid_mapping as tpdo4;
    let mut b = bench();
    b.write(&tpdo4::TPDO4_UPI_DS_1, 0x1CA4);
    b.write(&tpdo4::TPDO4_UPI_DS_2, 0x1CA6);
    b.write(&tpdo4::TPDO4_UPI_DS_3, 0x1B91);
    // The device maps 4F08h sub n with the bit length of the UPID's type; the scheme's aliases
    // know the types from the file.
    let entries = [
        (tpdo4::TPDO4_UPI_DS_1.addr, upid::U1CA4_RAM.data_type()),
        (tpdo4::TPDO4_UPI_DS_2.addr, upid::U1CA6_RAM.data_type()),
        (tpdo4::TPDO4_UPI_DS_3.addr, upid::U1B91_RAM.data_type()),
    ]
    .map(|(a, t)| {
        let bits = t.bits().expect("an integer type") as u8;
        MappingEntry::new(a.index, a.sub, bits).to_u32()
    });
    assert_eq!(entries, [0x4F08_0110, 0x4F08_0210, 0x4F08_0320]);
    // On the PLC side the placeholders 4F08h sub 7, 8 (2 bytes) and 9 (4 bytes) are mapped.
    let placeholders = [
        od::tpdo4_upid_mapping::TPDO4_2_BYTE_UPID_MAPPED_SUB_07.addr,
        od::tpdo4_upid_mapping::TPDO4_2_BYTE_UPID_MAPPED_SUB_08.addr,
        od::tpdo4_upid_mapping::TPDO4_4_BYTE_UPID_MAPPED_SUB_09.addr,
    ];
    assert_eq!(placeholders.map(|a| a.sub), [7, 8, 9]);
}

/// 7.1: homing, "Enter Operational State", and the motion command "VAI 16Bit Go To Pos"
/// (090xh), with the default PDO mapping. The layout is the manual's (5.1: RxPDO 1 = Control
/// Word 16 + MC Header 16 + MC Par Bytes 0..3; RxPDO 2 = MC Par Bytes 4..7 + 8..11), written
/// out here because the file cannot map it (see the file's documentation).
#[test]
fn motion_command_interface_layout() {
    fn rxpdo1(control_word: u16, header: u16, par: [u8; 4]) -> [u8; 8] {
        let (c, h) = (control_word.to_le_bytes(), header.to_le_bytes());
        [c[0], c[1], h[0], h[1], par[0], par[1], par[2], par[3]]
    }
    // VAI 16Bit Go To Pos, count nibble 1: position 50 mm (0.1 mm), velocity 1 m/s (mm/s),
    // acceleration and deceleration 10 m/s² (0.1 m/s²).
    let (position, velocity, acceleration, deceleration) = (500u16, 1000u16, 100u16, 100u16);
    let header = 0x0900 | 1;
    let (p, v) = (position.to_le_bytes(), velocity.to_le_bytes());
    let (a, d) = (acceleration.to_le_bytes(), deceleration.to_le_bytes());
    let frames = [
        CanFrame::new(0x201, rxpdo1(0x083F, 0, [0; 4])),
        CanFrame::new(0x201, rxpdo1(0x003F, 0, [0; 4])),
        CanFrame::new(0x201, rxpdo1(0x003F, header, [p[0], p[1], v[0], v[1]])),
        CanFrame::new(0x301, [a[0], a[1], d[0], d[1], 0, 0, 0, 0]),
    ];
    assert_same(
        &frames,
        &[
            printed("201 / 3F 08 00 00 00 00 00 00"),
            printed("201 / 3F 00 00 00 00 00 00 00"),
            printed("201 / 3F 00 01 09 F4 01 E8 03"),
            printed("301 / 64 00 64 00 00 00 00 00"),
        ],
    );
    // What the generated code has for these PDOs: nothing to map.
    assert!(odc_tests_devices::linmot_e1200::master::plan(NODE).is_empty());
}
