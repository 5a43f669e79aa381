//! What `odc convert` writes passes `odc check` whenever the input did: every corpus file
//! (EDS, DCF, each device of an ESI) without error-level diagnostics, written as EDS and as DCF
//! and read back. (The shipped files, through the binary: `crates/odc-cli/tests/it/convert.rs`.)
#![allow(clippy::unwrap_used, clippy::expect_used, clippy::panic)]

use std::collections::{BTreeMap, BTreeSet};

use odc_check::{Config, Level};
use odc_model::{Device, Diagnostic, Format, Severity, Sources};

/// `odc check`'s verdict on one device: the front-end's diagnostics and the rules', at the
/// default levels.
fn check(device: &Device, front_end: Vec<Diagnostic>, config: &Config) -> Vec<Diagnostic> {
    let mut all = config.apply(device, front_end);
    all.extend(odc_check::check(device, config));
    all
}

fn codes(diags: &[Diagnostic], severity: Severity) -> BTreeSet<&'static str> {
    diags.iter().filter(|d| d.severity == severity).map(|d| d.code).collect()
}

/// The format `odc convert` writes for `-o x.eds` (or `-o x.dcf`): a device with DCF values
/// stays a DCF, so that nothing is left out.
fn as_convert_writes(device: &Device, asked: Format) -> Format {
    if asked == Format::Eds && !odc_eds::dcf_only(device).is_empty() { Format::Dcf } else { asked }
}

#[test]
#[cfg_attr(
    odc_no_corpus,
    ignore = "needs the real-world corpus: set ODC_CORPUS to its directory (README, Tests)"
)]
fn corpus_files_that_pass_check_convert_to_files_that_pass_check() {
    let files = odc_tests_corpus::files(&["eds", "dcf", "esi"]);
    let (mut inputs, mut refused, mut outputs, mut kept_dcf) = (0, 0, 0, 0);
    let (mut refused_as_canopen, mut redirected) = (0, 0);
    let mut refused_on_read_back = BTreeSet::new();
    // The CiA 301 rules EtherCAT devices break as CANopen ones: code -> devices.
    let mut canopen_codes: BTreeMap<&str, usize> = BTreeMap::new();
    let mut failures = Vec::new();
    // Warnings an output has that its input had not: code -> outputs.
    let mut new_warnings: BTreeMap<&str, usize> = BTreeMap::new();
    for file in &files {
        let bytes = std::fs::read(odc_tests_corpus::path(file)).unwrap();
        let mut sources = Sources::new();
        let (devices, mut front_end) = if file.starts_with("esi/") {
            let p = odc_esi::parse(&mut sources, file, &bytes);
            (p.devices, p.diagnostics)
        } else {
            let p = odc_eds::parse(&mut sources, file, &bytes);
            (vec![p.device], p.diagnostics)
        };
        for (n, device) in devices.iter().enumerate() {
            inputs += 1;
            let mut before = check(
                device,
                std::mem::take(&mut front_end),
                &Config::in_registry(odc_check::rules()),
            );
            if before.iter().any(Diagnostic::is_error) {
                refused += 1;
                continue;
            }
            // An EtherCAT device written as EDS is a CANopen device, judged by the CiA 301
            // rules that do not apply to EtherCAT (mandatory 0x1000, 64-bit PDOs, ...). As
            // `odc convert` does, the mandatory objects the ESI lacks are added, and a device
            // that breaks those rules is refused; allowed by their codes (`-A C304`), it is
            // written, and its output passes check at the same levels.
            let mut device = device.clone();
            let mut config = Config::in_registry(odc_check::rules());
            if device.format == Some(Format::Esi) {
                odc_eds::add_mandatory_objects(&mut device);
                let canopen = odc_eds::as_canopen(&device);
                before = check(&canopen, Vec::new(), &config);
                let broken = codes(&before, Severity::Error);
                if !broken.is_empty() {
                    refused_as_canopen += 1;
                    for code in &broken {
                        *canopen_codes.entry(code).or_default() += 1;
                        config.set_level(code, Level::Allow).unwrap();
                    }
                    before = check(&canopen, Vec::new(), &config);
                    assert!(
                        !before.iter().any(Diagnostic::is_error),
                        "{file}#{n}: allowed, still errors"
                    );
                }
                // An EDS says a PDO's direction by its index alone (CiA 306: mapping objects
                // 0x1600-0x17FF receive, 0x1A00-0x1BFF transmit); a TxPdo numbered 0x1600
                // (Beckhoff's EL9800) becomes an RPDO, which `odc convert` warns about.
                redirected += usize::from(!odc_eds::pdo_directions_by_index(&device).is_empty());
            }
            for asked in [Format::Eds, Format::Dcf] {
                outputs += 1;
                let format = as_convert_writes(&device, asked);
                kept_dcf += usize::from(format != asked);
                let text = odc_eds::write(&device, format);
                let name = format!("{file}#{n}.{asked:?}");
                let back = odc_eds::parse(&mut sources, &name, text.as_bytes());
                let after = check(&back.device, back.diagnostics, &config);
                let esi = device.format == Some(Format::Esi);
                if esi
                    && after.iter().any(Diagnostic::is_error)
                    && mapping_differs(&device, &back.device)
                {
                    // `odc convert` reads its output back and refuses it (nothing written):
                    // the ESI's mapping objects map other entries than its PDO elements, and
                    // an EDS gives its PDOs by those objects alone.
                    refused_on_read_back.insert(format!("{file}#{n}"));
                } else if let Some(e) = after.iter().find(|d| d.is_error()) {
                    let shown = odc_model::diag::render_short(&sources, std::slice::from_ref(e));
                    failures.push(shown.trim_end().to_owned());
                }
                let had = codes(&before, Severity::Warning);
                for code in codes(&after, Severity::Warning).difference(&had) {
                    *new_warnings.entry(code).or_default() += 1;
                }
            }
        }
    }
    println!(
        "{} files, {inputs} devices: {refused} refused by check; {refused_as_canopen} EtherCAT \
         devices refused by convert as CANopen devices ({canopen_codes:?}), written with those \
         rules allowed; {redirected} with a PDO written in the other direction; {} refused on \
         reading the output back (mapping objects that disagree with the PDO elements); {outputs} \
         EDS/DCF outputs ({kept_dcf} asked as EDS written as DCF to keep their DCF values), {} \
         with an error",
        files.len(),
        refused_on_read_back.len(),
        failures.len()
    );
    println!("refused on read-back: {refused_on_read_back:?}");
    println!("warnings the input had not: {new_warnings:?}");
    assert!(failures.is_empty(), "converted output fails check:\n{}", failures.join("\n"));
    assert!(outputs > 300, "{outputs} outputs");
}

/// Whether a PDO's entries (index, sub-index, length) differ between the ESI device and the
/// EDS written from it, which takes them from the mapping objects' values.
fn mapping_differs(esi: &Device, eds: &Device) -> bool {
    let entries = |d: &Device, index: u16| -> Option<Vec<(u16, u8, u16)>> {
        let pdo = d.pdos.iter().find(|p| p.mapping_index == index)?;
        Some(pdo.entries.iter().map(|e| (e.index, e.sub, e.bits)).collect())
    };
    esi.pdos.iter().any(|p| entries(esi, p.mapping_index) != entries(eds, p.mapping_index))
}
