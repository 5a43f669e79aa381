//! Regression tests for what the EDS front-end reads and says about single keys: the three
//! defects found by comparing odc with python-canopen and lely (empty limits on strings,
//! odd-length hex, CompactPDO), data types written as names or as indexes of no type,
//! repeated sections, and merge-conflict markers.
#![allow(clippy::unwrap_used, clippy::expect_used, clippy::panic, missing_docs)]

use odc_model::{Diagnostic, Origin, Sources, Value};

fn parse(text: &str) -> (Sources, odc_eds::Parsed) {
    let mut sources = Sources::new();
    let parsed = odc_eds::parse(&mut sources, "t.eds", text.as_bytes());
    (sources, parsed)
}

fn codes(p: &odc_eds::Parsed) -> Vec<&'static str> {
    p.diagnostics.iter().map(|d| d.code).collect()
}

/// The text under a diagnostic's primary label.
fn at<'s>(sources: &'s Sources, d: &Diagnostic) -> &'s str {
    let span = d.primary_span().expect("a primary label");
    &sources.text(span.file).expect("the file")[span.range()]
}

fn var(index: &str, data_type: &str, extra: &str) -> String {
    format!(
        "[{index}]\nParameterName=x\nObjectType=0x7\nDataType={data_type}\nAccessType=rw\n{extra}\n"
    )
}

#[test]
fn empty_limits_of_strings_are_absent() {
    for dt in ["0x0009", "0x000A", "0x000B", "0x000F"] {
        let (sources, p) = parse(&var("2000", dt, "LowLimit=\nHighLimit=\nDefaultValue="));
        let s = p.device.sub(0x2000, 0).expect("0x2000");
        assert!(s.low_limit.is_none() && s.high_limit.is_none(), "{dt}: {s:?}");
        // The value stays the empty string, not reported.
        assert!(s.default.is_some(), "{dt}");
        let f112: Vec<_> =
            p.diagnostics.iter().filter(|d| d.code == "F112").map(|d| at(&sources, d)).collect();
        assert_eq!(f112, ["LowLimit=", "HighLimit="], "{dt}");
    }
}

#[test]
fn odd_length_hex_is_read_with_a_warning() {
    let (sources, p) = parse(&var("2000", "0x000A", "DefaultValue=ABC"));
    let s = p.device.sub(0x2000, 0).expect("0x2000");
    assert_eq!(s.default.as_ref().map(|v| &v.value), Some(&Value::Bytes(vec![0x0A, 0xBC].into())));
    let d = p.diagnostics.iter().find(|d| d.code == "F133").expect("F133");
    assert_eq!(at(&sources, d), "ABC");
    assert!(d.message.contains("read as `0A BC`"), "{}", d.message);
    // Even groups: nothing to say.
    let (_, p) = parse(&var("2000", "0x000F", "DefaultValue=0A BC 01"));
    assert!(!codes(&p).contains(&"F133"), "{:?}", p.diagnostics);
}

#[test]
fn data_type_that_is_no_type() {
    let (sources, p) = parse(&var("2000", "0x0099", ""));
    let d = p.diagnostics.iter().find(|d| d.code == "F134").expect("F134");
    assert_eq!(d.message, "`0x0099` is not a data type index");
    assert_eq!(at(&sources, d), "0x0099");
    // Defined by the file: a type.
    let text = format!("{}\n{}", var("0099", "0x0007", ""), var("2000", "0x0099", ""));
    let (_, p) = parse(&text);
    assert!(!codes(&p).contains(&"F134"), "{:?}", p.diagnostics);
    // CiA 301 types are types.
    let (_, p) = parse(&var("2000", "0x001B", ""));
    assert!(p.diagnostics.is_empty(), "{:?}", p.diagnostics);
}

#[test]
fn data_type_written_as_a_name() {
    let (sources, p) = parse(&var("2000", "UNSIGNED16", ""));
    let d = p.diagnostics.iter().find(|d| d.code == "F107").expect("F107");
    assert_eq!(at(&sources, d), "UNSIGNED16");
    assert!(d.labels[0].message.contains("did you mean 0x0006?"), "{d:?}");
    let (_, p) = parse(&var("2000", "visible_string", ""));
    let d = p.diagnostics.iter().find(|d| d.code == "F107").expect("F107");
    assert!(d.labels[0].message.contains("did you mean 0x0009?"), "{d:?}");
}

fn compact_pdo(device_info: &str, objects: &str) -> odc_model::Device {
    let (_, p) = parse(&format!("[DeviceInfo]\n{device_info}\n{objects}"));
    p.device
}

fn implied(dev: &odc_model::Device, range: std::ops::RangeInclusive<u16>) -> Vec<u16> {
    dev.objects
        .range(range)
        .filter(|(_, o)| o.origin == Origin::CompactPdo)
        .map(|(&i, _)| i)
        .collect()
}

fn record(index: &str) -> String {
    format!(
        "[{index}]\nParameterName=p\nObjectType=0x9\nSubNumber=1\n[{index}sub0]\nParameterName=n\nDataType=0x0005\nAccessType=ro\nDefaultValue=0\n"
    )
}

/// lely's reading: written-out PDOs count towards NrOfRXPDO and get their other half.
#[test]
fn compact_pdo_follows_lely() {
    let objects = format!("{}{}", record("1400"), record("1405"));
    let dev = compact_pdo("NrOfRXPDO=3\nCompactPDO=0x03", &objects);
    assert_eq!(implied(&dev, 0x1400..=0x17FF), [0x1401, 0x1600, 0x1601, 0x1605]);
    // Nothing is implied past the count when every PDO is written out.
    let objects = format!("{}{}{}", record("1400"), record("1600"), record("1401"));
    let dev = compact_pdo("NrOfRXPDO=2\nCompactPDO=0x3F", &objects);
    assert_eq!(implied(&dev, 0x1400..=0x17FF), [0x1601]);
    // None written out: the first n.
    let dev = compact_pdo("NrOfTXPDO=2\nCompactPDO=0x01", "");
    assert_eq!(implied(&dev, 0x1800..=0x1BFF), [0x1800, 0x1801, 0x1A00, 0x1A01]);
}

#[test]
fn compact_pdo_objects_are_lelys() {
    let dev = compact_pdo("NrOfRXPDO=1\nNrOfTXPDO=5\nCompactPDO=0x3F", "");
    let comm = &dev.objects[&0x1400];
    let value = |i: u16, s: u8| default(&dev, i, s);
    assert_eq!(comm.subs.len(), 7);
    assert_eq!(value(0x1400, 0), Some(Value::Unsigned(6)));
    assert_eq!(value(0x1400, 1), Some(Value::NodeIdPlus(0x200)));
    assert_eq!(value(0x1400, 2), Some(Value::Unsigned(0)), "transmission type 0, as lely");
    assert_eq!(value(0x1804, 1), Some(Value::Unsigned(0x8000_0000)));
    assert_eq!(dev.sub(0x1800, 4).map(|s| s.name.as_str()), Some("Reserved"));
    let map = &dev.objects[&0x1A00];
    assert_eq!(map.subs.len(), 1 + 0x40);
    assert_eq!(value(0x1A00, 0), Some(Value::Unsigned(0)));
    assert_eq!(dev.sub(0x1A00, 0x40).map(|s| s.name.as_str()), Some("Application object 64"));
    assert_eq!(value(0x1A00, 0x40), Some(Value::Unsigned(0)));
    // Only the bits named: COB-ID alone gives subs 0 and 1.
    let dev = compact_pdo("NrOfRXPDO=1\nCompactPDO=0x01", "");
    assert_eq!(dev.objects[&0x1400].subs.keys().copied().collect::<Vec<_>>(), [0, 1]);
    assert_eq!(default(&dev, 0x1400, 0), Some(Value::Unsigned(1)));
}

fn default(dev: &odc_model::Device, index: u16, sub: u8) -> Option<Value> {
    dev.sub(index, sub).and_then(|s| s.default.clone()).map(|v| v.value)
}

/// Two sections of one name are merged (F105); an error in the one whose value is replaced
/// is still reported, with a label at the value that replaced it.
#[test]
fn errors_of_both_merged_sections_are_reported() {
    let text = "[2000]\nParameterName=A\nObjectType=0x7\nDataType=0x0006\nAccessType=rw\n\
                DefaultValue=0x12345\nPDOMapping=2\n\n\
                [2000]\nParameterName=A\nAccessType=rw\nDefaultValue=70000\nPDOMapping=1\n\n\
                [2001]\nParameterName=R\nObjectType=0x9\nSubNumber=1\n\
                [2001sub0]\nParameterName=n\nDataType=0x0005\nAccessType=bogus\nDefaultValue=1\n\
                [2001sub0]\nAccessType=ro\nDataType=0x0005\n";
    let (sources, p) = parse(text);
    let found: Vec<_> =
        p.diagnostics.iter().filter(|d| d.is_error()).map(|d| (d.code, at(&sources, d))).collect();
    assert_eq!(
        found,
        [("F108", "0x12345"), ("F107", "2"), ("F108", "70000"), ("F115", "bogus")],
        "{:?}",
        p.diagnostics
    );
    let d = &p.diagnostics.iter().find(|d| d.code == "F115").expect("F115");
    assert!(d.notes.iter().any(|n| n.contains("a later `AccessType=` replaces it")), "{d:?}");
    // The later values are the ones used.
    assert_eq!(p.device.sub(0x2001, 0).map(|s| s.access), Some(odc_model::Access::Ro));
}

/// Merge-conflict markers: one diagnostic for the file, every marker line labelled, the note
/// once; `=======` is a marker, not an entry with an empty key.
#[test]
fn merge_markers_are_folded() {
    let block = "<<<<<<< HEAD\nDefaultValue=1\n=======\nDefaultValue=2\n>>>>>>> abc123\n";
    let text = format!(
        "[2000]\nParameterName=A\nObjectType=0x7\nDataType=0x0005\nAccessType=rw\n{block}{block}{block}"
    );
    let (sources, p) = parse(&text);
    let f101: Vec<_> = p.diagnostics.iter().filter(|d| d.code == "F101").collect();
    assert_eq!(f101.len(), 1, "{:?}", p.diagnostics);
    let d = f101[0];
    assert_eq!(d.message, "9 git merge-conflict marker lines (3 conflicts) ignored");
    assert_eq!(d.labels.len(), 9);
    assert_eq!(d.notes.len(), 1);
    assert_eq!(at(&sources, d), "<<<<<<< HEAD");
    assert!(p.device.objects[&0x2000].extra.is_empty(), "{:?}", p.device.objects[&0x2000].extra);
    // A line of equals signs that is not a marker is still an entry.
    let (_, p) = parse("[Comments]\nLines=1\nLine1=x\n========x\n");
    assert!(p.diagnostics.iter().all(|d| d.code != "F101"), "{:?}", p.diagnostics);
}
