//! Generates the code of every device file in `eds/` and `esi/` (role both, each with the
//! overlay beside it, as `odc-build` reads it by default), and refuses to build when a device
//! file is there that `DEVICES` (and so `src/main.rs`) does not include.

use std::path::Path;

/// Every device file of the repository and its module in `src/main.rs`.
const DEVICES: [(&str, &str); 6] = [
    ("eds/lenze-e94aycca.eds", "lenze_e94aycca"),
    ("eds/lexium-mdrive.eds", "lexium_mdrive"),
    ("eds/linmot-e1200.eds", "linmot_e1200"),
    ("eds/lxm23a.eds", "lxm23a"),
    ("eds/servoone.eds", "servoone"),
    ("esi/servoone.xml", "servoone_ecat"),
];

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("../..");
    for dir in ["eds", "esi"] {
        println!("cargo:rerun-if-changed={}", root.join(dir).display());
        for entry in std::fs::read_dir(root.join(dir))? {
            let name = entry?.file_name().to_string_lossy().into_owned();
            let device = [".eds", ".dcf", ".xml"].iter().any(|ext| name.ends_with(ext));
            let path = format!("{dir}/{name}");
            if device && !DEVICES.iter().any(|(file, _)| *file == path) {
                return Err(format!(
                    "{path} is not in tests/bin-warnings: add it to DEVICES in build.rs and a \
                     module for it to src/main.rs"
                )
                .into());
            }
        }
    }
    let mut config = odc_build::Config::new();
    config.role(odc_build::Role::Both);
    for (file, module) in DEVICES {
        config.device(root.join(file)).module_name(module);
    }
    config.compile()?;
    Ok(())
}
