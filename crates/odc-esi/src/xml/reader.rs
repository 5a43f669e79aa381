//! Building the tree: quick-xml events in, arena nodes out, with the limits (depth, element
//! count), the entity and DOCTYPE policy, and a diagnostic for every problem met.

use super::*;

/// Whether `s` is only XML white space (space, tab, line feed, carriage return), eight bytes at
/// a time: runs of indentation between tags are a good part of every file.
pub(super) fn xml_blank(s: &[u8]) -> bool {
    const ONES: u64 = 0x0101_0101_0101_0101;
    const LOW7: u64 = 0x7F7F_7F7F_7F7F_7F7F;
    /// 0x80 in each byte of `x` that is zero, exactly (no borrow between bytes).
    fn zero_bytes(x: u64) -> u64 {
        !(((x & LOW7) + LOW7) | x | LOW7)
    }
    let mut chunks = s.chunks_exact(8);
    for c in &mut chunks {
        let mut w = [0u8; 8];
        w.copy_from_slice(c);
        let x = u64::from_le_bytes(w);
        let ws = zero_bytes(x ^ (ONES * 0x20))
            | zero_bytes(x ^ (ONES * 0x09))
            | zero_bytes(x ^ (ONES * 0x0A))
            | zero_bytes(x ^ (ONES * 0x0D));
        if ws != ONES * 0x80 {
            return false;
        }
    }
    chunks.remainder().iter().all(|c| matches!(c, b' ' | b'\t' | b'\n' | b'\r'))
}

/// Whether `s` holds a carriage return, the only byte XML 1.0 line-end normalisation changes.
/// quick-xml's normalisation calls the `memchr` crate for every text, whose set-up costs more
/// than the whole search in the short texts most are; `contains` loops over those.
pub(super) fn has_cr(s: &[u8]) -> bool {
    s.contains(&b'\r')
}

pub(super) fn local(name: &str) -> &str {
    match name.as_bytes().iter().rposition(|&b| b == b':') {
        Some(colon) => name.get(colon + 1..).unwrap_or(name),
        None => name,
    }
}

/// Where `s` starts in `src`, when it is a slice of it (it is for a `&str` reader).
pub(super) fn offset_in(src: &str, s: &str) -> Option<u32> {
    let base = src.as_ptr() as usize;
    let p = s.as_ptr() as usize;
    (p >= base && p + s.len() <= base + src.len()).then(|| (p - base) as u32)
}

/// The text gathered so far for an open element.
pub(super) enum Text {
    Borrowed(u32, u32),
    Owned(String),
}

impl Text {
    fn is_empty(&self) -> bool {
        match self {
            Text::Borrowed(a, b) => a == b,
            Text::Owned(s) => s.is_empty(),
        }
    }
}

/// An element whose end tag has not been read yet.
pub(super) struct Open {
    idx: u32,
    /// End of the start tag.
    tag_end: u32,
    text: Text,
    /// Start and end of the non-blank text.
    bounds: Option<(u32, u32)>,
}

/// Byte classes of [`Builder::plain_attributes`]: XML white space,
const BLANK: u8 = 1;
/// what ends an attribute name (white space, `=`, quotes, `<`, `>`, `/`, `&`),
const NAME_END: u8 = 2;
/// what a plain value may not hold (`&`, `<`: references and errors; tab and line ends:
/// normalised to spaces),
const VALUE_BAD: u8 = 4;
/// the quotes,
const QUOTE: u8 = 8;
/// and the colon of a prefixed name.
const COLON: u8 = 16;

/// Where the first byte of `class` is in `bytes`. A function of its own, not a closure in the
/// scanner: alone, the loop compiles to a handful of instructions per byte.
#[inline(never)]
fn find(bytes: &[u8], class: u8) -> Option<usize> {
    bytes.iter().position(|&b| CLASS[b as usize] & class != 0)
}

/// Where the first byte not of `class` is in `bytes`.
#[inline(never)]
fn find_not(bytes: &[u8], class: u8) -> Option<usize> {
    bytes.iter().position(|&b| CLASS[b as usize] & class == 0)
}

/// The class of every byte (0 for most).
static CLASS: [u8; 256] = {
    let mut t = [0u8; 256];
    t[b' ' as usize] = BLANK | NAME_END;
    t[b'\t' as usize] = BLANK | NAME_END | VALUE_BAD;
    t[b'\n' as usize] = BLANK | NAME_END | VALUE_BAD;
    t[b'\r' as usize] = BLANK | NAME_END | VALUE_BAD;
    t[b'&' as usize] = NAME_END | VALUE_BAD;
    t[b'<' as usize] = NAME_END | VALUE_BAD;
    t[b'"' as usize] = NAME_END | QUOTE;
    t[b'\'' as usize] = NAME_END | QUOTE;
    t[b'=' as usize] = NAME_END;
    t[b'>' as usize] = NAME_END;
    t[b'/' as usize] = NAME_END;
    t[b':' as usize] = COLON;
    t
};

pub(super) struct Builder<'s> {
    doc: Document<'s>,
    stack: Vec<Open>,
    /// Span of the first top-level element, once closed.
    first_root: Option<Span>,
}

impl<'s> Builder<'s> {
    fn span(&self, start: u32, end: u32) -> Span {
        self.doc.span(start, end)
    }

    fn own(&mut self, text: String, (start, end): (u32, u32)) -> Str {
        self.doc.strings.push(Owned { text, start, end });
        Str { at: (self.doc.strings.len() - 1) as u32, len: OWNED }
    }

    /// `s` as a slice of the source when it is one, else an owned copy.
    fn store(&mut self, s: Cow<'_, str>) -> Str {
        if let Cow::Borrowed(b) = &s
            && let Some(at) = offset_in(self.doc.src, b)
        {
            return Str { at, len: b.len() as u32 };
        }
        self.own(s.into_owned(), (0, 0))
    }

    /// Appends the attributes of the tag spanning `start..end` to the arena.
    fn attributes(&mut self, e: &BytesStart<'_>, start: u32, end: u32) {
        for a in e.attributes() {
            match a {
                Ok(a) => {
                    let (vstart, vend) = match &a.value {
                        Cow::Borrowed(v) => match offset_in(self.doc.src, v) {
                            Some(o) => (o, o + v.len() as u32),
                            None => (start, end),
                        },
                        _ => (start, end),
                    };
                    let value = match a.normalized_value(XmlVersion::Implicit1_0) {
                        Ok(v) => self.store(v),
                        Err(err) => {
                            self.doc.diagnostics.push(
                                Diagnostic::warning(
                                    codes::UNRESOLVED_ENTITY,
                                    format!("attribute value has an unresolved reference: {err}"),
                                )
                                .with_label(self.span(vstart, vend), "kept as written"),
                            );
                            self.store(a.value.clone())
                        }
                    };
                    let name = self.store(Cow::Borrowed(local(a.key.as_ref())));
                    self.doc.attrs.push(RawAttr { name, value, start: vstart, end: vend });
                }
                Err(err) => {
                    self.doc.diagnostics.push(
                        Diagnostic::error(
                            codes::MALFORMED_XML,
                            format!("malformed attribute: {err}"),
                        )
                        .with_label(self.span(start, end), "in this tag"),
                    );
                }
            }
        }
    }

    /// Appends the attributes of a tag from its bytes when every one is plain: `name="value"`
    /// (or single quotes) after white space, no spaces around `=`, names distinct, values with
    /// nothing XML normalises (no `&`, tab, line end) and no `<`. Returns false, with nothing
    /// appended, for any other tag, which [`Self::attributes`] then reads.
    ///
    /// Why by hand: quick-xml's attribute iterator (with its duplicate check and value
    /// normalisation) cost more than the rest of the tree in CiA 311 files, which carry about
    /// ten attributes on every object and sub-object. What this accepts, the iterator reads to
    /// the same names, values and spans; everything else still goes through the iterator, so
    /// its diagnostics are unchanged.
    fn plain_attributes(&mut self, raw: &str) -> bool {
        /// Most attributes of one tag read here; a tag with more goes to the iterator.
        const MAX: usize = 32;
        let Some(base) = offset_in(self.doc.src, raw) else { return false };
        let raw = raw.as_bytes();
        let mark = self.doc.attrs.len();
        // Full names (prefix included) of the attributes read, for the duplicate check.
        let mut names = [(0u32, 0u32); MAX];
        let mut count = 0;
        let mut i = 0;
        let plain = loop {
            let rest = raw.get(i..).unwrap_or_default();
            let Some(gap) = find_not(rest, BLANK) else { break true };
            if gap == 0 || count == MAX {
                break false;
            }
            let name_start = i + gap;
            let rest = rest.get(gap..).unwrap_or_default();
            // The name, and where its local part starts (after the last colon).
            let mut name_len = 0;
            let mut local_start = 0;
            loop {
                let tail = rest.get(name_len..).unwrap_or_default();
                name_len += find(tail, NAME_END | COLON).unwrap_or(tail.len());
                if rest.get(name_len) != Some(&b':') {
                    break;
                }
                name_len += 1;
                local_start = name_len;
            }
            let name = rest.get(..name_len).unwrap_or_default();
            let quote = match (rest.get(name_len), rest.get(name_len + 1)) {
                (Some(b'='), Some(&q @ (b'"' | b'\''))) if !name.is_empty() => q,
                _ => break false,
            };
            // The value: up to the closing quote, with nothing to normalise on the way (the
            // other quote may be part of it).
            let value_start = name_start + name_len + 2;
            let rest = raw.get(value_start..).unwrap_or_default();
            let len = match find(rest, QUOTE | VALUE_BAD).and_then(|n| Some((n, *rest.get(n)?))) {
                Some((n, b)) if b == quote => n,
                Some((_, b)) if CLASS[b as usize] == QUOTE => {
                    let Some(close) = rest.iter().position(|&b| b == quote) else { break false };
                    if find(rest.get(..close).unwrap_or_default(), VALUE_BAD).is_some() {
                        break false;
                    }
                    close
                }
                _ => break false,
            };
            let duplicate = names.get(..count).unwrap_or_default().iter().any(|&(at, n)| {
                n as usize == name.len()
                    && raw.get(at as usize) == name.first()
                    && raw.get(at as usize..(at + n) as usize) == Some(name)
            });
            if duplicate {
                break false;
            }
            if let Some(slot) = names.get_mut(count) {
                *slot = (name_start as u32, name_len as u32);
            }
            count += 1;
            let at = base + (name_start + local_start) as u32;
            let local_name = Str { at, len: (name_len - local_start) as u32 };
            let vstart = base + value_start as u32;
            let value = Str { at: vstart, len: len as u32 };
            self.doc.attrs.push(RawAttr {
                name: local_name,
                value,
                start: vstart,
                end: vstart + len as u32,
            });
            i = value_start + len + 1;
        };
        if !plain {
            self.doc.attrs.truncate(mark);
        }
        plain
    }

    /// Appends the node of a start tag (or empty-element tag) spanning `start..end`.
    fn element(&mut self, e: &BytesStart<'_>, start: u32, end: u32) -> u32 {
        let attr_start = self.doc.attrs.len() as u32;
        // Most tags have no attributes: nothing after the name, no iterator to set up. Most of
        // the rest are plain and read straight from their bytes.
        let raw = e.attributes_raw();
        if !raw.is_empty() && !self.plain_attributes(raw) {
            self.attributes(e, start, end);
        }
        let name = self.store(Cow::Borrowed(local(e.name().as_ref())));
        let idx = self.doc.nodes.len() as u32;
        self.doc.nodes.push(Node {
            name,
            start,
            end,
            text: Str::EMPTY,
            subtree_end: idx + 1,
            attr_start,
        });
        idx
    }

    /// A top-level element is complete: a second one is an error.
    fn attached(&mut self, idx: u32) {
        if !self.stack.is_empty() {
            return;
        }
        let Some(n) = self.doc.nodes.get(idx as usize) else { return };
        let span = self.span(n.start, n.end);
        match self.first_root {
            Some(first) => {
                let d = Diagnostic::error(codes::MALFORMED_XML, "a second root element")
                    .with_label(span, "XML allows one root element")
                    .with_secondary(first, "the root element");
                self.doc.diagnostics.push(d);
            }
            None => self.first_root = Some(span),
        }
    }

    /// Closes the innermost open element at `end`; `text_span` is used when it has no text.
    fn close(&mut self, end: u32, eof: bool) -> Option<u32> {
        let open = self.stack.pop()?;
        let subtree_end = self.doc.nodes.len() as u32;
        let start = self.doc.nodes.get(open.idx as usize)?.start;
        let text = match (open.text, open.bounds) {
            // No text: the span is the element's (derived).
            (Text::Borrowed(a, b), None) if a == b && !eof => Str::EMPTY,
            // A slice of the source whose span is its trimmed extent (derived).
            (Text::Borrowed(a, b), Some(bounds))
                if a < b
                    && bounds
                        == (
                            a,
                            a + trim_end(self.doc.src.get(a as usize..b as usize).unwrap_or(""))
                                .len() as u32,
                        ) =>
            {
                Str { at: a, len: b - a }
            }
            // Anything else keeps its text and span in the table: texts built from pieces,
            // CDATA with trailing blanks, an element cut off by the end of the file (whose text
            // span without text is its start tag's).
            (text, bounds) => {
                let text = match text {
                    Text::Borrowed(a, b) => {
                        self.doc.src.get(a as usize..b as usize).unwrap_or("").to_string()
                    }
                    Text::Owned(s) => s,
                };
                let span = match bounds {
                    Some(b) => b,
                    None if eof => (start, open.tag_end),
                    None => (start, end),
                };
                self.own(text, span)
            }
        };
        let n = self.doc.nodes.get_mut(open.idx as usize)?;
        n.end = end;
        n.subtree_end = subtree_end;
        n.text = text;
        Some(open.idx)
    }

    /// Appends content to the innermost open element's text: `set` replaces an empty text.
    fn append(&mut self, piece: Cow<'_, str>, bounds: (u32, u32), set: bool) {
        let src = self.doc.src;
        let Some(top) = self.stack.last_mut() else { return };
        if top.text.is_empty() && set {
            top.text = match &piece {
                Cow::Borrowed(b) => match offset_in(src, b) {
                    Some(o) => Text::Borrowed(o, o + b.len() as u32),
                    None => Text::Owned(b.to_string()),
                },
                Cow::Owned(o) => Text::Owned(o.clone()),
            };
        } else {
            let owned = match &mut top.text {
                Text::Owned(s) => s,
                Text::Borrowed(a, b) => {
                    let s = src.get(*a as usize..*b as usize).unwrap_or("").to_string();
                    top.text = Text::Owned(s);
                    match &mut top.text {
                        Text::Owned(s) => s,
                        Text::Borrowed(..) => return,
                    }
                }
            };
            owned.push_str(&piece);
        }
        top.bounds = Some(match top.bounds {
            Some((a, _)) => (a, bounds.1),
            None => bounds,
        });
    }

    fn text(&mut self, s: Cow<'_, str>, start: u32, end: u32) {
        // The usual text, first of its element, a slice of the source with nothing to trim: what
        // the general path below does for it, without its trims and copies of the `Cow`.
        if let Cow::Borrowed(t) = &s
            && is_trimmed(t)
            && let Some(at) = offset_in(self.doc.src, t)
            && let Some(top) = self.stack.last_mut()
            && top.text.is_empty()
        {
            let len = t.len() as u32;
            top.text = Text::Borrowed(at, at + len);
            top.bounds = Some(match top.bounds {
                Some((a, _)) => (a, start + len),
                None => (start, start + len),
            });
            return;
        }
        if self.stack.is_empty() {
            if !trim(&s).is_empty() {
                let lead = (s.len() - trim_start(&s).len()) as u32;
                let d = Diagnostic::error(codes::MALFORMED_XML, "text outside the root element")
                    .with_label(self.span(start + lead, end.min(start + lead + 20)), "here");
                self.doc.diagnostics.push(d);
            }
            return;
        }
        let tlen = trim(&s).len() as u32;
        let lead = (s.len() - trim_start(&s).len()) as u32;
        let top_empty = self.stack.last().is_some_and(|t| t.text.is_empty());
        if top_empty {
            if tlen == 0 {
                return;
            }
            let trimmed = match s {
                Cow::Borrowed(b) => Cow::Borrowed(trim_start(b)),
                Cow::Owned(o) => Cow::Owned(trim_start(&o).to_owned()),
            };
            self.append(trimmed, (start + lead, start + lead + tlen), true);
        } else {
            let bounds = (start + lead, start + lead + tlen);
            // Blank pieces extend the text but not its span.
            let keep = self.stack.last().and_then(|t| t.bounds);
            self.append(s, bounds, false);
            if tlen == 0
                && let Some(top) = self.stack.last_mut()
            {
                top.bounds = keep;
            }
        }
    }
}

/// Reads `src` into an element tree. Stops at the first well-formedness error (reported with its
/// position) and returns what was read until then, open elements closed.
pub fn read(src: &str, file: FileId) -> Document<'_> {
    let mut reader = Reader::from_str(src);
    {
        let c = reader.config_mut();
        c.check_end_names = true;
        c.expand_empty_elements = false;
        c.trim_text(false);
    }
    // The corpus averages 38 source bytes per element, and from 430-660 per attribute (ESI) down
    // to 24 (CiA 311 files, about ten on every object and sub-object); reserved
    // pages that are never written cost no memory, and the arenas grow past this if needed.
    let nodes = src.len() / 32;
    let attrs = src.len() / 24;
    let mut b = Builder {
        doc: Document {
            src,
            file,
            nodes: Vec::with_capacity(nodes),
            attrs: Vec::with_capacity(attrs),
            strings: Vec::new(),
            diagnostics: odc_model::Capped::new(),
        },
        stack: Vec::new(),
        first_root: None,
    };
    // The decoder drops a file's byte-order mark, so a U+FEFF left at the start is a second one:
    // a character before the XML declaration, which XML 1.0 §2.8 does not allow. quick-xml
    // drops it too, but counts its positions from after it: `shift` puts them back in `src`.
    let shift = bom_shift(src);
    if shift > 0 {
        let d = Diagnostic::error(codes::MALFORMED_XML, "a second byte-order mark (U+FEFF)")
            .with_label(b.span(0, shift), "XML allows one, at the start of the file");
        b.doc.diagnostics.push(d);
    }
    let mut skip = 0usize;
    let mut depth_reported = false;
    loop {
        // Blank runs before a text are dropped (see `Builder::text`) unless they continue one:
        // then quick-xml may skip them itself, and a run of indentation before a tag makes no
        // event at all. In the prolog and epilog they are read, so that nothing but a BOM may
        // precede the XML declaration.
        let skip_blanks = skip > 0 || b.stack.last().is_some_and(|top| top.text.is_empty());
        if reader.config().trim_text_start != skip_blanks {
            reader.config_mut().trim_text_start = skip_blanks;
        }
        let read_from = reader.buffer_position() as u32 + shift;
        let ev = reader.read_event();
        let after = reader.buffer_position() as u32 + shift;
        // Where the event starts: skipped blanks may precede it.
        let before = event_start(src, &ev).unwrap_or(read_from);
        if skip > 0 {
            match ev {
                Ok(Event::Start(_)) => skip += 1,
                Ok(Event::End(_)) => skip -= 1,
                Ok(Event::Eof) => break,
                Err(e) => {
                    report(&mut b, &reader, e);
                    break;
                }
                _ => {}
            }
            continue;
        }
        if matches!(ev, Ok(Event::Start(_) | Event::Empty(_))) && b.doc.nodes.len() >= MAX_ELEMENTS
        {
            let d = Diagnostic::error(
                codes::ELEMENT_LIMIT,
                format!("more than {MAX_ELEMENTS} elements"),
            )
            .with_label(b.span(before, after), "reading stopped here")
            .with_note("what was read before this point is still used");
            b.doc.diagnostics.push(d);
            break;
        }
        match ev {
            Ok(Event::Start(e)) => {
                if b.stack.len() >= MAX_DEPTH {
                    if !depth_reported {
                        depth_reported = true;
                        let d = Diagnostic::error(
                            codes::DEPTH_LIMIT,
                            format!("elements nested deeper than {MAX_DEPTH} levels"),
                        )
                        .with_label(b.span(before, after), "this element and its content skipped");
                        b.doc.diagnostics.push(d);
                    }
                    skip = 1;
                    continue;
                }
                let idx = b.element(&e, before, after);
                b.stack.push(Open {
                    idx,
                    tag_end: after,
                    text: Text::Borrowed(0, 0),
                    bounds: None,
                });
            }
            Ok(Event::Empty(e)) => {
                if b.stack.len() >= MAX_DEPTH {
                    continue;
                }
                let idx = b.element(&e, before, after);
                b.attached(idx);
            }
            Ok(Event::End(_)) => {
                if let Some(idx) = b.close(after, false) {
                    b.attached(idx);
                }
            }
            Ok(Event::Text(t)) => {
                // Blank runs between tags (most text events) are dropped unless they continue a
                // text: no line-end normalisation for them.
                let blank = xml_blank(t.as_bytes()) || trim(&t).is_empty();
                if blank && b.stack.last().is_none_or(|top| top.text.is_empty()) {
                    continue;
                }
                // Line ends are normalised only where there is a carriage return to normalise.
                let s = if has_cr(t.as_bytes()) { t.xml10_content() } else { t.into_inner() };
                b.text(s, before, after);
            }
            Ok(Event::CData(t)) => {
                let s = t.xml10_content();
                // Positions of the content inside `<![CDATA[` ... `]]>`.
                let start = before + 9;
                let end = after.saturating_sub(3).max(start);
                b.append(s, (start, end), true);
            }
            Ok(Event::GeneralRef(r)) => {
                let name = r.xml10_content();
                let resolved: Option<String> = if r.is_char_ref() {
                    r.resolve_char_ref().ok().flatten().map(String::from)
                } else {
                    quick_xml::escape::resolve_predefined_entity(&name).map(String::from)
                };
                let text = match resolved {
                    Some(t) => t,
                    None => {
                        let message = if r.is_char_ref() {
                            format!("`&{name};` is not a character XML allows")
                        } else {
                            format!("unknown entity `&{name};` (entities are never resolved)")
                        };
                        let d = Diagnostic::warning(codes::UNRESOLVED_ENTITY, message)
                            .with_label(b.span(before, after), "kept as written");
                        b.doc.diagnostics.push(d);
                        format!("&{name};")
                    }
                };
                b.append(Cow::Owned(text), (before, after), false);
            }
            Ok(Event::DocType(_)) => {
                let d = Diagnostic::warning(codes::DOCTYPE_IGNORED, "DOCTYPE declaration ignored")
                    .with_label(b.span(before, after), "not read: no DTD, no external entities")
                    .with_note("ESI files are described by an XML schema; a DTD has no meaning");
                b.doc.diagnostics.push(d);
            }
            Ok(Event::Decl(_)) => {
                // Only a byte-order mark may come before the XML declaration (XML 1.0 §2.8); a
                // second one is reported above.
                if before != shift {
                    let d = Diagnostic::error(
                        codes::MALFORMED_XML,
                        "the XML declaration is not at the start of the file",
                    )
                    .with_label(b.span(before, after), "XML allows nothing before it");
                    b.doc.diagnostics.push(d);
                }
            }
            Ok(Event::PI(_) | Event::Comment(_)) => {}
            Ok(Event::Eof) => break,
            Err(e) => {
                report(&mut b, &reader, e);
                break;
            }
        }
    }
    // Close elements left open (error or truncated file).
    let end = src.len() as u32;
    if let Some(top) = b.stack.last()
        && !b.doc.diagnostics.iter().any(|d| {
            (d.code == codes::MALFORMED_XML || d.code == codes::ELEMENT_LIMIT) && d.is_error()
        })
        && let Some(n) = b.doc.nodes.get(top.idx as usize)
    {
        let open = b.doc.str(n.name).to_string();
        let span = b.span(n.start, n.end);
        b.doc.diagnostics.push(
            Diagnostic::error(
                codes::MALFORMED_XML,
                format!("the file ends inside element `{open}`"),
            )
            .with_label(span, "not closed"),
        );
    }
    while let Some(idx) = b.close(end, true) {
        b.attached(idx);
    }
    b.doc
}

/// Where the markup or text of `ev` starts in `src` (its content is a slice of it: the reader
/// reads a `&str`); `None` for the events whose position is the reader's before the call.
pub(super) fn event_start(src: &str, ev: &Result<Event<'_>, Error>) -> Option<u32> {
    let at = |content: &str, open: u32| {
        let base = src.as_ptr() as usize;
        let p = content.as_ptr() as usize;
        (p >= base + open as usize && p + content.len() <= base + src.len())
            .then(|| (p - base) as u32 - open)
    };
    match ev {
        // `<` before the name.
        Ok(Event::Start(e) | Event::Empty(e)) => at(e.as_ref(), 1),
        Ok(Event::Text(t)) => at(t.as_ref(), 0),
        // `<![CDATA[` before the content.
        Ok(Event::CData(t)) => at(t.as_ref(), 9),
        // `&` before the name.
        Ok(Event::GeneralRef(r)) => at(r.as_ref(), 1),
        _ => None,
    }
}

/// How many bytes of `src` quick-xml skips without counting them in its positions: a UTF-8
/// byte-order mark at the start (3), else none.
fn bom_shift(src: &str) -> u32 {
    if src.starts_with('\u{FEFF}') { 3 } else { 0 }
}

pub(super) fn report(b: &mut Builder<'_>, reader: &Reader<&[u8]>, e: Error) {
    let pos = (reader.error_position() as u32 + bom_shift(b.doc.src)).min(b.doc.src.len() as u32);
    let end = (pos + 1).min(b.doc.src.len() as u32).max(pos);
    let d =
        Diagnostic::error(codes::MALFORMED_XML, format!("the file is not well-formed XML: {e}"))
            .with_label(b.span(pos, end), "reading stopped here")
            .with_note("what was read before this point is still used");
    b.doc.diagnostics.push(d);
}
