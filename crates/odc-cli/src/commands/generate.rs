//! `odc generate`: typed Rust for a device file.

use std::path::PathBuf;
use std::process::ExitCode;

use anyhow::Context;
use odc_build::odc_codegen::{self, Options, Role};
use odc_model::{Sources, diag};

use crate::input;

/// Generate typed Rust (descriptors, PDO structs, slave dictionary, master plan, and the vendor
/// parameter schemes of the overlay beside the file) from a device file.
#[derive(clap::Args)]
pub struct Args {
    /// EDS, DCF or ESI file.
    file: PathBuf,
    /// Which side of the bus to generate for.
    #[arg(long, value_enum, default_value_t = RoleArg::Both)]
    role: RoleArg,
    /// Output file; standard output when absent.
    #[arg(short, long)]
    output: Option<PathBuf>,
    /// For a file with several devices: `PRODUCT[:REVISION]` or a name (`odc info` lists them).
    #[arg(long, value_name = "DEVICE")]
    device: Option<String>,
    /// Path of the runtime crate in the generated code.
    #[arg(long, default_value = "::odc")]
    runtime_path: String,
}

#[derive(Clone, Copy, Debug, clap::ValueEnum)]
enum RoleArg {
    Master,
    Slave,
    Both,
}

pub fn run(args: Args) -> anyhow::Result<ExitCode> {
    let bytes = odc_build::read_device_file(&args.file)
        .with_context(|| format!("cannot read {}", args.file.display()))?;
    let mut sources = Sources::new();
    let loaded = input::load(&mut sources, &args.file)?;
    super::require_clean(&sources, &loaded.diagnostics)?;
    let device = input::select(&loaded.devices, args.device.as_deref())?;
    let opts = Options {
        role: match args.role {
            RoleArg::Master => Role::Master,
            RoleArg::Slave => Role::Slave,
            RoleArg::Both => Role::Both,
        },
        runtime_path: args.runtime_path,
        source_name: args
            .file
            .file_name()
            .map(|n| n.to_string_lossy().into_owned())
            .unwrap_or_default(),
        source_sha256: odc_build::sha256_hex(&bytes),
        overlay: input::codegen_overlay_for(&args.file)?,
    };
    let code = match odc_codegen::generate(device, &opts) {
        Ok(code) => code,
        Err(diags) => {
            eprint!("{}", diag::render_human(&sources, &diags, false));
            return Ok(ExitCode::from(1));
        }
    };
    match &args.output {
        Some(path) => input::write_atomic(path, code.as_bytes())?,
        None => super::out(&code)?,
    }
    Ok(ExitCode::SUCCESS)
}
