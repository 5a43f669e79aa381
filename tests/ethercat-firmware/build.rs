//! Generates the slave side of the device (`esi/servoone.xml`, or the ESI that
//! `ODC_FIRMWARE_ESI` names: tests/slave-size/soes.sh builds SOES's demo device that way) as
//! module `device`, and what its ESI says of the sync managers and mailbox as the stack's
//! `Config` (`esi_config.rs`); for a bare-metal ARM target, also hands the firmware examples
//! their memory layout (`memory.x`) and cortex-m-rt's linker script.

use std::fmt::Write as _;
use std::path::{Path, PathBuf};

use odc_model::ethercat::SmUsage;

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let manifest = Path::new(env!("CARGO_MANIFEST_DIR"));
    let root = manifest.join("../..");
    let out = PathBuf::from(std::env::var("OUT_DIR")?);
    let target = std::env::var("TARGET")?;
    if target.starts_with("thumbv") && target.contains("-none-") {
        std::fs::copy(manifest.join("memory.x"), out.join("memory.x"))?;
        println!("cargo:rustc-link-search={}", out.display());
        println!("cargo:rustc-link-arg-examples=-Tlink.x");
        println!("cargo:rerun-if-changed=memory.x");
    }
    println!("cargo:rerun-if-env-changed=ODC_FIRMWARE_ESI");
    let esi = std::env::var_os("ODC_FIRMWARE_ESI")
        .map_or_else(|| root.join("esi/servoone.xml"), PathBuf::from);
    odc_build::Config::new()
        .device(&esi)
        .module_name("device")
        .role(odc_build::Role::Slave)
        .compile()?;
    let loaded = odc_pipeline::load(&esi, &odc_pipeline::Options::new())?;
    let device = loaded.device()?;
    let ecat = device.ethercat.as_deref().ok_or("not an EtherCAT device")?;
    std::fs::write(out.join("esi_config.rs"), config(device, ecat))?;
    Ok(())
}

/// The `SYNC_MANAGERS` and `CONFIG` of the ESI, as Rust.
fn config(device: &odc_model::Device, ecat: &odc_model::ethercat::EtherCat) -> String {
    let mut s = String::from("/// The ESI's `Sm` elements.\n");
    let _ = writeln!(s, "pub const SYNC_MANAGERS: [SmSpec; {}] = [", ecat.sync_managers.len());
    for sm in &ecat.sync_managers {
        let kind = match sm.usage {
            SmUsage::MBoxOut => "al::MBOX_OUT",
            SmUsage::MBoxIn => "al::MBOX_IN",
            SmUsage::Outputs => "al::OUTPUTS",
            SmUsage::Inputs => "al::INPUTS",
            _ => "0",
        };
        // Without `MaxSize`, the LAN9252's process RAM (4 KiB).
        let size = |v: Option<u32>, or: u32| v.unwrap_or(or).min(u32::from(u16::MAX));
        let _ = writeln!(
            s,
            "    SmSpec {{ number: {}, kind: {kind}, min: {}, max: {}, control: {:#04x} }},",
            sm.number,
            size(sm.min_size, 0),
            size(sm.max_size, 4096),
            sm.control_byte.as_ref().map_or(0, |c| c.value),
        );
    }
    s.push_str("];\n\n");
    // The mapping of PDOs on a sync manager without an assignment object (0x1C10 + n).
    let mut fixed = String::new();
    for sm in &ecat.sync_managers {
        if device.objects.contains_key(&(0x1C10 + u16::from(sm.number))) {
            continue;
        }
        for pdo in device.pdos.iter().filter(|p| p.sync_manager == Some(sm.number)) {
            for e in &pdo.entries {
                let index = if e.is_gap() { 0 } else { u32::from(e.index) };
                let value = index << 16 | u32::from(e.sub) << 8 | u32::from(e.bits);
                let _ = write!(fixed, "({}, {value:#010x}), ", sm.number);
            }
        }
    }
    let mailbox = ecat.mailbox.as_ref();
    let coe = mailbox.and_then(|m| m.coe.as_ref());
    let _ = write!(
        s,
        "/// The device as the stack serves it: CoE and FoE as the ESI's `Mailbox` says,\n\
         /// complete access as `CoE@CompleteAccess` says, the PDOs of sync managers without an\n\
         /// assignment object fixed, SDO Information from the generated `DESCRIPTION` as\n\
         /// `CoE@SdoInfo` says. Not served: BOOT.\n\
         pub const CONFIG: Config<'static> = Config {{\n    \
             sync_managers: &SYNC_MANAGERS,\n    \
             fixed: &[{fixed}],\n    \
             coe: {},\n    \
             complete_access: {},\n    \
             boot: false,\n    \
             foe: {},\n    \
             describe: {},\n\
         }};\n",
        coe.is_some(),
        coe.is_some_and(|c| c.complete_access),
        mailbox.is_some_and(|m| m.foe),
        if coe.is_some_and(|c| c.sdo_info) { "Some(&device::slave::DESCRIPTION)" } else { "None" },
    );
    s
}
