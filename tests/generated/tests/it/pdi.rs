//! The generated process image of the made-up terminal (`pdi-terminal.xml`) on the wire, with
//! the bytes worked out by hand from ETG.1000/ETG.2000: LSB-first bits, little-endian values,
//! SM2's 1-bit output, 7 bits of padding and a 16-bit value; SM3's two 1-bit inputs and a
//! 32-bit counter from bit 2.
#![allow(clippy::unwrap_used, clippy::expect_used, clippy::panic)]

use ethercrab_wire::{EtherCrabWireRead, EtherCrabWireSized, EtherCrabWireWrite, WireError};
use odc::Pdo;
use odc_tests_generated::pdi_terminal::{master, pdi, startup};

/// input_1 = 1, input_2 = 0, counter = -2 (0xFFFF_FFFE) shifted to bit 2: 0x3_FFFF_FFF9.
const INPUTS: [u8; 5] = [0xF9, 0xFF, 0xFF, 0xFF, 0x03];

#[test]
fn outputs_pack_and_inputs_unpack() {
    assert_eq!((pdi::OUTPUT_LEN, pdi::INPUT_LEN), (3, 5));
    let out = pdi::Outputs { output_1: true, value: 0xBEEF };
    assert_eq!(out.pack().unwrap(), [0x01, 0xEF, 0xBE]);
    let inputs = pdi::Inputs::unpack(&INPUTS).unwrap();
    assert_eq!(inputs, pdi::Inputs { input_1: true, input_2: false, counter: -2 });
    assert!(pdi::Inputs::unpack(&INPUTS[..4]).is_err());
}

#[test]
fn ethercrab_traits() {
    assert_eq!(<pdi::Inputs as EtherCrabWireSized>::PACKED_LEN, 5);
    let inputs = pdi::Inputs::unpack_from_slice(&INPUTS).unwrap();
    assert_eq!(inputs.counter, -2);
    assert_eq!(pdi::Inputs::unpack_from_slice(&INPUTS[..4]), Err(WireError::ReadBufferTooShort));
    let mut buf = [0xFFu8; 4];
    let out = pdi::Outputs { output_1: false, value: 0x1234 };
    assert_eq!(out.pack_to_slice(&mut buf).unwrap(), [0x00, 0x34, 0x12]);
    // The padding is cleared, the byte after the image left alone.
    assert_eq!(buf, [0x00, 0x34, 0x12, 0xFF]);
    assert_eq!(out.pack_to_slice(&mut [0u8; 2]), Err(WireError::WriteBufferTooShort));
    // The variant image of the alternative mapping "Short counter".
    let short = pdi::short_counter::Inputs::unpack_from_slice(&[0x0E, 0x00, 0x00]).unwrap();
    assert_eq!((short.input_1, short.input_2, short.counter_16), (false, true, 3));
}

#[test]
fn startup_plan() {
    let plan = startup::PLAN;
    assert_eq!(plan.identity.vendor_id, 2);
    assert_eq!(plan.identity.product_code, 0x03F0_3052);
    assert_eq!(plan.identity.revision, 0x0012_0000);
    // `CheckRevisionNo="LW_EQ"`: another major revision with the same low word passes.
    assert!(plan.identity.matches(2, 0x03F0_3052, 0x0013_0000));
    assert!(!plan.identity.matches(2, 0x03F0_3052, 0x0012_0001));
    // IP init command first, then PS; nothing else is a raw download.
    assert_eq!((plan.downloads[0].index, plan.downloads[0].sub), (0x8000, 1));
    assert_eq!(plan.downloads[0].data, [0x05]);
    assert_eq!((plan.downloads[1].index, plan.downloads[1].sub), (0x8000, 2));
    assert_eq!(plan.downloads.len(), 2);
    // The process data by the runtime's procedure: clear 0x1C12, then 0x1600 sub 1 =
    // 0x7000:01, 1 bit (0x70000101, little-endian on the wire), …, 0x1C13 count 2 last.
    use odc::plan::SdoWrite;
    assert_eq!(plan.pdo_writes[0], SdoWrite::u8(0x1C12, 0, 0));
    assert_eq!(plan.pdo_writes[2], SdoWrite::u32(0x1600, 1, 0x7000_0101));
    assert_eq!(plan.pdo_writes[2].to_le_bytes(), ([0x01, 0x01, 0x00, 0x70], 4));
    assert_eq!(plan.pdo_writes.last(), Some(&SdoWrite::u8(0x1C13, 0, 2)));
    assert_eq!((plan.output_len, plan.input_len), (3, 5));
    assert_eq!(startup::SHORT_COUNTER.input_len, 3);
}

/// The master's CoE plan (`master::PLAN`, the runtime's procedure through
/// `odc::plan::PlanBuilder`): per sync manager, clear the assignment, map each configurable
/// PDO, assign, count; `startup::PLAN` (this ESI lets the master map and assign) has the same
/// writes, by the same procedure.
#[test]
fn master_plan_maps_and_assigns() {
    use odc::plan::SdoWrite;
    let plan = master::PLAN;
    let addrs: Vec<(u16, u8)> = plan.iter().map(|w| (w.index, w.sub)).collect();
    let maps_1600 = addrs.iter().filter(|a| a.0 == 0x1600 && a.1 > 0).count();
    let maps_1a01 = addrs.iter().filter(|a| a.0 == 0x1A01 && a.1 > 0).count();
    assert_eq!(plan.first(), Some(&SdoWrite::u8(0x1C12, 0, 0)));
    assert_eq!(plan.get(1), Some(&SdoWrite::u8(0x1600, 0, 0)));
    assert_eq!(plan.get(2 + maps_1600), Some(&SdoWrite::u8(0x1600, 0, maps_1600 as u8)));
    assert_eq!(plan.last(), Some(&SdoWrite::u8(0x1C13, 0, 2)));
    // 0x1A00 is fixed: assigned, not mapped.
    assert!(!addrs.iter().any(|a| a.0 == 0x1A00));
    assert!(plan.contains(&SdoWrite::u16(0x1C13, 1, 0x1A00)));
    assert!(plan.contains(&SdoWrite::u16(0x1C13, 2, 0x1A01)));
    // SM2: clear, assign, count; SM3: clear, two assigns, count.
    assert_eq!(plan.len(), 3 + (2 + maps_1600) + 4 + (2 + maps_1a01));
    assert_eq!(startup::PLAN.pdo_writes, &plan[..]);
}
