//! The compile errors odc promises, each with its reviewed output beside it (`.stderr`): a
//! typed entry refuses a value of the wrong type (`tests/ui/entry_wrong_type.rs`);
//! `#[derive(Pdo)]` and `#[derive(PdoValue)]` point at the offending key or field
//! (`tests/ui/fail/`; `tests/ui/pass/` compiles and runs); `include_device!` names the bad
//! argument, value or file (`bad_args`, `bad_value`, `missing_file`). One `TestCases`, so
//! trybuild builds the dependencies once for all of them (#33). Re-bless with
//! `TRYBUILD=overwrite` after a deliberate toolchain bump (rustc 1.95 here).
//!
//! trybuild compiles the cases in a crate at `<target dir>/tests/trybuild/odc-tests-ui/`, which
//! is the `CARGO_MANIFEST_DIR` the macro resolves paths from. The device files the cases name
//! are copied into `fixtures/` there first, so the cases (and their expected output) name
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
    t.compile_fail("tests/ui/fail/*.rs");
    t.pass("tests/ui/pass/*.rs");
}
