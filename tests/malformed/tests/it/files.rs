//! Every file under `files/`: its front-end diagnostics, snapshotted. The snapshots were
//! reviewed one by one: each names the problem the file was broken with (README.md lists
//! them).
#![allow(clippy::unwrap_used, clippy::expect_used)] // test code: a panic is a failure report

use std::path::Path;

fn front_end(path: &Path, xml: bool) {
    let bytes = std::fs::read(path).unwrap();
    let name = path.file_name().unwrap().to_string_lossy().into_owned();
    let outcome = odc_tests_malformed::run(&name, &bytes, xml, true);
    insta::assert_snapshot!(outcome.report());
}

#[test]
fn eds_files() {
    insta::glob!("../../files", "eds/*", |path| front_end(path, false));
}

#[test]
fn esi_files() {
    insta::glob!("../../files", "esi/*", |path| front_end(path, true));
}

#[test]
fn xdd_files() {
    insta::glob!("../../files", "xdd/*", |path| {
        let bytes = std::fs::read(path).unwrap();
        let name = path.file_name().unwrap().to_string_lossy().into_owned();
        let outcome = odc_tests_malformed::run_as(&name, &bytes, "case.xdd", true);
        insta::assert_snapshot!(outcome.report());
    });
}

#[test]
fn the_suite_has_at_least_sixty_files() {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("files");
    let count: usize =
        ["eds", "esi", "xdd"].iter().map(|d| std::fs::read_dir(dir.join(d)).unwrap().count()).sum();
    assert!(count >= 60, "{count} files");
}
