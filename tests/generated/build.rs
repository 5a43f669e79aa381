//! Generates the code of the repository's device files (role both).

use std::path::Path;

fn main() -> Result<(), odc_build::Error> {
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("../..");
    let mut config = odc_build::Config::new();
    config.role(odc_build::Role::Both);
    for name in ["eds/lxm23a.eds", "eds/lexium-mdrive.eds"] {
        config.device(root.join(name));
    }
    config.device(root.join("crates/odc-codegen/tests/fixtures/mini-drive.eds"));
    config.device(root.join("esi/servoone.xml"));
    config.compile()
}
