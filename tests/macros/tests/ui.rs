//! Compile errors of `include_device!`, with their reviewed output in `tests/ui/*.stderr`.
//!
//! trybuild compiles each file in a crate under `target/tests/trybuild/odc-tests-macros/`,
//! which is the `CARGO_MANIFEST_DIR` the macro resolves paths from: the files reach back to
//! this directory with `../../../../tests/macros/tests/ui/`.

#[test]
fn ui() {
    let t = trybuild::TestCases::new();
    t.compile_fail("tests/ui/*.rs");
}
