use super::*;
use odc_model::{Access, DataType, Format, ObjectKind, PdoMapping, Value};

#[test]
fn rules_are_well_formed() {
    for (i, r) in RULES.iter().enumerate() {
        assert!(r.code.starts_with("F3") && r.code.len() == 4, "{}", r.code);
        assert_eq!(r.group, "format");
        assert!(RULES[..i].iter().all(|o| o.code != r.code), "dup {}", r.code);
    }
}

/// A CiA 311 container in the two forms real files use: the attribute form (dataType,
/// accessType, defaultValue on the object) and CANopenEditor's parameter form.
const SMALL: &str = r#"<?xml version="1.0" encoding="utf-8"?>
<ISO15745ProfileContainer xmlns="http://www.canopen.org/xml/1.1">
  <ISO15745Profile>
    <ProfileBody fileName="small.xdd" fileVersion="3">
      <DeviceIdentity><vendorName>ACME</vendorName><vendorID>0x0000012A</vendorID><productName>Widget</productName><productID>7</productID></DeviceIdentity>
      <ApplicationProcess>
        <dataTypeList><array name="a" uniqueID="T1"><subrange lowerLimit="1" upperLimit="2"/><UINT/></array></dataTypeList>
        <parameterList>
          <parameter uniqueID="P1005" access="readWrite"><label lang="en">SYNC</label><description lang="en">line 1
line 2</description><UDINT/><defaultValue value="0x80"/><property name="CO_storageGroup" value="PERSIST_COMM"/></parameter>
          <parameter uniqueID="P2000" access="readWriteOutput"><label lang="en">Out</label><dataTypeIDRef uniqueIDRef="T1"/></parameter>
          <parameter uniqueID="P2000_1" access="readWriteInput"><INT/><allowedValues><range><minValue value="-5"/><maxValue value="5"/></range></allowedValues></parameter>
        </parameterList>
      </ApplicationProcess>
    </ProfileBody>
  </ISO15745Profile>
  <ISO15745Profile>
    <ProfileBody>
      <ApplicationLayers>
        <CANopenObjectList>
          <CANopenObject index="1000" name="Device type" objectType="7" dataType="0007" accessType="ro" defaultValue="0x00020192" PDOmapping="no"/>
          <CANopenObject index="1005" name="COB-ID SYNC" objectType="7" PDOmapping="no" uniqueIDRef="P1005"/>
          <CANopenObject index="1400" name="RPDO1" objectType="9" subNumber="2">
            <CANopenSubObject subIndex="00" name="Highest" objectType="7" dataType="0005" accessType="ro" defaultValue="1"/>
            <CANopenSubObject subIndex="01" name="COB-ID" objectType="7" dataType="0007" accessType="rw" defaultValue="$NODEID+0x200"/>
          </CANopenObject>
          <CANopenObject index="2000" name="Out" objectType="8" dataType="0003" uniqueIDRef="P2000" subNumber="2">
            <CANopenSubObject subIndex="00" name="n" objectType="7" dataType="0005" accessType="ro"/>
            <CANopenSubObject subIndex="01" name="v" objectType="7" PDOmapping="TPDO" uniqueIDRef="P2000_1" actualValue="3"/>
          </CANopenObject>
        </CANopenObjectList>
        <dummyUsage><dummy entry="Dummy0002=1"/><dummy entry="Dummy0005=0"/></dummyUsage>
      </ApplicationLayers>
      <TransportLayers><PhysicalLayer><baudRate><supportedBaudRate value="250 Kbps"/><supportedBaudRate value="125 Kbps"/></baudRate></PhysicalLayer></TransportLayers>
      <NetworkManagement>
        <CANopenGeneralFeatures granularity="8" nrOfRxPDO="1" nrOfTxPDO="2" layerSettingServiceSlave="true" dynamicChannels="0"/>
        <CANopenMasterFeatures bootUpMaster="true"/>
        <deviceCommissioning nodeID="5" actualBaudRate="250" CANopenManager="false"/>
      </NetworkManagement>
    </ProfileBody>
  </ISO15745Profile>
</ISO15745ProfileContainer>
"#;

#[test]
fn small_file_lowers_as_cia_311_says() {
    let p = parse(&mut Sources::new(), "small.xdd", SMALL.as_bytes());
    assert!(p.diagnostics.is_empty(), "{:?}", p.diagnostics);
    let d = p.device.unwrap();
    // actualValue present: a configuration.
    assert_eq!(d.format, Some(Format::Xdc));
    assert_eq!(d.device_info.vendor_number.as_ref().unwrap().value, 0x12A);
    assert_eq!(d.device_info.product_number.as_ref().unwrap().value, 7);
    assert_eq!(d.file_info.file_version.as_ref().unwrap().value, 3);
    assert_eq!(d.device_info.baud_rates, vec![125, 250]);
    assert_eq!(d.device_info.granularity.as_ref().unwrap().value, 8);
    assert_eq!(d.device_info.nr_of_tx_pdo.as_ref().unwrap().value, 2);
    assert_eq!(d.device_info.lss_supported.as_ref().map(|v| v.value), Some(true));
    assert_eq!(d.device_info.simple_boot_up_master.as_ref().map(|v| v.value), Some(true));
    assert_eq!(d.dummy_usage.get(&2).map(|v| v.value), Some(true));
    assert_eq!(d.dummy_usage.get(&5).map(|v| v.value), Some(false));
    assert_eq!(d.commissioning.as_ref().unwrap().node_id.as_ref().unwrap().value, 5);
    let v = d.sub(0x1000, 0).unwrap();
    assert_eq!((v.data_type, v.access), (DataType::Unsigned32, Access::Ro));
    assert_eq!(v.default.as_ref().unwrap().value, Value::Unsigned(0x20192));
    // Parameter form: type, access and default from the parameter.
    let o = &d.objects[&0x1005];
    assert_eq!(o.kind, ObjectKind::Var);
    let s = o.var().unwrap();
    assert_eq!((s.data_type, s.access), (DataType::Unsigned32, Access::Rw));
    assert_eq!(s.default.as_ref().unwrap().value, Value::Unsigned(0x80));
    assert_eq!(o.extra[0].key, "Description");
    assert_eq!(o.extra[0].value, "line 1\\nline 2");
    assert_eq!(
        (o.extra[1].key.as_str(), o.extra[1].value.as_str()),
        ("CO_storageGroup", "PERSIST_COMM")
    );
    assert_eq!(d.sub(0x1400, 1).unwrap().default.as_ref().unwrap().value, Value::NodeIdPlus(0x200));
    // readWriteInput is rwr (a process input: transmitted), so `TPDO` is what the access says
    // already, as in an EDS (rwr, PDOMapping=1); the range gives the limits.
    let s = d.sub(0x2000, 1).unwrap();
    assert_eq!(
        (s.data_type, s.access, s.pdo_mapping),
        (DataType::Integer16, Access::Rwr, PdoMapping::Yes)
    );
    assert_eq!(s.low_limit.as_ref().unwrap().value, Value::Signed(-5));
    assert_eq!(s.high_limit.as_ref().unwrap().value, Value::Signed(5));
    assert_eq!(s.parameter_value.as_ref().unwrap().value, Value::Signed(3));
}

#[test]
fn small_file_round_trips() {
    let d = parse(&mut Sources::new(), "small.xdd", SMALL.as_bytes()).device.unwrap();
    let w = write(&d, Format::Xdc);
    assert!(w.lost.is_empty(), "{:?}", w.lost);
    assert_eq!(w.text, write(&d, Format::Xdc).text);
    let p = parse(&mut Sources::new(), "again.xdc", w.text.as_bytes());
    assert!(p.diagnostics.is_empty(), "{:?}", p.diagnostics);
    assert_eq!(p.device.unwrap(), d);
    // An XDD leaves the actual value out, and says so.
    let w = write(&d, Format::Xdd);
    assert_eq!(w.lost.len(), 1, "{:?}", w.lost);
    assert!(w.lost[0].contains("2000 sub 1"));
}

#[test]
fn problems_are_diagnostics() {
    let src = SMALL
        .replace(
            r#"accessType="ro" defaultValue="0x00020192""#,
            r#"accessType="rx" defaultValue="0x1FFFFFFFF""#,
        )
        .replace(r#"index="1400""#, r#"index="14G0""#)
        .replace(r#"uniqueIDRef="P2000""#, r#"uniqueIDRef="nope""#);
    let p = parse(&mut Sources::new(), "bad.xdd", src.as_bytes());
    let codes: Vec<&str> = p.diagnostics.iter().map(|d| d.code).collect();
    for c in [
        codes::UNKNOWN_ACCESS,
        codes::OUT_OF_RANGE,
        codes::INVALID_NUMBER,
        codes::UNRESOLVED_REFERENCE,
    ] {
        assert!(codes.contains(&c), "{c} not in {codes:?}");
    }
    let d = p.device.unwrap();
    assert!(!d.objects.contains_key(&0x1400));
    assert_eq!(
        d.sub(0x1000, 0).unwrap().default.as_ref().unwrap().value,
        Value::Invalid("0x1FFFFFFFF".into())
    );
}

#[test]
fn hostile_input_is_refused_plainly() {
    let mut s = Sources::new();
    let p = parse(&mut s, "x.xdd", b"<!DOCTYPE a [<!ENTITY x SYSTEM \"file:///etc/passwd\">]><ISO15745ProfileContainer>&x;</ISO15745ProfileContainer>");
    assert!(p.diagnostics.iter().any(|d| d.code == codes::DOCTYPE_IGNORED));
    let deep = format!(
        "<ISO15745ProfileContainer>{}{}</ISO15745ProfileContainer>",
        "<a>".repeat(1000),
        "</a>".repeat(1000)
    );
    let p = parse(&mut s, "x.xdd", deep.as_bytes());
    assert!(p.diagnostics.iter().any(|d| d.code == codes::DEPTH_LIMIT));
    let p = parse(&mut s, "x.xdd", b"<EtherCATInfo/>");
    assert!(p.device.is_none());
    assert_eq!(p.diagnostics[0].code, codes::NOT_XDD);
    for input in [&b""[..], b"\xFF\xFE<\x00", b"<", b"\x00\x01", b"<ISO15745ProfileContainer><ISO15745Profile><ProfileBody><ApplicationLayers><CANopenObjectList><CANopenObject/>"] {
        let p = parse(&mut s, "x.xdd", input);
        assert!(!p.diagnostics.is_empty() || p.device.is_some());
    }
}

#[test]
fn detection_by_root_element() {
    assert!(is_xdd(SMALL.as_bytes()));
    assert!(is_xdd(b"\xEF\xBB\xBF<?xml version=\"1.0\"?><!-- c --><x:ISO15745ProfileContainer>"));
    assert!(!is_xdd(b"<?xml version=\"1.0\"?><EtherCATInfo>"));
    assert!(!is_xdd(b"[FileInfo]"));
}

/// An ARRAY whose elements say no data type: a CiA 301 one (0x1016) is read with the
/// standard's element type and a warning; a manufacturer one stays DOMAIN with an error.
#[test]
fn untyped_array_elements_take_cia_301_types() {
    let arrays = r#"<CANopenObject index="1016" name="Consumer heartbeat time" objectType="8" subNumber="2">
            <CANopenSubObject subIndex="00" name="n" objectType="7" dataType="0005" accessType="ro" defaultValue="1"/>
            <CANopenSubObject subIndex="01" name="t" objectType="7" dataType="0000" accessType="rw"/>
          </CANopenObject>
          <CANopenObject index="2100" name="Vendor" objectType="8" subNumber="2">
            <CANopenSubObject subIndex="00" name="n" objectType="7" dataType="0005" accessType="ro" defaultValue="1"/>
            <CANopenSubObject subIndex="01" name="v" objectType="7" dataType="0000" accessType="rw"/>
          </CANopenObject>
        </CANopenObjectList>"#;
    let src = SMALL.replacen("</CANopenObjectList>", arrays, 1);
    let p = parse(&mut Sources::new(), "arrays.xdd", src.as_bytes());
    let of = |code| p.diagnostics.iter().filter(|d| d.code == code).count();
    assert_eq!((of(codes::STANDARD_DATA_TYPE), of(codes::MISSING_DATA_TYPE)), (1, 1));
    let d = p.device.unwrap();
    assert_eq!(d.sub(0x1016, 1).unwrap().data_type, DataType::Unsigned32);
    assert_eq!(d.sub(0x2100, 1).unwrap().data_type, DataType::Domain);
}

#[test]
fn allowed_values_with_labels_name_the_values() {
    // CiA 311 `t_allowedValues`: `value` elements (with `g_labels`) beside ranges.
    let param = r#"<parameter uniqueID="P6060" access="readWrite"><label lang="en">Modes of operation</label><SINT/><allowedValues><value value="1"><label lang="en">Profile position</label><label lang="de">Profillage</label></value><value value="3"><label lang="en"> Profile velocity </label></value><value value="6"/></allowedValues></parameter>
        </parameterList>"#;
    let object = r#"<CANopenObject index="6060" name="Modes of operation" objectType="7" PDOmapping="RPDO" uniqueIDRef="P6060"/>
        </CANopenObjectList>"#;
    let src =
        SMALL.replacen("</parameterList>", param, 1).replacen("</CANopenObjectList>", object, 1);
    let p = parse(&mut Sources::new(), "modes.xdd", src.as_bytes());
    assert!(p.diagnostics.is_empty(), "{:?}", p.diagnostics);
    let d = p.device.unwrap();
    let s = d.sub(0x6060, 0).unwrap();
    assert_eq!(s.value_name(&Value::Signed(1)), Some("Profile position"));
    assert_eq!(s.value_name(&Value::Signed(3)), Some("Profile velocity"));
    // A value without a label allows it and names nothing.
    assert_eq!(s.value_name(&Value::Signed(6)), None);
    assert_eq!(s.rare().value_names.len(), 2);
    // A JSON dump carries them (and a sub-object without names has no such field).
    let json = serde_json::to_string(s).unwrap();
    assert!(json.contains(r#""value_names":[{"value":"#), "{json}");
    assert!(!serde_json::to_string(d.sub(0x1000, 0).unwrap()).unwrap().contains("value_names"));
    // The writer keeps the element as read, so the names come back.
    let w = write(&d, Format::Xdc);
    assert!(w.text.contains(r#"<value value="3"><label lang="en"> Profile velocity </label>"#));
    let again = parse(&mut Sources::new(), "again.xdc", w.text.as_bytes()).device.unwrap();
    assert_eq!(again.sub(0x6060, 0).unwrap().rare().value_names.len(), 2);
}
