//! `odc-tests-corpus`'s integration tests as one binary (one link, one file on disk: #33); each
//! module was a test file of its own. One module's tests:
//! `cargo test -p odc-tests-corpus --test it MODULE::`.

mod check;
mod convert;
mod diff;
mod eds;
mod esi;
mod esi_to_eds;
mod process_image;
mod sii;
mod xdd;
mod xdd_pairs;
