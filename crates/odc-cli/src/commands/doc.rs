//! `odc doc`: a device's data sheet, as a self-contained HTML page and as Markdown.

use std::path::{Path, PathBuf};
use std::process::ExitCode;

use anyhow::Context;
use odc_model::Device;

use crate::input;

/// Which files to write.
#[derive(Clone, Copy, Debug, clap::ValueEnum)]
pub enum DocFormat {
    /// One self-contained HTML page per device (PDO bit diagrams as inline SVG, a filter box).
    Html,
    /// One Markdown file per device.
    Md,
}

/// Write a data sheet of a device file: identity, capabilities, CiA 402 modes, every object,
/// every default PDO (and an EtherCAT device's process image) drawn bit by bit, the overlay's
/// parameter schemes and what `odc check` says, linked to the objects.
///
/// Writes `<stem>.html` and `<stem>.md` into the output directory (for a file with several
/// devices, `<stem>-<product code>-<revision>.*` each); `--format` writes one kind only.
#[derive(clap::Args)]
pub struct Args {
    /// EDS, DCF, XDD, XDC or ESI file.
    file: PathBuf,
    /// Directory to write into (created if missing).
    #[arg(short, long, value_name = "DIR", default_value = ".")]
    output: PathBuf,
    /// Write only this kind (both when absent).
    #[arg(long, value_enum)]
    format: Option<DocFormat>,
    /// Levels, configuration and `--device`.
    #[command(flatten)]
    levels: input::Levels,
}

pub fn run(args: Args) -> anyhow::Result<ExitCode> {
    let loaded = input::load(&args.file, &args.levels)?;
    super::gate(&loaded)?;
    std::fs::create_dir_all(&args.output)
        .with_context(|| format!("cannot create {}", args.output.display()))?;
    let stem = args.file.file_stem().map_or("device".into(), |s| s.to_string_lossy().into_owned());
    let schemes = &loaded.codegen.scheme;
    let file_name = loaded.file_name();
    // Render everything first: nothing is written unless every file can be.
    let mut files = Vec::new();
    for dev in &loaded.devices {
        let name = if loaded.devices.len() == 1 { stem.clone() } else { device_stem(&stem, dev) };
        let single = loaded.devices.len() == 1;
        let diagnostics: Vec<_> =
            loaded.diagnostics.iter().filter(|d| single || concerns(d, dev)).cloned().collect();
        // The file's name, not its path: the sheet travels without the directory it was
        // made in.
        let input = odc_doc::Input {
            device: dev,
            file: &file_name,
            sources: Some(&loaded.sources),
            diagnostics: &diagnostics,
            schemes,
        };
        let sheet = odc_doc::sheet(&input);
        if !matches!(args.format, Some(DocFormat::Md)) {
            files.push((args.output.join(format!("{name}.html")), odc_doc::html::page(&sheet)));
        }
        if !matches!(args.format, Some(DocFormat::Html)) {
            files.push((
                args.output.join(format!("{name}.md")),
                odc_doc::markdown::markdown(&sheet),
            ));
        }
    }
    for (path, text) in &files {
        input::write_atomic(path, text.as_bytes())?;
    }
    let list: Vec<String> = files.iter().map(|(p, _)| display(p)).collect();
    super::out(&format!("{}\n", list.join("\n")))?;
    Ok(ExitCode::SUCCESS)
}

fn display(p: &Path) -> String {
    p.display().to_string()
}

/// `<stem>-<product code>-<revision>` for one device of a file with several.
fn device_stem(stem: &str, dev: &Device) -> String {
    let info = &dev.device_info;
    let code = info.product_number.as_ref().map_or(0, |v| v.value);
    let rev = info.revision_number.as_ref().map_or(0, |v| v.value);
    format!("{stem}-{code:08x}-{rev:08x}")
}

/// Whether a diagnostic belongs on the sheet of this device of a file with several (an ESI):
/// its primary label lies between the first and the last of the device's objects and PDOs in
/// the text, or it has no label.
fn concerns(d: &odc_model::Diagnostic, dev: &Device) -> bool {
    let Some(span) = d.primary_span() else { return true };
    let spans = dev.objects.values().map(|o| o.span).chain(dev.pdos.iter().map(|p| p.span));
    let inside = spans.filter(|s| s.file == span.file && s.end > s.start);
    let (lo, hi) = inside.fold((u32::MAX, 0), |(lo, hi), s| (lo.min(s.start), hi.max(s.end)));
    lo <= span.start && span.start <= hi
}
