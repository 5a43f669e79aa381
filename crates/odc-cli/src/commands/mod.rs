//! One module per subcommand: its arguments and its `run`.

pub mod check;
pub mod conformance;
pub mod convert;
pub mod diff;
pub mod doc;
pub mod dump;
pub mod explain;
pub mod generate;
pub mod info;
pub mod link;
pub mod lss;
pub mod monitor;
pub mod nmt;
pub mod sdo;
pub mod sii;
pub mod simulate;

use std::io::IsTerminal;

use odc_model::{Diagnostic, Severity, Sources, diag};

/// How diagnostics are printed.
#[derive(Clone, Copy, Debug, Default, clap::ValueEnum)]
pub enum DiagFormat {
    /// Source snippets with the offending key underlined, like rustc.
    #[default]
    Human,
    /// One line each: `path:line:col: error[CODE]: message`.
    Short,
    /// A JSON array of {severity, code, message, labels[{file, start, end, line, column,
    /// message, primary}], notes}.
    Json,
}

/// When to colour human output.
#[derive(Clone, Copy, Debug, Default, clap::ValueEnum)]
pub enum Color {
    /// When standard error is a terminal.
    #[default]
    Auto,
    Always,
    Never,
}

/// Writes to standard output. A closed pipe (`odc dump x.eds | head`) ends the output quietly
/// instead of panicking as `print!` would.
pub fn out(text: &str) -> anyhow::Result<()> {
    use std::io::Write;
    match std::io::stdout().lock().write_all(text.as_bytes()) {
        Err(e) if e.kind() != std::io::ErrorKind::BrokenPipe => Err(e.into()),
        _ => Ok(()),
    }
}

/// Prints diagnostics to standard error (human, short) or standard output (JSON).
pub fn print_diagnostics(
    sources: &Sources,
    diags: &[Diagnostic],
    format: DiagFormat,
    color: Color,
) -> anyhow::Result<()> {
    let text = render(sources, diags, format, color);
    match format {
        DiagFormat::Human | DiagFormat::Short => eprint!("{text}"),
        DiagFormat::Json => out(&(text + "\n"))?,
    }
    Ok(())
}

/// Diagnostics rendered in a format, as [`print_diagnostics`] prints them.
pub fn render(sources: &Sources, diags: &[Diagnostic], format: DiagFormat, color: Color) -> String {
    match format {
        DiagFormat::Human => {
            let color = match color {
                Color::Auto => std::io::stderr().is_terminal(),
                Color::Always => true,
                Color::Never => false,
            };
            diag::render_human(sources, diags, color)
        }
        DiagFormat::Short => diag::render_short(sources, diags),
        DiagFormat::Json => diag::render_json(sources, diags),
    }
}

/// A command stopped at the error gate: the file has error-level diagnostics (already
/// printed). Exit code 1, as for `odc check`, not 2 (usage or I/O).
#[derive(Debug)]
pub struct HasErrors(pub odc_pipeline::Refused);

impl std::fmt::Display for HasErrors {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        self.0.fmt(f)
    }
}

impl std::error::Error for HasErrors {}

/// The error gate of the commands that need a usable model (generate, info, dump, convert):
/// prints the file's errors and warnings, and fails with [`HasErrors`] when one is an error.
pub fn gate(loaded: &odc_pipeline::Loaded) -> anyhow::Result<()> {
    gate_over(loaded, &loaded.diagnostics)
}

/// [`gate`] over other diagnostics of the loaded file (those of a device derived from it).
pub fn gate_over(loaded: &odc_pipeline::Loaded, diagnostics: &[Diagnostic]) -> anyhow::Result<()> {
    let shown: Vec<Diagnostic> =
        diagnostics.iter().filter(|d| d.severity != Severity::Note).cloned().collect();
    print_diagnostics(&loaded.sources, &shown, DiagFormat::Human, Color::Auto)?;
    loaded.refuse(diagnostics).map_err(|refused| HasErrors(refused).into())
}
