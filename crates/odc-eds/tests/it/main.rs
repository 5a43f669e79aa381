//! `odc-eds`'s integration tests as one binary (one link, one file on disk: #33); each
//! module was a test file of its own. One module's tests:
//! `cargo test -p odc-eds --test it MODULE::`.

mod diagnostics;
mod fuzz_regressions;
mod round_trip;
mod snapshots;
