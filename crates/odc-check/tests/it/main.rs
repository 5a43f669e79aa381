//! `odc-check`'s integration tests as one binary (one link, one file on disk: #33); each
//! module was a test file of its own. One module's tests:
//! `cargo test -p odc-check --test it MODULE::`.

mod common;
mod config;
mod fixtures;
mod rules;
