//! Compile-fail tests: each error must point at the offending key or field.
//! Re-bless with `TRYBUILD=overwrite` after a deliberate toolchain bump (rustc 1.95 here).

#[test]
fn ui() {
    let t = trybuild::TestCases::new();
    t.compile_fail("tests/ui/fail/*.rs");
    t.pass("tests/ui/pass/*.rs");
}
