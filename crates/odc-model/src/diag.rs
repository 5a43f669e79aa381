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

/// Longest message, label or note kept (bytes); longer ones are cut with `…`.
pub const MAX_MESSAGE: usize = 300;

/// Cuts `s` to [`MAX_MESSAGE`] bytes (at a character boundary) plus `…`: messages quote values
/// from the file, and a hostile file's value can be megabytes long.
fn clip(mut s: String) -> String {
    if s.len() > MAX_MESSAGE {
        let mut at = MAX_MESSAGE;
        while !s.is_char_boundary(at) {
            at -= 1;
        }
        s.truncate(at);
        s.push('…');
    }
    s
}

impl Diagnostic {
    /// A diagnostic of `severity` with `code` and `message`, no labels yet.
    pub fn new(severity: Severity, code: &'static str, message: impl Into<String>) -> Self {
        Diagnostic {
            severity,
            code,
            message: clip(message.into()),
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
        self.push_label(Label { span, message: clip(message.into()), primary: true });
        self
    }

    /// Appends `label`. The first one allocates room for two (a diagnostic rarely has more):
    /// `push` on an empty vector takes the general growth path, which costs a front-end that
    /// reports thousands of diagnostics more than the allocation itself.
    #[inline]
    fn push_label(&mut self, label: Label) {
        if self.labels.capacity() == 0 {
            self.labels = Vec::with_capacity(2);
        }
        self.labels.push(label);
    }

    /// Adds a secondary label.
    pub fn with_secondary(mut self, span: Span, message: impl Into<String>) -> Self {
        self.push_label(Label { span, message: clip(message.into()), primary: false });
        self
    }

    /// Adds a note.
    pub fn with_note(mut self, note: impl Into<String>) -> Self {
        self.notes.push(clip(note.into()));
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

/// Most diagnostics of one code a front-end keeps for one file (see [`Capped`]). The real
/// file with the most of one code has about 2,100 (empty values, F112).
pub const MAX_PER_CODE: usize = 5000;

/// Diagnostics as a front-end collects them: at most [`MAX_PER_CODE`] of each code.
///
/// Hostile input can have a problem on every line, and a diagnostic costs a few hundred bytes:
/// a 32 MiB file of two-byte stray lines would otherwise make 16 million of them (gigabytes,
/// and a report nobody reads). The first ones of each code (in the order found, which is file
/// order for the scanners) are kept and the rest only counted; [`Capped::finish`] adds one note
/// per capped code, under that code, saying how many were left out. Read access (`iter`,
/// `len`, indexing) goes through `Deref` to the kept ones.
#[derive(Debug, Default)]
pub struct Capped {
    list: Vec<Diagnostic>,
    /// Per code seen: how many were pushed, and the span of the first one left out.
    counts: Vec<(&'static str, usize, Span)>,
}

impl Capped {
    /// An empty list.
    pub fn new() -> Self {
        Self::default()
    }

    /// Adds `d`, or only counts it when [`MAX_PER_CODE`] of its code are kept already.
    pub fn push(&mut self, d: Diagnostic) {
        // Codes are `&'static str` constants: the same address nearly always, so that is
        // looked for first (comparing the text calls `memcmp` for every code seen). Codes in
        // `counts` are distinct, so both searches find the same entry.
        let found = self.counts.iter().position(|c| std::ptr::eq(c.0, d.code));
        let i = match found.or_else(|| self.counts.iter().position(|c| c.0 == d.code)) {
            Some(i) => i,
            None => {
                self.counts.push((d.code, 0, Span::DUMMY));
                self.counts.len() - 1
            }
        };
        let count = &mut self.counts[i];
        count.1 += 1;
        if count.1 <= MAX_PER_CODE {
            self.list.push(d);
        } else if count.1 == MAX_PER_CODE + 1 {
            count.2 = d.primary_span().unwrap_or(Span::DUMMY);
        }
    }

    /// Adds each of `diags` as [`Capped::push`] does.
    pub fn extend(&mut self, diags: impl IntoIterator<Item = Diagnostic>) {
        for d in diags {
            self.push(d);
        }
    }

    /// The kept diagnostics, plus one note per code that had more than [`MAX_PER_CODE`].
    pub fn finish(self) -> Vec<Diagnostic> {
        let mut list = self.list;
        for (code, n, span) in self.counts {
            if n > MAX_PER_CODE {
                let d = Diagnostic::new(
                    Severity::Note,
                    code,
                    format!(
                        "{} more [{code}] diagnostics not shown (at most {MAX_PER_CODE} per code)",
                        n - MAX_PER_CODE
                    ),
                );
                list.push(if span.is_dummy() { d } else { d.with_label(span, "the next one") });
            }
        }
        list
    }
}

impl std::ops::Deref for Capped {
    type Target = [Diagnostic];
    fn deref(&self) -> &[Diagnostic] {
        &self.list
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
    /// Characters before each [`CHAR_MARK`]-byte block, for columns on long lines.
    char_marks: OnceLock<Vec<usize>>,
}

/// Block size of [`SourceFile::chars_before`]'s table.
const CHAR_MARK: usize = 4096;

/// Whether `b` starts a character (is not a UTF-8 continuation byte).
fn starts_char(b: u8) -> bool {
    b & 0xC0 != 0x80
}

impl SourceFile {
    /// The number of characters before byte `at`: a table lookup and at most one block
    /// counted, so that resolving the column of each of thousands of diagnostics on one
    /// 10 MB line does not count the line each time.
    fn chars_before(&self, at: usize) -> usize {
        let bytes = self.text.as_bytes();
        let at = at.min(bytes.len());
        let marks = self.char_marks.get_or_init(|| {
            let mut marks = Vec::with_capacity(bytes.len() / CHAR_MARK + 1);
            let mut n = 0;
            for block in bytes.chunks(CHAR_MARK) {
                marks.push(n);
                n += block.iter().filter(|&&b| starts_char(b)).count();
            }
            marks.push(n);
            marks
        });
        let block = at / CHAR_MARK;
        let base = marks.get(block).copied().unwrap_or(0);
        base + bytes[block * CHAR_MARK..at].iter().filter(|&&b| starts_char(b)).count()
    }

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

    fn column_number(
        &'a self,
        id: usize,
        line_index: usize,
        byte_index: usize,
    ) -> Result<usize, FilesError> {
        let f = self.files.get(id).ok_or(FilesError::FileMissing)?;
        let start = f.line_start(line_index)?;
        let end = byte_index.min(f.line_start(line_index + 1)?).max(start);
        // A line of usual length is counted directly; only a long one uses the table of
        // character counts, which costs a pass over the whole file to build.
        if end - start <= CHAR_MARK {
            let line = f.text.as_bytes().get(start..end).unwrap_or_default();
            return Ok(line.iter().filter(|&&b| starts_char(b)).count() + 1);
        }
        Ok(f.chars_before(end) - f.chars_before(start) + 1)
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
            char_marks: OnceLock::new(),
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
        let mut notes = Vec::new();
        let labels = d
            .labels
            .iter()
            .filter(|l| !l.span.is_dummy() && self.text(l.span.file).is_some())
            .filter(|l| {
                let Some(long) = self.long_line(l.span) else { return true };
                let at = match (self.name(l.span.file), self.line_col(l.span)) {
                    (Some(name), Some(lc)) => format!("{name}:{}:{}", lc.line, lc.column),
                    _ => String::new(),
                };
                let what = if l.message.is_empty() { "" } else { ": " };
                notes.push(format!(
                    "at {at}{what}{} (a line of {long} bytes, not shown)",
                    l.message
                ));
                false
            })
            .map(|l| {
                let style =
                    if l.primary { cs::LabelStyle::Primary } else { cs::LabelStyle::Secondary };
                cs::Label::new(style, l.span.file.0 as usize, l.span.range())
                    .with_message(&l.message)
            })
            .collect();
        notes.extend(d.notes.iter().cloned());
        cs::Diagnostic::new(severity)
            .with_code(d.code)
            .with_message(&d.message)
            .with_labels(labels)
            .with_notes(notes)
    }

    /// The length of the longest line `span` touches, when it is longer than
    /// [`MAX_SNIPPET_LINE`]: such lines (a minified XML file, a hostile 10 MB line) are not
    /// quoted, else every diagnostic on them would print the whole line.
    fn long_line(&self, span: Span) -> Option<usize> {
        let f = self.files.get(span.file.0 as usize)?;
        let starts = f.line_starts();
        let line_of = |at: usize| starts.binary_search(&at).unwrap_or_else(|next| next - 1);
        let (first, last) = (line_of(span.start as usize), line_of(span.end as usize));
        // codespan quotes the first and the last line of a multi-line label.
        let len = |l: usize| {
            let end = starts.get(l + 1).copied().unwrap_or(f.text.len());
            end - starts.get(l).copied().unwrap_or(end)
        };
        let longest = len(first).max(len(last));
        (longest > MAX_SNIPPET_LINE).then_some(longest)
    }

    /// Appends one rendered diagnostic to `out`.
    fn emit(&self, d: &Diagnostic, config: &term::Config, color: bool, out: &mut Vec<u8>) {
        use term::termcolor::{Ansi, NoColor};
        let start = out.len();
        let diagnostic = self.to_codespan(d);
        let written = if color {
            term::emit_to_write_style(&mut Ansi::new(&mut *out), config, self, &diagnostic)
        } else {
            term::emit_to_write_style(&mut NoColor::new(&mut *out), config, self, &diagnostic)
        };
        // Labels are filtered to files in this set, so rendering cannot fail on a missing file;
        // should it fail anyway (a span past the end of the text), fall back to the bare message.
        if written.is_err() {
            out.truncate(start);
            out.extend_from_slice(
                format!("{}[{}]: {}\n", d.severity.as_str(), d.code, d.message).as_bytes(),
            );
        }
    }
}

/// Longest source line quoted in a snippet by [`render_human`] (bytes); a label on a longer line
/// becomes a note with its position.
pub const MAX_SNIPPET_LINE: usize = 1000;

/// Renders diagnostics the way rustc does: header, source snippet, underlined span, notes.
pub fn render_human(sources: &Sources, diags: &[Diagnostic], color: bool) -> String {
    let config = term::Config::default();
    // One buffer for every diagnostic, a blank line between two.
    let mut out = Vec::new();
    for (i, d) in diags.iter().enumerate() {
        if i > 0 {
            out.push(b'\n');
        }
        sources.emit(d, &config, color, &mut out);
    }
    String::from_utf8(out).unwrap_or_else(|e| String::from_utf8_lossy(e.as_bytes()).into_owned())
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
    render_json_many([(sources, diags)])
}

/// [`render_json`] for the diagnostics of several loads (one [`Sources`] each), as one array in
/// the order given.
pub fn render_json_many<'a>(
    reports: impl IntoIterator<Item = (&'a Sources, &'a [Diagnostic])>,
) -> String {
    let items: Vec<JsonDiagnostic<'_>> = reports
        .into_iter()
        .flat_map(|(sources, diags)| diags.iter().map(move |d| (sources, d)))
        .map(|(sources, d)| JsonDiagnostic {
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

    #[test]
    fn columns_count_characters_on_long_lines() {
        let mut sources = Sources::new();
        let line = format!("{}é{}x", "a".repeat(5000), "ü".repeat(3000));
        let f = sources.add("f", format!("first\n{line}\n"));
        let at = |byte: usize| sources.line_col(Span::new(f, byte as u32, byte as u32));
        assert_eq!(at(0), Some(LineCol { line: 1, column: 1 }));
        let x = 6 + line.len() - 1;
        assert_eq!(at(x), Some(LineCol { line: 2, column: 5000 + 1 + 3000 + 1 }));
        assert_eq!(at(6 + 5000 + 2), Some(LineCol { line: 2, column: 5002 }));
        let text = sources.text(f).unwrap_or_default().to_owned();
        for byte in (0..text.len()).filter(|&b| text.is_char_boundary(b)).step_by(97) {
            let lc = at(byte).unwrap();
            let line_start = text[..byte].rfind('\n').map_or(0, |i| i + 1);
            assert_eq!(lc.column, text[line_start..byte].chars().count() + 1, "byte {byte}");
        }
    }

    #[test]
    fn columns_count_characters_on_short_lines() {
        let mut sources = Sources::new();
        let f = sources.add("f", "[2000]\nParameterName=Drehzahl öü=1\n".to_string());
        let at = |byte: u32| sources.line_col(Span::new(f, byte, byte));
        // `=1` after two 2-byte characters: byte 31 is the 29th character of line 2.
        assert_eq!(at(7 + 28), Some(LineCol { line: 2, column: 27 }));
        assert_eq!(at(7 + 29), Some(LineCol { line: 2, column: 28 }));
    }

    #[test]
    fn long_messages_are_clipped() {
        let value = "é".repeat(1000);
        let d = Diagnostic::error("F107", format!("`{value}` is not a number"))
            .with_label(Span::DUMMY, value.clone())
            .with_note(value);
        assert!(d.message.len() <= MAX_MESSAGE + 3 && d.message.ends_with('…'));
        assert!(d.message.starts_with("`éé"));
        assert!(d.labels[0].message.len() <= MAX_MESSAGE + 3);
        assert!(d.notes[0].len() <= MAX_MESSAGE + 3);
        let short = Diagnostic::error("F107", "short");
        assert_eq!(short.message, "short");
    }

    #[test]
    fn capped_keeps_the_first_of_each_code_and_counts_the_rest() {
        let mut c = Capped::new();
        for i in 0..(MAX_PER_CODE as u32 + 50) {
            c.push(
                Diagnostic::warning("F101", "stray").with_label(Span::new(FileId(0), i, i + 1), ""),
            );
        }
        c.push(Diagnostic::error("F107", "bad"));
        assert_eq!(c.len(), MAX_PER_CODE + 1);
        let all = c.finish();
        assert_eq!(all.len(), MAX_PER_CODE + 2);
        let note = &all[MAX_PER_CODE + 1];
        assert_eq!((note.severity, note.code), (Severity::Note, "F101"));
        assert_eq!(
            note.message,
            format!("50 more [F101] diagnostics not shown (at most {MAX_PER_CODE} per code)")
        );
        assert_eq!(note.primary_span().map(|s| s.start), Some(MAX_PER_CODE as u32));
    }

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
