//! `odc diff` (`odc_diff::diff`) on the corpus: every device against itself, each EDS against
//! the DCF of the same device, and revisions of one Beckhoff terminal in one ESI file. The
//! EDS/XDD pairs are `xdd_pairs.rs`, whose comparison is this one.

#![allow(clippy::unwrap_used, clippy::panic)]

use odc_diff::{Change, Options, Place, What, diff};
use odc_model::{Device, Sources};
use odc_tests_corpus::{files, path};

fn read(file: &str) -> Vec<Device> {
    let bytes = std::fs::read(path(file)).unwrap();
    let mut sources = Sources::new();
    if file.ends_with(".xml") {
        odc_esi::parse(&mut sources, file, &bytes).devices
    } else if file.ends_with(".xdd") || file.ends_with(".xdc") {
        odc_xdd::parse(&mut sources, file, &bytes).device.into_iter().collect()
    } else {
        vec![odc_eds::parse(&mut sources, file, &bytes).device]
    }
}

#[test]
#[cfg_attr(
    odc_no_corpus,
    ignore = "needs the real-world corpus: set ODC_CORPUS to its directory (README, Tests)"
)]
fn every_corpus_device_equals_itself() {
    let (mut files_read, mut devices) = (0, 0);
    for file in files(&["eds", "dcf", "xdd", "esi"]) {
        files_read += 1;
        for d in read(&file) {
            let changes = diff(&d, &d, &Options::default());
            assert!(changes.is_empty(), "{file}: {changes:?}");
            devices += 1;
        }
    }
    println!("{files_read} files, {devices} devices, each equal to itself");
    assert!(devices > files_read, "the ESI files hold several devices each");
}

#[test]
#[cfg_attr(
    odc_no_corpus,
    ignore = "needs the real-world corpus: set ODC_CORPUS to its directory (README, Tests)"
)]
fn eds_against_its_dcf() {
    let mut report = String::new();
    let mut pairs = 0;
    for dcf in files(&["dcf"]) {
        let eds = dcf.replace(".dcf", ".eds");
        if !path(&eds).is_file() {
            continue;
        }
        pairs += 1;
        let (a, b) = (read(&eds).remove(0), read(&dcf).remove(0));
        let changes = diff(&a, &b, &Options { ignore_comments: true, ..Options::default() });
        // What a DCF is for: configured values (ParameterValue) and the format.
        let values = changes
            .iter()
            .filter(|c| matches!(&c.what, What::Changed { field, a, .. } if field == "value" && a.is_empty()))
            .count();
        report.push_str(&format!(
            "\n## {eds} / {dcf}: {} differences, {values} of them a configured value\n{}",
            changes.len(),
            odc_diff::human(&changes, &a, &b, false)
        ));
    }
    assert_eq!(pairs, 5, "the corpus's EDS/DCF pairs (MANIFEST.tsv)");
    insta::assert_snapshot!(report);
}

#[test]
#[cfg_attr(
    odc_no_corpus,
    ignore = "needs the real-world corpus: set ODC_CORPUS to its directory (README, Tests)"
)]
fn revisions_of_one_terminal() {
    let file = "esi/beckhoff__Beckhoff_EL15xx.xml";
    let devices = read(file);
    let rev = |r: u32| {
        devices
            .iter()
            .find(|d| {
                d.device_info.product_number.as_ref().map(|v| v.value) == Some(0x05DE_3052)
                    && d.device_info.revision_number.as_ref().map(|v| v.value) == Some(r)
            })
            .unwrap_or_else(|| panic!("EL1502 revision 0x{r:08X} in {file}"))
    };
    // Two neighbours the file describes alike but for the revision number.
    let next = diff(rev(0x0015_0000), rev(0x0016_0000), &Options::default());
    assert_eq!(
        next,
        [Change {
            place: Place::Identity,
            what: What::Changed {
                field: "revision".into(),
                a: "0x00150000".into(),
                b: "0x00160000".into()
            },
            odc: None,
        }]
    );
    // Revision 0x00100000 against 0x00160000: the changes a user would read (reviewed).
    let (a, b) = (rev(0x0010_0000), rev(0x0016_0000));
    let changes = diff(a, b, &Options::default());
    insta::assert_snapshot!(odc_diff::human(&changes, a, b, false));
}
