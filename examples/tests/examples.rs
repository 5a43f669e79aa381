//! Every example program runs to completion: its `main` is compiled into this test and
//! called, exactly as `cargo run --example <name>` would call it (the frames it prints are
//! captured by the test harness).

#[path = "../lxm23a.rs"]
mod lxm23a_example;

#[path = "../lexium_mdrive.rs"]
mod lexium_mdrive_example;

#[path = "../servoone.rs"]
mod servoone_example;

#[path = "../linmot.rs"]
mod linmot_example;

// Its `main` parses the command line, which a test does not have: the test calls `program`.
#[path = "../async_three_drives/main.rs"]
#[allow(dead_code)]
mod async_three_drives_example;

#[test]
fn lxm23a_moves_to_its_target() {
    lxm23a_example::main().unwrap();
}

#[test]
fn lexium_mdrive_moves_to_its_target() {
    lexium_mdrive_example::main().unwrap();
}

#[test]
fn servoone_moves_to_its_target() {
    servoone_example::main().unwrap();
}

#[test]
fn linmot_runs_its_control_word_sequence() {
    linmot_example::main().unwrap();
}

/// One second of the async program: every drive configured over SDO while the cycle runs,
/// then moving; each drive's position as its last TPDO and an SDO read tell it (the timing
/// figures it prints are not asserted: `cargo run --example async_three_drives` measures
/// them).
#[test]
fn async_three_drives_move_on_one_bus() {
    let reports =
        async_three_drives_example::program(&async_three_drives_example::Options::new(1)).unwrap();
    assert_eq!(reports.len(), 3);
    for r in reports {
        assert!(r.moves >= 1, "{r:?}");
        assert_eq!(r.tpdo_position, Some(r.position), "{r:?}");
    }
}
