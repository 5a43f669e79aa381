//! One failing and one passing device per rule, with snapshots of the short rendering.
#![allow(clippy::unwrap_used, clippy::expect_used, clippy::panic, missing_docs)]

mod common;

use common::*;
use odc_model::Spanned;

/// Asserts that `dev` trips `code` and snapshots the whole output.
macro_rules! trips {
    ($name:ident, $code:literal, $dev:expr) => {
        #[test]
        fn $name() {
            let out = run($dev);
            assert!(out.contains(concat!("[", $code, "]")), "{} not tripped:\n{out}", $code);
            insta::assert_snapshot!(stringify!($name), out);
        }
    };
}

#[test]
fn base_device_passes_every_rule() {
    assert_eq!(run(base()), "");
    assert_eq!(run(base().lists()), "");
}

// C101–C105: object lists.

trips!(c101_listed_object_missing, "C101", base().lists().remove(0x1017));
trips!(c102_object_not_listed, "C102", base().lists().var(0x2000, "Unlisted", Unsigned8, Rw));
trips!(
    c103_supported_objects_count,
    "C103",
    base().lists().with(|d| {
        if let Some(l) = d.object_lists.optional.as_mut() {
            l.supported_objects = Some(Spanned::synthetic(5));
        }
    })
);
trips!(
    c104_object_in_wrong_list,
    "C104",
    base().lists().with(|d| {
        if let Some(l) = d.object_lists.optional.as_mut() {
            l.entries.push(Spanned::synthetic(0x1018));
            l.entries.push(Spanned::synthetic(0x0007));
            l.supported_objects = Some(Spanned::synthetic(l.entries.len() as u16));
        }
        if let Some(l) = d.object_lists.mandatory.as_mut() {
            l.entries.retain(|e| e.value != 0x1018);
            l.supported_objects = Some(Spanned::synthetic(l.entries.len() as u16));
        }
    })
);
trips!(
    c105_object_listed_twice,
    "C105",
    base().lists().with(|d| {
        if let Some(l) = d.object_lists.optional.as_mut() {
            l.entries.push(Spanned::synthetic(0x1000));
            l.supported_objects = Some(Spanned::synthetic(l.entries.len() as u16));
        }
    })
);

// C110–C117: structure.

fn record_2000() -> Dev {
    base().record(
        0x2000,
        "Settings",
        &[(1, "A", Unsigned16, Rw, None), (3, "C", Unsigned16, Rw, None)],
    )
}

#[test]
fn structured_objects_with_gaps_pass() {
    assert_eq!(run(record_2000()), "");
    let arr = base().array(
        0x2001,
        "Table",
        &[(1, "a", Integer16, Rw, None), (2, "b", Integer16, Rw, None)],
    );
    assert_eq!(run(arr), "");
    // 0x1003 sub 0 counts errors: 0 with subs 1..2 is fine.
    let errs = base()
        .array(0x1003, "Pre-defined error field", &[(1, "e1", Unsigned32, Ro, None)])
        .at(0x1003, 0)
        .default(u(0));
    assert_eq!(run(errs), "");
}

trips!(c110_sub_number_mismatch, "C110", record_2000().sub_number(4));
trips!(c111_sub0_type, "C111", record_2000().at(0x2000, 0).data_type(Unsigned16));
trips!(c112_sub0_value, "C112", record_2000().at(0x2000, 0).default(u(2)));
trips!(
    c113_sub_index_ff,
    "C113",
    record_2000()
        .sub(0xFF, "Structure", Unsigned32, Ro)
        .sub_number(4)
        .at(0x2000, 0)
        .default(u(0xFF))
);
trips!(
    c114_array_not_uniform,
    "C114",
    base().array(0x2001, "Table", &[(1, "a", Integer16, Rw, None), (2, "b", Integer32, Rw, None)],)
);
trips!(c115_sub_number_or_compact, "C115", record_2000().no_sub_number());
trips!(
    c116_var_with_subs,
    "C116",
    base().var(0x2002, "Var", Unsigned8, Rw).sub(1, "stray", Unsigned8, Rw)
);
trips!(c117_missing_sub0, "C117", record_2000().remove_sub(0x2000, 0).sub_number(2));

// C201–C208: values.

#[test]
fn values_within_limits_pass() {
    let d = base()
        .var(0x2000, "Speed", Integer16, Rw)
        .low(i(-100))
        .high(i(100))
        .default(i(-5))
        .var(0x2001, "Node-relative", Unsigned16, Rw)
        .default(node(0x100))
        .low(node(0x80))
        .high(node(0x200))
        .var(0x2002, "Flag", Boolean, Rw)
        .default(u(1));
    assert_eq!(run(d), "");
}

trips!(
    c201_value_out_of_type_range,
    "C201",
    base()
        .var(0x2000, "Small", Unsigned8, Rw)
        .default(u(300))
        .var(0x2001, "Neg", Unsigned16, Rw)
        .default(i(-1))
);
trips!(
    c202_limits_inverted,
    "C202",
    base().var(0x2000, "x", Integer16, Rw).low(i(10)).high(i(-10))
);
trips!(
    c203_value_outside_limits,
    "C203",
    base().var(0x2000, "x", Integer16, Rw).low(i(0)).high(i(10)).default(i(11)).param(i(-1))
);
trips!(
    c204_nodeid_value_out_of_range,
    "C204",
    base().var(0x2000, "x", Unsigned8, Rw).default(node(0xF0))
);
trips!(c205_missing_mandatory_object, "C205", base().remove(0x1001));
trips!(
    c206_wrong_object_type,
    "C206",
    base().remove(0x1017).var(0x1017, "Producer heartbeat time", Unsigned32, Rw)
);
trips!(
    c207_identity_mismatch,
    "C207",
    base().with(|d| {
        d.device_info.vendor_number = Some(Spanned::synthetic(0x1234));
        d.device_info.product_number = Some(Spanned::synthetic(0x43));
    })
);
trips!(c208_limits_on_non_numeric, "C208", base().var(0x2000, "Name", VisibleString, Ro).low(u(0)));
