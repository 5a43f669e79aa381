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

/// The fixture with `CoE@PdoAssign`/`@PdoConfig` on and 0x1A00 configurable (not `Fixed`).
fn configurable() -> String {
    FIXTURE
        .replacen(r#"PdoUpload="1"/>"#, r#"PdoUpload="1" PdoAssign="1" PdoConfig="1"/>"#, 1)
        .replacen(r#"<TxPdo Sm="3" Fixed="1">"#, r#"<TxPdo Sm="3">"#, 1)
}

fn access(dev: &Device, index: u16) -> Vec<(u8, odc_model::Access)> {
    dev.objects[&index].subs.values().map(|s| (s.sub_index, s.access)).collect()
}

#[test]
fn writable_where_the_esi_lets_a_master_assign_and_map() {
    use odc_model::Access::{Ro, Rw};
    let dev = lower(&configurable());
    // 0x1C12: SM 2 may hold 0x1600 only (the one RxPDO): sub 0 and sub 1, both rw.
    assert_eq!(access(&dev, 0x1C12), [(0, Rw), (1, Rw)]);
    // 0x1C13: SM 3 may hold 0x1A00 (Sm="3"), 0x1A01 and 0x1A02 (no Sm): three subs; the
    // default assignment still counts two, the third is 0x0000.
    assert_eq!(access(&dev, 0x1C13), [(0, Rw), (1, Rw), (2, Rw), (3, Rw)]);
    assert_eq!(values(&dev, 0x1C13).0, [0x1A00, 0x1A02]);
    let third = dev.objects[&0x1C13].sub(3).unwrap().default.as_ref().unwrap();
    assert_eq!(third.value, Value::Unsigned(0));
    // 0x1A00 is not Fixed: its mapping is writable; 0x1600 and 0x1A01 are Fixed: read-only.
    assert_eq!(access(&dev, 0x1A00), [(0, Rw), (1, Rw), (2, Rw)]);
    assert_eq!(access(&dev, 0x1600), [(0, Ro), (1, Ro)]);
    assert_eq!(access(&dev, 0x1A01), [(0, Ro), (1, Ro)]);
    // 0x1C00 is the ESC's sync managers: never written.
    assert!(access(&dev, 0x1C00).iter().all(|&(_, a)| a == Ro));
}

#[test]
fn read_only_without_pdo_assign_and_pdo_config() {
    // The fixture as it is: neither attribute, so every synthesised object stays read-only
    // and an assignment object has room for its default assignment only.
    let dev = lower(FIXTURE);
    for index in [0x1C12, 0x1C13, 0x1600, 0x1A00, 0x1A01, 0x1A02] {
        assert!(access(&dev, index).iter().all(|&(_, a)| a == odc_model::Access::Ro), "{index:X}");
    }
    assert_eq!(access(&dev, 0x1C13).len(), 3);
    // PdoConfig alone maps 0x1A00 but assigns nothing.
    let xml = configurable().replacen(r#" PdoAssign="1""#, "", 1);
    let dev = lower(&xml);
    assert_eq!(access(&dev, 0x1C13).len(), 3);
    assert!(access(&dev, 0x1C13).iter().all(|&(_, a)| a == odc_model::Access::Ro));
    assert!(access(&dev, 0x1A00).iter().all(|&(_, a)| a == odc_model::Access::Rw));
}

/// The file's own 0x1C13 and 0x1A00, `sub 0` without a default (and 0x1C13's entries with
/// none): they start with the ESI's assignment and entries, with a note each, values without
/// a span, and the file's sub 0 kept in `esi_defaults`.
#[test]
fn the_files_empty_objects_start_with_the_esi_pdos() {
    let own = r#"<Object><Index>#x1C13</Index><Name>TxPDO assign</Name><Type>DT1C13</Type>
      <BitSize>48</BitSize></Object>
      <Object><Index>#x1A00</Index><Name>TxPDO map</Name><Type>DT1A00</Type>
      <BitSize>80</BitSize></Object>
    </Objects>"#;
    let types = r#"<DataType><Name>DT1C13</Name><BitSize>48</BitSize>
        <SubItem><SubIdx>0</SubIdx><Name>SubIndex 000</Name><Type>USINT</Type><BitSize>8</BitSize><BitOffs>0</BitOffs><Flags><Access>rw</Access></Flags></SubItem>
        <SubItem><SubIdx>1</SubIdx><Name>SubIndex 001</Name><Type>UINT</Type><BitSize>16</BitSize><BitOffs>16</BitOffs><Flags><Access>rw</Access></Flags></SubItem>
        <SubItem><SubIdx>2</SubIdx><Name>SubIndex 002</Name><Type>UINT</Type><BitSize>16</BitSize><BitOffs>32</BitOffs><Flags><Access>rw</Access></Flags></SubItem>
      </DataType>
      <DataType><Name>DT1A00</Name><BitSize>80</BitSize>
        <SubItem><SubIdx>0</SubIdx><Name>SubIndex 000</Name><Type>USINT</Type><BitSize>8</BitSize><BitOffs>0</BitOffs><Flags><Access>ro</Access></Flags></SubItem>
        <SubItem><SubIdx>1</SubIdx><Name>SubIndex 001</Name><Type>UDINT</Type><BitSize>32</BitSize><BitOffs>16</BitOffs><Flags><Access>ro</Access></Flags></SubItem>
        <SubItem><SubIdx>2</SubIdx><Name>SubIndex 002</Name><Type>UDINT</Type><BitSize>32</BitSize><BitOffs>48</BitOffs><Flags><Access>ro</Access></Flags></SubItem>
      </DataType>
    </DataTypes>"#;
    let xml = FIXTURE.replacen("</Objects>", own, 1).replacen("</DataTypes>", types, 1);
    let parsed = odc_esi::parse(&mut Sources::new(), "coe_implied.xml", xml.as_bytes());
    let notes: Vec<&str> = parsed
        .diagnostics
        .iter()
        .filter(|d| d.code == odc_esi::codes::ESI_DEFAULT)
        .map(|d| d.message.as_str())
        .collect();
    assert_eq!(notes.len(), 2, "{notes:?}");
    assert!(notes[0].starts_with("0x1C13 has no default"), "{}", notes[0]);
    assert!(notes[1].starts_with("0x1A00 has no default"), "{}", notes[1]);
    let dev = parsed.devices.into_iter().next().unwrap();
    // TxPdo 0x1A00 Sm="3" and the mandatory 0x1A02, as the synthesised object has them.
    assert_eq!(values(&dev, 0x1C13), (vec![0x1A00, 0x1A02], Origin::File));
    // 0x6000:01/16, then an 8-bit gap.
    assert_eq!(values(&dev, 0x1A00), (vec![0x6000_0110, 0x0000_0008], Origin::File));
    let s0 = dev.objects[&0x1C13].sub(0).unwrap();
    assert!(s0.default.as_ref().unwrap().span.is_dummy(), "odc's value, not the file's");
    let ec = dev.ethercat.as_deref().unwrap();
    let filled: Vec<(u16, bool)> =
        ec.esi_defaults.iter().map(|d| (d.index, d.file_count.is_some())).collect();
    assert_eq!(filled, [(0x1C13, false), (0x1A00, false)]);
    // Access stays the file's: these are its objects.
    assert_eq!(access(&dev, 0x1A00)[1].1, odc_model::Access::Ro);
}

#[test]
fn a_file_default_or_too_little_room_is_kept() {
    // 0x1C13 with one UINT sub: no room for the two PDOs SM 3 gets; and 0x1C13 with a
    // default of its own (counting 0x1A01) is the file's.
    let one = r#"<Object><Index>#x1C13</Index><Name>TxPDO assign</Name><Type>DT1C13</Type>
      <BitSize>32</BitSize></Object></Objects>"#;
    let types = r#"<DataType><Name>DT1C13</Name><BitSize>32</BitSize>
        <SubItem><SubIdx>0</SubIdx><Name>SubIndex 000</Name><Type>USINT</Type><BitSize>8</BitSize><BitOffs>0</BitOffs><Flags><Access>rw</Access></Flags></SubItem>
        <SubItem><SubIdx>1</SubIdx><Name>SubIndex 001</Name><Type>UINT</Type><BitSize>16</BitSize><BitOffs>16</BitOffs><Flags><Access>rw</Access></Flags></SubItem>
      </DataType></DataTypes>"#;
    let xml = FIXTURE.replacen("</Objects>", one, 1).replacen("</DataTypes>", types, 1);
    let dev = lower(&xml);
    let s0 = dev.objects[&0x1C13].sub(0).unwrap();
    assert!(s0.initial_value().is_none());
    assert!(dev.ethercat.as_deref().unwrap().esi_defaults.is_empty());
    let own = one.replacen(
        "<BitSize>32</BitSize></Object>",
        "<BitSize>32</BitSize><Info><SubItem><Name>SubIndex 000</Name><Info><DefaultData>01</DefaultData></Info></SubItem>\
         <SubItem><Name>SubIndex 001</Name><Info><DefaultData>011A</DefaultData></Info></SubItem></Info></Object>",
        1,
    );
    let xml = FIXTURE.replacen("</Objects>", &own, 1).replacen("</DataTypes>", types, 1);
    let dev = lower(&xml);
    assert_eq!(values(&dev, 0x1C13), (vec![0x1A01], Origin::File));
    assert!(dev.ethercat.as_deref().unwrap().esi_defaults.is_empty());
}
