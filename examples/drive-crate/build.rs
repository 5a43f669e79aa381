//! Generates the master side of the drive's device file: descriptors for every object, the PDO
//! structs, the CiA 402 process data and plan, and the vendor's keypad parameter scheme from
//! the overlay beside it (`lxm23a.odc.toml`).
//!
//! A published drive crate keeps its device file (and overlay) inside the crate, say in
//! `device/`; this one, in odc's workspace, reads the one odc ships.

fn main() -> Result<(), odc_build::Error> {
    let file = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../../eds/lxm23a.eds");
    odc_build::Config::new().role(odc_build::Role::Master).device(file).compile()
}
