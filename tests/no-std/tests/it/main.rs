//! `odc-tests-no-std`'s integration tests as one binary (one link, one file on disk: #33); each
//! module was a test file of its own. One module's tests:
//! `cargo test -p odc-tests-no-std --test it MODULE::`.

mod device_type;
mod readme;
