//! Byte spans into source files.
//!
//! A span is provenance, not content: `PartialEq` on [`Span`] is always true, so two models read
//! from differently laid-out files compare equal when what they say is equal (syn's
//! `extra-traits` makes the same choice). This is what lets the EDS round trip
//! (EDS → model → EDS → model) be checked with a plain `==`.

use serde::Serialize;

/// Index of a file in [`crate::Sources`].
#[derive(Clone, Copy, Debug, Default, Eq, Hash, Ord, PartialOrd, PartialEq, Serialize)]
#[serde(transparent)]
pub struct FileId(pub u32);

/// A byte range `start..end` in one source file (in its decoded UTF-8 text).
#[derive(Clone, Copy, Debug, Default)]
pub struct Span {
    /// The file this span points into.
    pub file: FileId,
    /// First byte.
    pub start: u32,
    /// One past the last byte.
    pub end: u32,
}

impl Span {
    /// A span of `start..end` in `file`.
    pub const fn new(file: FileId, start: u32, end: u32) -> Self {
        Span { file, start, end }
    }

    /// The dummy span of things that have no place in a file (synthesised objects, defaults).
    pub const DUMMY: Span = Span { file: FileId(u32::MAX), start: 0, end: 0 };

    /// Whether this is [`Span::DUMMY`].
    pub fn is_dummy(&self) -> bool {
        self.file.0 == u32::MAX
    }

    /// The byte range, for slicing the source text.
    pub fn range(&self) -> std::ops::Range<usize> {
        self.start as usize..self.end as usize
    }

    /// The smallest span covering both (same file assumed).
    pub fn to(self, other: Span) -> Span {
        Span { file: self.file, start: self.start.min(other.start), end: self.end.max(other.end) }
    }
}

impl PartialEq for Span {
    fn eq(&self, _: &Span) -> bool {
        true
    }
}
impl Eq for Span {}

impl Serialize for Span {
    fn serialize<S: serde::Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
        if self.is_dummy() {
            s.serialize_str("-")
        } else {
            s.collect_str(&format_args!("{}..{}", self.start, self.end))
        }
    }
}

/// A value with the span it was read from. Serialises as the bare value.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Spanned<T> {
    /// The value.
    pub value: T,
    /// Where it was read from.
    pub span: Span,
}

impl<T: Serialize> Serialize for Spanned<T> {
    fn serialize<S: serde::Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
        self.value.serialize(s)
    }
}

impl<T> Spanned<T> {
    /// Pairs a value with its span.
    pub const fn new(value: T, span: Span) -> Self {
        Spanned { value, span }
    }

    /// A value with no place in a file.
    pub const fn synthetic(value: T) -> Self {
        Spanned { value, span: Span::DUMMY }
    }
}

impl<T> std::ops::Deref for Spanned<T> {
    type Target = T;
    fn deref(&self) -> &T {
        &self.value
    }
}
