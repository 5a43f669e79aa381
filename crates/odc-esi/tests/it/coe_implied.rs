//! The objects a CoE device's ESI dictionary leaves out (0x1C00, 0x1C1n, the PDOs' mapping
//! objects), synthesised by the lowering from the ESI's own `Sm` elements and PDOs. Expected
//! values are read off `tests/fixtures/coe_implied.xml` by hand.
#![allow(clippy::unwrap_used, clippy::expect_used, clippy::panic)]

use odc_model::{Device, Origin, Sources, Value};

const FIXTURE: &str = include_str!("../fixtures/coe_implied.xml");

fn lower(xml: &str) -> Device {
    let parsed = odc_esi::parse(&mut Sources::new(), "coe_implied.xml", xml.as_bytes());
    assert!(!parsed.diagnostics.iter().any(|d| d.is_error()), "{:?}", parsed.diagnostics);
    parsed.devices.into_iter().next().unwrap()
}

/// Sub 0 and the values of subs 1..=sub 0 of `index`, and its origin.
fn values(dev: &Device, index: u16) -> (Vec<u64>, Origin) {
    let o = dev.objects.get(&index).unwrap_or_else(|| panic!("no 0x{index:04X}"));
    let num = |sub: u8| match o.sub(sub).and_then(|s| s.default.as_ref()).map(|v| &v.value) {
        Some(Value::Unsigned(v)) => *v,
        other => panic!("0x{index:04X}:{sub} is {other:?}"),
    };
    let count = num(0);
    ((1..=count as u8).map(num).collect(), o.origin)
}

#[test]
fn sync_manager_types_from_the_sm_elements() {
    let dev = lower(FIXTURE);
    // MBoxOut, MBoxIn, Outputs, Inputs: ETG.1000.6 types 1, 2, 3, 4.
    assert_eq!(values(&dev, 0x1C00), (vec![1, 2, 3, 4], Origin::CoeImplied));
    let s1 = dev.objects[&0x1C00].sub(1).unwrap();
    assert_eq!(s1.access, odc_model::Access::Ro);
}

#[test]
fn assignment_from_sm_attributes_and_mandatory() {
    let dev = lower(FIXTURE);
    // RxPdo 0x1600 Sm="2".
    assert_eq!(values(&dev, 0x1C12), (vec![0x1600], Origin::CoeImplied));
    // TxPdo 0x1A00 Sm="3"; 0x1A01 has no Sm; 0x1A02 is Mandatory without one: on the first
    // Inputs sync manager (SM 3).
    assert_eq!(values(&dev, 0x1C13), (vec![0x1A00, 0x1A02], Origin::CoeImplied));
    // No assignment object for the mailbox sync managers.
    assert!(!dev.objects.contains_key(&0x1C10) && !dev.objects.contains_key(&0x1C11));
}

#[test]
fn mapping_objects_of_every_pdo() {
    let dev = lower(FIXTURE);
    // 0x7000:01, 16 bits.
    assert_eq!(values(&dev, 0x1600), (vec![0x7000_0110], Origin::CoeImplied));
    // 0x6000:01, 16 bits; a gap of 8 bits (index 0).
    assert_eq!(values(&dev, 0x1A00), (vec![0x6000_0110, 0x0000_0008], Origin::CoeImplied));
    // Not assigned by default, yet a master may assign it: its mapping is there too.
    assert_eq!(values(&dev, 0x1A01), (vec![0x6000_0208], Origin::CoeImplied));
    assert_eq!(values(&dev, 0x1A02), (vec![0x6000_0208], Origin::CoeImplied));
    // The file's own objects stay the file's.
    assert_eq!(dev.objects[&0x1000].origin, Origin::File);
    assert_eq!(dev.objects[&0x6000].origin, Origin::File);
}

#[test]
fn objects_of_the_file_are_kept() {
    // The same device with its own 0x1C13 (empty by default): kept as written.
    let own = r#"<Object><Index>#x1C13</Index><Name>TxPDO assign</Name><Type>USINT</Type>
      <BitSize>8</BitSize><Info><DefaultData>00</DefaultData></Info></Object>
    </Objects>"#;
    let dev = lower(&FIXTURE.replacen("</Objects>", own, 1));
    let o = &dev.objects[&0x1C13];
    assert_eq!((o.origin, o.name.as_str()), (Origin::File, "TxPDO assign"));
    assert_eq!(values(&dev, 0x1C12).1, Origin::CoeImplied);
}

#[test]
fn nothing_without_coe() {
    let start = FIXTURE.find("<Mailbox").unwrap();
    let end = FIXTURE.find("</Mailbox>").unwrap() + "</Mailbox>".len();
    let xml = format!("{}{}", &FIXTURE[..start], &FIXTURE[end..]);
    let dev = lower(&xml);
    assert!(dev.objects.values().all(|o| o.origin == Origin::File));
    assert!(!dev.objects.contains_key(&0x1C00) && !dev.objects.contains_key(&0x1600));
}

#[test]
fn virtual_sync_managers_get_no_assignment_object() {
    // SM 3 marked Virtual (ESC registers TwinCAT maps, not a sync manager): no 0x1C13, and
    // 0x1C00 still counts it.
    let xml = FIXTURE.replacen(
        r##"<Sm StartAddress="#x1400" ControlByte="#x20" Enable="1">"##,
        r##"<Sm StartAddress="#x1400" ControlByte="#x20" Enable="1" Virtual="1">"##,
        1,
    );
    let dev = lower(&xml);
    assert!(!dev.objects.contains_key(&0x1C13));
    assert_eq!(values(&dev, 0x1C00).0, vec![1, 2, 3, 4]);
    assert_eq!(values(&dev, 0x1C12).0, vec![0x1600]);
}

#[test]
fn no_mapping_object_outside_the_coe_ranges() {
    // A PDO index that is no CoE mapping index (a SoE drive's IDN, S-0-0016 = 0x0010).
    let xml = FIXTURE.replacen("<Index>#x1A01</Index>", "<Index>#x0010</Index>", 1);
    let dev = lower(&xml);
    assert!(dev.pdos.iter().any(|p| p.mapping_index == 0x0010));
    assert!(!dev.objects.contains_key(&0x0010));
    assert_eq!(values(&dev, 0x1A00).1, Origin::CoeImplied);
}
