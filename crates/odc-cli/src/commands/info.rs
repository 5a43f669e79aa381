//! `odc info`: what a device file describes, at a glance.

use std::path::PathBuf;
use std::process::ExitCode;

use odc_model::{Device, Direction, Value};

use crate::input;

/// Summarise a device file: identity, object counts, default PDO mappings.
///
/// A file with several devices (an ESI with many products or revisions) is listed one line per
/// device unless `--device` picks one.
#[derive(clap::Args)]
pub struct Args {
    /// EDS, DCF or ESI file, or an SII EEPROM image (`.bin`); `-` reads standard input.
    file: PathBuf,
    /// Levels, configuration and `--device`.
    #[command(flatten)]
    levels: input::Levels,
}

pub fn run(args: Args) -> anyhow::Result<ExitCode> {
    // Read once: `/dev/stdin` or `-` cannot be read twice. An SII EEPROM image (`odc sii`'s
    // output) is read back instead.
    let (path, bytes) = input::read(&args.file)?;
    if super::sii::is_image(&path, &bytes) {
        return super::sii::info(&path, &bytes);
    }
    let loaded = input::load_bytes(&path, bytes, &args.levels)?;
    super::gate(&loaded)?;
    if loaded.devices.len() > 1 {
        super::out(&format!(
            "{} devices:\n{}",
            loaded.devices.len(),
            odc_pipeline::list_devices(&loaded.devices)
        ))?;
    } else {
        super::out(&summary(loaded.device()?))?;
    }
    Ok(ExitCode::SUCCESS)
}

fn hex(v: Option<u32>) -> String {
    v.map_or_else(|| "-".to_owned(), |v| format!("0x{v:08X}"))
}

fn summary(dev: &Device) -> String {
    use std::fmt::Write;
    let info = &dev.device_info;
    let mut out = String::new();
    let vendor = info.vendor_name.as_deref().map_or("-", String::as_str);
    let _ = writeln!(out, "{} ({vendor})", dev.name());
    let _ = writeln!(
        out,
        "  vendor {}  product {}  revision {}",
        hex(info.vendor_number.as_deref().copied()),
        hex(info.product_number.as_deref().copied()),
        hex(info.revision_number.as_deref().copied()),
    );
    let subs: usize = dev.objects.values().map(|o| o.subs.len()).sum();
    let _ = writeln!(out, "  {} objects, {subs} sub-objects", dev.objects.len());
    if !info.baud_rates.is_empty() {
        let rates: Vec<String> = info.baud_rates.iter().map(u32::to_string).collect();
        let _ = writeln!(out, "  bit rates (kbit/s): {}", rates.join(", "));
    }
    for pdo in &dev.pdos {
        let dir = match pdo.direction {
            Direction::Rx => "RPDO",
            Direction::Tx => "TPDO",
        };
        let cob = match &pdo.cob_id {
            Some(Value::NodeIdPlus(n)) => format!(" cob-id $NODEID+0x{n:X}"),
            Some(Value::Unsigned(n)) => format!(" cob-id 0x{n:X}"),
            _ => String::new(),
        };
        let _ = writeln!(
            out,
            "  {dir} 0x{:04X} \"{}\"{cob}, {} bits:",
            pdo.mapping_index,
            pdo.name,
            pdo.bits()
        );
        let mut offset = 0u32;
        for e in &pdo.entries {
            let name = match (dev.objects.get(&e.index), dev.sub(e.index, e.sub)) {
                _ if e.is_gap() => "(gap)".to_owned(),
                (Some(o), Some(s)) if o.kind.has_subs() => format!("{}.{}", o.name, s.name),
                (Some(o), Some(_)) => o.name.clone(),
                _ => "(missing object)".to_owned(),
            };
            let _ = writeln!(
                out,
                "    bit {offset:>3}+{:<2} 0x{:04X}:{:02X} {name}",
                e.bits, e.index, e.sub
            );
            offset += u32::from(e.bits);
        }
    }
    out
}
