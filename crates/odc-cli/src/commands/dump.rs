//! `odc dump`: the object-dictionary model, as JSON or YAML.

use std::path::PathBuf;
use std::process::ExitCode;

use crate::input;

/// Print the object-dictionary model of a device file (all devices of an ESI).
#[derive(clap::Args)]
pub struct Args {
    /// EDS, DCF or ESI file.
    file: PathBuf,
    /// Output format.
    #[arg(long, value_enum, default_value_t)]
    format: DumpFormat,
    /// Levels, configuration and `--device` (default: every device).
    #[command(flatten)]
    levels: input::Levels,
}

#[derive(Clone, Copy, Debug, Default, clap::ValueEnum)]
enum DumpFormat {
    #[default]
    Yaml,
    Json,
}

pub fn run(args: Args) -> anyhow::Result<ExitCode> {
    let loaded = input::load(&args.file, &args.levels)?;
    super::gate(&loaded)?;
    let text = match (args.format, loaded.devices.as_slice()) {
        (DumpFormat::Yaml, [one]) => serde_norway::to_string(one)?,
        (DumpFormat::Yaml, many) => serde_norway::to_string(many)?,
        (DumpFormat::Json, [one]) => serde_json::to_string_pretty(one)? + "\n",
        (DumpFormat::Json, many) => serde_json::to_string_pretty(many)? + "\n",
    };
    super::out(&text)?;
    Ok(ExitCode::SUCCESS)
}
