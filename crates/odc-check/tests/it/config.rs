//! Levels, strict mode and per-object allowances applied to diagnostics.
#![allow(clippy::unwrap_used, clippy::expect_used, clippy::panic, missing_docs)]

use crate::common;

use common::*;
use odc_check::{Config, Level};

fn noisy() -> Dev {
    // C201 (error) on 0x2000 and on 0x2001; C206 (warning) on 0x1017.
    base()
        .var(0x2000, "a", Unsigned8, Rw)
        .default(u(300))
        .record(0x2001, "b", &[(1, "x", Unsigned8, Rw, Some(u(256)))])
        .remove(0x1017)
        .var(0x1017, "Producer heartbeat time", Unsigned32, Rw)
}

#[test]
fn default_levels() {
    insta::assert_snapshot!(run(noisy()), @r"
    error[C201]: 0x2000 DefaultValue: 300 is out of the range of UNSIGNED8 (0..=255)
    error[C201]: 0x2001:01 DefaultValue: 256 is out of the range of UNSIGNED8 (0..=255)
    warning[C206]: 0x1017 is UNSIGNED32; CiA 301 makes it UNSIGNED16
    ");
}

#[test]
fn levels_by_rule_name_and_group() {
    let mut c = Config::in_registry(odc_check::rules());
    c.set_level("value-out-of-type-range", Level::Warn).unwrap();
    c.set_level("cia301", Level::Deny).unwrap();
    insta::assert_snapshot!(run_with(noisy(), &c), @r"
    warning[C201]: 0x2000 DefaultValue: 300 is out of the range of UNSIGNED8 (0..=255)
    warning[C201]: 0x2001:01 DefaultValue: 256 is out of the range of UNSIGNED8 (0..=255)
    error[C206]: 0x1017 is UNSIGNED32; CiA 301 makes it UNSIGNED16
    ");
    c.set_level("C201", Level::Allow).unwrap();
    insta::assert_snapshot!(run_with(noisy(), &c), @"error[C206]: 0x1017 is UNSIGNED32; CiA 301 makes it UNSIGNED16");
}

#[test]
fn strict_turns_warnings_into_errors() {
    let mut c = Config::in_registry(odc_check::rules());
    c.strict(true);
    let out = run_with(noisy(), &c);
    assert!(!out.contains("warning"), "{out}");
    assert!(out.contains("error[C206]"), "{out}");
}

#[test]
fn allowances_per_object_and_sub() {
    let c = Config::from_toml_in(
        "[allow-object]\nC201 = [\"0x2000\", \"0x2001:1\"]\n",
        odc_check::rules(),
    )
    .unwrap();
    insta::assert_snapshot!(run_with(noisy(), &c), @"warning[C206]: 0x1017 is UNSIGNED32; CiA 301 makes it UNSIGNED16");
    // A sub-index selects only that sub-object.
    let c = Config::from_toml_in(
        "[allow-object]\nvalue-out-of-type-range = [\"2001:2\"]\n",
        odc_check::rules(),
    )
    .unwrap();
    assert!(run_with(noisy(), &c).contains("0x2001:01"));
    // A group allowance covers every rule of the group.
    let c = Config::from_toml_in("[allow-object]\ncia301 = [\"0x1017\"]\n", odc_check::rules())
        .unwrap();
    assert!(!run_with(noisy(), &c).contains("C206"));
}
