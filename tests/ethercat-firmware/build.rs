//! Generates the slave side of `esi/servoone.xml`; for a bare-metal ARM target, also hands
//! the firmware examples their memory layout (`memory.x`) and cortex-m-rt's linker script.

use std::path::{Path, PathBuf};

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let manifest = Path::new(env!("CARGO_MANIFEST_DIR"));
    let root = manifest.join("../..");
    let target = std::env::var("TARGET")?;
    if target.starts_with("thumbv") && target.contains("-none-") {
        let out = PathBuf::from(std::env::var("OUT_DIR")?);
        std::fs::copy(manifest.join("memory.x"), out.join("memory.x"))?;
        println!("cargo:rustc-link-search={}", out.display());
        println!("cargo:rustc-link-arg-examples=-Tlink.x");
        println!("cargo:rerun-if-changed=memory.x");
    }
    odc_build::Config::new()
        .device(root.join("esi/servoone.xml"))
        .role(odc_build::Role::Slave)
        .compile()?;
    Ok(())
}
