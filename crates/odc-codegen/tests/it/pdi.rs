//! The process image of ESI devices (`image`, `pdi`, `startup`) against layouts worked out by
//! hand from ETG.2000 (`PdoType@Sm`) and ETG.1000.4 (sync managers): sync managers in index order, PDOs in
//! assignment order, entries bit-packed, each sync manager rounded up to whole bytes.
#![allow(clippy::unwrap_used, clippy::expect_used, clippy::panic)]

use odc_codegen::image::{self, Assignment};
use odc_model::{Device, Direction, Sources};

/// A made-up terminal: two process-data SMs, padding, a virtual SM, `Exclude`, an
/// alternative mapping, an oversampled DC op-mode, CoE init commands.
const ESI: &str = include_str!("../fixtures/pdi-terminal.xml");

fn device() -> Device {
    parse(ESI)
}

fn parse(text: &str) -> Device {
    let mut sources = Sources::new();
    let mut parsed = odc_esi::parse(&mut sources, "test.xml", text.as_bytes());
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
fn default_assignment_follows_sm_and_virtual() {
    let dev = device();
    let a = image::default_assignment(&dev);
    // 0x1A02 and 0x1A03 have no `Sm`; SM4 is virtual.
    let expected: Assignment = [(2, vec![0x1600]), (3, vec![0x1A00, 0x1A01])].into();
    assert_eq!(a, expected);
}

#[test]
fn an_excluded_pdo_is_not_assigned_with_the_one_before_it() {
    // Both with `Sm` (the checker's T611): the first listed wins, as in TwinCAT.
    let dev = parse(&ESI.replace("<TxPdo><Index>#x1A02", "<TxPdo Sm=\"3\"><Index>#x1A02"));
    let expected: Assignment = [(2, vec![0x1600]), (3, vec![0x1A00, 0x1A01])].into();
    assert_eq!(image::default_assignment(&dev), expected);
    assert_eq!(dev.pdos.iter().filter(|p| p.sync_manager == Some(3)).count(), 3);
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
        "#[pdo(bits = 40)]",
        "pub struct Inputs {",
        "::odc::impl_wire!(Inputs);",
        "::odc::configure_fn!(PLAN);",
        "assign_activate: 0x0300,",
        "pub mod short_counter {",
        "pub const SHORT_COUNTER: ::odc::ethercat::Startup",
        "output_len: super::pdi::short_counter::OUTPUT_LEN,",
        // `pdo`: the counter PDO after two 1-bit inputs, SM3 of 5 bytes, as in `pdi`.
        "pub const SM_BIT_OFFSET: u32 = 2;",
        "pub const SIZE: usize = 5;",
    ] {
        assert!(code.contains(want), "missing `{want}` in:\n{code}");
    }
    // The start-up: the init commands, IP before PS, SO left out; then the process data
    // through the runtime's PlanBuilder: per SM, clear 0x1C1x, the CiA 301 mapping procedure
    // of the configurable 0x1600 and 0x1A01 (0x1A00 is Fixed), assign and count.
    let start = code.find("pub const PLAN").unwrap();
    let end = code.find("pub const DC_OP_MODES").unwrap();
    let plan = &code[start..end];
    let order: Vec<&str> =
        plan.split("index: ").skip(1).filter_map(|rest| rest.split(',').next()).collect();
    assert_eq!(order, ["0x8000", "0x8000"], "IP sub 1, PS sub 2");
    assert!(plan.contains("pdo_writes: &PDO_WRITES,"), "{plan}");
    let flat: String = code.split_whitespace().collect();
    let steps = flat.find("constfnpdo_plan<constN:usize>()").unwrap();
    let steps = &flat[steps..flat[steps..].find('}').unwrap() + steps];
    assert_eq!(
        steps.split(").").skip(1).map(|s| s.split('(').next().unwrap()).collect::<Vec<_>>(),
        ["push", "pdo", "assign", "push", "pdo", "assign"],
        "{steps}"
    );
    for want in [
        ".push(::odc::plan::SdoWrite::u8(0x1C12,0x00,0))",
        "PdoConfig::new(0x1600,&[0x7000_0101,0x0000_0007,0x7010_0110],)",
        ".assign(0x1C12,&[0x1600])",
        ".push(::odc::plan::SdoWrite::u8(0x1C13,0x00,0))",
        "PdoConfig::new(0x1A01,&[0x6010_0120]),0)",
        ".assign(0x1C13,&[0x1A00,0x1A01])",
    ] {
        assert!(steps.contains(want), "missing `{want}` in {steps}");
    }
    assert!(!plan.contains("0x5A"), "the SO command is not part of PRE-OP");
    // Nothing is assigned to the virtual SM 4, in either plan.
    assert!(!code.contains("0x1C14"), "a virtual sync manager has no 0x1C14");
}

/// The top-level module `name` of generated code, with its doc comment.
fn module<'a>(code: &'a str, name: &str) -> &'a str {
    let at = code.find(&format!("\npub mod {name} {{")).unwrap();
    let start = code[..at].rfind("\n}\n").map_or(0, |i| i + 3);
    let end = at + code[at..].find("\n}\n").unwrap() + 3;
    &code[start..end]
}

/// How the `pdi` and `startup` modules read, for review.
#[test]
fn pdi_and_startup_snapshot() {
    let code = odc_codegen::generate(&device(), &odc_codegen::Options::default()).unwrap();
    insta::assert_snapshot!("pdi", module(&code, "pdi"));
    insta::assert_snapshot!("startup", module(&code, "startup"));
}
