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
