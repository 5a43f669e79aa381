//! Finds the real-world corpus: `ODC_CORPUS`, else `../shared/corpus` beside the repository
//! (the team's setup). With its `MANIFEST.tsv` there, the tests get its directory as
//! `ODC_TESTS_CORPUS`; without, they are compiled with `cfg(odc_no_corpus)`, which marks them
//! `#[ignore]` with the reason, so `cargo test` prints `ignored, needs the corpus ...` for each
//! instead of passing without having run.
//!
//! Rebuilt when `ODC_CORPUS` changes or the manifest found appears changed or goes away. A
//! `../shared/corpus` that appears later without `ODC_CORPUS` set is seen after
//! `cargo clean -p odc-tests-corpus` (or by setting `ODC_CORPUS`), as the ignore reason says.

use std::path::PathBuf;

fn main() {
    println!("cargo::rustc-check-cfg=cfg(odc_no_corpus)");
    println!("cargo::rerun-if-changed=build.rs");
    println!("cargo::rerun-if-env-changed=ODC_CORPUS");
    let manifest_dir = PathBuf::from(std::env::var_os("CARGO_MANIFEST_DIR").unwrap_or_default());
    let dir = std::env::var_os("ODC_CORPUS")
        .map(PathBuf::from)
        .unwrap_or_else(|| manifest_dir.join("../../../shared/corpus"));
    let manifest = dir.join("MANIFEST.tsv");
    if manifest.is_file() {
        let dir = std::fs::canonicalize(&dir).unwrap_or(dir);
        println!("cargo::rerun-if-changed={}", manifest.display());
        println!("cargo::rustc-env=ODC_TESTS_CORPUS={}", dir.display());
    } else {
        println!("cargo::rustc-cfg=odc_no_corpus");
        println!("cargo::rustc-env=ODC_TESTS_CORPUS=");
    }
}
