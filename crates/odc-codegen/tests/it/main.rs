//! `odc-codegen`'s integration tests as one binary (one link, one file on disk: #33); each
//! module was a test file of its own. One module's tests:
//! `cargo test -p odc-codegen --test it MODULE::`.

mod common;
mod names;
mod pdi;
mod schemes;
mod snapshots_rust;
