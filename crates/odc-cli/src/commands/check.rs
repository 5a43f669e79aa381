//! `odc check`: parse and check device files, print diagnostics.

use std::path::PathBuf;
use std::process::ExitCode;

use odc_check::Level;
use odc_model::{Sources, diag};

use super::{Color, DiagFormat, print_diagnostics};
use crate::input;

/// Check device files against CiA 306/301/402 and ETG rules.
///
/// Exit status 0 when no diagnostic is at error level, 1 when one is, 2 when a file cannot be
/// read. Rule levels come from `--config`, else `<stem>.odc.toml` beside each file, else
/// `odc.toml` in its directory; the flags below override them.
#[derive(clap::Args)]
pub struct Args {
    /// EDS, DCF or ESI files.
    #[arg(required = true)]
    files: Vec<PathBuf>,
    /// Output format of the diagnostics.
    #[arg(long, value_enum, default_value_t)]
    format: DiagFormat,
    /// Turn every warning into an error.
    #[arg(long)]
    strict: bool,
    /// Make a rule or group (`format`, `cia301`, `cia402`, `etg`) an error.
    #[arg(long, short = 'D', value_name = "RULE|GROUP")]
    deny: Vec<String>,
    /// Make a rule or group a warning.
    #[arg(long, short = 'W', value_name = "RULE|GROUP")]
    warn: Vec<String>,
    /// Silence a rule or group.
    #[arg(long, short = 'A', value_name = "RULE|GROUP")]
    allow: Vec<String>,
    /// Checker configuration (odc.toml format).
    #[arg(long, value_name = "FILE")]
    config: Option<PathBuf>,
    /// Only this device of each file: `PRODUCT[:REVISION]` or a name (default: all).
    #[arg(long, value_name = "DEVICE")]
    device: Option<String>,
    /// When to colour the output.
    #[arg(long, value_enum, default_value_t)]
    color: Color,
}

pub fn run(args: Args) -> anyhow::Result<ExitCode> {
    let mut sources = Sources::new();
    let mut all = Vec::new();
    for path in &args.files {
        let mut config = input::config_for(args.config.as_deref(), path)?;
        for (names, level) in
            [(&args.allow, Level::Allow), (&args.warn, Level::Warn), (&args.deny, Level::Deny)]
        {
            for name in names {
                config.set_level(name, level).map_err(|e| anyhow::anyhow!("{e}"))?;
            }
        }
        config.strict(args.strict);
        let loaded = input::load(&mut sources, path)?;
        let mut front_end = loaded.diagnostics;
        let devices = match &args.device {
            Some(spec) => std::slice::from_ref(input::select(&loaded.devices, Some(spec))?),
            None => loaded.devices.as_slice(),
        };
        for device in devices {
            let diags = std::mem::take(&mut front_end);
            all.extend(config.apply(device, diags));
            all.extend(odc_check::check(device, &config));
        }
        // A file with no device left its front-end diagnostics unreported so far.
        all.extend(front_end);
    }
    diag::sort(&mut all);
    print_diagnostics(&sources, &all, args.format, args.color)?;
    let errors = all.iter().filter(|d| d.is_error()).count();
    if !matches!(args.format, DiagFormat::Json) {
        let warnings = all.iter().filter(|d| d.severity == odc_model::Severity::Warning).count();
        if errors + warnings > 0 {
            eprintln!("{errors} error(s), {warnings} warning(s)");
        }
    }
    Ok(if errors > 0 { ExitCode::from(1) } else { ExitCode::SUCCESS })
}
