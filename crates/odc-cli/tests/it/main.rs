//! `odc-cli`'s integration tests as one binary (one link, one file on disk: #33); each
//! module was a test file of its own. One module's tests:
//! `cargo test -p odc-cli --test it MODULE::`.

mod bench_tools;
mod cli;
mod conformance;
mod convert;
mod doc_diff;
mod gate;
mod sii;
