//! Names in generated code: the standard object keeps a name it shares with others, trade
//! names stay one word.
#![allow(clippy::expect_used)] // a failure is the test failing

use crate::common;

use odc_codegen::{Options, generate};

/// The identifier of the descriptor of `index`: `pub const NAME: … Entry::new(<index>, …`,
/// however the formatter broke its lines.
fn const_for(code: &str, index: &str) -> String {
    let needle = format!("Entry::new({index},");
    code.split("pub const ")
        .find(|item| {
            let item = item.split(';').next().unwrap_or_default();
            item.split_whitespace().collect::<String>().contains(&needle)
        })
        .and_then(|item| item.split(':').next())
        .expect("descriptor generated")
        .to_string()
}

#[test]
fn the_standard_object_keeps_the_plain_name() {
    let code = generate(&common::twins(), &Options::default()).expect("generates");
    // od: 0x6064 is the object CiA 402 calls "Position actual value"; the vendor object and
    // the starred profile twin get their index.
    assert_eq!(const_for(&code, "0x6064"), "POSITION_ACTUAL_VALUE");
    assert_eq!(const_for(&code, "0x2064"), "POSITION_ACTUAL_VALUE_OBJ_2064");
    assert_eq!(const_for(&code, "0x6063"), "POSITION_ACTUAL_VALUE_OBJ_6063");
    // The TPDO maps the vendor object first; the standard one still keeps the plain field.
    assert!(code.contains("#[pdo(index = 0x2064, sub = 0x00, bits = 32)]\n        pub position_actual_value_obj_2064_00: i32,"), "{code}");
    assert!(
        code.contains(
            "#[pdo(index = 0x6064, sub = 0x00, bits = 32)]\n        pub position_actual_value: i32,"
        ),
        "{code}"
    );
    // The slave dictionary's rows name the descriptors (with whichever `row` macro).
    assert!(code.contains("!(od::POSITION_ACTUAL_VALUE),"));
    assert!(code.contains("!(od::POSITION_ACTUAL_VALUE_OBJ_2064),"));
}

#[test]
fn trade_names_stay_one_word() {
    let code = generate(&common::twins(), &Options::default()).expect("generates");
    assert_eq!(const_for(&code, "0x2301"), "CANOPEN_BAUD_RATE_P3_01");
    assert!(code.contains("!(od::CANOPEN_BAUD_RATE_P3_01),"));
    assert!(!code.contains("CA_NOPEN"));
}
