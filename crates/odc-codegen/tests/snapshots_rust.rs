//! Snapshots of the code generated for devices built in Rust.

mod common;

use odc_codegen::{Options, Role, generate};

fn opts(role: Role) -> Options {
    Options {
        role,
        source_name: "mini-drive.eds".to_string(),
        source_sha256: "0".repeat(64),
        ..Options::default()
    }
}

#[test]
fn drive_both() {
    let out = generate(&common::drive(), &opts(Role::Both)).expect("generates");
    insta::assert_snapshot!(out);
}
