//! `odc dump`: the object-dictionary model, as JSON or YAML.

use std::path::PathBuf;
use std::process::ExitCode;

use odc_model::Sources;

use crate::input;

/// Print the object-dictionary model of a device file (all devices of an ESI).
#[derive(clap::Args)]
pub struct Args {
    /// EDS, DCF or ESI file.
    file: PathBuf,
    /// Output format.
    #[arg(long, value_enum, default_value_t)]
    format: DumpFormat,
    /// Only this device: `PRODUCT[:REVISION]` or a name (default: all).
    #[arg(long, value_name = "DEVICE")]
    device: Option<String>,
}

#[derive(Clone, Copy, Debug, Default, clap::ValueEnum)]
enum DumpFormat {
    #[default]
    Yaml,
    Json,
}

pub fn run(args: Args) -> anyhow::Result<ExitCode> {
    let mut sources = Sources::new();
    let loaded = input::load(&mut sources, &args.file)?;
    super::require_clean(&sources, &loaded.diagnostics)?;
    let devices = match &args.device {
        Some(spec) => std::slice::from_ref(input::select(&loaded.devices, Some(spec))?),
        None => loaded.devices.as_slice(),
    };
    let text = match (args.format, devices) {
        (DumpFormat::Yaml, [one]) => serde_norway::to_string(one)?,
        (DumpFormat::Yaml, many) => serde_norway::to_string(many)?,
        (DumpFormat::Json, [one]) => serde_json::to_string_pretty(one)? + "\n",
        (DumpFormat::Json, many) => serde_json::to_string_pretty(many)? + "\n",
    };
    super::out(&text)?;
    Ok(ExitCode::SUCCESS)
}
