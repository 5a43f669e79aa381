//! `odc_diff::diff` on device files of the repository: a file against itself, and a file
//! against a copy edited by hand, where every expected change is the edit made.
#![allow(clippy::unwrap_used, clippy::expect_used, clippy::panic)]

use std::path::{Path, PathBuf};

use odc_diff::{Change, Options, Place, What, diff};
use odc_model::{Device, Sources};

fn root() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../..")
}

fn eds_text(text: &str) -> Device {
    odc_eds::parse(&mut Sources::new(), "x.eds", text.as_bytes()).device
}

fn changed(place: Place, field: &str, a: &str, b: &str) -> Change {
    Change {
        place,
        what: What::Changed { field: field.into(), a: a.into(), b: b.into() },
        odc: None,
    }
}

#[test]
fn every_shipped_device_equals_itself() {
    let mut devices = 0;
    for dir in ["eds", "esi"] {
        for entry in std::fs::read_dir(root().join(dir)).unwrap() {
            let path = entry.unwrap().path();
            if path.extension().is_some_and(|e| e == "toml") {
                continue;
            }
            let loaded = odc_pipeline::load(&path, &odc_pipeline::Options::new()).unwrap();
            for d in &loaded.devices {
                assert_eq!(diff(d, d, &Options::default()), [], "{}", path.display());
                devices += 1;
            }
        }
    }
    // eds/: 5 EDS files; esi/: servoone.xml.
    assert_eq!(devices, 6);
}

#[test]
fn hand_edits_are_found_and_nothing_else() {
    let original = std::fs::read_to_string(root().join("eds/lxm23a.eds")).unwrap();
    let edited = original
        // 0x6040: access rww -> rw (so it maps both ways), default 0 -> 6.
        .replacen(
            "ParameterName=Controlword\nObjectType=0x7\nDataType=0x0006\nAccessType=rww\nDefaultValue=0",
            "ParameterName=Controlword\nObjectType=0x7\nDataType=0x0006\nAccessType=rw\nDefaultValue=0x6",
            1,
        )
        // 0x6060: renamed.
        .replacen("ParameterName=Modes of operation\n", "ParameterName=Operating mode\n", 1)
        // TPDO2's second entry maps 0x606C (32 bits) instead of 0x6064.
        .replacen("DefaultValue=0x60640020", "DefaultValue=0x606C0020", 1);
    assert_ne!(original, edited);
    let (a, b) = (eds_text(&original), eds_text(&edited));
    let changes = diff(&a, &b, &Options::default());
    let object = |index| Place::Object { index };
    let expected = vec![
        changed(object(0x6040), "access", "rww", "rw"),
        changed(object(0x6040), "PDO mapping", "RPDO", "RPDO/TPDO"),
        // Values in CiA 306 canonical form (odc_analysis::value_text): unsigned as hex.
        changed(object(0x6040), "default", "0x0", "0x6"),
        changed(object(0x6060), "name", "Modes of operation", "Operating mode"),
        changed(Place::Sub { index: 0x1A01, sub: 2 }, "default", "0x60640020", "0x606C0020"),
        changed(
            Place::Pdo { mapping_index: 0x1A01 },
            "entries",
            "0x6041:00/16 0x6064:00/32",
            "0x6041:00/16 0x606C:00/32",
        ),
    ];
    // Sorted as the output is: objects by index (0x1A01 before 0x6040), then PDOs.
    let mut expected_sorted = expected.clone();
    expected_sorted.sort_by_key(|c| match c.place {
        Place::Object { index } | Place::Sub { index, .. } => (0, index),
        _ => (1, 0),
    });
    assert_eq!(changes, expected_sorted, "{changes:#?}");
    // Ignoring names drops the rename, and only it.
    let quiet = diff(&a, &b, &Options { ignore_names: true, ..Options::default() });
    assert_eq!(quiet.len(), changes.len() - 1);
    assert!(
        !quiet.iter().any(|c| matches!(&c.what, What::Changed { field, .. } if field == "name"))
    );
}

#[test]
fn a_default_written_another_way_is_the_same_value() {
    let original = std::fs::read_to_string(root().join("eds/lxm23a.eds")).unwrap();
    // 0x6060's default 0 written as 0x0, and 0x6040's 0 as 0x00: no difference.
    let edited = original
        .replacen("ParameterName=Modes of operation\nObjectType=0x7\nDataType=0x0002\nAccessType=rww\nDefaultValue=0", "ParameterName=Modes of operation\nObjectType=0x7\nDataType=0x0002\nAccessType=rww\nDefaultValue=0x0", 1)
        .replacen("ParameterName=Controlword\nObjectType=0x7\nDataType=0x0006\nAccessType=rww\nDefaultValue=0", "ParameterName=Controlword\nObjectType=0x7\nDataType=0x0006\nAccessType=rww\nDefaultValue=0x00", 1);
    assert_ne!(original, edited);
    assert_eq!(diff(&eds_text(&original), &eds_text(&edited), &Options::default()), []);
}

fn esi_text(text: &str) -> Device {
    let parsed = odc_esi::parse(&mut Sources::new(), "x.xml", text.as_bytes());
    parsed.devices.into_iter().next().unwrap()
}

/// Objects odc synthesised for a CoE device (odc-esi's fixture: 0x1C00, 0x1C12/0x1C13, the
/// mapping objects) are labelled in a change: an edit of a PDO changes its synthesised
/// mapping object on both sides (`odc: "a, b"`), and the file's own 0x1C13 where odc had
/// synthesised one is odc's on side A only. The file's own objects carry no label.
#[test]
fn objects_odc_made_are_labelled() {
    let path = root().join("crates/odc-esi/tests/fixtures/coe_implied.xml");
    let original = std::fs::read_to_string(path).unwrap();
    // TxPDO 0x1A00's gap: 8 -> 16 bits; 0x1000's default 0x1389 -> 0x1388.
    let edited = original
        .replacen(
            "<Entry><Index>0</Index><BitLen>8</BitLen></Entry>",
            "<Entry><Index>0</Index><BitLen>16</BitLen></Entry>",
            1,
        )
        .replacen("<DefaultData>89130000</DefaultData>", "<DefaultData>88130000</DefaultData>", 1);
    assert_ne!(original, edited);
    let (a, b) = (esi_text(&original), esi_text(&edited));
    let changes = diff(&a, &b, &Options::default());
    let labels: Vec<(&Place, Option<&str>)> = changes.iter().map(|c| (&c.place, c.odc)).collect();
    assert_eq!(
        labels,
        [
            (&Place::Object { index: 0x1000 }, None),
            (&Place::Sub { index: 0x1A00, sub: 2 }, Some("a, b")),
            (&Place::Pdo { mapping_index: 0x1A00 }, None),
            // SM 3's input image: 4 bytes -> 5.
            (&Place::Image { direction: "inputs" }, None),
        ],
        "{changes:#?}"
    );
    let text = odc_diff::human(&changes, &a, &b, false);
    assert!(text.contains("object 0x1A00 Inputs (odc's in A, B, not the file's)\n"), "{text}");
    assert!(text.contains("object 0x1000 Device type\n"), "{text}");
    assert!(odc_diff::json(&changes).contains("\"odc\": \"a, b\""));

    // B with its own 0x1C13 (a VAR with no room for the assignment: kept as written).
    let own = r#"<Object><Index>#x1C13</Index><Name>TxPDO assign</Name><Type>USINT</Type>
      <BitSize>8</BitSize><Info><DefaultData>00</DefaultData></Info></Object></Objects>"#;
    let b = esi_text(&original.replacen("</Objects>", own, 1));
    let changes = diff(&a, &b, &Options::default());
    assert!(!changes.is_empty());
    assert!(
        changes.iter().all(|c| c.place == Place::Object { index: 0x1C13 }
            || matches!(c.place, Place::Sub { index: 0x1C13, .. })),
        "{changes:#?}"
    );
    assert!(changes.iter().all(|c| c.odc == Some("a")), "{changes:#?}");
}
