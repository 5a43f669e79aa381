//! Inputs the `eds_roundtrip` and `eds_parse` fuzz targets (fuzz/) found, minimised: each one
//! broke parse → write → parse or the parser once. The property checked is the fuzz target's:
//! the re-read model equals the first one (spans and the order of unknown sections aside), and
//! the writer is stable.

use odc_model::{Device, Format, Sources};

fn canonical(d: &Device) -> Device {
    let mut d = d.clone();
    d.extra_sections.sort_by_key(|s| s.name.to_ascii_lowercase());
    d
}

fn round_trip(input: &[u8]) -> String {
    let mut sources = Sources::new();
    let first = odc_eds::parse(&mut sources, "fuzz.eds", input);
    let format = first.device.format.unwrap_or(Format::Eds);
    let text = odc_eds::write(&first.device, format);
    let name = if format == Format::Dcf { "fuzz.dcf" } else { "fuzz.eds" };
    let second = odc_eds::parse(&mut sources, name, text.as_bytes());
    assert_eq!(canonical(&first.device), canonical(&second.device), "written:\n{text}");
    let again = odc_eds::write(&second.device, format);
    let third = odc_eds::parse(&mut sources, name, again.as_bytes());
    assert_eq!(odc_eds::write(&third.device, format), again, "writer not stable");
    text
}

/// An object list without `SupportedObjects` was written with one (`SupportedObjects=0`).
#[test]
fn object_list_without_count() {
    let text = round_trip(b";nd\n\n[MandatoryObjects\n");
    assert!(!text.contains("SupportedObjects"), "{text}");
    let text = round_trip(b"[OptionalObjects]\nSupportedObjects=1\n1=0x1000\n");
    assert!(text.contains("SupportedObjects=1\n1=0x1000"), "{text}");
}

/// A `SubNumber` on a VAR (warned about, kept in the model) was not written back.
#[test]
fn sub_number_on_a_var() {
    let text = round_trip(b"\xbf\n[1A00]\n\n\nSubNumber=2\n");
    assert!(text.contains("SubNumber=2"), "{text}");
}

/// A CompactSubObj object whose DataType does not read: the text kept for every implied
/// sub-object was lost.
#[test]
fn compact_object_with_unreadable_data_type() {
    let text = round_trip(b"[Dee3]\nP\nObjectType=0x8\nDataType=o\nCompactSubObj=3\nSpe");
    assert!(text.contains("DataType=o"), "{text}");
}

/// A list entry kept as written (its value does not read) shares its number with the entries
/// the writer renumbers; on re-reading it replaced one of them.
#[test]
fn kept_list_entry_keeps_its_number() {
    let text = round_trip(b"[OptionalObjects]\n1=0n\n6=0x1\n");
    assert!(text.contains("2=0x0001"), "{text}");
}

/// `[ConnectedModules]` and `Denotation` exist in DCFs only: a file that has them is a DCF,
/// else the EDS writer dropped them.
#[test]
fn dcf_only_content_makes_a_dcf() {
    let mut sources = Sources::new();
    for input in [&b"s0\n[ConnectedModules]\nr=\n3=1"[..], b"[1001\nDenotation="] {
        let p = odc_eds::parse(&mut sources, "x.eds", input);
        assert_eq!(p.device.format, Some(Format::Dcf));
        round_trip(input);
    }
}

/// An empty `[1003Value]` section makes a DCF that only its name says is one.
#[test]
fn empty_value_section() {
    round_trip(b"[1003]\n[1003Value");
}

/// An unknown section before a known one that also keeps unknown keys: sections come back in
/// another order (the writer writes the known ones first), nothing else changes.
#[test]
fn unknown_sections_change_order_only() {
    round_trip(b"e\n[O\n[OptionalObjects\n=");
}
