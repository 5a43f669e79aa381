//! ESI → EDS → model keeps every object, type, access and default (issue: ESI front-end §6).
//!
//! Runs over `esi/servoone.xml` and every device of every corpus ESI file (`$ODC_CORPUS`).
#![allow(clippy::unwrap_used)] // test code

use std::path::{Path, PathBuf};

use odc_model::{Access, Device, Direction, Format, PdoMapping, Sources, SubObject};

/// What must survive the trip, per sub-object: (index, sub) → (type, access, default).
///
/// The access is the one an EDS must say: an ESI object whose access forbids a PDO direction
/// its `PdoMapping` allows (`ro` with `R`) is written with the access that allows it (`rww`),
/// as an EDS has no other way to say it (the EDS writer's policy).
fn essentials(dev: &Device) -> Vec<(u16, u8, String, String, String)> {
    dev.objects
        .values()
        .flat_map(|o| {
            o.subs.values().map(move |s| {
                (
                    o.index,
                    s.sub_index,
                    format!("{:?}", s.data_type),
                    format!("{:?}", eds_access(s)),
                    format!("{:?}", s.default.as_ref().map(|d| &d.value)),
                )
            })
        })
        .collect()
}

fn eds_access(s: &SubObject) -> Access {
    let yes = |dir| PdoMapping::Yes.allows(s.access, dir);
    match s.pdo_mapping {
        PdoMapping::Rx if !yes(Direction::Rx) => Access::Rww,
        PdoMapping::Tx if !yes(Direction::Tx) => Access::Rwr,
        PdoMapping::Both if !yes(Direction::Rx) || !yes(Direction::Tx) => Access::Rw,
        _ => s.access,
    }
}

/// Converts every device of one ESI file and returns the mismatches found.
fn check_file(path: &Path) -> Vec<String> {
    let bytes = std::fs::read(path).unwrap();
    let mut sources = Sources::new();
    let parsed = odc_esi::parse(&mut sources, &path.display().to_string(), &bytes);
    let mut problems = Vec::new();
    // Only devices that lower cleanly need to survive; a file with front-end errors (values that
    // do not fit their type, kept as text) has nothing exact to keep.
    if parsed.diagnostics.iter().any(|d| d.is_error()) {
        return problems;
    }
    for (n, dev) in parsed.devices.iter().enumerate() {
        let eds = odc_eds::write(dev, Format::Eds);
        let back = odc_eds::parse(&mut sources, "converted.eds", eds.as_bytes());
        if let Some(e) = back.diagnostics.iter().find(|d| d.is_error()) {
            problems.push(format!(
                "{} device {n}: EDS reads back with {}: {}",
                path.display(),
                e.code,
                e.message
            ));
            continue;
        }
        let (want, got) = (essentials(dev), essentials(&back.device));
        if want != got {
            let first = want.iter().zip(&got).find(|(a, b)| a != b);
            problems.push(format!(
                "{} device {n}: {} vs {} sub-objects; first difference {first:?}",
                path.display(),
                want.len(),
                got.len()
            ));
        }
    }
    problems
}

#[test]
fn servoone_esi_converts_to_an_equivalent_eds() {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../esi/servoone.xml");
    assert_eq!(check_file(&path), Vec::<String>::new());
}

#[test]
#[cfg_attr(
    odc_no_corpus,
    ignore = "needs the real-world corpus: set ODC_CORPUS to its directory (README, Tests)"
)]
fn corpus_esi_devices_convert_to_equivalent_eds() {
    let files: Vec<PathBuf> =
        odc_tests_corpus::files(&["esi"]).iter().map(|f| odc_tests_corpus::path(f)).collect();
    let problems: Vec<String> = files.iter().flat_map(|f| check_file(f)).collect();
    println!("{} ESI files converted; {} problems", files.len(), problems.len());
    assert!(problems.is_empty(), "{}", problems.join("\n"));
}
