//! `odc check`: parse and check device files, print diagnostics.

use std::path::PathBuf;
use std::process::ExitCode;

use odc_model::diag;
use odc_pipeline::Loaded;

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
    /// Levels, configuration and `--device` (default: every device of each file).
    #[command(flatten)]
    levels: input::Levels,
    /// When to colour the output.
    #[arg(long, value_enum, default_value_t)]
    color: Color,
}

pub fn run(args: Args) -> anyhow::Result<ExitCode> {
    let all = load_all(&args.files, &args.levels).into_iter().collect::<Result<Vec<_>, _>>()?;
    let errors: usize = all.iter().map(|loaded| loaded.errors().count()).sum();
    if let DiagFormat::Json = args.format {
        let reports = all.iter().map(|l| (&l.sources, l.diagnostics.as_slice()));
        super::out(&(diag::render_json_many(reports) + "\n"))?;
        return Ok(if errors > 0 { ExitCode::from(1) } else { ExitCode::SUCCESS });
    }
    for loaded in &all {
        let diags = &loaded.diagnostics;
        let file_errors = loaded.errors().count();
        print_diagnostics(&loaded.sources, diags, args.format, args.color)?;
        let warnings = loaded.warnings().count();
        let plural = |n: usize| if n == 1 { "" } else { "s" };
        eprintln!(
            "{}: {file_errors} error{}, {warnings} warning{}",
            loaded.path.display(),
            plural(file_errors),
            plural(warnings)
        );
    }
    Ok(if errors > 0 { ExitCode::from(1) } else { ExitCode::SUCCESS })
}

/// Loads every file, on as many threads as there are cores, in the order given.
fn load_all(files: &[PathBuf], levels: &input::Levels) -> Vec<anyhow::Result<Loaded>> {
    use std::sync::Mutex;
    use std::sync::atomic::{AtomicUsize, Ordering};
    let threads = std::thread::available_parallelism().map_or(1, |n| n.get()).min(files.len());
    let next = AtomicUsize::new(0);
    let results: Mutex<Vec<Option<anyhow::Result<Loaded>>>> =
        Mutex::new(files.iter().map(|_| None).collect());
    std::thread::scope(|scope| {
        for _ in 0..threads {
            scope.spawn(|| {
                loop {
                    let i = next.fetch_add(1, Ordering::Relaxed);
                    let Some(path) = files.get(i) else { break };
                    let loaded = input::load(path, levels);
                    // A poisoned lock means another worker panicked; the scope re-raises that
                    // panic when it ends, so this result is not needed.
                    if let Ok(mut results) = results.lock()
                        && let Some(slot) = results.get_mut(i)
                    {
                        *slot = Some(loaded);
                    }
                }
            });
        }
    });
    let results = results.into_inner().unwrap_or_else(std::sync::PoisonError::into_inner);
    results
        .into_iter()
        .zip(files)
        .map(|(r, path)| {
            r.unwrap_or_else(|| Err(anyhow::anyhow!("{} was not checked", path.display())))
        })
        .collect()
}
