//! The lossless layer: a CiA 306 INI file as sections, entries, comments and byte spans.
//!
//! A hand-written line scanner rather than `rust-ini` or `configparser`: those crates give
//! neither byte spans (needed for diagnostics that underline the exact key or value) nor the
//! original spelling of keys (they fold case), they drop comments, and they reject or silently
//! merge duplicate sections and keys. Real EDS files have all of these (see the corpus notes), so
//! the scanner keeps everything and leaves the judgement to the lowering.
//!
//! Design, for speed: the scanner walks the text with `memchr` for newlines, borrows every key,
//! value and name as a `&str` slice of the text (no allocation per line), and records positions
//! as `u32` byte offsets. Section lookup goes through a hash map keyed by the name compared
//! ASCII-case-insensitively (no lower-cased copies).
//!
//! Rules of the scanner:
//! - line endings LF, CRLF or a mix; a missing final newline is fine;
//! - a line whose first non-blank character is `;` or `#` is a comment line (`#` is not CiA 306
//!   but kacanopen and Synapticon files use it); comments are kept as [`Trivia`];
//! - a `;` or `#` *after* a value is **not** stripped here: `ParameterName=Motor #1` is a valid
//!   name. The lowering strips a trailing ` # ...` / ` ; ...` only from values that must be a
//!   number or a keyword and do not read as one otherwise (with a warning);
//! - `[name]` starts a section; text after the `]` is reported and ignored;
//! - `key=value` (first `=`), key and value trimmed of blanks; lines without `=` are reported
//!   and kept as trivia; git merge-conflict markers (`<<<<<<< x`, `=======`, `>>>>>>> y`) are
//!   trivia too, reported in one diagnostic for the whole file;
//! - keys before the first section go into [`RawFile::preamble`] and are reported;
//! - duplicate sections and duplicate keys are kept and reported; lookups answer the **last**
//!   occurrence (python `configparser(strict=False)` behaves the same, and a later line is the
//!   one an editor appended): [`RawFile::get_in`], [`RawFile::get`].
//! - entries and trivia of all sections live in two flat vectors ([`RawFile::entries`],
//!   [`RawFile::trivia`]); a [`Section`] holds ranges into them (no allocation per section).

use std::collections::HashMap;
use std::hash::{Hash, Hasher};

use odc_model::{Diagnostic, FileId, Span};

use crate::rules::codes;

/// A byte range in the text, `start..end`.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct Pos {
    /// First byte.
    pub start: u32,
    /// One past the last byte.
    pub end: u32,
}

impl Pos {
    /// The span of this range in `file`.
    pub fn span(self, file: FileId) -> Span {
        Span::new(file, self.start, self.end)
    }
}

/// One `key=value` line.
#[derive(Clone, Debug)]
pub struct Entry<'a> {
    /// The key as written (trimmed).
    pub key: &'a str,
    /// The value as written (trimmed; may be empty).
    pub value: &'a str,
    /// Where the key is.
    pub key_pos: Pos,
    /// Where the value is (empty range just after `=` when the value is empty).
    pub value_pos: Pos,
    /// The whole line without its line ending.
    pub line_pos: Pos,
}

/// What a non-entry line is.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum TriviaKind {
    /// `; ...` or `# ...`.
    Comment,
    /// Only blanks.
    Blank,
    /// Neither a comment, a header nor `key=value` (reported).
    Stray,
}

/// A line that is not an entry, with its place among the entries of its section.
#[derive(Clone, Debug)]
pub struct Trivia<'a> {
    /// What it is.
    pub kind: TriviaKind,
    /// The line text without its line ending.
    pub text: &'a str,
    /// The line.
    pub pos: Pos,
    /// How many entries of the section precede it.
    pub before: u32,
}

/// A section: header and the lines up to the next header.
#[derive(Clone, Debug)]
pub struct Section<'a> {
    /// The name as written, without brackets, trimmed. Empty for the preamble.
    pub name: &'a str,
    /// Where the name is.
    pub name_pos: Pos,
    /// The header line.
    pub header_pos: Pos,
    /// Text after the closing `]` (reported, ignored).
    pub after_header: Option<Pos>,
    /// Its entries in file order, duplicates included: a range of [`RawFile::entries`]
    /// (see [`RawFile::entries_of`]).
    pub entries: std::ops::Range<u32>,
    /// Its comments, blank and stray lines: a range of [`RawFile::trivia`].
    pub trivia: std::ops::Range<u32>,
    /// The next section with the same name (case-insensitive), if the name repeats.
    pub next_same: Option<u32>,
    /// Whether an earlier section has the same name.
    pub is_duplicate: bool,
}

impl<'a> Section<'a> {
    fn new(name: &'a str, name_pos: Pos, header_pos: Pos, entries: u32, trivia: u32) -> Self {
        Section {
            name,
            name_pos,
            header_pos,
            after_header: None,
            entries: entries..entries,
            trivia: trivia..trivia,
            next_same: None,
            is_duplicate: false,
        }
    }
}

/// A name compared and hashed ASCII-case-insensitively.
#[derive(Clone, Copy, Debug)]
struct Caseless<'a>(&'a str);

impl PartialEq for Caseless<'_> {
    fn eq(&self, other: &Self) -> bool {
        self.0.eq_ignore_ascii_case(other.0)
    }
}
impl Eq for Caseless<'_> {}
impl Hash for Caseless<'_> {
    fn hash<H: Hasher>(&self, state: &mut H) {
        // Eight bytes at a time, each word mixed into the hasher's state ([`FoldHasher`]).
        // `| 0x20` folds ASCII case (names equal ignoring ASCII case hash alike; other bytes may
        // collide, which `eq` sorts out). The bytes past the last whole word are read with
        // fixed-size loads (overlapping ones; which bytes land where depends only on the length,
        // so equal names still hash alike): copying a variable-length tail into a zeroed word
        // called `memcpy` and then stalled on reading the word back (the hottest instruction of
        // the section index).
        const CASE: u64 = 0x2020_2020_2020_2020;
        let b = self.0.as_bytes();
        let n = b.len();
        state.write_u64(n as u64);
        let mut i = 0;
        while i + 8 <= n {
            state.write_u64(word(b, i) | CASE);
            i += 8;
        }
        if i < n {
            let w = if n >= 8 {
                word(b, n - 8)
            } else if n >= 4 {
                u64::from(word32(b, 0)) | (u64::from(word32(b, n - 4)) << 32)
            } else {
                u64::from(b[0]) | (u64::from(b[n / 2]) << 8) | (u64::from(b[n - 1]) << 16)
            };
            state.write_u64(w | CASE);
        }
    }
}

/// Mixes each word into its state by a folded multiply (the high and low halves of the
/// 128-bit product xored): every input bit reaches every output bit. A plain 64-bit multiply
/// only carries bits upwards, so the low bits hashbrown picks the bucket from ignored the last
/// bytes of a word, and names such as `1A00sub1`..`1A00sub8` all probed from one bucket.
struct FoldHasher(u64);

impl FoldHasher {
    #[inline(always)]
    fn mix(&mut self, w: u64) {
        const K: u64 = 0x9E37_79B9_7F4A_7C15;
        let m = u128::from(self.0 ^ w) * u128::from(K);
        self.0 = (m as u64) ^ ((m >> 64) as u64);
    }
}

impl Hasher for FoldHasher {
    fn finish(&self) -> u64 {
        self.0
    }
    fn write(&mut self, bytes: &[u8]) {
        for &b in bytes {
            self.mix(u64::from(b));
        }
    }
    #[inline(always)]
    fn write_u64(&mut self, w: u64) {
        self.mix(w);
    }
}

/// Builds [`FoldHasher`]s that start from a random seed, one per map. With a fixed start a
/// file could be written whose section names or keys all hash alike (the mix is public, and
/// a name's second word can cancel what its first did), and the index would take quadratic
/// time; not knowing the seed, a file cannot aim at it. std's `RandomState` supplies the seed.
#[derive(Clone)]
struct Seeded(u64);

impl Seeded {
    fn new() -> Self {
        use std::hash::BuildHasher;
        Seeded(std::collections::hash_map::RandomState::new().hash_one(0u8))
    }
}

impl std::hash::BuildHasher for Seeded {
    type Hasher = FoldHasher;
    fn build_hasher(&self) -> FoldHasher {
        FoldHasher(self.0)
    }
}

/// A scanned file.
#[derive(Clone, Debug)]
pub struct RawFile<'a> {
    /// The text scanned.
    pub text: &'a str,
    /// The file id spans refer to.
    pub file: FileId,
    /// Lines before the first section header (entries there are reported).
    pub preamble: Section<'a>,
    /// Sections in file order, duplicates included.
    pub sections: Vec<Section<'a>>,
    /// All entries in file order; sections hold ranges of it.
    pub entries: Vec<Entry<'a>>,
    /// All comment, blank and stray lines in file order; sections hold ranges of it.
    pub trivia: Vec<Trivia<'a>>,
    index: HashMap<Caseless<'a>, (u32, u32), Seeded>,
}

impl<'a> RawFile<'a> {
    /// The entries of one section (not of its repeats).
    pub fn entries_of(&self, s: &Section<'a>) -> &[Entry<'a>] {
        self.entries.get(s.entries.start as usize..s.entries.end as usize).unwrap_or(&[])
    }

    /// The comment, blank and stray lines of one section.
    pub fn trivia_of(&self, s: &Section<'a>) -> &[Trivia<'a>] {
        self.trivia.get(s.trivia.start as usize..s.trivia.end as usize).unwrap_or(&[])
    }

    /// The last entry of section `s` (not of its repeats) whose key equals `key`
    /// ASCII-case-insensitively.
    pub fn get_in(&self, s: &Section<'a>, key: &str) -> Option<&Entry<'a>> {
        self.entries_of(s).iter().rev().find(|e| e.key.eq_ignore_ascii_case(key))
    }

    /// The first section named `name` (case-insensitive); follow [`Section::next_same`] or use
    /// [`RawFile::sections_named`] for repeats.
    pub fn section(&self, name: &str) -> Option<&Section<'a>> {
        let &(first, _) = self.index.get(&Caseless(name))?;
        self.sections.get(first as usize)
    }

    /// Every section named `name` (case-insensitive), in file order.
    pub fn sections_named(&self, name: &str) -> SameName<'_, 'a> {
        SameName { file: self, next: self.index.get(&Caseless(name)).map(|&(first, _)| first) }
    }

    /// The sections with the same name as `sections[first]`, starting there.
    pub fn chain(&self, first: u32) -> SameName<'_, 'a> {
        SameName { file: self, next: Some(first) }
    }

    /// The value of `key` in section `section`: the last occurrence over all sections of that
    /// name (duplicates: last wins).
    pub fn get(&self, section: &str, key: &str) -> Option<&Entry<'a>> {
        self.sections_named(section).filter_map(|s| self.get_in(s, key)).last()
    }
}

/// Iterator over the sections that share one name.
pub struct SameName<'f, 'a> {
    file: &'f RawFile<'a>,
    next: Option<u32>,
}

impl<'f, 'a> Iterator for SameName<'f, 'a> {
    type Item = &'f Section<'a>;
    fn next(&mut self) -> Option<Self::Item> {
        let s = self.file.sections.get(self.next? as usize)?;
        self.next = s.next_same;
        Some(s)
    }
}

/// Blanks the scanner trims around lines, keys and values (`\r` too: a lone CR before the
/// line end is not content).
#[inline]
fn is_blank(b: u8) -> bool {
    matches!(b, b' ' | b'\t' | b'\r' | 0x0B | 0x0C)
}

fn trim_pos(text: &str, start: usize, end: usize) -> (usize, usize) {
    let b = text.as_bytes();
    let mut s = start;
    while s < end && is_blank(b[s]) {
        s += 1;
    }
    (s, trim_end(b, s, end))
}

/// `end` moved back over blanks, not before `start`.
#[inline]
fn trim_end(b: &[u8], start: usize, mut end: usize) -> usize {
    while end > start && is_blank(b[end - 1]) {
        end -= 1;
    }
    end
}

const LO: u64 = 0x0101_0101_0101_0101;
const HI: u64 = 0x8080_8080_8080_8080;

/// The high bit of each byte of `w` that is zero. The lowest set bit is exact (borrows only
/// go upwards), which is all the searches below use.
#[inline]
fn zero_bytes(w: u64) -> u64 {
    w.wrapping_sub(LO) & !w & HI
}

#[inline]
fn word(hay: &[u8], i: usize) -> u64 {
    let mut chunk = [0u8; 8];
    chunk.copy_from_slice(&hay[i..i + 8]);
    u64::from_le_bytes(chunk)
}

#[inline]
fn word32(hay: &[u8], i: usize) -> u32 {
    let mut chunk = [0u8; 4];
    chunk.copy_from_slice(&hay[i..i + 4]);
    u32::from_le_bytes(chunk)
}

/// The first `needle` in `hay[from..]`, or `hay.len()`, 8 bytes at a time. Lines are short (16
/// bytes on average in the corpus): cheaper than a `memchr` call per line.
#[inline]
fn find_byte(hay: &[u8], from: usize, needle: u8) -> usize {
    let pat = LO * u64::from(needle);
    let mut i = from;
    while i + 8 <= hay.len() {
        let z = zero_bytes(word(hay, i) ^ pat);
        if z != 0 {
            return i + (z.trailing_zeros() / 8) as usize;
        }
        i += 8;
    }
    hay[i..].iter().position(|&b| b == needle).map_or(hay.len(), |j| i + j)
}

/// The first `=` or newline in `hay[from..]`, or `hay.len()`: one pass finds the end of a key
/// or learns that the line has none.
#[inline]
fn find_eq_or_nl(hay: &[u8], from: usize) -> usize {
    const EQ: u64 = LO * b'=' as u64;
    const NL: u64 = LO * b'\n' as u64;
    let mut i = from;
    while i + 8 <= hay.len() {
        let w = word(hay, i);
        let z = zero_bytes(w ^ EQ) | zero_bytes(w ^ NL);
        if z != 0 {
            return i + (z.trailing_zeros() / 8) as usize;
        }
        i += 8;
    }
    hay[i..].iter().position(|&b| b == b'=' || b == b'\n').map_or(hay.len(), |j| i + j)
}

/// The end of the line that ends at `nl`: before a `\r` there.
#[inline]
fn cut_cr(bytes: &[u8], line_start: usize, nl: usize) -> usize {
    if nl > line_start && bytes[nl - 1] == b'\r' { nl - 1 } else { nl }
}

fn pos(s: usize, e: usize) -> Pos {
    Pos { start: s as u32, end: e as u32 }
}

/// Scans `text` (at most 4 GiB; longer text is cut there) into sections and entries, pushing
/// problems to `diags`. Never fails.
pub fn scan<'a>(text: &'a str, file: FileId, diags: &mut odc_model::Capped) -> RawFile<'a> {
    let text = if text.len() > u32::MAX as usize {
        let mut cut = u32::MAX as usize;
        while !text.is_char_boundary(cut) {
            cut -= 1;
        }
        &text[..cut]
    } else {
        text
    };
    let bytes = text.as_bytes();
    let n = bytes.len();
    let mut preamble = Section::new("", Pos::default(), Pos::default(), 0, 0);
    // Sized from the line count (cheap with memchr): the entries never outgrow it, and with the
    // usual share of blank/comment lines and of headers (about one line in eight in the corpus)
    // the other two rarely grow. Growing used to copy the vectors, several times per file.
    let lines = memchr::memchr_iter(b'\n', bytes).count() + 1;
    let mut entries: Vec<Entry<'a>> = Vec::with_capacity(lines);
    let mut trivia: Vec<Trivia<'a>> = Vec::with_capacity(lines / 4 + 4);
    let mut sections: Vec<Section<'a>> = Vec::with_capacity(lines / 6 + 4);
    // Where the entries and trivia of the current section (the preamble first) start; its
    // ranges are written when the next header (or the end) closes it.
    let (mut cur_entries, mut cur_trivia) = (0u32, 0u32);
    // Git merge-conflict marker lines, reported in one diagnostic.
    let mut markers: Vec<Pos> = Vec::new();
    // Each line is read once, left to right: blanks, then the first character decides; for an
    // entry, one search finds the `=` (or that there is none), a second the newline.
    let mut line_start = 0usize;
    while line_start < n {
        let mut s = line_start;
        while s < n && is_blank(bytes[s]) {
            s += 1;
        }
        let first = bytes.get(s).copied().unwrap_or(b'\n');
        let (nl, kind) = match first {
            b'\n' => (s, TriviaKind::Blank),
            b';' | b'#' => (find_byte(bytes, s, b'\n'), TriviaKind::Comment),
            b'[' => (find_byte(bytes, s, b'\n'), TriviaKind::Stray),
            // `=======`, the middle of a merge conflict, is no `key=value`.
            b'=' if is_conflict_marker(&bytes[s..find_byte(bytes, s, b'\n')]) => {
                (find_byte(bytes, s, b'\n'), TriviaKind::Stray)
            }
            _ => {
                let eq = find_eq_or_nl(bytes, s);
                if eq < n && bytes[eq] == b'=' {
                    // key=value: the value's blanks are skipped before looking for the newline.
                    let mut vs = eq + 1;
                    while vs < n && is_blank(bytes[vs]) {
                        vs += 1;
                    }
                    let nl = if bytes.get(vs) == Some(&b'\n') {
                        vs
                    } else {
                        find_byte(bytes, vs, b'\n')
                    };
                    let line_end = cut_cr(bytes, line_start, nl);
                    let vs = vs.min(line_end);
                    let ve = trim_end(bytes, vs, line_end);
                    let ke = trim_end(bytes, s, eq);
                    entries.push(Entry {
                        key: &text[s..ke],
                        value: &text[vs..ve],
                        key_pos: pos(s, ke),
                        value_pos: if vs == ve { pos(eq + 1, eq + 1) } else { pos(vs, ve) },
                        line_pos: pos(line_start, line_end),
                    });
                    line_start = nl + 1;
                    continue;
                }
                (eq, TriviaKind::Stray)
            }
        };
        let line_end = cut_cr(bytes, line_start, nl);
        let line_pos = pos(line_start, line_end);
        let e = trim_end(bytes, s, line_end);
        let before = entries.len() as u32 - cur_entries;
        let line = &text[line_start..line_end];
        line_start = nl + 1;
        if first == b'[' {
            let close = memchr::memchr(b']', &bytes[s..e]).map(|i| s + i);
            let name_end = close.unwrap_or(e);
            let (ns, ne) = trim_pos(text, s + 1, name_end);
            let mut sec = Section::new(
                &text[ns..ne],
                pos(ns, ne),
                pos(s, e),
                entries.len() as u32,
                trivia.len() as u32,
            );
            match close {
                None => diags.push(
                    Diagnostic::warning(
                        codes::MALFORMED_HEADER,
                        "section header without closing `]`",
                    )
                    .with_label(pos(s, e).span(file), "expected `]` at the end")
                    .with_note("the whole rest of the line is taken as the name"),
                ),
                Some(c) => {
                    let (ts, te) = trim_pos(text, c + 1, e);
                    if ts < te {
                        sec.after_header = Some(pos(ts, te));
                        diags.push(
                            Diagnostic::warning(
                                codes::TEXT_AFTER_HEADER,
                                format!("text after section header [{}]", sec.name),
                            )
                            .with_label(pos(ts, te).span(file), "ignored"),
                        );
                    }
                }
            }
            if ns == ne {
                diags.push(
                    Diagnostic::warning(codes::MALFORMED_HEADER, "empty section name")
                        .with_label(pos(s, e).span(file), "no name between brackets"),
                );
            }
            let cur = sections.last_mut().unwrap_or(&mut preamble);
            cur.entries = cur_entries..entries.len() as u32;
            cur.trivia = cur_trivia..trivia.len() as u32;
            (cur_entries, cur_trivia) = (sec.entries.start, sec.trivia.start);
            sections.push(sec);
            continue;
        }
        if kind == TriviaKind::Stray {
            if is_conflict_marker(&bytes[s..e]) {
                // Reported together below: a file with one conflict has three, and real
                // files have dozens.
                markers.push(pos(s, e));
            } else {
                diags.push(
                    Diagnostic::warning(
                        codes::STRAY_LINE,
                        "line is neither `key=value`, a `[section]` nor a comment",
                    )
                    .with_label(pos(s, e).span(file), "ignored"),
                );
            }
        }
        trivia.push(Trivia { kind, text: line, pos: line_pos, before });
    }
    let cur = sections.last_mut().unwrap_or(&mut preamble);
    cur.entries = cur_entries..entries.len() as u32;
    cur.trivia = cur_trivia..trivia.len() as u32;

    if let Some((first, rest)) = markers.split_first() {
        let conflicts = markers.iter().filter(|m| bytes[m.start as usize] == b'<').count();
        let message = match (markers.len(), conflicts) {
            (1, _) => "git merge-conflict marker line ignored".to_string(),
            (n, 1) => format!("{n} git merge-conflict marker lines (1 conflict) ignored"),
            (n, c) => format!("{n} git merge-conflict marker lines ({c} conflicts) ignored"),
        };
        let mut d = Diagnostic::warning(codes::STRAY_LINE, message)
            .with_label(first.span(file), "ignored")
            .with_note(
                "the file was committed with an unresolved conflict: the lines of both versions \
                 are read, and for a key given in both the later one wins",
            );
        for m in rest {
            d = d.with_secondary(m.span(file), "ignored");
        }
        diags.push(d);
    }

    for e in
        entries.get(preamble.entries.start as usize..preamble.entries.end as usize).unwrap_or(&[])
    {
        diags.push(
            Diagnostic::warning(codes::KEY_OUTSIDE_SECTION, "key before the first section")
                .with_label(e.line_pos.span(file), "not in any section")
                .with_note("the entry is kept but not interpreted"),
        );
    }

    // Index the sections and link duplicates.
    let mut index: HashMap<Caseless<'a>, (u32, u32), Seeded> =
        HashMap::with_capacity_and_hasher(sections.len(), Seeded::new());
    for i in 0..sections.len() {
        let name = sections[i].name;
        match index.entry(Caseless(name)) {
            std::collections::hash_map::Entry::Vacant(v) => {
                v.insert((i as u32, i as u32));
            }
            std::collections::hash_map::Entry::Occupied(mut o) => {
                let slot = o.get_mut();
                let (first, last) = *slot;
                slot.1 = i as u32;
                sections[last as usize].next_same = Some(i as u32);
                sections[i].is_duplicate = true;
                let first_pos = sections[first as usize].header_pos;
                diags.push(
                    Diagnostic::warning(
                        codes::DUPLICATE_SECTION,
                        format!("section [{name}] appears more than once"),
                    )
                    .with_label(sections[i].header_pos.span(file), "repeated here")
                    .with_secondary(first_pos.span(file), "first here")
                    .with_note("the sections are merged; for a key given in both, the later wins"),
                );
            }
        }
        let sec = &sections[i];
        let own = entries.get(sec.entries.start as usize..sec.entries.end as usize).unwrap_or(&[]);
        check_duplicate_keys(sec, own, file, diags);
    }

    RawFile { text, file, preamble, sections, entries, trivia, index }
}

/// Whether a line (without its line end, blanks trimmed at the start) is a git merge-conflict
/// marker: `<<<<<<< ours`, `=======`, `>>>>>>> theirs` (or `|||||||` of the diff3 style).
fn is_conflict_marker(line: &[u8]) -> bool {
    let Some((&c, _)) = line.split_first() else { return false };
    if !matches!(c, b'<' | b'=' | b'>' | b'|')
        || line.len() < 7
        || line[..7].iter().any(|&b| b != c)
    {
        return false;
    }
    let rest = &line[7..];
    if c == b'=' {
        // `=======` alone: `========x` or `=======x` is not a marker.
        rest.iter().all(|&b| is_blank(b))
    } else {
        rest.first().is_none_or(|&b| is_blank(b))
    }
}

/// The first byte of `key` with ASCII case folded by `| 0x20` (0 for an empty key): equal keys
/// ignoring ASCII case have equal values.
#[inline(always)]
fn fold_first(key: &str) -> u8 {
    key.as_bytes().first().map_or(0, |b| b | 0x20)
}

fn check_duplicate_keys(
    sec: &Section<'_>,
    entries: &[Entry<'_>],
    file: FileId,
    diags: &mut odc_model::Capped,
) {
    let n = entries.len();
    let report = |first: &Entry<'_>, later: &Entry<'_>, diags: &mut odc_model::Capped| {
        diags.push(
            Diagnostic::warning(
                codes::DUPLICATE_KEY,
                format!("key `{}` repeated in section [{}]", later.key, sec.name),
            )
            .with_label(later.key_pos.span(file), "repeated here; this one wins")
            .with_secondary(first.key_pos.span(file), "first here"),
        );
    };
    if n <= 24 {
        for j in 1..n {
            let k = &entries[j];
            // Length and folded first byte first: most keys of a section differ there
            // (`ObjectType`, `AccessType` and `PDOMapping` share their length), which spares
            // the byte-wise comparison of nearly every pair.
            let (len, lead) = (k.key.len(), fold_first(k.key));
            if let Some(first) = entries[..j].iter().find(|e| {
                e.key.len() == len && fold_first(e.key) == lead && e.key.eq_ignore_ascii_case(k.key)
            }) {
                report(first, k, diags);
            }
        }
    } else {
        let mut seen: HashMap<Caseless<'_>, usize, Seeded> =
            HashMap::with_capacity_and_hasher(n, Seeded::new());
        for (j, e) in entries.iter().enumerate() {
            if let Some(&first) = seen.get(&Caseless(e.key)) {
                report(&entries[first], e, diags);
            } else {
                seen.insert(Caseless(e.key), j);
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn names_equal_ignoring_case_hash_alike() {
        use std::hash::BuildHasher;
        let build = Seeded::new();
        let name = "1A00sub1ManufacturerStatus";
        let mut seen = std::collections::HashSet::new();
        for n in 1..=name.len() {
            let lower = name[..n].to_ascii_lowercase();
            let upper = name[..n].to_ascii_uppercase();
            let h = build.hash_one(Caseless(&lower));
            assert_eq!(h, build.hash_one(Caseless(&upper)), "{lower}");
            seen.insert(h);
        }
        assert_eq!(seen.len(), name.len(), "prefixes of different lengths hash apart");
    }

    #[test]
    fn each_index_hashes_from_its_own_seed() {
        use std::hash::BuildHasher;
        // Two names that collide from a known start: the second word cancels what the first
        // left in the state. From another seed they hash apart.
        let start = Seeded(16);
        let first = |w: u64| {
            let mut h = start.build_hasher();
            h.write_u64(16);
            h.write_u64(w);
            h.finish()
        };
        let (a1, b1) = (u64::from_le_bytes(*b"aaaaaaaa"), u64::from_le_bytes(*b"bbbbbbbb"));
        let a2 = u64::from_le_bytes(*b"cccccccc");
        let b2 = a2 ^ first(a1) ^ first(b1);
        let name = |w1: u64, w2: u64| {
            let mut v = w1.to_le_bytes().to_vec();
            v.extend(w2.to_le_bytes());
            v
        };
        let hash = |seed: &Seeded, bytes: &[u8]| {
            let mut h = seed.build_hasher();
            h.write_u64(bytes.len() as u64);
            for c in bytes.chunks(8) {
                h.write_u64(u64::from_le_bytes(c.try_into().unwrap()));
            }
            h.finish()
        };
        let (a, b) = (name(a1, a2), name(b1, b2));
        assert_eq!(hash(&start, &a), hash(&start, &b), "crafted for this start");
        let seeded = Seeded::new();
        assert_ne!(hash(&seeded, &a), hash(&seeded, &b));
        let other = Seeded::new();
        assert_ne!(seeded.hash_one(Caseless("1A00")), other.hash_one(Caseless("1A00")));
    }

    fn scan_str(text: &str) -> (RawFile<'_>, Vec<Diagnostic>) {
        let mut d = odc_model::Capped::new();
        let r = scan(text, FileId(0), &mut d);
        (r, d.finish())
    }

    #[test]
    fn searches_match_a_plain_search() {
        let hay = b"ab=c\nxxxxxxxxxxxxxxxxxxxxxx=\x80\xff\n==\n0123456789abcdef\n";
        for from in 0..=hay.len() {
            for needle in [b'\n', b'=', b'a', b'f', 0x80, 0xff, b'z'] {
                let want =
                    hay[from..].iter().position(|&b| b == needle).map_or(hay.len(), |j| from + j);
                assert_eq!(find_byte(hay, from, needle), want, "{from} {needle}");
                let want = hay[from..]
                    .iter()
                    .position(|&b| b == b'=' || b == b'\n')
                    .map_or(hay.len(), |j| from + j);
                assert_eq!(find_eq_or_nl(hay, from), want, "{from}");
            }
        }
    }

    #[test]
    fn the_first_equals_sign_of_each_line_splits() {
        let text = "; a=b\n[A] = c\nk = v=w \r\n  x  \nk2==\n=\n \t\r\n\n[B]\nk3= \r\nlast=1=2";
        let (r, d) = scan_str(text);
        let v: Vec<_> = r.entries.iter().map(|e| (e.key, e.value)).collect();
        assert_eq!(v, [("k", "v=w"), ("k2", "="), ("", ""), ("k3", ""), ("last", "1=2")]);
        let e = &r.entries[0];
        assert_eq!(&text[e.line_pos.start as usize..e.line_pos.end as usize], "k = v=w ");
        assert_eq!(&text[e.value_pos.start as usize..e.value_pos.end as usize], "v=w");
        let e = &r.entries[3];
        assert_eq!(&text[e.line_pos.start as usize..e.line_pos.end as usize], "k3= ");
        assert_eq!((e.value_pos.start, e.value_pos.end), (e.key_pos.end + 1, e.key_pos.end + 1));
        assert_eq!(r.trivia_of(&r.preamble)[0].text, "; a=b");
        let a: Vec<_> =
            r.trivia_of(&r.sections[0]).iter().map(|t| (t.kind, t.text, t.before)).collect();
        assert_eq!(
            a,
            [
                (TriviaKind::Stray, "  x  ", 1),
                (TriviaKind::Blank, " \t", 3),
                (TriviaKind::Blank, "", 3)
            ]
        );
        let codes: Vec<_> = d.iter().map(|d| d.code).collect();
        assert_eq!(codes, [codes::TEXT_AFTER_HEADER, codes::STRAY_LINE]);
    }

    #[test]
    fn sections_entries_and_spans() {
        let text = "[FileInfo]\nFileName = a.eds \r\n\n; c\n[1000]\nDataType=0x0007";
        let (r, d) = scan_str(text);
        assert!(d.is_empty(), "{d:?}");
        assert_eq!(r.sections.len(), 2);
        let e = &r.entries_of(&r.sections[0])[0];
        assert_eq!(e.key, "FileName");
        assert_eq!(e.value, "a.eds");
        assert_eq!(&text[e.value_pos.start as usize..e.value_pos.end as usize], "a.eds");
        assert_eq!(r.trivia_of(&r.sections[0]).len(), 2);
        assert_eq!(r.trivia_of(&r.sections[0])[1].kind, TriviaKind::Comment);
        assert_eq!(r.get("FILEINFO", "filename").map(|e| e.value), Some("a.eds"));
        assert_eq!(r.get("1000", "datatype").map(|e| e.value), Some("0x0007"));
    }

    #[test]
    fn crlf_lf_mixed_and_no_final_newline() {
        let (r, _) = scan_str("[A]\r\nx=1\ny=2\r\nz=3");
        let v: Vec<_> = r.entries_of(&r.sections[0]).iter().map(|e| (e.key, e.value)).collect();
        assert_eq!(v, [("x", "1"), ("y", "2"), ("z", "3")]);
    }

    #[test]
    fn duplicates_last_wins_and_reported() {
        let (r, d) = scan_str("[A]\nx=1\nX=2\n[a]\nx=3\n");
        assert_eq!(r.get("a", "x").map(|e| e.value), Some("3"));
        assert_eq!(r.get_in(&r.sections[0], "x").map(|e| e.value), Some("2"));
        let codes: Vec<_> = d.iter().map(|d| d.code).collect();
        assert_eq!(codes, [codes::DUPLICATE_KEY, codes::DUPLICATE_SECTION]);
        assert_eq!(r.sections_named("A").count(), 2);
    }

    #[test]
    fn hash_comments_and_inline_hash_kept() {
        let (r, d) = scan_str("# top\n[1000]\nObjectType=0x07 # VAR\n  ; x\n");
        assert!(d.is_empty());
        assert_eq!(r.trivia_of(&r.preamble)[0].kind, TriviaKind::Comment);
        assert_eq!(r.entries_of(&r.sections[0])[0].value, "0x07 # VAR");
    }

    #[test]
    fn oddities_reported() {
        let (r, d) = scan_str("k=v\n[A] junk\nnot a pair\n[B\n=v\n");
        let codes: Vec<_> = d.iter().map(|d| d.code).collect();
        assert!(codes.contains(&codes::KEY_OUTSIDE_SECTION));
        assert!(codes.contains(&codes::TEXT_AFTER_HEADER));
        assert!(codes.contains(&codes::STRAY_LINE));
        assert!(codes.contains(&codes::MALFORMED_HEADER));
        assert_eq!(r.sections[1].name, "B");
        assert_eq!(r.entries_of(&r.sections[1])[0].key, "");
    }
}
