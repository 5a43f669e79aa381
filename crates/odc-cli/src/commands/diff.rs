//! `odc diff`: what changed between two device descriptions, of any formats.

use std::path::{Path, PathBuf};
use std::process::ExitCode;

use odc_pipeline::{Level, Loaded, Options, Select};

use super::Color;

/// How the differences are printed.
#[derive(Clone, Copy, Debug, Default, clap::ValueEnum)]
pub enum DiffFormat {
    /// Grouped by object, `+` added, `-` removed, `~` changed.
    #[default]
    Human,
    /// A JSON array, one object per difference.
    Json,
}

/// Compare two device descriptions object by object: objects and sub-objects added and
/// removed; changes of name, type, access, PDO mapping, default and limits; default PDO
/// mappings and EtherCAT process images; identity and capabilities.
///
/// Exit status: 0 when the two are equal, 1 when they differ, 2 on error.
#[derive(clap::Args)]
pub struct Args {
    /// The first file (EDS, DCF, XDD, XDC or ESI).
    a: PathBuf,
    /// The second file (any of those formats; may be the first, with other devices).
    b: PathBuf,
    /// The device of the first file (for an ESI): `PRODUCT[:REVISION]` or a name.
    #[arg(long, value_name = "DEVICE")]
    device_a: Option<String>,
    /// The device of the second file.
    #[arg(long, value_name = "DEVICE")]
    device_b: Option<String>,
    /// Output format.
    #[arg(long, value_enum, default_value_t)]
    format: DiffFormat,
    /// Leave out names (objects, sub-objects, PDOs, vendor and product).
    #[arg(long)]
    ignore_names: bool,
    /// Leave out comments, descriptions, denotations and the file's own information.
    #[arg(long)]
    ignore_comments: bool,
    /// Leave out default and configured values.
    #[arg(long)]
    ignore_defaults: bool,
    /// Colour the human output.
    #[arg(long, value_enum, default_value_t)]
    color: Color,
    /// Rule levels for both files (on top of diff's own: the CiA and ETG groups allowed).
    #[command(flatten)]
    rules: crate::input::Rules,
}

pub fn run(args: Args) -> anyhow::Result<ExitCode> {
    let a = load(&args.a, args.device_a.as_deref(), &args.rules)?;
    let b = load(&args.b, args.device_b.as_deref(), &args.rules)?;
    let (da, db) = (one(&a, "--device-a")?, one(&b, "--device-b")?);
    let opts = odc_diff::Options {
        ignore_names: args.ignore_names,
        ignore_comments: args.ignore_comments,
        ignore_defaults: args.ignore_defaults,
    };
    let changes = odc_diff::diff(da, db, &opts);
    let text = match args.format {
        DiffFormat::Json => odc_diff::json(&changes) + "\n",
        DiffFormat::Human => {
            let color = args.color.on(&std::io::stdout());
            if changes.is_empty() {
                "no differences\n".to_owned()
            } else {
                let n = changes.len();
                format!(
                    "{}{n} difference{}\n",
                    odc_diff::human(&changes, da, db, color),
                    if n == 1 { "" } else { "s" }
                )
            }
        }
    };
    super::out(&text)?;
    Ok(if changes.is_empty() { ExitCode::SUCCESS } else { ExitCode::from(1) })
}

/// Reads a file for comparison. Only the front-end's rules gate it: a file whose text cannot
/// be read as a device description is refused, as it would be compared by what was lost; the
/// CiA and ETG rules say nothing about what changed, so they are not run as errors here
/// (unless `rules` asks for them).
fn load(path: &Path, device: Option<&str>, rules: &crate::input::Rules) -> anyhow::Result<Loaded> {
    let mut options = Options::new();
    for group in ["cia301", "cia402", "etg"] {
        options = options.level(group.to_owned(), Level::Allow);
    }
    let mut options = rules.apply(options);
    if let Some(spec) = device {
        options = options.select(Select::Spec(spec.to_owned()));
    }
    let loaded = odc_pipeline::load(path, &options)?;
    super::gate(&loaded)?;
    Ok(loaded)
}

/// The one device of a loaded file, or a usage error listing them.
fn one<'l>(loaded: &'l Loaded, flag: &str) -> anyhow::Result<&'l odc_model::Device> {
    match loaded.devices.as_slice() {
        [d] => Ok(d),
        [] => anyhow::bail!("{}: no device read", loaded.path.display()),
        many => anyhow::bail!(
            "{} describes {} devices; pick one with {flag}:\n{}",
            loaded.path.display(),
            many.len(),
            odc_pipeline::list_devices(many)
        ),
    }
}
