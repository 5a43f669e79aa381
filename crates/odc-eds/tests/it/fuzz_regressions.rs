//! Inputs the `eds_roundtrip` and `eds_parse` fuzz targets (fuzz/) found, minimised: each one
//! broke parse → write → parse or the parser once. The property checked is the fuzz target's:
//! the re-read model equals the first one (spans, the order of unknown sections and the
//! documented module normalisations aside; see tests/round_trip/mod.rs), and the
//! writer is stable.

use crate::round_trip;
use odc_model::{Format, Sources};
use round_trip::round_trip;

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

/// A CompactSubObj object whose explicit `[IIIIsub1]` has an unknown key: sub 1 is the
/// template of the implied sub-objects, and its unknown key was written into the object's
/// section (then read back as the object's own).
#[test]
fn explicit_sub_1_of_a_compact_object_keeps_its_unknown_keys() {
    let text = round_trip(
        b"[\n\n[1003]\nObjectType=0xc\nCompactSubObj=3\nDe\n\n[1003sub1]\nA6\n5=0x4\xff ",
    );
    assert!(text.contains("[1003sub1]\nParameterName="), "{text}");
}

/// The writer normalises modular devices (documented): NrOfEntries is the number of modules,
/// and every module gets its `[MxModuleInfo]`.
#[test]
fn modules_are_normalised() {
    let text = round_trip(
        b"[SupportedModules]\nNrOfEntries=5\n[M1ModuleInfo]\nProductName=a\n[M2Comments]\nLines=0\n",
    );
    assert!(text.contains("[SupportedModules]\nNrOfEntries=2"), "{text}");
    assert!(text.contains("[M2ModuleInfo]"), "{text}");
}

/// A Denotation (a DCF key) in a module's object made a file that the EDS writer then wrote
/// without it: module objects count when deciding EDS or DCF.
#[test]
fn module_denotation_makes_a_dcf() {
    let mut sources = Sources::new();
    let p = odc_eds::parse(&mut sources, "x.eds", b"[M1SubExt6200\nDenotation=Sd");
    assert_eq!(p.device.format, Some(Format::Dcf));
    round_trip(b"[M1SubExt6200\nDenotation=Sd");
}

/// A kept key in `[ConnectEdModules]` (the known section in another spelling): re-read, the
/// kept section takes the spelling the writer gives the known one.
#[test]
fn kept_section_in_another_spelling() {
    round_trip(b"[DeviceComissioning]\nNodeID=1\n[ConnectEdModules]\nNrOfEntries=1\n1=1\nX=y\n");
}

/// An object whose ObjectType does not read is a RECORD when it has sub-objects; the writer
/// turned its explicit sub 1 into an implied (CompactSubObj) one, and the re-read object, with
/// no sub section left, became a VAR.
#[test]
fn unreadable_object_type_with_compact_sub_objects() {
    round_trip(
        b"[1003]\nObjectType=bad\nCompactSubObj=3\nDataType=0x0007\nAccessType=ro\n\n\
          [1003sub1]\nParameterName=orphan\nDataType=0x0007\nAccessType=ro\n",
    );
}

/// A `[xxxxName]` companion of an object whose own header lacks its `]`.
#[test]
fn name_companion_of_an_unclosed_object_header() {
    round_trip(b"[1003\n[1003Name\n0=0");
}

/// `HighLimit=0x` on a DOMAIN reads as a limit of zero bytes; written as an empty value, it
/// read back as no limit (the CI fuzzing run of stop 38).
#[test]
fn limit_of_zero_bytes() {
    let text = round_trip(b"[2001]\nParameterName=d\nObjectType=0x7\nDataType=0x000F\nAccessType=rw\nHighLimit=0x\nLowLimit=0X \n");
    assert!(text.contains("HighLimit=0x\n") && text.contains("LowLimit=0x\n"), "{text}");
}

/// The explicit `[IIIIsub1]` of a CompactSubObj object with its own `ObjFlags` (read, or kept
/// as written because it does not read): the writer took it for the template of the implied
/// sub-objects and wrote it into the object's section, where it reads back as the object's.
#[test]
fn obj_flags_of_an_explicit_sub_1_of_a_compact_object() {
    let object = "[1016]\nParameterName=c\nObjectType=0x8\nDataType=0x0007\nAccessType=rw\nCompactSubObj=2\n";
    for flags in ["0x1", "0x10 x"] {
        let input = format!(
            "{object}[1016sub1]\nParameterName=s\nDataType=0x0007\nAccessType=rw\nObjFlags={flags}\n"
        );
        let text = round_trip(input.as_bytes());
        assert!(text.contains("[1016sub1]"), "{text}");
    }
}
