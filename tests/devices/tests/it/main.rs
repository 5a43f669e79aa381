//! `odc-tests-devices`'s integration tests as one binary (one link, one file on disk: #33); each
//! module was a test file of its own. One module's tests:
//! `cargo test -p odc-tests-devices --test it MODULE::`.

mod common;
mod lenze;
mod lexium_mdrive;
mod lexium_mdrive_lss;
mod linmot;
mod lxm23a;
mod node_bench;
mod schemes;
mod servoone;
mod table;
