//! Generates the code of the six device files of the manuals (role both), each with the
//! overlay beside it (quirk allowances and vendor parameter schemes).

use std::path::Path;

fn main() -> Result<(), odc_build::Error> {
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("../..");
    let mut config = odc_build::Config::new();
    config.role(odc_build::Role::Both);
    for name in [
        "eds/lxm23a.eds",
        "eds/lexium-mdrive.eds",
        "eds/servoone.eds",
        "eds/lenze-e94aycca.eds",
        "eds/linmot-e1200.eds",
    ] {
        config.device(root.join(name));
    }
    config.device(root.join("esi/servoone.xml")).module_name("servoone_ecat");
    config.compile()
}
