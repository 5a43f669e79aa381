//! `odc-sim`'s integration tests as one binary (one link, one file on disk: #33); each
//! module was a test file of its own. One module's tests:
//! `cargo test -p odc-sim --test it MODULE::`.

mod domain_unicode;
mod drive_frames;
mod ethercat_coe;
mod ethercat_esc;
mod ethercat_spi;
mod ethercat_sweep_faults;
mod frames;
mod virtual_bus;
