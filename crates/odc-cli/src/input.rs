//! The options every command that reads a device file shares, and the one call that loads it
//! ([`odc_pipeline::load`]: the same pipeline as `odc-build` and `include_device!`).

use std::path::{Path, PathBuf};

use anyhow::Context;
use odc_pipeline::{Level, Loaded, Options, Select};

/// Rule levels and the device to work on: the flags of every command that reads one device
/// file (`check`, `generate`, `info`, `dump`, `convert`, `doc`, `sii`, `simulate`), so that each
/// refuses exactly the files `check` reports errors for.
#[derive(clap::Args, Clone, Debug, Default)]
pub struct Levels {
    /// `--strict`, `-D`, `-W`, `-A`, `--config`.
    #[command(flatten)]
    pub rules: Rules,
    /// For a file with several devices: `PRODUCT[:REVISION]` or a name (`odc info` lists them).
    #[arg(long, value_name = "DEVICE")]
    pub device: Option<String>,
}

/// Rule levels: the flags of every command that loads device files, including those that
/// name a device by other means (`sdo`/`monitor`'s `--node ID=FILE`, `diff`'s two files,
/// `conformance`). The refusal of a file names `-A CODE`; every such command takes it.
#[derive(clap::Args, Clone, Debug, Default)]
pub struct Rules {
    /// Turn every warning into an error.
    #[arg(long)]
    pub strict: bool,
    /// Make a rule or group (`format`, `cia301`, `cia402`, `etg`) an error.
    #[arg(long, short = 'D', value_name = "RULE|GROUP")]
    pub deny: Vec<String>,
    /// Make a rule or group a warning.
    #[arg(long, short = 'W', value_name = "RULE|GROUP")]
    pub warn: Vec<String>,
    /// Silence a rule or group.
    #[arg(long, short = 'A', value_name = "RULE|GROUP")]
    pub allow: Vec<String>,
    /// Checker configuration (odc.toml form), instead of the overlay beside the device file.
    #[arg(long, value_name = "FILE")]
    pub config: Option<PathBuf>,
}

impl Rules {
    /// `options` with these flags on top: `--config`, then `-A`, `-W`, `-D` (each later kind
    /// wins over an earlier one for the same rule, and all over levels `options` has), then
    /// `--strict`.
    pub fn apply(&self, mut options: Options) -> Options {
        options = options.strict(self.strict);
        options.config_file = self.config.clone();
        for (names, level) in
            [(&self.allow, Level::Allow), (&self.warn, Level::Warn), (&self.deny, Level::Deny)]
        {
            for name in names {
                options = options.level(name.clone(), level);
            }
        }
        options
    }
}

impl Levels {
    /// The pipeline's options: [`Rules::apply`] and the device selection.
    pub fn options(&self) -> Options {
        let mut options = self.rules.apply(Options::new());
        if let Some(spec) = &self.device {
            options = options.select(Select::Spec(spec.clone()));
        }
        options
    }
}

/// Reads and checks one device file (`-`: standard input). I/O, overlay and selection
/// problems are errors (exit 2); problems in the content are diagnostics.
pub fn load(path: &Path, levels: &Levels) -> anyhow::Result<Loaded> {
    let (path, bytes) = read(path)?;
    load_bytes(&path, bytes, levels)
}

/// [`load`] of a file already [`read`].
pub fn load_bytes(path: &Path, bytes: Vec<u8>, levels: &Levels) -> anyhow::Result<Loaded> {
    Ok(odc_pipeline::load_bytes(path, bytes, &levels.options())?)
}

/// How diagnostics name standard input.
const STDIN: &str = "<stdin>";

/// A device file's bytes, read once (so `/dev/stdin` or a pipe works), and the path that
/// names it: `-` reads standard input, named `<stdin>`.
pub fn read(path: &Path) -> anyhow::Result<(PathBuf, Vec<u8>)> {
    let io = |source| odc_pipeline::Error::Io { path: path.to_path_buf(), source };
    if path == Path::new("-") {
        let bytes = odc_pipeline::read_device(std::io::stdin().lock()).map_err(io)?;
        return Ok((PathBuf::from(STDIN), bytes));
    }
    let bytes = odc_pipeline::read_device_file(path).map_err(io)?;
    Ok((path.to_path_buf(), bytes))
}

/// Writes `contents` to `path` atomically ([`odc_build::write_atomic`]): into a temporary file
/// beside it, then renamed over it, so an interrupted or failed run never leaves a half-written
/// file.
pub fn write_atomic(path: &Path, contents: &[u8]) -> anyhow::Result<()> {
    odc_build::write_atomic(path, |w| w.write_all(contents))
        .with_context(|| format!("cannot write {}", path.display()))
}
