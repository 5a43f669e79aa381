//! `odc-esi`'s integration tests as one binary (one link, one file on disk: #33); each
//! module was a test file of its own. One module's tests:
//! `cargo test -p odc-esi --test it MODULE::`.

mod coe_implied;
mod ethercat_extras;
mod fixtures;
mod object_data;
