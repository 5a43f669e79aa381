//! Looks for python-canopen for the `odc simulate` test against it (tests/simulate.rs), as
//! tests/interop/build.rs does: `ODC_INTEROP_PYTHON`, else `python3`. Without one that imports
//! `canopen` and `can` (and without `ODC_INTEROP_REQUIRED`), the test is compiled with
//! `cfg(odc_cli_no_python)`, which marks it ignored with the reason.

include!("../../build-support/probes.rs");

fn main() {
    soem();
    find_corpus("odc_cli");
    println!("cargo::rustc-check-cfg=cfg(odc_cli_no_python)");
    println!("cargo:rerun-if-env-changed=ODC_INTEROP_PYTHON");
    println!("cargo:rerun-if-env-changed=ODC_INTEROP_REQUIRED");
    let py = std::env::var_os("ODC_INTEROP_PYTHON").unwrap_or_else(|| "python3".into());
    let ok = std::process::Command::new(&py)
        .args(["-c", "import canopen, can"])
        .stdout(std::process::Stdio::null())
        .stderr(std::process::Stdio::null())
        .status()
        .is_ok_and(|s| s.success());
    if ok {
        if std::path::Path::new(&py).is_file() {
            println!("cargo:rerun-if-changed={}", std::path::Path::new(&py).display());
        }
    } else if std::env::var_os("ODC_INTEROP_REQUIRED").is_none() {
        println!("cargo:rustc-cfg=odc_cli_no_python");
    }
}

/// The SOEM test (tests/simulate_soem.rs) needs pysoem in that python and a veth pair in a
/// network namespace of its own (root, iproute2); without them, and unless both
/// `ODC_INTEROP_REQUIRED` and `ODC_NET_REQUIRED` are set (`.ci/run`), it is compiled with
/// `cfg(odc_cli_no_soem)` and shows as ignored with the reason.
fn soem() {
    use std::process::{Command, Stdio};
    println!("cargo::rustc-check-cfg=cfg(odc_cli_no_soem)");
    println!("cargo:rerun-if-env-changed=ODC_NET_REQUIRED");
    let py = std::env::var_os("ODC_INTEROP_PYTHON").unwrap_or_else(|| "python3".into());
    let runs = |cmd: &mut Command| {
        cmd.stdout(Stdio::null()).stderr(Stdio::null()).status().is_ok_and(|s| s.success())
    };
    let pysoem = runs(Command::new(&py).args(["-c", "import pysoem"]));
    let required = std::env::var_os("ODC_INTEROP_REQUIRED").is_some()
        && std::env::var_os("ODC_NET_REQUIRED").is_some();
    if !(required || pysoem && can_make_netdevs()) {
        println!("cargo:rustc-cfg=odc_cli_no_soem");
    }
}
