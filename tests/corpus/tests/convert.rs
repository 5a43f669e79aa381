//! What `odc convert` writes passes `odc check` whenever the input did: every corpus file
//! (EDS, DCF, each device of an ESI) without error-level diagnostics, written as EDS and as DCF
//! and read back. (The shipped files, through the binary: `crates/odc-cli/tests/convert.rs`.)
#![allow(clippy::unwrap_used, clippy::expect_used, clippy::panic)]

use std::collections::{BTreeMap, BTreeSet};

use odc_check::Config;
use odc_model::{Device, Diagnostic, Format, Severity, Sources};

/// `odc check`'s verdict on one device: the front-end's diagnostics and the rules', at the
/// default levels.
fn check(device: &Device, front_end: Vec<Diagnostic>) -> Vec<Diagnostic> {
    let config = Config::default();
    let mut all = config.apply(device, front_end);
    all.extend(odc_check::check(device, &config));
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
    let (mut inputs, mut refused, mut not_canopen, mut outputs, mut kept_dcf) = (0, 0, 0, 0, 0);
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
            let mut before = check(device, std::mem::take(&mut front_end));
            if before.iter().any(Diagnostic::is_error) {
                refused += 1;
                continue;
            }
            // An EtherCAT device written as EDS is a CANopen device, judged by the CiA 301
            // rules that do not apply to EtherCAT (mandatory 0x1000, 64-bit PDOs, ...): the
            // output can pass only if the device, taken as CANopen, does.
            let mut device = device.clone();
            if device.format == Some(Format::Esi) {
                // As `odc convert` does: the CiA 301 mandatory objects the ESI lacks added.
                odc_eds::add_mandatory_objects(&mut device);
                let mut canopen = device.clone();
                canopen.format = Some(Format::Eds);
                before = check(&canopen, Vec::new());
                // An EDS says a PDO's direction by its index alone (CiA 306: mapping objects
                // 0x1600-0x17FF receive, 0x1A00-0x1BFF transmit); a TxPdo numbered 0x1600
                // (Beckhoff's EL9800) becomes an RPDO, which `odc convert` warns about.
                if before.iter().any(Diagnostic::is_error)
                    || !odc_eds::pdo_directions_by_index(&device).is_empty()
                {
                    not_canopen += 1;
                    continue;
                }
            }
            for asked in [Format::Eds, Format::Dcf] {
                outputs += 1;
                let format = as_convert_writes(&device, asked);
                kept_dcf += usize::from(format != asked);
                let text = odc_eds::write(&device, format);
                let name = format!("{file}#{n}.{asked:?}");
                let back = odc_eds::parse(&mut sources, &name, text.as_bytes());
                let after = check(&back.device, back.diagnostics);
                if let Some(e) = after.iter().find(|d| d.is_error()) {
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
        "{} files, {inputs} devices: {refused} refused by check, {not_canopen} EtherCAT devices \
         that are not valid CANopen ones; {outputs} EDS/DCF outputs ({kept_dcf} asked as EDS \
         written as DCF to keep their DCF values), {} with an error",
        files.len(),
        failures.len()
    );
    println!("warnings the input had not: {new_warnings:?}");
    assert!(failures.is_empty(), "converted output fails check:\n{}", failures.join("\n"));
    assert!(outputs > 300, "{outputs} outputs");
}
