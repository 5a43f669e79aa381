//! The strings category (ETG.2010 category 10) under construction.

use crate::Note;

/// Texts by first use, each once. Index 0 means "no string"; a disabled table (the ESI gives
/// its own strings category) answers 0 to everything.
#[derive(Default)]
pub(crate) struct Strings {
    texts: Vec<Vec<u8>>,
    pub notes: Vec<Note>,
    disabled: bool,
}

impl Strings {
    /// A table whose every index is 0: the ESI's own strings category is written instead, and
    /// generated indexes would point into it.
    pub fn disabled() -> Strings {
        Strings { disabled: true, ..Strings::default() }
    }

    /// The 1-based index of `text`, added if new; 0 for no text or a full table.
    pub fn index(&mut self, text: Option<&str>) -> u8 {
        if self.disabled {
            return 0;
        }
        let Some(text) = text.map(str::trim).filter(|t| !t.is_empty()) else { return 0 };
        let mut end = text.len().min(255);
        while !text.is_char_boundary(end) {
            end -= 1;
        }
        let bytes = &text.as_bytes()[..end];
        if let Some(i) = self.texts.iter().position(|t| t == bytes) {
            return u8::try_from(i + 1).unwrap_or(0);
        }
        if self.texts.len() == 255 {
            self.notes.push(Note::StringTableFull(text.to_string()));
            return 0;
        }
        if end < text.len() {
            self.notes.push(Note::StringCut(text.to_string()));
        }
        self.texts.push(bytes.to_vec());
        u8::try_from(self.texts.len()).unwrap_or(0)
    }

    /// Whether no text was added.
    pub fn is_empty(&self) -> bool {
        self.texts.is_empty()
    }

    /// The category's data: a count byte, then each text as a length byte and its bytes.
    pub fn bytes(&self) -> Vec<u8> {
        // At most 255 texts of at most 255 bytes: `index` keeps both bounds.
        let mut out = vec![u8::try_from(self.texts.len()).unwrap_or(u8::MAX)];
        for t in &self.texts {
            out.push(u8::try_from(t.len()).unwrap_or(u8::MAX));
            out.extend_from_slice(t);
        }
        out
    }
}
