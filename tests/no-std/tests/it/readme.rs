//! README.md's "A slave in firmware" program is the body of `examples/firmware.rs` (between
//! its `// slave: begin` and `// slave: end` lines), so the README shows code that builds.
#![allow(clippy::unwrap_used, clippy::expect_used, clippy::panic, missing_docs)]

use std::path::Path;

#[test]
fn readme_shows_the_firmware_example() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let example = std::fs::read_to_string(root.join("examples/firmware.rs")).unwrap();
    let readme = std::fs::read_to_string(root.join("../../README.md")).unwrap();
    let body = example
        .split_once("// slave: begin\n")
        .and_then(|(_, rest)| rest.split_once("// slave: end"))
        .map(|(body, _)| body)
        .expect("examples/firmware.rs has the slave markers");
    let section = readme
        .split_once("## A slave in firmware")
        .and_then(|(_, rest)| rest.split_once("```rust\n"))
        .and_then(|(_, rest)| rest.split_once("```"))
        .map(|(code, _)| code)
        .expect("README.md has the section and its code block");
    assert_eq!(section, body, "README.md's firmware program differs from examples/firmware.rs");
}
