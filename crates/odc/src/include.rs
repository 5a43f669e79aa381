//! `include_od!`: the code `odc-build` wrote into `OUT_DIR`.

/// Includes the module `odc-build` generated for a device, by module name:
/// `pub mod lxm23a { odc::include_od!("lxm23a"); }` is
/// `include!(concat!(env!("OUT_DIR"), "/lxm23a.rs"))`.
#[macro_export]
macro_rules! include_od {
    ($name:literal) => {
        include!(concat!(env!("OUT_DIR"), "/", $name, ".rs"));
    };
}
