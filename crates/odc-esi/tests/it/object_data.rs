//! An object's own `Info/DefaultData` (ETG.2000 `ObjectInfoType`: the whole object's bytes
//! instead of `SubItem`s), split into its sub-objects at their data type's `BitOffs`. The
//! expected values are read off the hex bytes below by hand.
#![allow(clippy::unwrap_used, clippy::expect_used, clippy::panic)]

use odc_model::{Severity, Sources, Value};

const ESI: &str = r##"<?xml version="1.0"?>
<EtherCATInfo>
  <Vendor><Id>2</Id><Name>Test</Name></Vendor>
  <Descriptions><Groups><Group><Type>T</Type><Name>T</Name></Group></Groups>
  <Devices><Device>
    <Type ProductCode="#x1" RevisionNo="#x1">T1</Type>
    <Name>T1</Name>
    <GroupType>T</GroupType>
    <Profile><Dictionary>
      <DataTypes>
        <DataType><Name>DT1C13ARR</Name><BaseType>UINT</BaseType><BitSize>32</BitSize>
          <ArrayInfo><LBound>1</LBound><Elements>2</Elements></ArrayInfo></DataType>
        <DataType><Name>DT1C13</Name><BitSize>48</BitSize>
          <SubItem><SubIdx>0</SubIdx><Name>SubIndex 000</Name><Type>USINT</Type><BitSize>8</BitSize><BitOffs>0</BitOffs></SubItem>
          <SubItem><Name>Elements</Name><Type>DT1C13ARR</Type><BitSize>32</BitSize><BitOffs>16</BitOffs></SubItem>
        </DataType>
        <DataType><Name>DT8000</Name><BitSize>48</BitSize>
          <SubItem><SubIdx>0</SubIdx><Name>SubIndex 000</Name><Type>USINT</Type><BitSize>8</BitSize><BitOffs>0</BitOffs></SubItem>
          <SubItem><SubIdx>1</SubIdx><Name>Enable</Name><Type>BOOL</Type><BitSize>1</BitSize><BitOffs>16</BitOffs></SubItem>
          <SubItem><SubIdx>2</SubIdx><Name>Mode</Name><Type>BIT3</Type><BitSize>3</BitSize><BitOffs>17</BitOffs></SubItem>
          <SubItem><SubIdx>3</SubIdx><Name>Offset</Name><Type>INT</Type><BitSize>16</BitSize><BitOffs>32</BitOffs></SubItem>
        </DataType>
        <DataType><Name>DT8003</Name><BitSize>72</BitSize>
          <SubItem><SubIdx>1</SubIdx><Name>Wide</Name><Type>ULINT</Type><BitSize>65</BitSize><BitOffs>0</BitOffs></SubItem>
        </DataType>
      </DataTypes>
      <Objects>
        <Object><Index>#x1c13</Index><Name>TxPDO assign</Name><Type>DT1C13</Type><BitSize>48</BitSize>
          <Info><DefaultData>0100001A0000</DefaultData></Info></Object>
        <Object><Index>#x8000</Index><Name>Settings</Name><Type>DT8000</Type><BitSize>48</BitSize>
          <Info><DefaultData>03000B00FEFF</DefaultData></Info></Object>
        <Object><Index>#x8001</Index><Name>Short</Name><Type>DT1C13</Type><BitSize>48</BitSize>
          <Info><DefaultData>0200</DefaultData></Info></Object>
        <Object><Index>#x8002</Index><Name>Array</Name><Type>DT1C13ARR</Type><BitSize>32</BitSize>
          <Info><DefaultData>01000200</DefaultData></Info></Object>
        <Object><Index>#x8003</Index><Name>Wide</Name><Type>DT8003</Type><BitSize>72</BitSize>
          <Info><DefaultData>FFFFFFFFFFFFFFFF01</DefaultData></Info></Object>
      </Objects>
    </Dictionary></Profile>
  </Device></Devices></Descriptions>
</EtherCATInfo>"##;

fn parsed() -> odc_esi::Parsed {
    odc_esi::parse(&mut Sources::new(), "t.xml", ESI.as_bytes())
}

fn default(index: u16, sub: u8) -> Option<Value> {
    let parsed = parsed();
    let object = &parsed.devices[0].objects[&index];
    object.subs[&sub].default.as_ref().map(|d| d.value.clone())
}

#[test]
fn an_assignment_objects_data_fills_its_count_and_entries() {
    // 01 00 | 00 1A | 00 00: one PDO, 0x1A00, an unused second entry.
    assert_eq!(default(0x1C13, 0), Some(Value::Unsigned(1)));
    assert_eq!(default(0x1C13, 1), Some(Value::Unsigned(0x1A00)));
    assert_eq!(default(0x1C13, 2), Some(Value::Unsigned(0)));
}

#[test]
fn bit_fields_and_signed_values_are_read_at_their_offsets() {
    // 03 00 | 0B = 0b0000_1011 (bit 16: 1, bits 17..19: 0b101) 00 | FE FF (INT -2).
    assert_eq!(default(0x8000, 0), Some(Value::Unsigned(3)));
    assert_eq!(default(0x8000, 1), Some(Value::Bool(true)));
    assert_eq!(default(0x8000, 2), Some(Value::Unsigned(5)));
    assert_eq!(default(0x8000, 3), Some(Value::Signed(-2)));
}

#[test]
fn data_that_ends_early_and_array_types_are_said_not_dropped() {
    let parsed = parsed();
    assert_eq!(default(0x8001, 0), Some(Value::Unsigned(2)));
    assert_eq!(default(0x8001, 1), None);
    let f224: Vec<_> = parsed.diagnostics.iter().filter(|d| d.code == "F224").collect();
    assert_eq!(f224.len(), 3, "{f224:#?}");
    assert!(f224.iter().all(|d| d.severity == Severity::Warning));
    assert!(f224[0].labels[0].message.contains("no default for sub-index 1, 2"), "{f224:#?}");
    assert!(f224[1].labels[0].message.contains("array type"), "{f224:#?}");
    // A 65-bit field that is not whole bytes does not fit the u64 a bit field is read into.
    assert_eq!(default(0x8003, 1), None);
    assert!(f224[2].labels[0].message.contains("no default for sub-index 1"), "{f224:#?}");
    // No other object's data gave a diagnostic.
    assert!(
        parsed.diagnostics.iter().all(|d| d.severity != Severity::Error),
        "{:#?}",
        parsed.diagnostics
    );
}

#[test]
fn an_odd_number_of_hex_digits_is_read_with_a_leading_zero_and_said() {
    // `100001A0000` is `0100001A0000` without its first digit.
    let esi = ESI.replace("0100001A0000", "100001A0000");
    let parsed = odc_esi::parse(&mut Sources::new(), "t.xml", esi.as_bytes());
    let subs = &parsed.devices[0].objects[&0x1C13].subs;
    assert_eq!(subs[&0].default.as_ref().map(|d| d.value.clone()), Some(Value::Unsigned(1)));
    assert_eq!(subs[&1].default.as_ref().map(|d| d.value.clone()), Some(Value::Unsigned(0x1A00)));
    let f219: Vec<_> = parsed.diagnostics.iter().filter(|d| d.code == "F219").collect();
    assert_eq!(f219.len(), 1, "{:#?}", parsed.diagnostics);
    assert!(f219[0].message.contains("odd number of hex digits"), "{f219:#?}");
}
