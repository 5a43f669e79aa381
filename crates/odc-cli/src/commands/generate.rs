//! `odc generate`: typed Rust for a device file.

use std::path::PathBuf;
use std::process::ExitCode;

use odc_model::diag;
use odc_pipeline::Role;

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
    #[command(flatten)]
    levels: input::Levels,
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
    let loaded = input::load(&args.file, &args.levels)?;
    super::gate(&loaded)?;
    let device = loaded.device()?;
    let role = match args.role {
        RoleArg::Master => Role::Master,
        RoleArg::Slave => Role::Slave,
        RoleArg::Both => Role::Both,
    };
    let code = match loaded.generate(device, role, &args.runtime_path) {
        Ok(code) => code,
        Err(diags) => {
            eprint!("{}", diag::render_human(&loaded.sources, &diags, false));
            return Ok(ExitCode::from(1));
        }
    };
    let what = format!("{} objects, {} PDOs", device.objects.len(), device.pdos.len());
    match &args.output {
        Some(path) => {
            input::write_atomic(path, code.as_bytes())?;
            eprintln!("wrote {}: {what}", path.display());
        }
        None => {
            super::out(&code)?;
            eprintln!("generated {}: {what}", loaded.file_name());
        }
    }
    Ok(ExitCode::SUCCESS)
}
