//! Generates the slave side of `eds/lxm23a.eds`.

use std::path::Path;

fn main() -> Result<(), odc_build::Error> {
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("../..");
    odc_build::Config::new()
        .device(root.join("eds/lxm23a.eds"))
        .role(odc_build::Role::Slave)
        .compile()
}
