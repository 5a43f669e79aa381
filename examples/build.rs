//! Generates the code of the device files the examples drive (role both: the master side for
//! the controller, the slave side for the simulated drive), each with its overlay.

use std::path::Path;

fn main() -> Result<(), odc_build::Error> {
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("..");
    let mut config = odc_build::Config::new();
    config.role(odc_build::Role::Both);
    for name in
        ["eds/lxm23a.eds", "eds/lexium-mdrive.eds", "eds/servoone.eds", "eds/linmot-e1200.eds"]
    {
        config.device(root.join(name));
    }
    config.compile()
}
