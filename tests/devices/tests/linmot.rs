//! The worked examples of the LinMot E1200 manual (`shared/seeds/linmot-e1200-canopen-
//! manual.txt`), rebuilt from the code generated from `eds/linmot-e1200.eds` (and its UPID
//! scheme) and the odc runtime.
//!
//! Count (12 frames or frame templates printed with bytes): 12 reproduced.
//! - 6.2.1 UPID commands (8 request templates, `yy yy` = 2000h + UPID, `xx` the value): built
//!   with odc's client on the scheme's aliases for UPID 1B91h (SInt32) and compared with the
//!   template's fixed bytes: reproduced. For a 16-bit UPID the template's write command 23h
//!   ("size depends on the UPID") differs from odc's 2Bh (2 bytes, size indicated, CiA 301);
//!   the 32-bit UPID is where both agree. The device answers with 42h (no size); odc's server
//!   indicates the size, and odc's client accepts 42h answers (checked below).
//! - 7.1 homing and motion command (4 RxPDO frames): reproduced with the generated `process`
//!   structs. The manual gives the content of RxPDO 1/2 (Control Word, MC Header, MC parameter
//!   bytes) but no object for these built-in items (the file's [Comments] Line5), so the file
//!   maps nothing and the `pdo` module is empty; the layout is declared as `[[process-data]]`
//!   in the overlay beside the file, from manual 5.1, and generated from there.
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
use odc_tests_devices::linmot_e1200::{self, od, slave, upid};

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
    b.write(&tpdo4::TPDO4_UPIDS_1, 0x1CA4);
    b.write(&tpdo4::TPDO4_UPIDS_2, 0x1CA6);
    b.write(&tpdo4::TPDO4_UPIDS_3, 0x1B91);
    // The device maps 4F08h sub n with the bit length of the UPID's type; the scheme's aliases
    // know the types from the file.
    let entries = [
        (tpdo4::TPDO4_UPIDS_1.addr, upid::U1CA4_RAM.data_type()),
        (tpdo4::TPDO4_UPIDS_2.addr, upid::U1CA6_RAM.data_type()),
        (tpdo4::TPDO4_UPIDS_3.addr, upid::U1B91_RAM.data_type()),
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
/// (090xh), with the default PDO mapping: RxPDO 1 and 2 as the overlay declares them (manual
/// 5.1), node 1.
#[test]
fn motion_command_interface() {
    use linmot_e1200::process::{RxPdo1, RxPdo2};
    let mut b = bench();
    // 1) Homing, 2) Enter Operational State.
    for control_word in [0x083F, 0x003F] {
        b.frame(RxPdo1::cob_id(NODE), &RxPdo1 { control_word, ..RxPdo1::default() }.pack());
    }
    // 3) VAI 16Bit Go To Pos, count nibble 1: position 50 mm (0.1 mm/LSB), maximal velocity
    // 1 m/s (mm/s), acceleration and deceleration 10 m/s² (0.1 m/s²): parameter bytes 0..7.
    let (position, velocity, acceleration, deceleration) = (500u16, 1000u16, 100u16, 100u16);
    let command = RxPdo1 {
        control_word: 0x003F,
        mc_header: 0x0900 | 1,
        mc_par_bytes_0_3: u32::from(position) | u32::from(velocity) << 16,
    };
    b.frame(RxPdo1::cob_id(NODE), &command.pack());
    let rest = RxPdo2 {
        mc_par_bytes_4_7: u32::from(acceleration) | u32::from(deceleration) << 16,
        mc_par_bytes_8_11: 0,
    };
    b.frame(RxPdo2::cob_id(NODE), &rest.pack());
    assert_same(
        &b.wire.log,
        &[
            printed("201 / 3F 08 00 00 00 00 00 00"),
            printed("201 / 3F 00 00 00 00 00 00 00"),
            printed("201 / 3F 00 01 09 F4 01 E8 03"),
            printed("301 / 64 00 64 00 00 00 00 00"),
        ],
    );
    assert_eq!(RxPdo1::unpack(&command.pack()), Some(command));
    // TxPDO 1 (Status Word, State Var, Actual Position) the other way, a negative position.
    use linmot_e1200::process::TxPdo1;
    let status = TxPdo1 { status_word: 0x0C37, state_var: 0x0800, actual_position: -500 };
    assert_eq!(status.pack(), [0x37, 0x0C, 0x00, 0x08, 0x0C, 0xFE, 0xFF, 0xFF]);
    assert_eq!(TxPdo1::unpack(&status.pack()), Some(status));
    assert_eq!(TxPdo1::unpack(&[0; 7]), None);
}
