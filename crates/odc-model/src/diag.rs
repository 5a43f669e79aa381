//! Diagnostics: one type for every problem any stage finds, and its three renderings.
//!
//! A [`Diagnostic`] is plain data (severity, stable code, message, labelled spans, notes);
//! rendering happens at the edges: [`render_human`] (a source snippet with the offending key
//! underlined, via codespan-reporting), [`render_short`] (`path:line:col: error[CODE]: message`,
//! for build scripts and editors) and [`render_json`].

use codespan_reporting::diagnostic as cs;
use std::ops::Range;
use std::sync::OnceLock;

use codespan_reporting::files::{Error as FilesError, Files};
use codespan_reporting::term;
use serde::Serialize;

use crate::span::{FileId, Span};

/// How bad a problem is.
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord, Hash, Serialize)]
#[serde(rename_all = "lowercase")]
pub enum Severity {
    /// The file cannot be used as it is.
    Error,
    /// The file can be used, but something is probably wrong.
    Warning,
    /// Information.
    Note,
}

impl Severity {
    /// `error`, `warning` or `note`.
    pub fn as_str(self) -> &'static str {
        match self {
            Severity::Error => "error",
            Severity::Warning => "warning",
            Severity::Note => "note",
        }
    }
}

/// A span with a message. The primary label is the place the problem is; secondary ones give
/// context ("first defined here").
#[derive(Clone, Debug, PartialEq, Eq, Serialize)]
pub struct Label {
    /// Where.
    pub span: Span,
    /// What to say there (may be empty).
    pub message: String,
    /// Whether this is the main place.
    pub primary: bool,
}

/// One problem found in a file.
#[derive(Clone, Debug, PartialEq, Eq, Serialize)]
pub struct Diagnostic {
    /// How bad it is.
    pub severity: Severity,
    /// The stable code of the rule (e.g. `F104`), documented by `odc explain`.
    pub code: &'static str,
    /// One line saying what is wrong.
    pub message: String,
    /// Places in the source.
    pub labels: Vec<Label>,
    /// Further explanation or help, one item per note.
    pub notes: Vec<String>,
    /// The object the problem is about: index and, when it is about one sub-object, its
    /// sub-index. Used for per-object allowances (`odc.toml` `[allow-object]`).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub object: Option<(u16, Option<u8>)>,
}

impl Diagnostic {
    /// A diagnostic of `severity` with `code` and `message`, no labels yet.
    pub fn new(severity: Severity, code: &'static str, message: impl Into<String>) -> Self {
        Diagnostic {
            severity,
            code,
            message: message.into(),
            labels: Vec::new(),
            notes: Vec::new(),
            object: None,
        }
    }

    /// An error.
    pub fn error(code: &'static str, message: impl Into<String>) -> Self {
        Self::new(Severity::Error, code, message)
    }

    /// A warning.
    pub fn warning(code: &'static str, message: impl Into<String>) -> Self {
        Self::new(Severity::Warning, code, message)
    }

    /// Adds the primary label.
    pub fn with_label(mut self, span: Span, message: impl Into<String>) -> Self {
        self.labels.push(Label { span, message: message.into(), primary: true });
        self
    }

    /// Adds a secondary label.
    pub fn with_secondary(mut self, span: Span, message: impl Into<String>) -> Self {
        self.labels.push(Label { span, message: message.into(), primary: false });
        self
    }

    /// Adds a note.
    pub fn with_note(mut self, note: impl Into<String>) -> Self {
        self.notes.push(note.into());
        self
    }

    /// Says which object (and sub-object) the problem is about.
    pub fn with_object(mut self, index: u16, sub: Option<u8>) -> Self {
        self.object = Some((index, sub));
        self
    }

    /// The first primary label's span, if any.
    pub fn primary_span(&self) -> Option<Span> {
        self.labels.iter().find(|l| l.primary && !l.span.is_dummy()).map(|l| l.span)
    }

    /// Whether this is an error.
    pub fn is_error(&self) -> bool {
        self.severity == Severity::Error
    }
}

/// Sorts diagnostics by file, position and code, so output and snapshots are stable.
///
/// Stable. Front-ends mostly produce diagnostics in file order already: that case is one pass,
/// otherwise each key is computed once (not once per comparison).
pub fn sort(diags: &mut [Diagnostic]) {
    fn key(d: &Diagnostic) -> (FileId, u32, &'static str) {
        let s = d.primary_span().unwrap_or(Span::DUMMY);
        (s.file, s.start, d.code)
    }
    if !diags.is_sorted_by_key(key) {
        diags.sort_by_cached_key(key);
    }
}

/// A rule's description, for the registry and `odc explain`.
#[derive(Clone, Copy, Debug, Serialize)]
pub struct RuleInfo {
    /// Stable code, e.g. `F104`.
    pub code: &'static str,
    /// kebab-case name, e.g. `invalid-number`.
    pub name: &'static str,
    /// Group: `format`, `cia301`, `cia402` or `etg`.
    pub group: &'static str,
    /// Default severity.
    pub default: Severity,
    /// One-line summary.
    pub summary: &'static str,
    /// Long explanation: what is checked, why it matters, how to fix it, spec reference.
    pub explanation: &'static str,
}

/// The source files diagnostics point into, by [`FileId`].
///
/// Line starts are computed lazily, the first time a position in the file is resolved: most
/// files parsed produce no diagnostic that needs one.
#[derive(Default)]
pub struct Sources {
    files: Vec<SourceFile>,
}

struct SourceFile {
    name: String,
    text: String,
    line_starts: OnceLock<Vec<usize>>,
}

impl SourceFile {
    fn line_starts(&self) -> &[usize] {
        self.line_starts.get_or_init(|| {
            let bytes = self.text.as_bytes();
            let mut starts = Vec::with_capacity(memchr::memchr_iter(b'\n', bytes).count() + 1);
            starts.push(0);
            starts.extend(memchr::memchr_iter(b'\n', bytes).map(|i| i + 1));
            starts
        })
    }

    /// Start of line `line` (the text's length for the line after the last).
    fn line_start(&self, line: usize) -> Result<usize, FilesError> {
        let starts = self.line_starts();
        match line.cmp(&starts.len()) {
            std::cmp::Ordering::Less => Ok(starts[line]),
            std::cmp::Ordering::Equal => Ok(self.text.len()),
            std::cmp::Ordering::Greater => {
                Err(FilesError::LineTooLarge { given: line, max: starts.len() - 1 })
            }
        }
    }
}

impl<'a> Files<'a> for Sources {
    type FileId = usize;
    type Name = &'a str;
    type Source = &'a str;

    fn name(&'a self, id: usize) -> Result<&'a str, FilesError> {
        self.files.get(id).map(|f| f.name.as_str()).ok_or(FilesError::FileMissing)
    }

    fn source(&'a self, id: usize) -> Result<&'a str, FilesError> {
        self.files.get(id).map(|f| f.text.as_str()).ok_or(FilesError::FileMissing)
    }

    fn line_index(&'a self, id: usize, byte_index: usize) -> Result<usize, FilesError> {
        let f = self.files.get(id).ok_or(FilesError::FileMissing)?;
        Ok(f.line_starts().binary_search(&byte_index).unwrap_or_else(|next| next - 1))
    }

    fn line_range(&'a self, id: usize, line_index: usize) -> Result<Range<usize>, FilesError> {
        let f = self.files.get(id).ok_or(FilesError::FileMissing)?;
        Ok(f.line_start(line_index)?..f.line_start(line_index + 1)?)
    }
}

/// A 1-based line and column (column counted in characters).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize)]
pub struct LineCol {
    /// Line, from 1.
    pub line: usize,
    /// Column, from 1.
    pub column: usize,
}

impl Sources {
    /// An empty set.
    pub fn new() -> Self {
        Self::default()
    }

    /// Adds a file's (decoded) text under a display name.
    pub fn add(&mut self, name: impl Into<String>, text: impl Into<String>) -> FileId {
        self.files.push(SourceFile {
            name: name.into(),
            text: text.into(),
            line_starts: OnceLock::new(),
        });
        FileId(self.files.len() as u32 - 1)
    }

    /// The name of a file.
    pub fn name(&self, file: FileId) -> Option<&str> {
        self.files.get(file.0 as usize).map(|f| f.name.as_str())
    }

    /// The text of a file.
    pub fn text(&self, file: FileId) -> Option<&str> {
        self.files.get(file.0 as usize).map(|f| f.text.as_str())
    }

    /// Line and column of the start of `span`.
    pub fn line_col(&self, span: Span) -> Option<LineCol> {
        let loc = self.location(span.file.0 as usize, span.start as usize).ok()?;
        Some(LineCol { line: loc.line_number, column: loc.column_number })
    }

    fn to_codespan(&self, d: &Diagnostic) -> cs::Diagnostic<usize> {
        let severity = match d.severity {
            Severity::Error => cs::Severity::Error,
            Severity::Warning => cs::Severity::Warning,
            Severity::Note => cs::Severity::Note,
        };
        let labels = d
            .labels
            .iter()
            .filter(|l| !l.span.is_dummy() && self.text(l.span.file).is_some())
            .map(|l| {
                let style =
                    if l.primary { cs::LabelStyle::Primary } else { cs::LabelStyle::Secondary };
                cs::Label::new(style, l.span.file.0 as usize, l.span.range())
                    .with_message(&l.message)
            })
            .collect();
        cs::Diagnostic::new(severity)
            .with_code(d.code)
            .with_message(&d.message)
            .with_labels(labels)
            .with_notes(d.notes.clone())
    }

    fn emit(&self, d: &Diagnostic, config: &term::Config, color: bool) -> String {
        use term::termcolor::Buffer;
        let mut buffer = if color { Buffer::ansi() } else { Buffer::no_color() };
        // Labels are filtered to files in this set, so rendering cannot fail on a missing file;
        // should it fail anyway (a span past the end of the text), fall back to the bare message.
        match term::emit_to_write_style(&mut buffer, config, self, &self.to_codespan(d)) {
            Ok(()) => String::from_utf8_lossy(buffer.as_slice()).into_owned(),
            Err(_) => format!("{}[{}]: {}\n", d.severity.as_str(), d.code, d.message),
        }
    }
}

/// Renders diagnostics the way rustc does: header, source snippet, underlined span, notes.
pub fn render_human(sources: &Sources, diags: &[Diagnostic], color: bool) -> String {
    let config = term::Config::default();
    diags.iter().map(|d| sources.emit(d, &config, color)).collect::<Vec<_>>().join("\n")
}

/// Renders one line per diagnostic: `path:line:col: error[CODE]: message`.
pub fn render_short(sources: &Sources, diags: &[Diagnostic]) -> String {
    let mut out = String::new();
    for d in diags {
        if let Some(span) = d.primary_span()
            && let (Some(name), Some(lc)) = (sources.name(span.file), sources.line_col(span))
        {
            out.push_str(&format!("{name}:{}:{}: ", lc.line, lc.column));
        }
        out.push_str(&format!("{}[{}]: {}\n", d.severity.as_str(), d.code, d.message));
    }
    out
}

#[derive(Serialize)]
struct JsonLabel<'a> {
    file: Option<&'a str>,
    start: u32,
    end: u32,
    line: Option<usize>,
    column: Option<usize>,
    message: &'a str,
    primary: bool,
}

#[derive(Serialize)]
struct JsonDiagnostic<'a> {
    severity: Severity,
    code: &'a str,
    message: &'a str,
    labels: Vec<JsonLabel<'a>>,
    notes: &'a [String],
}

/// Renders diagnostics as a JSON array, with file names, lines and columns resolved.
pub fn render_json(sources: &Sources, diags: &[Diagnostic]) -> String {
    let items: Vec<JsonDiagnostic<'_>> = diags
        .iter()
        .map(|d| JsonDiagnostic {
            severity: d.severity,
            code: d.code,
            message: &d.message,
            notes: &d.notes,
            labels: d
                .labels
                .iter()
                .filter(|l| !l.span.is_dummy())
                .map(|l| {
                    let lc = sources.line_col(l.span);
                    JsonLabel {
                        file: sources.name(l.span.file),
                        start: l.span.start,
                        end: l.span.end,
                        line: lc.map(|x| x.line),
                        column: lc.map(|x| x.column),
                        message: &l.message,
                        primary: l.primary,
                    }
                })
                .collect(),
        })
        .collect();
    // Serialising plain structs of strings and numbers cannot fail.
    serde_json::to_string_pretty(&items).unwrap_or_else(|e| format!("[{{\"error\":\"{e}\"}}]"))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn sample() -> (Sources, Vec<Diagnostic>) {
        let mut sources = Sources::new();
        let text = "[1000]\nDataType=0x0007\nDefaultValue=0xZZ\n";
        let file = sources.add("dev.eds", text);
        let start = text.find("0xZZ").unwrap() as u32;
        let d = Diagnostic::error("F104", "`0xZZ` is not a number")
            .with_label(Span::new(file, start, start + 4), "expected an UNSIGNED32")
            .with_note("numbers are decimal, 0x-hex or 0-octal");
        (sources, vec![d])
    }

    #[test]
    fn short_form_has_path_line_and_column() {
        let (sources, diags) = sample();
        assert_eq!(
            render_short(&sources, &diags),
            "dev.eds:3:14: error[F104]: `0xZZ` is not a number\n"
        );
    }

    #[test]
    fn human_form_underlines_the_value() {
        let (sources, diags) = sample();
        let out = render_human(&sources, &diags, false);
        assert!(out.contains("error[F104]"), "{out}");
        assert!(out.contains("DefaultValue=0xZZ"), "{out}");
        assert!(out.contains("^^^^ expected an UNSIGNED32"), "{out}");
        assert!(out.contains("numbers are decimal"), "{out}");
    }

    #[test]
    fn json_form_resolves_positions() {
        let (sources, diags) = sample();
        let v: serde_json::Value = serde_json::from_str(&render_json(&sources, &diags)).unwrap();
        assert_eq!(v[0]["code"], "F104");
        assert_eq!(v[0]["labels"][0]["line"], 3);
        assert_eq!(v[0]["labels"][0]["column"], 14);
        assert_eq!(v[0]["labels"][0]["file"], "dev.eds");
    }
}
