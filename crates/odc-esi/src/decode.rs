//! Bytes to text: BOM, UTF-8, ISO-8859-1 (and its spellings) per the XML declaration.

use crate::codes;
use std::borrow::Cow;

use odc_model::Diagnostic;

/// Why the bytes could not be turned into text at all.
pub(crate) enum DecodeError {
    Utf16,
    Unsupported(String),
}

/// The decoded text and any warnings.
pub(crate) struct Decoded {
    pub text: String,
    pub diagnostics: Vec<Diagnostic>,
}

/// Reads `encoding="..."` from an XML declaration at the start of `bytes` (ASCII-compatible).
fn declared_encoding(bytes: &[u8]) -> Option<String> {
    if !bytes.starts_with(b"<?xml") {
        return None;
    }
    let end = bytes.iter().take(512).position(|&b| b == b'>')?;
    let decl = std::str::from_utf8(&bytes[..end]).ok()?;
    let at = decl.find("encoding")?;
    let rest = decl[at + "encoding".len()..].trim_start().strip_prefix('=')?.trim_start();
    let quote = rest.chars().next()?;
    if quote != '"' && quote != '\'' {
        return None;
    }
    let rest = &rest[1..];
    let close = rest.find(quote)?;
    Some(rest[..close].trim().to_string())
}

/// Decodes the file: a UTF-8 BOM is dropped, UTF-16 (by BOM) is refused, otherwise the XML
/// declaration's encoding is used (UTF-8 when it names none). Latin-1 in any spelling
/// (`ISO-8859-1`, `ISO8859-1`, `latin1`, ...) is decoded as Windows-1252, as browsers do.
/// Bytes given by value become the text without a copy when they are UTF-8 or ASCII.
pub(crate) fn decode(input: Cow<'_, [u8]>) -> Result<Decoded, DecodeError> {
    let bytes: &[u8] = &input;
    if bytes.starts_with(&[0xFF, 0xFE]) || bytes.starts_with(&[0xFE, 0xFF]) {
        return Err(DecodeError::Utf16);
    }
    // UTF-16 without BOM: `<` followed by NUL (or the reverse).
    if bytes.starts_with(&[b'<', 0]) || bytes.starts_with(&[0, b'<']) {
        return Err(DecodeError::Utf16);
    }
    let bom = bytes.starts_with(&[0xEF, 0xBB, 0xBF]);
    let body = if bom { bytes.get(3..).unwrap_or_default() } else { bytes };
    let mut diagnostics = Vec::new();
    let label = declared_encoding(body);
    let encoding = match label.as_deref() {
        None => encoding_rs::UTF_8,
        Some(l) => {
            let norm: String =
                l.chars().filter(|c| *c != '-' && *c != '_').collect::<String>().to_lowercase();
            match norm.as_str() {
                "utf8" => encoding_rs::UTF_8,
                "iso88591" | "latin1" | "l1" | "iso885915" | "cp1252" | "windows1252"
                | "usascii" | "ascii" => encoding_rs::WINDOWS_1252,
                "utf16" | "utf16le" | "utf16be" => {
                    // Declared UTF-16 but bytes were ASCII-compatible: trust the bytes.
                    encoding_rs::UTF_8
                }
                _ => match encoding_rs::Encoding::for_label(l.as_bytes()) {
                    Some(e) if e != encoding_rs::UTF_16LE && e != encoding_rs::UTF_16BE => e,
                    _ => return Err(DecodeError::Unsupported(l.to_string())),
                },
            }
        }
    };
    // ASCII declared as Latin-1 (most such files) is UTF-8 as it stands.
    let as_is = encoding == encoding_rs::UTF_8
        || (encoding == encoding_rs::WINDOWS_1252 && body.is_ascii());
    let text = if as_is {
        match input {
            // Bytes given by value: validated in place, no copy.
            Cow::Owned(mut v) => {
                if bom {
                    v.drain(..3);
                }
                String::from_utf8(v).unwrap_or_else(|e| {
                    diagnostics.push(invalid_utf8(e.utf8_error().valid_up_to()));
                    String::from_utf8_lossy(e.as_bytes()).into_owned()
                })
            }
            Cow::Borrowed(_) => match std::str::from_utf8(body) {
                Ok(s) => s.to_owned(),
                Err(e) => {
                    diagnostics.push(invalid_utf8(e.valid_up_to()));
                    String::from_utf8_lossy(body).into_owned()
                }
            },
        }
    } else if encoding == encoding_rs::WINDOWS_1252 {
        latin1(body)
    } else {
        let (s, _) = encoding.decode_without_bom_handling(body);
        s.into_owned()
    };
    Ok(Decoded { text, diagnostics })
}

fn invalid_utf8(bad: usize) -> Diagnostic {
    Diagnostic::warning(
        codes::INVALID_UTF8,
        format!("the file is not valid UTF-8 (first bad byte at offset {bad})"),
    )
    .with_note(
        "invalid bytes were replaced with U+FFFD; declare the real encoding in the XML \
         declaration, e.g. encoding=\"ISO-8859-1\"",
    )
}

/// Windows-1252 into a string sized for the text (the generic decoder reserves three bytes per
/// input byte, which for a large file is most of the peak memory).
fn latin1(body: &[u8]) -> String {
    // 0x80..=0x9F map to characters of up to three UTF-8 bytes, 0xA0..=0xFF to two.
    let extra: usize =
        body.iter().map(|&b| usize::from(b >= 0x80) + usize::from((0x80..0xA0).contains(&b))).sum();
    let mut out = String::with_capacity(body.len() + extra);
    let mut decoder = encoding_rs::WINDOWS_1252.new_decoder_without_bom_handling();
    let (result, _, _) = decoder.decode_to_string(body, &mut out, true);
    if result == encoding_rs::CoderResult::InputEmpty {
        out
    } else {
        encoding_rs::WINDOWS_1252.decode_without_bom_handling(body).0.into_owned()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn ok(b: &[u8]) -> Decoded {
        let owned = match decode(Cow::Owned(b.to_vec())) {
            Ok(d) => d,
            Err(_) => panic!("decode failed"),
        };
        let borrowed = match decode(Cow::Borrowed(b)) {
            Ok(d) => d,
            Err(_) => panic!("decode failed"),
        };
        // Bytes by value (no copy) and by reference decode alike.
        assert_eq!(owned.text, borrowed.text);
        assert_eq!(owned.diagnostics, borrowed.diagnostics);
        borrowed
    }

    #[test]
    fn latin1_spellings() {
        for label in ["ISO-8859-1", "ISO8859-1", "iso-8859-1", "latin1"] {
            let mut b = format!("<?xml version=\"1.0\" encoding=\"{label}\"?><a>").into_bytes();
            b.push(0xE4);
            b.extend_from_slice(b"</a>");
            assert!(ok(&b).text.contains("<a>\u{e4}</a>"), "{label}");
        }
    }

    #[test]
    fn bom_dropped_and_utf16_refused() {
        assert_eq!(ok(b"\xEF\xBB\xBF<a/>").text, "<a/>");
        assert!(matches!(decode(Cow::Borrowed(b"\xFF\xFE<\0a\0")), Err(DecodeError::Utf16)));
    }

    #[test]
    fn invalid_utf8_warns() {
        let d = ok(b"<a>\xE4</a>");
        assert_eq!(d.diagnostics.len(), 1);
        assert!(d.text.contains('\u{FFFD}'));
        // The offset counts from after a BOM, by value and by reference.
        let d = ok(b"\xEF\xBB\xBF<a>\xE4</a>");
        assert!(d.diagnostics[0].message.contains("offset 3"), "{:?}", d.diagnostics);
        assert_eq!(d.text, "<a>\u{FFFD}</a>");
    }
}
