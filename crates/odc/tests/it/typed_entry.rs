//! A typed descriptor refuses a value of the wrong type at compile time.

#[test]
fn wrong_value_type_does_not_compile() {
    trybuild::TestCases::new().compile_fail("tests/ui/*.rs");
}
