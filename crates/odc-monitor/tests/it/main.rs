//! `odc-monitor`'s integration tests as one binary (one link, one file on disk: #33); each
//! module was a test file of its own. One module's tests:
//! `cargo test -p odc-monitor --test it MODULE::`.

mod decode;
mod manual_logs;
