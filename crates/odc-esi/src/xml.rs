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
//!
//! Layout: one flat arena of fixed-size nodes in document order (pre-order), so that reading a
//! file makes a handful of allocations instead of several per element, and the tree stays
//! about the size of the text (a node is 32 bytes; an ESI element averages ~38 source bytes).
//! A node's first child is the node after it and its next sibling is the node after its
//! subtree (`subtree_end`); its attributes are the run of the attribute arena up to the next
//! node's. Names, texts and attribute values are offsets into the source; the few that differ
//! from it (entities resolved, line ends normalised, text broken by child elements) live in a
//! side table of owned strings. A text's span is that of its trimmed slice (the element's span
//! when it has none); texts whose span is not (CDATA, owned texts) keep theirs in the table. [`Element`] and [`Attr`] are copyable handles onto the arena.

use crate::codes;
use std::borrow::Cow;

use odc_model::{Diagnostic, FileId, Span};
use quick_xml::XmlVersion;
use quick_xml::events::{BytesStart, Event};
use quick_xml::{Error, Reader};

use odc_model::trim::{is_trimmed, trim, trim_end, trim_start};

mod reader;

pub use reader::read;

/// Deepest element nesting read; deeper content is skipped with a diagnostic.
pub const MAX_DEPTH: usize = 256;

/// Most elements read; reading stops there with a diagnostic (`F221`). The largest real ESI
/// files have about 100,000.
pub const MAX_ELEMENTS: usize = 2_000_000;

/// A string of the tree: `len` bytes of the source at `at`, or (`len == OWNED`) the owned
/// string number `at` of the document.
#[derive(Clone, Copy, Debug)]
struct Str {
    at: u32,
    len: u32,
}

/// `Str::len` of an owned string. Never a real length: files are at most 256 MiB.
const OWNED: u32 = u32::MAX;

impl Str {
    /// No text (a borrowed text is never empty: see [`Builder::close`]).
    const EMPTY: Str = Str { at: 0, len: 0 };
}

/// An owned string of the document, with the span of what it was read from (texts only).
#[derive(Debug)]
struct Owned {
    text: String,
    start: u32,
    end: u32,
}

/// An element in the arena.
#[derive(Debug)]
struct Node {
    /// Local name (namespace prefix dropped).
    name: Str,
    /// From `<` to the end of the end tag.
    start: u32,
    end: u32,
    /// Text and CDATA content, entities resolved, leading white space dropped.
    text: Str,
    /// One past the last node of this element's subtree.
    subtree_end: u32,
    /// This element's first attribute in [`Document::attrs`].
    attr_start: u32,
}

/// An attribute in the arena.
#[derive(Debug)]
struct RawAttr {
    name: Str,
    value: Str,
    /// Span of the value as written.
    start: u32,
    end: u32,
}

/// The elements read (normally under one root) and the problems met while reading.
pub struct Document<'s> {
    src: &'s str,
    file: FileId,
    nodes: Vec<Node>,
    attrs: Vec<RawAttr>,
    strings: Vec<Owned>,
    /// Problems met while reading (well-formedness, limits, entities).
    pub diagnostics: odc_model::Capped,
}

impl<'s> Document<'s> {
    #[inline]
    fn str(&self, s: Str) -> &str {
        if s.len == OWNED {
            self.strings.get(s.at as usize).map_or("", |o| o.text.as_str())
        } else {
            self.src.get(s.at as usize..s.at as usize + s.len as usize).unwrap_or("")
        }
    }

    #[inline]
    fn span(&self, start: u32, end: u32) -> Span {
        Span::new(self.file, start, end)
    }

    #[inline]
    fn attr(&self, a: &RawAttr) -> Attr<'_> {
        Attr { name: self.str(a.name), value: self.str(a.value), span: self.span(a.start, a.end) }
    }

    /// The top-level elements (more than one only in a malformed file).
    pub fn roots(&self) -> Children<'_> {
        Children { doc: self, next: 0, end: self.nodes.len() as u32 }
    }
}

/// An attribute: name (local part), value (entities resolved) and the span of the value.
#[derive(Clone, Copy, Debug)]
pub struct Attr<'d> {
    /// Local name.
    pub name: &'d str,
    /// Value, entities resolved.
    pub value: &'d str,
    /// Span of the value as written.
    pub span: Span,
}

/// An element: a handle onto the document's arena.
#[derive(Clone, Copy)]
pub struct Element<'d> {
    doc: &'d Document<'d>,
    /// Invariant: a valid index of `doc.nodes` (handles are only made by [`Children`]).
    idx: u32,
}

impl std::fmt::Debug for Element<'_> {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "<{}> at {:?}", self.name(), self.span())
    }
}

/// The child elements of an element (or the roots of a document), in document order.
#[derive(Clone)]
pub struct Children<'d> {
    doc: &'d Document<'d>,
    next: u32,
    end: u32,
}

impl<'d> Iterator for Children<'d> {
    type Item = Element<'d>;

    #[inline]
    fn next(&mut self) -> Option<Element<'d>> {
        if self.next >= self.end {
            return None;
        }
        let idx = self.next;
        let after = self.doc.nodes.get(idx as usize)?.subtree_end;
        // `subtree_end > idx` for every closed node; `max` keeps a bad value from looping.
        self.next = after.max(idx + 1);
        Some(Element { doc: self.doc, idx })
    }
}

impl<'d> Element<'d> {
    #[inline]
    fn node(self) -> &'d Node {
        // `idx` is valid (see the field); index rather than `get` keeps the accessors total.
        &self.doc.nodes[self.idx as usize]
    }

    /// Local name (namespace prefix dropped).
    #[inline]
    pub fn name(self) -> &'d str {
        self.doc.str(self.node().name)
    }

    /// From `<` to the end of the end tag.
    #[inline]
    pub fn span(self) -> Span {
        let n = self.node();
        self.doc.span(n.start, n.end)
    }

    /// The element's source text, from `<` to the end of its end tag (to keep an element
    /// the lowering does not interpret as written).
    pub fn source_text(self) -> &'d str {
        let n = self.node();
        self.doc.src.get(n.start as usize..n.end as usize).unwrap_or("")
    }

    /// Span of the text without surrounding white space (the element's span if none).
    pub fn text_span(self) -> Span {
        let n = self.node();
        let t = n.text;
        if t.len == OWNED {
            let (start, end) =
                self.doc.strings.get(t.at as usize).map_or((0, 0), |o| (o.start, o.end));
            return self.doc.span(start, end);
        }
        if t.len == 0 {
            return self.doc.span(n.start, n.end);
        }
        self.doc.span(t.at, t.at + trim_end(self.doc.str(t)).len() as u32)
    }

    /// The text and CDATA content, entities resolved, leading white space dropped.
    #[inline]
    pub fn raw_text(self) -> &'d str {
        self.doc.str(self.node().text)
    }

    /// The text, trimmed.
    #[inline]
    pub fn text(self) -> &'d str {
        trim_end(self.raw_text())
    }

    /// The child elements, in document order.
    #[inline]
    pub fn children(self) -> Children<'d> {
        let n = self.node();
        Children { doc: self.doc, next: self.idx + 1, end: n.subtree_end }
    }

    /// Whether the element is called `name` (lengths compared first: most are not).
    ///
    /// This and the lookups by name are always inlined: the lowering calls them with literal
    /// names, and a comparison with a known name is a length test and a load or two, where
    /// one with an unknown name is a call to `memcmp`.
    #[inline(always)]
    pub fn is(self, name: &str) -> bool {
        let n = self.node().name;
        if n.len == OWNED {
            return self.doc.str(n) == name;
        }
        // Bytes rather than `str` slicing: no char-boundary checks on this hot path.
        n.len == name.len() as u32
            && self.doc.src.as_bytes().get(n.at as usize..(n.at + n.len) as usize)
                == Some(name.as_bytes())
    }

    /// The first child called `name`.
    #[inline(always)]
    pub fn child(self, name: &str) -> Option<Element<'d>> {
        self.children().find(|c| c.is(name))
    }

    /// The first child called each of `names` (as [`Self::child`] would find it), in one pass
    /// over the children: the lowering reads several children of every object, sub-item and
    /// PDO entry, and one scan per name (most of them over all children, for the absent ones)
    /// cost more than building the model.
    #[inline(always)]
    pub fn pick<const N: usize>(self, names: [&str; N]) -> [Option<Element<'d>>; N] {
        let mut found = [None; N];
        let mut missing = N;
        for c in self.children() {
            let name = c.name().as_bytes();
            // Names known (inlined): each comparison is a length test and a load or two.
            let Some(i) = names.iter().position(|n| n.as_bytes() == name) else { continue };
            if let Some(slot @ None) = found.get_mut(i) {
                *slot = Some(c);
                missing -= 1;
                if missing == 0 {
                    break;
                }
            }
        }
        found
    }

    /// The children called `name`.
    #[inline(always)]
    pub fn children_named<'a>(self, name: &'a str) -> impl Iterator<Item = Element<'d>> + 'a
    where
        'd: 'a,
    {
        self.children().filter(move |c| c.is(name))
    }

    /// This element's run of the attribute arena.
    #[inline]
    fn raw_attrs(self) -> &'d [RawAttr] {
        let doc = self.doc;
        let from = self.node().attr_start as usize;
        let to =
            doc.nodes.get(self.idx as usize + 1).map_or(doc.attrs.len(), |n| n.attr_start as usize);
        doc.attrs.get(from..to).unwrap_or_default()
    }

    /// The attributes, in document order.
    #[inline]
    pub fn attrs(self) -> impl Iterator<Item = Attr<'d>> {
        let doc = self.doc;
        self.raw_attrs().iter().map(move |a| doc.attr(a))
    }

    /// The attribute called `name` (local name).
    ///
    /// Always inlined, as [`Self::is`]: the lowering looks up a dozen literal names on every
    /// object and sub-object of a CiA 311 file, and against a known name each attribute costs a
    /// length test, rarely a load or two.
    #[inline(always)]
    pub fn attr(self, name: &str) -> Option<Attr<'d>> {
        // Names compared before the value and span of each are looked up.
        let doc = self.doc;
        let src = doc.src.as_bytes();
        let a = self.raw_attrs().iter().find(|a| {
            let n = a.name;
            if n.len == OWNED {
                return doc.str(n) == name;
            }
            n.len == name.len() as u32
                && src.get(n.at as usize..(n.at + n.len) as usize) == Some(name.as_bytes())
        })?;
        Some(doc.attr(a))
    }
}

#[cfg(test)]
mod tests {
    use super::reader::xml_blank;
    use super::*;

    #[test]
    fn spans_and_text() {
        let src =
            "<?xml version=\"1.0\"?>\n<a x=\"#x10\"><b> hi &amp; <![CDATA[<c>]]> </b><e/></a>";
        let doc = read(src, FileId(0));
        assert!(doc.diagnostics.is_empty(), "{:?}", doc.diagnostics);
        let a = doc.roots().next().unwrap();
        assert_eq!(&src[a.span().range()], &src[22..]);
        let x = a.attr("x").unwrap();
        assert_eq!(&src[x.span.range()], "#x10");
        let b = a.child("b").unwrap();
        assert_eq!(b.text(), "hi & <c>");
        assert_eq!(&src[b.text_span().range()], "hi &amp; <![CDATA[<c>");
        assert!(a.child("e").is_some());
    }

    /// A U+FEFF left at the start of the decoded text (a file with two byte-order marks; the
    /// decoder drops the first) is reported, and the spans still point into the text: quick-xml
    /// skips the mark without counting it (found by fuzzing: a label ending before it started).
    #[test]
    fn a_second_byte_order_mark_is_reported_and_spans_stay_in_place() {
        let src = "\u{FEFF}<?xml version=\"1.0\"?>\n<a x=\"1\"><b>hi</b></a>";
        let doc = read(src, FileId(0));
        let msgs: Vec<_> = doc.diagnostics.iter().map(|d| d.message.as_str()).collect();
        assert_eq!(msgs, ["a second byte-order mark (U+FEFF)"]);
        assert_eq!(doc.diagnostics[0].labels[0].span.range(), 0..3);
        let a = doc.roots().next().unwrap();
        assert_eq!(&src[a.span().range()], "<a x=\"1\"><b>hi</b></a>");
        assert_eq!(&src[a.attr("x").unwrap().span.range()], "1");
        assert_eq!(&src[a.child("b").unwrap().text_span().range()], "hi");
        // The fuzzer's input: text before the root, then a broken document.
        let src = "\u{FEFF}D?<Modules>on=\"1.0\"?>\n<EthrCeATInfo>\n  <Vendor>< <Devices>";
        let doc = read(src, FileId(0));
        assert!(doc.diagnostics.len() >= 2, "{:?}", doc.diagnostics);
        for d in doc.diagnostics.iter() {
            for l in &d.labels {
                assert!(l.span.start <= l.span.end && l.span.end as usize <= src.len(), "{d:?}");
            }
        }
        let outside = doc.diagnostics.iter().find(|d| d.message == "text outside the root element");
        assert_eq!(&src[outside.unwrap().labels[0].span.range()], "D?");
    }

    /// The attributes read from a tag's bytes ([`reader::Builder::plain_attributes`]) are those
    /// quick-xml's iterator gives, whichever of the two reads a tag: names (local part), values
    /// (normalised) and value spans; and a duplicate is still reported.
    #[test]
    fn attributes_as_quick_xml_reads_them() {
        let tags = [
            r#"<a x="1" y='two' z="" />"#,
            r#"<a p:x="1" q:y="2"/>"#,
            "<a\tx=\"1\"\n  y=\"2\"\r\n>t</a>",
            r#"<a x="it's" y='say "hi"'/>"#,
            r#"<a x="a&amp;b" y="&#x41;"/>"#,
            "<a x=\"tab\there\" y=\"line\nend\"/>",
            r#"<a x = "spaced" y= '1' z ="2"/>"#,
            r#"<a x="1>2" y="/"/>"#,
            // No blank between two attributes: quick-xml reads both, and so does the tree.
            r#"<a x="1"y="2"/>"#,
            r#"<a uniqueIDRef="UID_PARAM_1000" index="1000" name="Device type" objectType="7"/>"#,
            r#"<a xmlns="urn:x" xmlns:xsi="urn:y" xsi:type="t"/>"#,
        ];
        for src in tags {
            let doc = read(src, FileId(0));
            assert!(doc.diagnostics.is_empty(), "{src}: {:?}", doc.diagnostics);
            let got: Vec<_> = doc
                .roots()
                .next()
                .unwrap()
                .attrs()
                .map(|a| (a.name.to_string(), a.value.to_string(), src[a.span.range()].to_string()))
                .collect();
            let mut reader = quick_xml::Reader::from_str(src);
            let start = loop {
                match reader.read_event().unwrap() {
                    Event::Start(e) | Event::Empty(e) => break e.into_owned(),
                    _ => {}
                }
            };
            let want: Vec<_> = start
                .attributes()
                .map(|a| {
                    let a = a.unwrap();
                    let raw = a.value.to_string();
                    let name = a.key.local_name().as_ref().to_string();
                    let value = a.normalized_value(XmlVersion::Implicit1_0).unwrap().into_owned();
                    (name, value, raw)
                })
                .collect();
            assert_eq!(got, want, "{src}");
        }
        for src in [r#"<a x="1" x="2"/>"#, r#"<a p:x="1" p:x='2'/>"#] {
            let doc = read(src, FileId(0));
            assert!(
                doc.diagnostics.iter().any(|d| d.code == codes::MALFORMED_XML),
                "{src}: {:?}",
                doc.diagnostics
            );
        }
    }

    #[test]
    fn node_is_32_bytes() {
        // The arena is about the size of the text because of this (see the module docs).
        assert_eq!(std::mem::size_of::<Node>(), 32);
    }

    #[test]
    fn text_spans_of_every_kind() {
        let src = "<a><b> x </b><c><![CDATA[ y ]]></c><d>p<e/>q</d><f/><g></g><h><![CDATA[]]></h>\
                   <i>&amp;</i><j>  </j><k>cut";
        let doc = read(src, FileId(0));
        let a = doc.roots().next().unwrap();
        let at = |name: &str| {
            let e = a.child(name).unwrap();
            (e.raw_text(), &src[e.text_span().range()], &src[e.span().range()])
        };
        assert_eq!(at("b"), (" x ".trim_start(), "x", "<b> x </b>"));
        // CDATA keeps its blanks in the text; its span is the whole content.
        assert_eq!(at("c"), (" y ", " y ", "<c><![CDATA[ y ]]></c>"));
        // Text around a child: pieces joined, span from the first to the last.
        assert_eq!(at("d"), ("pq", "p<e/>q", "<d>p<e/>q</d>"));
        // No text: the element's span.
        assert_eq!(at("f"), ("", "<f/>", "<f/>"));
        assert_eq!(at("g"), ("", "<g></g>", "<g></g>"));
        assert_eq!(at("j"), ("", "<j>  </j>", "<j>  </j>"));
        // Empty CDATA: an empty span where its content would be.
        let h = a.child("h").unwrap();
        let content = (src.find("<h>").unwrap() + "<h><![CDATA[".len()) as u32;
        assert_eq!((h.raw_text(), h.text_span().start, h.text_span().end), ("", content, content));
        assert_eq!(at("i"), ("&", "&amp;", "<i>&amp;</i>"));
        // Cut off by the end of the file: the text as read, or without text the start tag.
        assert_eq!(at("k"), ("cut", "cut", "<k>cut"));
        let doc = read("<a><b>", FileId(0));
        let b = doc.roots().next().unwrap().child("b").unwrap();
        assert_eq!((b.text_span().start, b.text_span().end), (3, 6));
    }

    #[test]
    fn blank_runs() {
        for s in
            ["", " ", "\r\n\t\t\t\t\t\t\t\t", "        \n", "\t\t\t\t\t\t\t\t\t\t\t\t\t\t\t\t\t"]
        {
            assert!(xml_blank(s.as_bytes()), "{s:?}");
        }
        for s in
            ["x", "\t\t\t\t\t\t\t\tx", "\t\t\t\t\t\t\tx\t", "\u{a0}", "\x0c", "\t\t\t\t\t\t\t\x00"]
        {
            assert!(!xml_blank(s.as_bytes()), "{s:?}");
        }
        // Every single byte value at every position of a word.
        for b in 0..=255u8 {
            for at in 0..9 {
                let mut v = vec![b' '; 9];
                v[at] = b;
                let expected = matches!(b, b' ' | b'\t' | b'\n' | b'\r');
                assert_eq!(xml_blank(&v), expected, "{b:#x} at {at}");
            }
        }
    }

    #[test]
    fn errors_have_positions() {
        let doc = read("<a><b></a>", FileId(0));
        assert_eq!(doc.diagnostics.len(), 1);
        assert_eq!(doc.diagnostics[0].code, codes::MALFORMED_XML);
        let doc = read("<a></a>junk", FileId(0));
        assert_eq!(doc.diagnostics[0].code, codes::MALFORMED_XML);
    }

    #[test]
    fn depth_limited() {
        let src = format!("{}{}", "<a>".repeat(1000), "</a>".repeat(1000));
        let doc = read(&src, FileId(0));
        assert!(doc.diagnostics.iter().any(|d| d.code == codes::DEPTH_LIMIT));
        assert_eq!(doc.diagnostics.len(), 1);
    }

    #[test]
    fn doctype_not_resolved() {
        let src = "<!DOCTYPE a [<!ENTITY x SYSTEM \"file:///etc/passwd\">]><a>&x;</a>";
        let doc = read(src, FileId(0));
        assert_eq!(doc.roots().next().unwrap().text(), "&x;");
        assert!(doc.diagnostics.iter().any(|d| d.code == codes::DOCTYPE_IGNORED));
    }
}
