//! Snapshots of the code generated for devices built in Rust.

use crate::common;

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

/// A drive whose default RPDO puts the controlword with something the driver does not set
/// (0x6060) and the target elsewhere still gets `cia402::Pdos` and `plan`: RPDO 1 and TPDO 1
/// mapped for the driver (controlword + target position, statusword + position actual
/// value); one without RPDO 1 gets none, and the module's documentation says why and what to
/// do instead.
#[test]
fn cia402_pdos_for_a_drive_with_split_default_pdos() {
    use odc_model::{Spanned, Value};
    let mut split = common::drive();
    let map = split.objects.get_mut(&0x1600).unwrap();
    for (sub, v) in [(0u8, 2u64), (1, 0x6040_0010), (2, 0x6060_0008)] {
        map.subs.get_mut(&sub).unwrap().default = Some(Spanned::synthetic(Value::Unsigned(v)));
    }
    map.subs.remove(&3);
    split.pdos = odc_model::pdo::resolve_canopen_pdos(&split);
    let out = generate(&split, &opts(Role::Master)).expect("generates");
    for want in [
        "pub struct Command {",
        "pub const MAPPING_VALUES: [u32; 2] = [0x6040_0010, 0x607A_0020];",
        "pub const MAPPING_VALUES: [u32; 2] = [0x6041_0010, 0x6064_0020];",
        "type Command = Command;",
        "0x200 + node_id.get() as u32",
        "&Command::MAPPING_VALUES",
        ".with_comm(0x1400, true)",
        ".with_transmission_type(1)",
        "target_position: o.target_position.unwrap_or(0)",
        "i.position = Some(t.position_actual_value);",
        "pub const fn plan(",
    ] {
        assert!(out.contains(want), "no `{want}` in:\n{out}");
    }
    // The default pair is still preferred where there is one (the snapshot's drive).
    let both = generate(&common::drive(), &opts(Role::Master)).expect("generates");
    assert!(both.contains("type Command = super::pdo::Rpdo1;"));
    assert!(!both.contains("pub struct Command {"));

    let mut bare = split.clone();
    bare.objects.remove(&0x1400);
    bare.pdos = odc_model::pdo::resolve_canopen_pdos(&bare);
    let out = generate(&bare, &opts(Role::Master)).expect("generates");
    assert!(!out.contains("pub struct Pdos"), "{out}");
    assert!(out.contains("/// No `Pdos`: the default PDO mapping has no RPDO"), "{out}");
    assert!(out.contains("the device has no 0x1400 (RPDO 1 and TPDO 1)"), "{out}");
    assert!(out.contains("`odc::master::mapping_plan`"), "{out}");
}
