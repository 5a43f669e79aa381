//! `odc`'s integration tests as one binary (one link, one file on disk: #33); each
//! module was a test file of its own. One module's tests:
//! `cargo test -p odc --test it MODULE::`.

mod asynch;
mod asynch_node;
mod asynch_socketcand;
mod derive;
mod node;
mod pdo_prop;
mod subdevice;
