//! `odc convert`: write a device file as EDS or DCF.

use std::path::PathBuf;
use std::process::ExitCode;

use odc_model::Format;

use crate::input;

/// Convert a device file: EDS ↔ DCF, a normalised EDS, or one device of an ESI as EDS.
///
/// The output format follows `--to`, else the extension of `-o`. Keys and sections odc does
/// not interpret are carried over. The output file is replaced only when writing succeeded.
#[derive(clap::Args)]
pub struct Args {
    /// EDS, DCF or ESI file.
    input: PathBuf,
    /// Output file; standard output when absent.
    #[arg(short, long)]
    output: Option<PathBuf>,
    /// Output format.
    #[arg(long, value_enum)]
    to: Option<Target>,
    #[command(flatten)]
    levels: input::Levels,
}

#[derive(Clone, Copy, Debug, clap::ValueEnum)]
enum Target {
    Eds,
    Dcf,
}

pub fn run(args: Args) -> anyhow::Result<ExitCode> {
    let target = match (args.to, &args.output) {
        (Some(Target::Eds), _) => Format::Eds,
        (Some(Target::Dcf), _) => Format::Dcf,
        (None, Some(out)) if out.extension().is_some_and(|e| e.eq_ignore_ascii_case("dcf")) => {
            Format::Dcf
        }
        _ => Format::Eds,
    };
    let loaded = input::load(&args.input, &args.levels)?;
    super::gate(&loaded)?;
    let device = loaded.device()?;
    let text = odc_eds::write(device, target);
    match &args.output {
        Some(path) => input::write_atomic(path, text.as_bytes())?,
        None => super::out(&text)?,
    }
    Ok(ExitCode::SUCCESS)
}
