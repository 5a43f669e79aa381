//! `odc-tests-generated`'s integration tests as one binary (one link, one file on disk: #33); each
//! module was a test file of its own. One module's tests:
//! `cargo test -p odc-tests-generated --test it MODULE::`.

mod allowed_values;
mod cia402_typed;
mod coe_implied;
mod drive_sim;
mod initial_image;
mod master;
mod mini_drive;
mod pdi;
mod read_back;
mod roundtrip;
