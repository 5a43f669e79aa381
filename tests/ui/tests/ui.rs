//! Compile errors of `include_device!`, with their reviewed output in `tests/ui/*.stderr`.
//!
//! trybuild compiles each case in a crate at `<target dir>/tests/trybuild/odc-tests-macros/`,
//! which is the `CARGO_MANIFEST_DIR` the macro resolves paths from. The device files the cases
//! name are copied into `fixtures/` there first, so the cases (and their expected output) name
//! `fixtures/servoone.xml` wherever the target directory is (`CARGO_TARGET_DIR`, a shared
//! cache).
#![allow(clippy::unwrap_used, clippy::expect_used)] // test code: a failure is the test failing

use std::path::{Path, PathBuf};
use std::process::Command;

/// The target directory as trybuild finds it: `cargo metadata`'s `target_directory`.
fn target_dir() -> PathBuf {
    let cargo = std::env::var_os("CARGO").unwrap_or_else(|| "cargo".into());
    let out = Command::new(cargo)
        .args(["metadata", "--no-deps", "--format-version=1"])
        .current_dir(env!("CARGO_MANIFEST_DIR"))
        .output()
        .expect("cargo metadata runs");
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    let meta: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    PathBuf::from(meta["target_directory"].as_str().expect("target_directory"))
}

#[test]
fn ui() {
    let manifest = Path::new(env!("CARGO_MANIFEST_DIR"));
    let fixtures =
        target_dir().join("tests/trybuild").join(env!("CARGO_PKG_NAME")).join("fixtures");
    std::fs::create_dir_all(&fixtures).unwrap();
    for file in ["../../eds/lxm23a.eds", "../../esi/servoone.xml", "tests/ui/bad_value.eds"] {
        let from = manifest.join(file);
        std::fs::copy(&from, fixtures.join(from.file_name().unwrap())).unwrap();
    }
    let t = trybuild::TestCases::new();
    t.compile_fail("tests/ui/*.rs");
}
