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

/// The slave implements `odc::cia402::DriveObjects` only for a CiA 402 drive (device type
/// 0x…0192) whose controlword and statusword are UNSIGNED16 as the profile types them.
#[test]
fn drive_objects_only_for_a_402_drive() {
    let has = |dev: &odc_model::Device| {
        generate(dev, &opts(Role::Slave))
            .expect("generates")
            .contains("DriveObjects for Dictionary")
    };
    let drive = common::drive();
    assert!(has(&drive));
    // Another profile: no impl.
    let mut io = common::drive();
    let s = io.objects.get_mut(&0x1000).unwrap().subs.get_mut(&0).unwrap();
    s.default = Some(odc_model::Spanned::new(odc_model::Value::Unsigned(0x0001_0191), s.span));
    assert!(!has(&io));
    // A controlword typed INTEGER16 is no `Controlword`: no impl.
    let mut odd = common::drive();
    odd.objects.get_mut(&0x6040).unwrap().subs.get_mut(&0).unwrap().data_type =
        odc_model::DataType::Integer16;
    assert!(!has(&odd));
}
