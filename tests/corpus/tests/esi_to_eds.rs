//! ESI → EDS → model keeps every object, type, access and default (issue: ESI front-end §6).
#![allow(clippy::unwrap_used)] // test code
//!
//! Runs over `esi/servoone.xml` and every device of every corpus ESI file (`$ODC_CORPUS`).

use std::path::{Path, PathBuf};

use odc_model::{Device, Format, Sources};

/// What must survive the trip, per sub-object: (index, sub) → (type, access, default).
fn essentials(dev: &Device) -> Vec<(u16, u8, String, String, String)> {
    dev.objects
        .values()
        .flat_map(|o| {
            o.subs.values().map(move |s| {
                (
                    o.index,
                    s.sub_index,
                    format!("{:?}", s.data_type),
                    format!("{:?}", s.access),
                    format!("{:?}", s.default.as_ref().map(|d| &d.value)),
                )
            })
        })
        .collect()
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
fn corpus_esi_devices_convert_to_equivalent_eds() {
    let corpus = std::env::var_os("ODC_CORPUS")
        .map(PathBuf::from)
        .unwrap_or_else(|| Path::new(env!("CARGO_MANIFEST_DIR")).join("../../../shared/corpus"));
    let Ok(entries) = std::fs::read_dir(corpus.join("esi")) else {
        eprintln!("corpus not found at {}: skipped", corpus.display());
        return;
    };
    let mut files: Vec<PathBuf> = entries.filter_map(|e| Some(e.ok()?.path())).collect();
    files.sort();
    let problems: Vec<String> = files.iter().flat_map(|f| check_file(f)).collect();
    println!("{} ESI files converted; {} problems", files.len(), problems.len());
    assert!(problems.is_empty(), "{}", problems.join("\n"));
}
