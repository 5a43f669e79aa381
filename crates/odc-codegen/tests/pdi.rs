//! The process image of ESI devices (`image`, `pdi`, `startup`) against layouts worked out by
//! hand from ETG.2000 §5.4.4 and ETG.1000.4 §6.7: sync managers in index order, PDOs in
//! assignment order, entries bit-packed, each sync manager rounded up to whole bytes.
#![allow(clippy::unwrap_used, clippy::expect_used, clippy::panic)]

use odc_codegen::image::{self, Assignment};
use odc_model::{Device, Direction, Sources};

const ESI: &str = r##"<?xml version="1.0"?>
<EtherCATInfo>
  <Vendor><Id>#x00000002</Id><Name>Test</Name></Vendor>
  <Descriptions><Groups><Group><Type>T</Type><Name>T</Name></Group></Groups>
  <Devices><Device>
    <Type ProductCode="#x03F03052" RevisionNo="#x00120000">EL1008</Type>
    <Name>Test device</Name>
    <Info><VendorSpecific><TwinCAT>
      <AlternativeSmMapping Default="1"><Name>Standard</Name>
        <Sm No="3"><Pdo>#x1A00</Pdo><Pdo>#x1A01</Pdo></Sm></AlternativeSmMapping>
      <AlternativeSmMapping><Name>Short counter</Name>
        <Sm No="3"><Pdo>#x1A00</Pdo><Pdo>#x1A02</Pdo></Sm></AlternativeSmMapping>
    </TwinCAT></VendorSpecific></Info>
    <GroupType>T</GroupType>
    <Sm StartAddress="#x1000" ControlByte="#x26" Enable="1">MBoxOut</Sm>
    <Sm StartAddress="#x1080" ControlByte="#x22" Enable="1">MBoxIn</Sm>
    <Sm DefaultSize="3" StartAddress="#x1100" ControlByte="#x64" Enable="1">Outputs</Sm>
    <Sm DefaultSize="7" StartAddress="#x1180" ControlByte="#x20" Enable="1">Inputs</Sm>
    <Sm StartAddress="#x0981" Virtual="true">Outputs</Sm>
    <RxPdo Sm="2"><Index>#x1600</Index><Name>Out</Name>
      <Entry><Index>#x7000</Index><SubIndex>1</SubIndex><BitLen>1</BitLen><Name>Output 1</Name><DataType>BOOL</DataType></Entry>
      <Entry><Index>#x0</Index><BitLen>7</BitLen></Entry>
      <Entry><Index>#x7010</Index><SubIndex>1</SubIndex><BitLen>16</BitLen><Name>Value</Name><DataType>UINT</DataType></Entry>
    </RxPdo>
    <RxPdo Sm="4"><Index>#x1610</Index><Name>Virtual</Name>
      <Entry><Index>#x1d09</Index><SubIndex>#x81</SubIndex><BitLen>8</BitLen><Name>Activate</Name><DataType>USINT</DataType></Entry>
    </RxPdo>
    <TxPdo Sm="3" Fixed="1"><Index>#x1A00</Index><Name>Status</Name>
      <Entry><Index>#x6000</Index><SubIndex>1</SubIndex><BitLen>1</BitLen><Name>Input 1</Name><DataType>BOOL</DataType></Entry>
      <Entry><Index>#x6000</Index><SubIndex>2</SubIndex><BitLen>1</BitLen><Name>Input 2</Name><DataType>BOOL</DataType></Entry>
    </TxPdo>
    <TxPdo Sm="3"><Index>#x1A01</Index><Name>Counter</Name><Exclude>#x1A02</Exclude>
      <Entry><Index>#x6010</Index><SubIndex>1</SubIndex><BitLen>32</BitLen><Name>Counter</Name><DataType>DINT</DataType></Entry>
    </TxPdo>
    <TxPdo Sm="3"><Index>#x1A02</Index><Name>Counter 16</Name><Exclude>#x1A01</Exclude>
      <Entry><Index>#x6010</Index><SubIndex>2</SubIndex><BitLen>16</BitLen><Name>Counter 16</Name><DataType>INT</DataType></Entry>
    </TxPdo>
    <TxPdo><Index>#x1A03</Index><Name>Optional</Name>
      <Entry><Index>#x6020</Index><SubIndex>1</SubIndex><BitLen>8</BitLen><Name>Extra</Name><DataType>USINT</DataType></Entry>
    </TxPdo>
    <Mailbox><CoE PdoAssign="1" PdoConfig="1">
      <InitCmd><Transition>PS</Transition><Index>#x8000</Index><SubIndex>2</SubIndex><Data>0100</Data></InitCmd>
      <InitCmd><Transition>IP</Transition><Index>#x8000</Index><SubIndex>1</SubIndex><Data>05</Data></InitCmd>
      <InitCmd><Transition>SO</Transition><Index>#x8000</Index><SubIndex>3</SubIndex><Data>5A</Data></InitCmd>
    </CoE></Mailbox>
    <Dc><OpMode><Name>DC</Name><AssignActivate>#x300</AssignActivate>
      <Sm No="3"><Pdo>#x1A00</Pdo><Pdo OSFac="2">#x1A01</Pdo></Sm></OpMode></Dc>
  </Device></Devices></Descriptions>
</EtherCATInfo>"##;

fn device() -> Device {
    let mut sources = Sources::new();
    let mut parsed = odc_esi::parse(&mut sources, "test.xml", ESI.as_bytes());
    assert_eq!(parsed.devices.len(), 1, "{:?}", parsed.diagnostics);
    parsed.devices.remove(0)
}

fn offsets(dev: &Device, img: &image::Image) -> Vec<(u16, u32, u32)> {
    img.segments
        .iter()
        .flat_map(|s| &s.entries)
        .map(|p| (dev.pdos[p.pdo].entries[p.entry].index, p.range.offset, p.range.bits))
        .collect()
}

#[test]
fn default_assignment_follows_sm_exclude_and_virtual() {
    let dev = device();
    let a = image::default_assignment(&dev);
    // 0x1A02 excludes 0x1A01, listed before it; 0x1A03 has no `Sm`; SM4 is virtual.
    let expected: Assignment = [(2, vec![0x1600]), (3, vec![0x1A00, 0x1A01])].into();
    assert_eq!(a, expected);
}

#[test]
fn entries_are_bit_packed_and_segments_byte_rounded() {
    let dev = device();
    let (outputs, inputs) = image::default_images(&dev).unwrap();
    assert_eq!(outputs.direction, Direction::Rx);
    // SM2: bit 0 output, 7 bits padding, 16-bit value at bit 8: 3 bytes (DefaultSize 3).
    assert_eq!(offsets(&dev, &outputs), [(0x7000, 0, 1), (0, 1, 7), (0x7010, 8, 16)]);
    assert_eq!(outputs.len(), 3);
    // SM3: two 1-bit inputs, then the 32-bit counter at bit 2 (no alignment): 34 bits, 5
    // bytes. The ESI's DefaultSize 7 is wrong for this assignment on purpose: the image
    // follows the PDOs, not the attribute.
    assert_eq!(offsets(&dev, &inputs), [(0x6000, 0, 1), (0x6000, 1, 1), (0x6010, 2, 32)]);
    assert_eq!(inputs.len(), 5);
    assert_eq!(inputs.segments[0].sm, 3);
}

#[test]
fn variants_replace_the_sync_managers_they_list() {
    let dev = device();
    let (variants, skipped) = image::variants(&dev);
    assert_eq!(variants.len(), 1);
    assert_eq!(variants[0].name, "Short counter");
    let expected: Assignment = [(2, vec![0x1600]), (3, vec![0x1A00, 0x1A02])].into();
    assert_eq!(variants[0].assignment, expected);
    // Two 1-bit inputs and the 16-bit counter at bit 2: 18 bits, 3 bytes.
    let inputs = image::image(&dev, &variants[0].assignment, Direction::Tx).unwrap();
    assert_eq!(offsets(&dev, &inputs), [(0x6000, 0, 1), (0x6000, 1, 1), (0x6010, 2, 16)]);
    assert_eq!(inputs.len(), 3);
    let reasons: Vec<(&str, &str)> =
        skipped.iter().map(|s| (s.name.as_str(), s.reason.as_str())).collect();
    assert_eq!(
        reasons,
        [
            ("DC", "PDO 0x1A01 is oversampled 2 times"),
            ("Standard", "the same assignment as the default"),
        ]
    );
}

#[test]
fn generated_pdi_and_startup() {
    let dev = device();
    let code = odc_codegen::generate(&dev, &odc_codegen::Options::default()).unwrap();
    for want in [
        "pub const OUTPUT_LEN: usize = 3;",
        "pub const INPUT_LEN: usize = 5;",
        "#[pdo(bits = 40, max_bits = 40)]",
        "pub struct Inputs {",
        "::odc::impl_wire!(Inputs);",
        "::odc::configure_fn!(PLAN);",
        "assign_activate: 0x0300,",
        "pub mod short_counter {",
        "pub const SHORT_COUNTER: ::odc::ethercat::Startup",
        "output_len: super::pdi::short_counter::OUTPUT_LEN,",
    ] {
        assert!(code.contains(want), "missing `{want}` in:\n{code}");
    }
    // The start-up: IP before PS, SO left out; the mapping of the configurable 0x1600 and
    // 0x1A01 (0x1A00 is Fixed); then 0x1C12 = [0x1600], 0x1C13 = [0x1A00, 0x1A01].
    let start = code.find("pub const PLAN").unwrap();
    let end = code.find("pub const DC_OP_MODES").unwrap();
    let plan = &code[start..end];
    let order: Vec<&str> = plan
        .lines()
        .filter_map(|l| l.trim().strip_prefix("index: "))
        .map(|l| l.trim_end_matches(','))
        .collect();
    assert_eq!(
        order,
        [
            "0x8000", "0x8000", // IP sub 1, PS sub 2
            "0x1600", "0x1600", "0x1600", "0x1600", "0x1600", // 0, 3 entries, count
            "0x1A01", "0x1A01", "0x1A01", // 0, 1 entry, count
            "0x1C12", "0x1C12", "0x1C12", // 0, 0x1600, count
            "0x1C13", "0x1C13", "0x1C13", "0x1C13", // 0, 0x1A00, 0x1A01, count
        ]
    );
    assert!(!plan.contains("0x5A"), "the SO command is not part of PRE-OP");
}
