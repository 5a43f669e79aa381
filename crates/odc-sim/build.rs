//! Whether the tests that need their own network interfaces (a veth pair made with `ip`, as
//! root) can run: `cfg(odc_sim_no_netdev)` when not root and `ODC_NET_REQUIRED` is unset, so
//! they show as ignored with the reason. `.ci/run` sets `ODC_NET_REQUIRED`: there they run,
//! and fail if the machine refuses them. Likewise `cfg(odc_sim_no_corpus)` without the
//! real-world corpus (`ODC_CORPUS`, default `../shared/corpus` beside the repository), whose
//! path reaches the tests as `ODC_SIM_CORPUS`.

use std::process::Command;

fn main() {
    find_corpus();
    println!("cargo::rustc-check-cfg=cfg(odc_sim_no_netdev)");
    println!("cargo:rerun-if-env-changed=ODC_NET_REQUIRED");
    let root = Command::new("id")
        .arg("-u")
        .output()
        .is_ok_and(|o| String::from_utf8_lossy(&o.stdout).trim() == "0");
    let ip = Command::new("ip").arg("-V").output().is_ok_and(|o| o.status.success());
    if std::env::var_os("ODC_NET_REQUIRED").is_none() && !(root && ip) {
        println!("cargo:rustc-cfg=odc_sim_no_netdev");
    }
}

fn find_corpus() {
    println!("cargo::rustc-check-cfg=cfg(odc_sim_no_corpus)");
    println!("cargo:rerun-if-env-changed=ODC_CORPUS");
    let root = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../..");
    let corpus = std::env::var_os("ODC_CORPUS")
        .map(std::path::PathBuf::from)
        .unwrap_or_else(|| root.join("../shared/corpus"));
    if corpus.join("MANIFEST.tsv").is_file() {
        println!("cargo:rustc-env=ODC_SIM_CORPUS={}", corpus.display());
    } else {
        println!("cargo:rustc-cfg=odc_sim_no_corpus");
        println!("cargo:rustc-env=ODC_SIM_CORPUS=");
    }
}
