//! Memory stays bounded on every hostile input: the peak resident set of a process that reads,
//! checks and renders one case grows by no more than a fixed multiple of the input plus a
//! constant (which covers the documented limits: the sub-objects types may expand to, the
//! diagnostics kept per code).
//!
//! Each case runs in a child process (this test binary again, running [`child`]), measured with
//! Linux's own accounting (`VmHWM` of `/proc/self/status`), so the bound covers everything the
//! process did, input included, and no other test or earlier case is counted. Run with
//! `--nocapture` to see the table; `peak-memory.sh` measures the `odc` binary the same way.
#![allow(clippy::unwrap_used, clippy::expect_used)] // test code: a panic is a failure report

use std::process::Command;

/// Allowed growth of the peak over the resident set at the start: this many times the input,
/// plus [`SLACK`].
const FACTOR: u64 = 4;
/// 262,144 ESI sub-objects (`odc_esi::MAX_SUB_OBJECTS`) of 408 bytes are 107 MB.
const SLACK: u64 = 160 << 20;
const CASE: &str = "ODC_MALFORMED_MEMORY_CASE";

fn status(key: &str) -> Option<u64> {
    let text = std::fs::read_to_string("/proc/self/status").ok()?;
    let line = text.lines().find(|l| l.starts_with(key))?;
    let kb: u64 = line.split_whitespace().nth(1)?.parse().ok()?;
    Some(kb * 1024)
}

/// One case: name, read as ESI, its bytes on demand.
type Case = (String, bool, Box<dyn Fn() -> Vec<u8>>);

/// Every case.
fn cases() -> Vec<Case> {
    let dir = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("files");
    let mut cases: Vec<Case> = Vec::new();
    for (sub, xml) in [("eds", false), ("esi", true)] {
        let mut paths: Vec<_> =
            std::fs::read_dir(dir.join(sub)).unwrap().map(|e| e.unwrap().path()).collect();
        paths.sort();
        for path in paths {
            let name = format!("{sub}/{}", path.file_name().unwrap().to_string_lossy());
            cases.push((name, xml, Box::new(move || std::fs::read(&path).unwrap())));
        }
    }
    for g in odc_tests_malformed::generated() {
        cases.push((g.name.to_string(), g.xml, Box::new(g.make)));
    }
    cases
}

/// In a child process: runs the case named by the environment and prints its peak.
#[test]
fn child() {
    let Ok(which) = std::env::var(CASE) else { return };
    let before = status("VmRSS:").unwrap_or(0);
    let (name, xml, make) = cases().into_iter().find(|c| c.0 == which).unwrap();
    let bytes = make();
    let outcome = odc_tests_malformed::run(&name, &bytes, xml, false);
    let _ = outcome.report();
    let peak = status("VmHWM:").unwrap_or(0);
    println!("odc-peak {} {} {}", bytes.len(), before, peak);
}

#[test]
fn peak_memory_is_bounded() {
    if status("VmHWM:").is_none() {
        eprintln!("skipped: no /proc/self/status (not Linux)");
        return;
    }
    let exe = std::env::current_exe().unwrap();
    // The harness's name of [`child`]: its module path without the crate (`memory::child` in
    // the tests/it binary), or `child` in a binary of its own.
    let child = match module_path!().split_once("::") {
        Some((_, module)) => format!("{module}::child"),
        None => "child".to_owned(),
    };
    let mut worst = (0u64, String::new(), 0u64);
    let mut table = String::new();
    let cases = cases();
    for (name, _, _) in &cases {
        let out = Command::new(&exe)
            .args(["--exact", &child, "--nocapture", "--test-threads=1"])
            .env(CASE, name)
            .output()
            .unwrap();
        let stdout = String::from_utf8_lossy(&out.stdout);
        let line = stdout
            .lines()
            .find_map(|l| l.split_once("odc-peak ").map(|p| p.1))
            .unwrap_or_else(|| {
                panic!("{name}: no measurement\n{stdout}\n{}", String::from_utf8_lossy(&out.stderr))
            });
        let v: Vec<u64> = line.split(' ').map(|x| x.parse().unwrap()).collect();
        let (len, before, peak) = (v[0], v[1], v[2]);
        let growth = peak.saturating_sub(before);
        table.push_str(&format!("{name:45} input {len:>9} B  peak +{:>7} KiB\n", growth >> 10));
        assert!(
            growth <= FACTOR * len + SLACK,
            "{name}: peak grew by {growth} bytes for {len} bytes of input"
        );
        if growth > worst.0 {
            worst = (growth, name.clone(), len);
        }
    }
    eprintln!("{table}");
    eprintln!(
        "worst case: {} (input {} B): peak resident set +{} KiB over {} cases",
        worst.1,
        worst.2,
        worst.0 >> 10,
        cases.len()
    );
}
