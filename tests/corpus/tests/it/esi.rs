//! Reads every ESI file of the shared corpus (`$ODC_CORPUS/MANIFEST.tsv`, kind `esi`): no file may
//! panic, and all but the two known not-well-formed files must parse without errors.
#![allow(clippy::unwrap_used, clippy::expect_used, clippy::panic)]

use odc_model::{Severity, Sources};

/// Files known not to be well-formed XML (see the corpus README).
/// Files with real faults, each reported as an error:
const KNOWN_BAD: &[&str] = &[
    // Not well-formed XML (F202).
    "esi/hangx__eeprom.xml",
    "esi/abt__DS402_PDOs_EasyCatProject.xml",
    // Defaults that do not fit their data type (F218): `00000003` (4 bytes) for UINT objects.
    "esi/higen__Higen_FDA7000_CoE_20111219.xml",
    // `#x70000101` as the default of a USINT sub-object.
    "esi/trinamic__ethCat_slv_config.xml",
    // `-4294967295` as the minimum of a DINT.
    "esi/tormach-bogus__BogusServo.xml",
    "esi/tormach-bogus__bogus_devices-device_xml-BogusServo.xml",
];

#[test]
#[cfg_attr(
    odc_no_corpus,
    ignore = "needs the real-world corpus: set ODC_CORPUS to its directory (README, Tests)"
)]
fn corpus_esi_files() {
    let dir = odc_tests_corpus::dir();
    let files = odc_tests_corpus::files(&["esi"]);
    let (mut devices, mut clean, mut panics) = (0usize, 0usize, Vec::new());
    let mut failures = Vec::new();
    let mut code_counts = std::collections::BTreeMap::<String, usize>::new();
    for f in files.iter().map(String::as_str) {
        let bytes = std::fs::read(dir.join(f)).unwrap();
        let result = std::panic::catch_unwind(|| {
            let mut sources = Sources::new();
            let parsed = odc_esi::parse(&mut sources, f, &bytes);
            let errors: Vec<_> =
                parsed.diagnostics.iter().filter(|d| d.severity == Severity::Error).collect();
            let first = errors.first().map(|d| {
                odc_model::diag::render_short(&sources, std::slice::from_ref(*d)).trim().to_string()
            });
            let codes: Vec<String> =
                parsed.diagnostics.iter().map(|d| d.code.to_string()).collect();
            (parsed.devices.len(), errors.len(), first, codes)
        });
        match result {
            Ok((n, errors, first, codes)) => {
                devices += n;
                for c in codes {
                    *code_counts.entry(c).or_default() += 1;
                }
                if errors == 0 {
                    clean += 1;
                } else {
                    failures.push((f.to_string(), errors, first.unwrap_or_default()));
                }
            }
            Err(_) => panics.push(f.to_string()),
        }
    }
    println!("ESI corpus: {} files, {devices} devices, {clean} with zero errors", files.len());
    println!("diagnostic codes: {code_counts:?}");
    for (f, n, first) in &failures {
        println!("  FAIL {f}: {n} error(s), first: {first}");
    }
    assert!(panics.is_empty(), "panicked on: {panics:?}");
    let unexpected: Vec<_> =
        failures.iter().filter(|(f, _, _)| !KNOWN_BAD.contains(&f.as_str())).collect();
    assert!(unexpected.is_empty(), "unexpected failures: {unexpected:#?}");
}
