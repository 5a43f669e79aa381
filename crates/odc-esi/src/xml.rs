//! A small span-keeping element tree built from quick-xml events.
//!
//! Why a tree of our own rather than serde on XML or a DOM crate: every element, attribute value
//! and text needs its byte span for diagnostics, which serde deserialisation throws away; ESI
//! files are tolerant territory (unknown and vendor elements must be kept as raw text, a bad
//! number must not stop the rest of the file), which a derive-driven schema makes hard; and the
//! reader must stay in control of the input: DOCTYPE and external entities are never resolved and
//! the nesting depth is limited. quick-xml's pull reader on a `&str` gives byte positions before
//! and after every event (`buffer_position`), and borrowing attribute values lets their spans be
//! computed exactly. The tree holds only element names, attributes, trimmed text and spans.

use std::borrow::Cow;

use odc_model::{Diagnostic, FileId, Span};
use quick_xml::XmlVersion;
use quick_xml::events::{BytesStart, Event};
use quick_xml::{Error, Reader};

/// Deepest element nesting read; deeper content is skipped with a diagnostic.
pub const MAX_DEPTH: usize = 256;

/// An attribute: name (local part), value (entities resolved) and the span of the value.
#[derive(Debug)]
pub struct Attr<'s> {
    pub name: Cow<'s, str>,
    pub value: Cow<'s, str>,
    pub span: Span,
}

/// An element.
#[derive(Debug)]
pub struct Element<'s> {
    /// Local name (namespace prefix dropped).
    pub name: Cow<'s, str>,
    pub attrs: Vec<Attr<'s>>,
    pub children: Vec<Element<'s>>,
    /// Text and CDATA content, entities resolved, leading white space dropped.
    pub text: Cow<'s, str>,
    /// Span of the text without surrounding white space (the element's span if none).
    pub text_span: Span,
    /// From `<` to the end of the end tag.
    pub span: Span,
}

impl<'s> Element<'s> {
    pub fn child(&self, name: &str) -> Option<&Element<'s>> {
        self.children.iter().find(|c| &*c.name == name)
    }

    pub fn children_named<'a>(&'a self, name: &'a str) -> impl Iterator<Item = &'a Element<'s>> {
        self.children.iter().filter(move |c| &*c.name == name)
    }

    pub fn attr(&self, name: &str) -> Option<&Attr<'s>> {
        self.attrs.iter().find(|a| &*a.name == name)
    }

    /// The text, trimmed.
    pub fn text(&self) -> &str {
        self.text.trim_end()
    }
}

fn local(name: &str) -> &str {
    name.rsplit(':').next().unwrap_or(name)
}

struct Builder<'s> {
    src: &'s str,
    file: FileId,
    stack: Vec<Element<'s>>,
    /// Finished elements waiting for their parent's end tag (children of open elements).
    pending: Vec<Element<'s>>,
    /// Start of each open element's children in `pending`.
    child_start: Vec<usize>,
    roots: Vec<Element<'s>>,
    diags: Vec<Diagnostic>,
    /// Text start/end of the element on top of the stack.
    text_bounds: Vec<Option<(u32, u32)>>,
}

impl<'s> Builder<'s> {
    fn span(&self, start: u32, end: u32) -> Span {
        Span::new(self.file, start, end)
    }

    fn offset_of(&self, s: &str) -> Option<u32> {
        let base = self.src.as_ptr() as usize;
        let p = s.as_ptr() as usize;
        (p >= base && p + s.len() <= base + self.src.len()).then(|| (p - base) as u32)
    }

    /// `s` as a slice of the source when it points into it (it does for a `&str` reader).
    fn reborrow(&self, s: Cow<'_, str>) -> Cow<'s, str> {
        match s {
            Cow::Borrowed(b) => match self.offset_of(b) {
                Some(o) => Cow::Borrowed(&self.src[o as usize..o as usize + b.len()]),
                None => Cow::Owned(b.to_owned()),
            },
            Cow::Owned(o) => Cow::Owned(o),
        }
    }

    fn name_of(&self, raw: &str) -> Cow<'s, str> {
        self.reborrow(Cow::Borrowed(local(raw)))
    }

    fn element(&mut self, e: &BytesStart<'_>, start: u32, end: u32) -> Element<'s> {
        let mut attrs = Vec::new();
        for a in e.attributes() {
            match a {
                Ok(a) => {
                    let vspan = match &a.value {
                        std::borrow::Cow::Borrowed(v) => self
                            .offset_of(v)
                            .map(|o| self.span(o, o + v.len() as u32))
                            .unwrap_or(self.span(start, end)),
                        _ => self.span(start, end),
                    };
                    let value = match a.normalized_value(XmlVersion::Implicit1_0) {
                        Ok(v) => self.reborrow(v),
                        Err(err) => {
                            self.diags.push(
                                Diagnostic::warning(
                                    "F216",
                                    format!("attribute value has an unresolved reference: {err}"),
                                )
                                .with_label(vspan, "kept as written"),
                            );
                            self.reborrow(a.value.clone())
                        }
                    };
                    attrs.push(Attr { name: self.name_of(a.key.as_ref()), value, span: vspan });
                }
                Err(err) => {
                    self.diags.push(
                        Diagnostic::error("F202", format!("malformed attribute: {err}"))
                            .with_label(self.span(start, end), "in this tag"),
                    );
                }
            }
        }
        Element {
            name: self.name_of(e.name().as_ref()),
            attrs,
            children: Vec::new(),
            text: Cow::Borrowed(""),
            text_span: self.span(start, end),
            span: self.span(start, end),
        }
    }

    fn attach(&mut self, el: Element<'s>) {
        match self.stack.last_mut() {
            Some(_) => self.pending.push(el),
            None => {
                if let Some(first) = self.roots.first() {
                    let d = Diagnostic::error("F202", "a second root element")
                        .with_label(el.span, "XML allows one root element")
                        .with_secondary(first.span, "the root element");
                    self.diags.push(d);
                }
                self.roots.push(el);
            }
        }
    }

    /// Pushes an opened element.
    fn open(&mut self, el: Element<'s>) {
        self.stack.push(el);
        self.child_start.push(self.pending.len());
        self.text_bounds.push(None);
    }

    /// Pops the innermost open element, its children gathered.
    fn close(&mut self) -> Option<Element<'s>> {
        let mut el = self.stack.pop()?;
        let from = self.child_start.pop().unwrap_or(self.pending.len()).min(self.pending.len());
        if from < self.pending.len() {
            el.children = self.pending.drain(from..).collect();
        }
        Some(el)
    }

    fn text(&mut self, s: Cow<'s, str>, start: u32, end: u32) {
        if self.stack.is_empty() {
            if !s.trim().is_empty() {
                let lead = (s.len() - s.trim_start().len()) as u32;
                let d = Diagnostic::error("F202", "text outside the root element")
                    .with_label(self.span(start + lead, end.min(start + lead + 20)), "here");
                self.diags.push(d);
            }
            return;
        }
        let tlen = s.trim().len();
        let lead = (s.len() - s.trim_start().len()) as u32;
        let Some(top) = self.stack.last_mut() else { return };
        if top.text.is_empty() {
            if tlen == 0 {
                return;
            }
            top.text = match s {
                Cow::Borrowed(b) => Cow::Borrowed(b.trim_start()),
                Cow::Owned(o) => Cow::Owned(o.trim_start().to_owned()),
            };
        } else {
            top.text.to_mut().push_str(&s);
        }
        if tlen != 0 {
            let t0 = start + lead;
            let t1 = t0 + tlen as u32;
            if let Some(b) = self.text_bounds.last_mut() {
                *b = Some(match *b {
                    Some((a, _)) => (a, t1),
                    None => (t0, t1),
                });
            }
        }
    }
}

/// The root elements (normally one) and the problems met while reading.
pub struct Document<'s> {
    pub roots: Vec<Element<'s>>,
    pub diagnostics: Vec<Diagnostic>,
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
    let mut b = Builder {
        src,
        file,
        stack: Vec::new(),
        pending: Vec::new(),
        child_start: Vec::new(),
        roots: Vec::new(),
        diags: Vec::new(),
        text_bounds: Vec::new(),
    };
    let mut skip = 0usize;
    let mut depth_reported = false;
    loop {
        let before = reader.buffer_position() as u32;
        let ev = reader.read_event();
        let after = reader.buffer_position() as u32;
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
        match ev {
            Ok(Event::Start(e)) => {
                if b.stack.len() >= MAX_DEPTH {
                    if !depth_reported {
                        depth_reported = true;
                        let d = Diagnostic::error(
                            "F204",
                            format!("elements nested deeper than {MAX_DEPTH} levels"),
                        )
                        .with_label(b.span(before, after), "this element and its content skipped");
                        b.diags.push(d);
                    }
                    skip = 1;
                    continue;
                }
                let el = b.element(&e, before, after);
                b.open(el);
            }
            Ok(Event::Empty(e)) => {
                if b.stack.len() >= MAX_DEPTH {
                    continue;
                }
                let el = b.element(&e, before, after);
                b.attach(el);
            }
            Ok(Event::End(_)) => {
                if let Some(mut el) = b.close() {
                    el.span.end = after;
                    if let Some(Some((t0, t1))) = b.text_bounds.pop() {
                        el.text_span = b.span(t0, t1);
                    } else {
                        el.text_span = el.span;
                    }
                    b.attach(el);
                }
            }
            Ok(Event::Text(t)) => {
                let s = t.xml10_content();
                b.text(s, before, after);
            }
            Ok(Event::CData(t)) => {
                let s = t.xml10_content();
                // Positions of the content inside `<![CDATA[` ... `]]>`.
                let start = before + 9;
                let end = after.saturating_sub(3).max(start);
                if let Some(top) = b.stack.last_mut() {
                    if top.text.is_empty() {
                        top.text = s;
                    } else {
                        top.text.to_mut().push_str(&s);
                    }
                    if let Some(bounds) = b.text_bounds.last_mut() {
                        *bounds = Some(match *bounds {
                            Some((a, _)) => (a, end),
                            None => (start, end),
                        });
                    }
                }
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
                        let d = Diagnostic::warning(
                            "F216",
                            format!("unknown entity `&{name};` (entities are never resolved)"),
                        )
                        .with_label(b.span(before, after), "kept as written");
                        b.diags.push(d);
                        format!("&{name};")
                    }
                };
                if let Some(top) = b.stack.last_mut() {
                    top.text.to_mut().push_str(&text);
                    if let Some(bounds) = b.text_bounds.last_mut() {
                        *bounds = Some(match *bounds {
                            Some((a, _)) => (a, after),
                            None => (before, after),
                        });
                    }
                }
            }
            Ok(Event::DocType(_)) => {
                let d = Diagnostic::warning("F217", "DOCTYPE declaration ignored")
                    .with_label(b.span(before, after), "not read: no DTD, no external entities")
                    .with_note("ESI files are described by an XML schema; a DTD has no meaning");
                b.diags.push(d);
            }
            Ok(Event::Decl(_) | Event::PI(_) | Event::Comment(_)) => {}
            Ok(Event::Eof) => break,
            Err(e) => {
                report(&mut b, &reader, e);
                break;
            }
        }
    }
    // Close elements left open (error or truncated file).
    let end = src.len() as u32;
    if !b.stack.is_empty() && !b.diags.iter().any(|d| d.code == "F202" && d.is_error()) {
        let open = b.stack.last().map(|e| e.name.to_string()).unwrap_or_default();
        let span = b.stack.last().map(|e| e.span).unwrap_or(b.span(end, end));
        b.diags.push(
            Diagnostic::error("F202", format!("the file ends inside element `{open}`"))
                .with_label(span, "not closed"),
        );
    }
    while let Some(mut el) = b.close() {
        el.span.end = end;
        let bounds = b.text_bounds.pop().flatten();
        if let Some((t0, t1)) = bounds {
            el.text_span = b.span(t0, t1);
        }
        b.attach(el);
    }
    Document { roots: b.roots, diagnostics: b.diags }
}

fn report(b: &mut Builder<'_>, reader: &Reader<&[u8]>, e: Error) {
    let pos = (reader.error_position() as u32).min(b.src.len() as u32);
    let end = (pos + 1).min(b.src.len() as u32).max(pos);
    let d = Diagnostic::error("F202", format!("the file is not well-formed XML: {e}"))
        .with_label(b.span(pos, end), "reading stopped here")
        .with_note("what was read before this point is still used");
    b.diags.push(d);
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn spans_and_text() {
        let src =
            "<?xml version=\"1.0\"?>\n<a x=\"#x10\"><b> hi &amp; <![CDATA[<c>]]> </b><e/></a>";
        let doc = read(src, FileId(0));
        assert!(doc.diagnostics.is_empty(), "{:?}", doc.diagnostics);
        let a = &doc.roots[0];
        assert_eq!(&src[a.span.range()], &src[22..]);
        let x = a.attr("x").unwrap();
        assert_eq!(&src[x.span.range()], "#x10");
        let b = a.child("b").unwrap();
        assert_eq!(b.text(), "hi & <c>");
        assert_eq!(&src[b.text_span.range()], "hi &amp; <![CDATA[<c>");
        assert!(a.child("e").is_some());
    }

    #[test]
    fn errors_have_positions() {
        let doc = read("<a><b></a>", FileId(0));
        assert_eq!(doc.diagnostics.len(), 1);
        assert_eq!(doc.diagnostics[0].code, "F202");
        let doc = read("<a></a>junk", FileId(0));
        assert_eq!(doc.diagnostics[0].code, "F202");
    }

    #[test]
    fn depth_limited() {
        let src = format!("{}{}", "<a>".repeat(1000), "</a>".repeat(1000));
        let doc = read(&src, FileId(0));
        assert!(doc.diagnostics.iter().any(|d| d.code == "F204"));
        assert_eq!(doc.diagnostics.len(), 1);
    }

    #[test]
    fn doctype_not_resolved() {
        let src = "<!DOCTYPE a [<!ENTITY x SYSTEM \"file:///etc/passwd\">]><a>&x;</a>";
        let doc = read(src, FileId(0));
        assert_eq!(doc.roots[0].text(), "&x;");
        assert!(doc.diagnostics.iter().any(|d| d.code == "F217"));
    }
}
