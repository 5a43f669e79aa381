//! The worked examples of the LinMot E1200 manual (`shared/seeds/linmot-e1200-canopen-
//! manual.txt`), rebuilt from the code generated from `eds/linmot-e1200.eds` (and its UPID
//! scheme and `[[process-data]]` layouts) and the odc runtime.
//!
//! Every comparison with a printed frame goes through `common::Records` (the counts of
//! tests/devices/README.md).
//!
//! What is compared, and what is not:
//! - 6.2 command templates (`yy yy` = 2000h + UPID or 2000h + CurveID/EntryNr/ErrCode, `xx` a
//!   value, `-` unused): every request is sent by odc's client on a generated descriptor and
//!   compared exactly in the bytes the template prints as values; its placeholders (`xxh`,
//!   `-`, `CurveID`, `EntryNr`, `2000h + ErrCode`) are transcribed `..` and not compared. The
//!   writes use command 23h (4 bytes) as every template does, through the scheme's
//!   `write-size`. The device's answers are 42h (expedited, size not indicated): odc's server
//!   indicates the size (43h), and the test's `answer()` builds the 42h frames, so every
//!   answer is recorded as not reproduced.
//!   Templates whose index is "2000h + CurveID" (or EntryNr, ErrCode) are sent at 2000h
//!   (CurveID 0), where the file defines the command objects; several commands print `00h
//!   20h` in the request and `CurveID 20h` in the answer, and CurveID 0 is the one reading
//!   under which both agree. The "Start getting UPID List" template prints its `yy yy` as
//!   "2000h + UPID" where the object table gives 2000h sub 20h: it is sent at 2000h.
//! - 7.1 homing and motion command (4 RxPDO frames): the generated `process` structs; the
//!   command's parameter bytes are the fields of the overlay's `RxPdo1GoToPos16` and
//!   `RxPdo2GoToPos16`, which were written from the very figure they are compared with:
//!   recorded as not reproduced.
//! - 5.1 default mapping (layouts, not frames: not counted): RxPDO 1–3 and TxPDO 1–3 as the
//!   overlay declares them, packed in the printed order.
//! - 9.1.3 UPIDs in TxPDO 4: values, no frames (not counted); the mapping entries `4F080110h`
//!   (printed garbled as "ARUSITEn"), `4F080210h`, `4F080320h` from the UPID objects' types.
//! - The TxPDO 4 picture of 9.1.3 (`xxh zzh`) and the "Read Command" screenshot of 7.1 print
//!   placeholders and the values of the frames above, not frames of their own.

use crate::common;

use common::{Bench, Printed, Records, printed};
use odc::can::CanFrame;
use odc::sdo::Client;
use odc::sdo::frame::{Init, Response};
use odc::slave::ObjectDictionary;
use odc::{Entry, MappingEntry, ObjValue, ObjectAddr, SdoAbort};
use odc_tests_devices::linmot_e1200::{self, od, slave, upid};

const NODE: odc::cob::NodeId = odc::node_id!(1);

/// The generated dictionary, taking writes as the E1200 does: 4 bytes whatever the object's
/// width ("size depends on the UPID that will be written"), the value in the low bytes.
struct LinMot {
    od: slave::Dictionary,
}

impl ObjectDictionary for LinMot {
    fn read(&self, index: u16, sub: u8, buf: &mut [u8]) -> Result<usize, SdoAbort> {
        self.od.read(index, sub, buf)
    }

    fn write(&mut self, index: u16, sub: u8, data: &[u8]) -> Result<(), SdoAbort> {
        match self.od.write(index, sub, data) {
            // A narrower object: the low bytes, when the rest only extends them.
            Err(SdoAbort::TooLong) => {
                for n in [2, 1] {
                    let (low, rest) = data.split_at(n.min(data.len()));
                    let negative = low.last().is_some_and(|b| b & 0x80 != 0);
                    let extends = rest.iter().all(|&b| b == 0)
                        || (negative && rest.iter().all(|&b| b == 0xFF));
                    if !extends {
                        break;
                    }
                    match self.od.write(index, sub, low) {
                        Err(SdoAbort::TooLong) => continue,
                        r => return r,
                    }
                }
                Err(SdoAbort::TooLong)
            }
            r => r,
        }
    }
}

fn bench() -> Bench<LinMot> {
    Bench::new(NODE, LinMot { od: slave::Dictionary::new(NODE) })
}

/// A write as the templates send it: command 23h, 4 bytes (the scheme's `write-size`).
#[allow(clippy::expect_used)] // a test helper: a refused write is the test failing
fn write<T: ObjValue>(b: &mut Bench<LinMot>, entry: &Entry<T>, value: T) {
    b.client.write_widened(&mut b.wire, entry, value, upid::WRITE_SIZE).expect("accepted");
}

/// The device's answer to a read of `entry`: 42h (expedited, size not indicated), the 4
/// data bytes from its dictionary, built with odc's frame codec.
#[allow(clippy::expect_used)] // a test helper: an unreadable object is the test failing
fn answer<T: ObjValue>(b: &Bench<LinMot>, entry: &Entry<T>) -> CanFrame {
    let mut data = [0u8; 4];
    let mut buf = [0u8; 4];
    let n = b.wire.od.read(entry.addr.index, entry.addr.sub, &mut buf).expect("readable");
    data[..n].copy_from_slice(&buf[..n]);
    let init = Init::Expedited { data, len: 4, sized: false };
    CanFrame::standard(b.client.response_id(), Response::InitiateUpload(entry.addr, init).encode())
}

/// A read as the templates print it: odc's client's request, and the device's 42h answer.
fn read<T: ObjValue>(b: &mut Bench<LinMot>, entry: &Entry<T>, frames: &mut Vec<CanFrame>) {
    let before = b.wire.log.len();
    b.read(entry);
    frames.push(b.wire.log[before]);
    frames.push(answer(b, entry));
}

/// Why a device answer does not count.
const ANSWER: &str = "the device answers 42h (size not indicated); odc's server answers 43h, so the test's answer() built it";

/// A template frame: requests compared in their printed values, answers not reproduced.
fn template(text: &'static str) -> Printed {
    let p = printed(text);
    if p.id == 0x581 { p.not_reproduced(ANSWER) } else { p }
}

/// A write as the templates print it: odc's client's request (23h).
fn send<T: ObjValue>(
    b: &mut Bench<LinMot>,
    entry: &Entry<T>,
    value: T,
    frames: &mut Vec<CanFrame>,
) {
    let before = b.wire.log.len();
    write(b, entry, value);
    frames.push(b.wire.log[before]);
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
    write(&mut b, &upid::U1B91_RAM, value);
    b.read(&upid::U1B91_ROM);
    write(&mut b, &upid::U1B91_ROM, value);
    b.read(&upid::U1B91_MIN);
    b.read(&upid::U1B91_MAX);
    b.read(&upid::U1B91_DEFAULT);
    write(&mut b, &upid::U1B91_RAM_ROM, value);
    assert_eq!(b.wire.od.od.get(upid::U1B91_RAM), Ok(value));
    // The templates' fixed bytes (command, index, sub-index) and the value written (-1234 =
    // FFFFFB2Eh) in the `xx`; "-" is not used (zero).
    // "yy yy: 2000h + UPID" is 3B91h for UPID 1B91h (9.1.3); `xxh` and `-` are placeholders.
    let mut rec = Records::new("upid_commands");
    rec.compare(
        "6.2.1, UPID commands",
        &b.requests(),
        &[
            printed("601 / 40 91 3B 01 .. .. .. .."),
            printed("601 / 23 91 3B 01 .. .. .. .."),
            printed("601 / 40 91 3B 02 .. .. .. .."),
            printed("601 / 23 91 3B 02 .. .. .. .."),
            printed("601 / 40 91 3B 03 .. .. .. .."),
            printed("601 / 40 91 3B 04 .. .. .. .."),
            printed("601 / 40 91 3B 05 .. .. .. .."),
            printed("601 / 23 91 3B 06 .. .. .. .."),
        ],
    );
    let values: Vec<[u8; 4]> =
        b.requests().iter().map(|f| f.data()[4..].try_into().unwrap()).collect();
    assert!(values.iter().all(|v| *v == [0; 4] || *v == [0x2E, 0xFB, 0xFF, 0xFF]));
}

/// 6.2.1 with a 16-bit UPID: X4.4 Analog Voltage (1CA4h, UInt16) written with the template's
/// command 23h, the value in the low bytes ("size depends on the UPID").
#[test]
fn upid_write_16_bit() {
    let mut b = bench();
    assert_eq!(upid::U1CA4_RAM.data_type().bytes(), Some(2));
    write(&mut b, &upid::U1CA4_RAM, 0x1234);
    write(&mut b, &upid::U1CA4_RAM_ROM, 0x1234);
    assert_eq!(b.wire.od.od.get(upid::U1CA4_RAM), Ok(0x1234));
    // The templates' frames with this UPID's value (counted under upid_commands).
    let data: Vec<[u8; 8]> = b.requests().iter().map(|f| f.data()).collect();
    assert_eq!(
        data,
        [[0x23, 0xA4, 0x3C, 0x01, 0x34, 0x12, 0, 0], [0x23, 0xA4, 0x3C, 0x06, 0x34, 0x12, 0, 0]]
    );
    // A signed UPID (1CA6h, SInt16) is sign-extended; the manual prints no such value, the
    // device takes the low bytes.
    write(&mut b, &upid::U1CA6_RAM, -2);
    assert_eq!(b.requests()[2].data(), [0x23, 0xA6, 0x3C, 0x01, 0xFE, 0xFF, 0xFF, 0xFF]);
    assert_eq!(b.wire.od.od.get(upid::U1CA6_RAM), Ok(-2));
    // A value that does not fit the UPID's 16 bits is refused.
    let e = b.client.download(&mut b.wire, 0x3CA4, 0x01, &[0x34, 0x12, 0x01, 0x00]);
    assert_eq!(e.err().and_then(|e| e.abort()), Some(SdoAbort::TooLong));
    // CiA 301's own form of this write (2Bh, 2 bytes) is what the manual does not print.
    let mut plain = bench();
    plain.write(&upid::U1CA4_RAM, 0x1234);
    assert_eq!(plain.requests()[0].data()[0], 0x2B);
}

/// The device answers reads with command 42h (expedited, size not indicated, 4 bytes); odc's
/// client takes the width from the descriptor's type.
#[test]
fn answers_without_size() {
    let mut client = Client::<8>::new(NODE);
    let addr = upid::U1CA4_RAM.addr;
    client.start_upload(addr.index, addr.sub, odc::time::Instant::ZERO).expect("idle");
    let answer = Response::InitiateUpload(
        addr,
        Init::Expedited { data: [0x34, 0x12, 0, 0], len: 4, sized: false },
    );
    assert_eq!(answer.encode()[0], 0x42);
    let frame = CanFrame::new(0x581, answer.encode()).unwrap();
    assert_eq!(
        client.handle(&frame, odc::time::Instant::from_millis(1)),
        Some(odc::sdo::Step::Done)
    );
    let value: u16 = odc::ObjValue::decode(&client.data()[..2]).expect("2 bytes");
    assert_eq!(value, 0x1234);
}

/// 6.2.1: the UPID list: "Start getting UPID List" (2000h sub 20h, Unsigned16, sent as 23h),
/// "Get Next UPID List item" (sub 21h) and its answer, here the end of the list ("When the end
/// of the list is reached, the UPID FFFFh is sent"; address usage 0).
#[test]
fn upid_list() {
    use od::command_interface_system_upid_list_curve_error_log_command_table as cmd;
    let mut b = bench();
    write(&mut b, &cmd::START_GETTING_UPID_LIST, 0x0000);
    let mut frames = b.requests();
    // The answer: "yy yy: Address Usage", "xx xx: UPID which was found" (low word, high word).
    b.wire.od.od.set(cmd::GET_NEXT_UPID_LIST_ITEM, 0xFFFF_0000).expect("0x2000:21");
    read(&mut b, &cmd::GET_NEXT_UPID_LIST_ITEM, &mut frames);
    // Printed `23h yyh yyh 20h xxh xxh xxh xxh`, `40h yyh yyh 21h - - - -` and the answer
    // `42h yyh yyh 21h yyh yyh xxh xxh`, yy yy "2000h + UPID" where the object table gives
    // 2000h (see the file's documentation): placeholders, not compared.
    let mut rec = Records::new("upid_list");
    rec.compare(
        "6.2.1, UPID list",
        &frames,
        &[
            printed("601 / 23 .. .. 20 .. .. .. .."),
            printed("601 / 40 .. .. 21 .. .. .. .."),
            printed("581 / 42 .. .. 21 .. .. .. ..").not_reproduced(ANSWER),
        ],
    );
}

/// 6.2.2–6.2.5: the system, curve service, error log and command table templates, at 2000h
/// (CurveID, EntryNr and ErrCode 0), "any data" written as 0.
#[test]
fn service_commands() {
    use od::command_interface_system_upid_list_curve_error_log_command_table as cmd;
    let mut b = bench();
    let mut frames = Vec::new();
    // 6.2.2 system commands.
    for e in [
        &cmd::SET_ROM_TO_DEFAULT_OS,
        &cmd::SET_ROM_TO_DEFAULT_MC_SW,
        &cmd::SET_ROM_TO_DEFAULT_INTERFACE,
        &cmd::SET_ROM_TO_DEFAULT_APPLICATION,
        &cmd::RESET_CONTROLLER,
        &cmd::STOP_MC_AND_APPL_SOFTWARE,
        &cmd::START_MC_AND_APPL_SOFTWARE,
    ] {
        send(&mut b, e, 0, &mut frames);
    }
    // 6.2.3 curve service: "Add Curve" carries the info block size (low word) and the data
    // block size (high word); the test's curve has none.
    send(&mut b, &cmd::CURVE_SERVICE_SAVE_TO_FLASH, 0, &mut frames);
    send(&mut b, &cmd::CURVE_SERVICE_DELETE_ALL_CURVES_RAM, 0, &mut frames);
    read(&mut b, &cmd::CURVE_SERVICE_POLL_FLASH, &mut frames);
    read(&mut b, &cmd::CURVE_SERVICE_GET_LAST_RESULT, &mut frames);
    send(&mut b, &cmd::CURVE_SERVICE_ADD_CURVE, 0, &mut frames);
    send(&mut b, &cmd::CURVE_SERVICE_ADD_CURVE_DATA_32BIT, 0, &mut frames);
    send(&mut b, &cmd::CURVE_SERVICE_ADD_CURVE_INFO_BLOCK_32BIT, 0, &mut frames);
    read(&mut b, &cmd::CURVE_SERVICE_GET_CURVE, &mut frames);
    read(&mut b, &cmd::CURVE_SERVICE_GET_CURVE_INFO_BLOCK, &mut frames);
    read(&mut b, &cmd::CURVE_SERVICE_GET_CURVE_DATA_BLOCK, &mut frames);
    // 6.2.4 error log.
    read(&mut b, &cmd::GET_ERROR_LOG_ENTRY_COUNTER, &mut frames);
    read(&mut b, &cmd::GET_ERROR_LOG_ENTRY_ERROR_CODE, &mut frames);
    read(&mut b, &cmd::GET_ERROR_LOG_ENTRY_TIME_LOW, &mut frames);
    read(&mut b, &cmd::GET_ERROR_LOG_ENTRY_TIME_HIGH, &mut frames);
    read(&mut b, &cmd::GET_ERROR_CODE_TEXT_STRINGLET_NR_0, &mut frames);
    // 6.2.5 command table: sub 80h writes "Save to Flash" and reads "Poll Flash".
    send(&mut b, &cmd::CT_SAVE_TO_FLASH_POLL_FLASH, 0, &mut frames);
    read(&mut b, &cmd::CT_SAVE_TO_FLASH_POLL_FLASH, &mut frames);
    send(&mut b, &cmd::CT_DELETE_ALL_ENTRIES_RAM, 0, &mut frames);
    send(&mut b, &cmd::CT_DELETE_ENTRY, 0, &mut frames);
    send(&mut b, &cmd::CT_WRITE_ENTRY, 0, &mut frames);
    send(&mut b, &cmd::CT_WRITE_ENTRY_DATA, 0, &mut frames);
    read(&mut b, &cmd::CT_GET_ENTRY, &mut frames);
    read(&mut b, &cmd::CT_GET_ENTRY_DATA, &mut frames);
    read(&mut b, &cmd::CT_GET_ENTRY_LIST_ENTRY_0_31, &mut frames);
    let mut rec = Records::new("service_commands");
    rec.compare("6.2.2-6.2.5, service commands", &frames, &SERVICE_COMMANDS.map(template));
}

/// The frames of 6.2.2–6.2.5 in the order of the manual, as `service_commands` sends them.
const SERVICE_COMMANDS: [&str; 45] = [
    "601 / 23 00 20 07 .. .. .. ..",
    "601 / 23 00 20 08 .. .. .. ..",
    "601 / 23 00 20 09 .. .. .. ..",
    "601 / 23 00 20 0A .. .. .. ..",
    "601 / 23 00 20 0B .. .. .. ..",
    "601 / 23 00 20 35 .. .. .. ..",
    "601 / 23 00 20 36 .. .. .. ..",
    "601 / 23 00 20 40 .. .. .. ..",
    "601 / 23 00 20 41 .. .. .. ..",
    "601 / 40 00 20 42 .. .. .. ..",
    "581 / 42 .. .. 42 .. .. .. ..",
    "601 / 40 00 20 43 .. .. .. ..",
    "581 / 42 .. .. 43 .. .. .. ..",
    "601 / 23 .. 20 50 .. .. .. ..",
    "601 / 23 .. 20 53 .. .. .. ..",
    "601 / 23 .. 20 54 .. .. .. ..",
    "601 / 40 00 20 60 .. .. .. ..",
    "581 / 42 .. .. 60 .. .. .. ..",
    "601 / 40 00 20 61 .. .. .. ..",
    "581 / 42 .. .. 61 .. .. .. ..",
    "601 / 40 00 20 62 .. .. .. ..",
    "581 / 42 .. .. 62 .. .. .. ..",
    "601 / 40 00 20 70 .. .. .. ..",
    "581 / 42 .. .. 70 .. .. .. ..",
    "601 / 40 00 20 71 .. .. .. ..",
    "581 / 42 .. .. 71 .. .. .. ..",
    "601 / 40 00 20 72 .. .. .. ..",
    "581 / 42 .. .. 72 .. .. .. ..",
    "601 / 40 00 20 73 .. .. .. ..",
    "581 / 42 .. .. 73 .. .. .. ..",
    "601 / 40 .. .. 74 .. .. .. ..",
    "581 / 42 .. .. 74 .. .. .. ..",
    "601 / 23 00 20 80 .. .. .. ..",
    "601 / 40 00 20 80 .. .. .. ..",
    "581 / 42 .. .. 80 .. .. .. ..",
    "601 / 23 00 20 81 .. .. .. ..",
    "601 / 23 .. 20 82 .. .. .. ..",
    "601 / 23 .. 20 83 .. .. .. ..",
    "601 / 23 .. 20 84 .. .. .. ..",
    "601 / 40 .. 20 85 .. .. .. ..",
    "581 / 42 .. .. 85 .. .. .. ..",
    "601 / 40 .. 20 86 .. .. .. ..",
    "581 / 42 .. .. 86 .. .. .. ..",
    "601 / 40 00 20 87 .. .. .. ..",
    "581 / 42 .. .. 87 .. .. .. ..",
];

/// 5.1: the default mapping of RxPDO 1–3 and TxPDO 1–3 (the items in order, their widths),
/// as the overlay declares it: each layout's fields packed little-endian in the printed
/// order, on the pre-defined connection set's identifiers (5.1.3, hex column).
#[test]
fn default_mapping_layouts() {
    use linmot_e1200::process::{RxPdo1, RxPdo2, RxPdo3, TxPdo1, TxPdo2, TxPdo3};
    // "Control Word [16Bit], Motion Cmd Header [16Bit], Motion Cmd Par Byte 00..03 [32Bit]".
    let rx1 = RxPdo1 { control_word: 0x0201, mc_header: 0x0403, mc_par_bytes_0_3: 0x0807_0605 };
    // "Motion Cmd Par Byte 04..07 [32Bit], 08..11 [32Bit]", "12..15, 16..19".
    let rx2 = RxPdo2 { mc_par_bytes_4_7: 0x0403_0201, mc_par_bytes_8_11: 0x0807_0605 };
    let rx3 = RxPdo3 { mc_par_bytes_12_15: 0x0403_0201, mc_par_bytes_16_19: 0x0807_0605 };
    // "Status Word [16Bit], State Var [16Bit], Actual Position [32Bit]".
    let tx1 = TxPdo1 { status_word: 0x0201, state_var: 0x0403, actual_position: 0x0807_0605 };
    // "Demand Position [32Bit], Demand Current [32Bit]".
    let tx2 = TxPdo2 { demand_position: 0x0403_0201, demand_current: 0x0807_0605 };
    // "Warn Word [16Bit], Logged Error Code [16Bit]", UPIDs "[32Bit]".
    let tx3 = TxPdo3 { warn_word: 0x0201, logged_error_code: 0x0403, upid_data: 0x0807_0605 };
    let counting = [1, 2, 3, 4, 5, 6, 7, 8];
    for packed in [rx1.pack(), rx2.pack(), rx3.pack(), tx1.pack(), tx2.pack(), tx3.pack()] {
        assert_eq!(packed, counting);
    }
    let ids = [
        RxPdo1::cob_id(NODE),
        RxPdo2::cob_id(NODE),
        RxPdo3::cob_id(NODE),
        TxPdo1::cob_id(NODE),
        TxPdo2::cob_id(NODE),
        TxPdo3::cob_id(NODE),
    ];
    assert_eq!(ids, [0x201, 0x301, 0x401, 0x181, 0x281, 0x381]);
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
/// 5.1 and 7.1), node 1.
#[test]
fn motion_command_interface() {
    use linmot_e1200::process::{RxPdo1, RxPdo1GoToPos16, RxPdo2, RxPdo2GoToPos16};
    let mut b = bench();
    // 1) Homing, 2) Enter Operational State.
    for control_word in [0x083F, 0x003F] {
        b.frame(RxPdo1::cob_id(NODE), &RxPdo1 { control_word, ..RxPdo1::default() }.pack());
    }
    // 3) VAI 16Bit Go To Pos, header 0901h (count nibble 1): position 50 mm (0.1 mm/LSB),
    // maximal velocity 1 m/s (mm/s), acceleration and deceleration 10 m/s² (0.1 m/s²).
    let command = RxPdo1GoToPos16 {
        control_word: 0x003F,
        mc_header: 0x0901,
        target_position: 500,
        maximal_velocity: 1000,
    };
    b.frame(RxPdo1GoToPos16::cob_id(NODE), &command.pack());
    let rest = RxPdo2GoToPos16 { acceleration: 100, deceleration: 100, mc_par_bytes_8_11: 0 };
    b.frame(RxPdo2GoToPos16::cob_id(NODE), &rest.pack());
    let circular =
        "packed by the overlay's RxPdo1GoToPos16/RxPdo2GoToPos16, written from this very figure";
    let mut rec = Records::new("motion_command_interface");
    rec.compare(
        "7.1, motion command",
        &b.wire.log,
        &[
            printed("201 / 3F 08 00 00 00 00 00 00").not_reproduced(circular),
            printed("201 / 3F 00 00 00 00 00 00 00").not_reproduced(circular),
            printed("201 / 3F 00 01 09 F4 01 E8 03").not_reproduced(circular),
            printed("301 / 64 00 64 00 00 00 00 00").not_reproduced(circular),
        ],
    );
    // The same frames in the general layouts of 5.1: the parameter bytes as 32-bit words.
    let general = RxPdo1::unpack(&command.pack()).expect("8 bytes");
    assert_eq!((general.control_word, general.mc_header), (0x003F, 0x0901));
    assert_eq!(RxPdo2::unpack(&rest.pack()).map(|p| p.mc_par_bytes_8_11), Some(0));
    assert_eq!(RxPdo1GoToPos16::unpack(&command.pack()), Some(command));
    // TxPDO 1 (Status Word, State Var, Actual Position) the other way, a negative position.
    use linmot_e1200::process::TxPdo1;
    let status = TxPdo1 { status_word: 0x0C37, state_var: 0x0800, actual_position: -500 };
    assert_eq!(status.pack(), [0x37, 0x0C, 0x00, 0x08, 0x0C, 0xFE, 0xFF, 0xFF]);
    assert_eq!(TxPdo1::unpack(&status.pack()), Some(status));
    assert_eq!(TxPdo1::unpack(&[0; 7]), None);
}
