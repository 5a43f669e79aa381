//! `odc check`: parse and check device files, print diagnostics.

use std::path::{Path, PathBuf};
use std::process::ExitCode;

use odc_model::diag;

use super::{Color, DiagFormat};
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
    let mut options = args.levels.options();
    // Nothing is generated: the source's fingerprint is not needed.
    options.source_hash = false;
    if let DiagFormat::Json = args.format {
        let all = parallel(&args.files, |path| Ok(odc_pipeline::load(path, &options)?))
            .into_iter()
            .collect::<anyhow::Result<Vec<_>>>()?;
        let errors: usize = all.iter().map(|loaded| loaded.errors().count()).sum();
        let reports = all.iter().map(|l| (&l.sources, l.diagnostics.as_slice()));
        super::out(&(diag::render_json_many(reports) + "\n"))?;
        return Ok(if errors > 0 { ExitCode::from(1) } else { ExitCode::SUCCESS });
    }
    // Each file is loaded and its report rendered on a worker; the reports are printed in the
    // order of the files.
    let reports = parallel(&args.files, |path| {
        let loaded = odc_pipeline::load(path, &options)?;
        let text = super::render(&loaded.sources, &loaded.diagnostics, args.format, args.color);
        Ok((loaded.errors().count(), loaded.warnings().count(), text))
    });
    let mut total = 0;
    for (path, report) in args.files.iter().zip(reports) {
        let (errors, warnings, text) = report?;
        total += errors;
        let plural = |n: usize| if n == 1 { "" } else { "s" };
        eprint!("{text}");
        eprintln!(
            "{}: {errors} error{}, {warnings} warning{}",
            path.display(),
            plural(errors),
            plural(warnings)
        );
    }
    Ok(if total > 0 { ExitCode::from(1) } else { ExitCode::SUCCESS })
}

/// `work` on every file, on as many threads as there are cores; the results in file order.
fn parallel<T: Send>(
    files: &[PathBuf],
    work: impl Fn(&Path) -> anyhow::Result<T> + Sync,
) -> Vec<anyhow::Result<T>> {
    use std::sync::Mutex;
    use std::sync::atomic::{AtomicUsize, Ordering};
    let threads = std::thread::available_parallelism().map_or(1, |n| n.get()).min(files.len());
    let next = AtomicUsize::new(0);
    let results: Mutex<Vec<Option<anyhow::Result<T>>>> =
        Mutex::new(files.iter().map(|_| None).collect());
    std::thread::scope(|scope| {
        for _ in 0..threads {
            scope.spawn(|| {
                loop {
                    let i = next.fetch_add(1, Ordering::Relaxed);
                    let Some(path) = files.get(i) else { break };
                    let result = work(path);
                    // A poisoned lock means another worker panicked; the scope re-raises that
                    // panic when it ends, so this result is not needed.
                    if let Ok(mut results) = results.lock()
                        && let Some(slot) = results.get_mut(i)
                    {
                        *slot = Some(result);
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
