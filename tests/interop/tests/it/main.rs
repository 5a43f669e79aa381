//! `odc-tests-interop`'s integration tests as one binary (one link, one file on disk: #33); each
//! module was a test file of its own. One module's tests:
//! `cargo test -p odc-tests-interop --test it MODULE::`.

mod block;
mod conformance;
mod lss;
mod node;
mod python;
