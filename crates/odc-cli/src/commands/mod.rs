//! One module per subcommand: its arguments and its `run`.

/// `eprintln!` that ignores a closed standard error ([`err`]): for servers and long runs.
macro_rules! elog {
    ($($arg:tt)*) => {
        $crate::commands::err(&format!("{}\n", format_args!($($arg)*)))
    };
}

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
    /// When the output is a terminal, unless `NO_COLOR` is set (`CLICOLOR_FORCE` forces it).
    #[default]
    Auto,
    Always,
    Never,
}

impl Color {
    /// Whether to colour what goes to `stream`: `Auto` follows the conventions through
    /// `anstream` (NO_COLOR, CLICOLOR, CLICOLOR_FORCE, TERM, a terminal).
    pub fn on(self, stream: &impl anstream::stream::RawStream) -> bool {
        match self {
            Color::Auto => anstream::AutoStream::choice(stream) != anstream::ColorChoice::Never,
            Color::Always => true,
            Color::Never => false,
        }
    }
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

/// [`out`], flushed at once: a line a waiting client reads (`listening on …`).
pub fn out_flushed(text: &str) -> anyhow::Result<()> {
    use std::io::Write;
    out(text)?;
    match std::io::stdout().lock().flush() {
        Err(e) if e.kind() != std::io::ErrorKind::BrokenPipe => Err(e.into()),
        _ => Ok(()),
    }
}

/// Writes a progress or log line to standard error, ignoring a closed one: a server whose
/// log pipe was closed (`odc simulate … 2>&1 | head`) goes on serving instead of panicking as
/// `eprint!` would.
pub fn err(text: &str) {
    use std::io::Write;
    let _ = std::io::stderr().lock().write_all(text.as_bytes());
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
        DiagFormat::Human => diag::render_human(sources, diags, color.on(&std::io::stderr())),
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

/// The error gate of the commands that talk to a bus (`sdo`, `monitor`, `simulate`,
/// `conformance`): errors in full, as [`gate`] prints them, but the warnings as one count
/// with the command that shows them, not dozens of lines on every call.
pub fn gate_bus(loaded: &odc_pipeline::Loaded) -> anyhow::Result<()> {
    let errors: Vec<Diagnostic> = loaded.errors().cloned().collect();
    print_diagnostics(&loaded.sources, &errors, DiagFormat::Human, Color::Auto)?;
    let n = loaded.warnings().count();
    if n > 0 {
        let plural = if n == 1 { "" } else { "s" };
        elog!(
            "{}: {n} warning{plural} (`odc check {}` shows them)",
            loaded.name,
            loaded.path.display()
        );
    }
    loaded.refuse(&loaded.diagnostics).map_err(|refused| HasErrors(refused).into())
}

/// [`gate`] over other diagnostics of the loaded file (those of a device derived from it).
pub fn gate_over(loaded: &odc_pipeline::Loaded, diagnostics: &[Diagnostic]) -> anyhow::Result<()> {
    let shown: Vec<Diagnostic> =
        diagnostics.iter().filter(|d| d.severity != Severity::Note).cloned().collect();
    print_diagnostics(&loaded.sources, &shown, DiagFormat::Human, Color::Auto)?;
    loaded.refuse(diagnostics).map_err(|refused| HasErrors(refused).into())
}
