// What a test needs of the machine, probed by the build scripts of the crates whose tests
// need it (`include!`d: build scripts cannot share a library without a crate of their own).
// A test that cannot run is compiled with a cfg that marks it ignored with the reason.

/// `cfg({prefix}_no_corpus)` without the real-world corpus (`ODC_CORPUS`, default
/// `../shared/corpus` beside the repository); its path reaches the tests as the environment
/// variable `{PREFIX}_CORPUS` (empty without it).
#[allow(dead_code)]
fn find_corpus(prefix: &str) {
    println!("cargo::rustc-check-cfg=cfg({prefix}_no_corpus)");
    println!("cargo:rerun-if-env-changed=ODC_CORPUS");
    let root = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../..");
    let corpus = std::env::var_os("ODC_CORPUS")
        .map(std::path::PathBuf::from)
        .unwrap_or_else(|| root.join("../shared/corpus"));
    let var = format!("{}_CORPUS", prefix.to_uppercase());
    if corpus.join("MANIFEST.tsv").is_file() {
        println!("cargo:rustc-env={var}={}", corpus.display());
    } else {
        println!("cargo:rustc-cfg={prefix}_no_corpus");
        println!("cargo:rustc-env={var}=");
    }
}

/// Whether this machine lets a test make network interfaces of its own (veth pairs, network
/// namespaces with iproute2's `ip`): root and `ip` there.
#[allow(dead_code)]
fn can_make_netdevs() -> bool {
    let root = std::process::Command::new("id")
        .arg("-u")
        .output()
        .is_ok_and(|o| String::from_utf8_lossy(&o.stdout).trim() == "0");
    let ip = std::process::Command::new("ip").arg("-V").output().is_ok_and(|o| o.status.success());
    root && ip
}
