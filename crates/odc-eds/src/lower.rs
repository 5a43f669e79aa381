//! Lowering: raw sections and entries → [`odc_model::Device`], with diagnostics.

use std::collections::BTreeMap;

use odc_model::trim::trim;
use odc_model::{
    Access, Commissioning, DataType, Device, Diagnostic, FileId, Format, Module, Name, Object,
    ObjectKind, ObjectList, PdoMapping, RawEntry, RawSection, Severity, Span, Spanned, SubExtend,
    SubObject, Value, ValueClass,
};

use crate::num;
use crate::raw::{Entry, RawFile, Section};
use crate::rules::codes;

/// The note of a value that does not read: the model keeps its text.
const KEPT_AS_WRITTEN: &str = "the text is kept as written";

/// The name CiA 306 tools give the implied sub-index 0 of a compact object.
pub(crate) const COMPACT_SUB0_NAME: &str = "NrOfObjects";

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Kind {
    FileInfo,
    DeviceInfo,
    DummyUsage,
    Comments,
    ObjList(u8),
    Commissioning,
    SupportedModules,
    ConnectedModules,
    Object(u16),
    Sub(u16, u8),
    Name(u16),
    Value(u16),
    Denotation(u16),
    Links(u16),
    ModInfo(u16),
    ModFixedObjects(u16),
    ModFixed(u16, u16),
    ModFixedSub(u16, u16, u8),
    ModSubExtends(u16),
    ModSubExt(u16, u16),
    ModComments(u16),
    Malformed,
    Unknown,
}

fn hex4(b: &[u8]) -> Option<u16> {
    if b.len() != 4 {
        return None;
    }
    let mut v = 0u16;
    for &c in b {
        let d = num::hex_digit(c)?;
        v = (v << 4) | u16::from(d);
    }
    Some(v)
}

fn hex_u8(b: &[u8]) -> Option<u8> {
    if b.is_empty() || b.len() > 4 {
        return None;
    }
    let mut v = 0u32;
    for &c in b {
        let d = num::hex_digit(c)?;
        v = (v << 4) | u32::from(d);
    }
    u8::try_from(v).ok()
}

fn dec_u16(b: &[u8]) -> Option<u16> {
    if b.is_empty() || b.len() > 5 || !b.iter().all(u8::is_ascii_digit) {
        return None;
    }
    b.iter()
        .try_fold(0u32, |v, &c| Some(v * 10 + u32::from(c - b'0')))
        .and_then(|v| u16::try_from(v).ok())
}

fn strip_prefix_ci<'b>(b: &'b [u8], p: &str) -> Option<&'b [u8]> {
    if b.len() >= p.len() && b[..p.len()].eq_ignore_ascii_case(p.as_bytes()) {
        Some(&b[p.len()..])
    } else {
        None
    }
}

/// Classifies the part after a 4-hex-digit index: ``, `subN`, `Name`, `Value`, ...
fn classify_object_tail(index: u16, tail: &[u8]) -> Kind {
    if tail.is_empty() {
        return Kind::Object(index);
    }
    if let Some(s) = strip_prefix_ci(tail, "sub") {
        return hex_u8(s).map_or(Kind::Malformed, |s| Kind::Sub(index, s));
    }
    if tail.eq_ignore_ascii_case(b"Name") {
        Kind::Name(index)
    } else if tail.eq_ignore_ascii_case(b"Value") {
        Kind::Value(index)
    } else if tail.eq_ignore_ascii_case(b"Denotation") {
        Kind::Denotation(index)
    } else if tail.eq_ignore_ascii_case(b"ObjectLinks") {
        Kind::Links(index)
    } else {
        Kind::Malformed
    }
}

fn classify(name: &str) -> Kind {
    let b = name.as_bytes();
    if b.len() >= 4
        && let Some(index) = hex4(&b[..4])
    {
        let k = classify_object_tail(index, &b[4..]);
        // Names such as `[DEADBEEF]` that are not ours: only report when it looks like ours.
        return k;
    }
    const NAMED: &[(&str, Kind)] = &[
        ("FileInfo", Kind::FileInfo),
        ("DeviceInfo", Kind::DeviceInfo),
        ("DummyUsage", Kind::DummyUsage),
        ("Comments", Kind::Comments),
        ("MandatoryObjects", Kind::ObjList(0)),
        ("OptionalObjects", Kind::ObjList(1)),
        ("ManufacturerObjects", Kind::ObjList(2)),
        ("DeviceComissioning", Kind::Commissioning),
        ("DeviceCommissioning", Kind::Commissioning),
        ("SupportedModules", Kind::SupportedModules),
        ("ConnectedModules", Kind::ConnectedModules),
    ];
    for &(n, k) in NAMED {
        if name.eq_ignore_ascii_case(n) {
            return k;
        }
    }
    // Modules: M<decimal><rest>.
    if b.len() > 2 && (b[0] == b'M' || b[0] == b'm') && b[1].is_ascii_digit() {
        let digits = b[1..].iter().take_while(|c| c.is_ascii_digit()).count();
        let Some(x) = dec_u16(&b[1..1 + digits]) else { return Kind::Unknown };
        let rest = &b[1 + digits..];
        if rest.eq_ignore_ascii_case(b"ModuleInfo") {
            return Kind::ModInfo(x);
        }
        if rest.eq_ignore_ascii_case(b"FixedObjects") {
            return Kind::ModFixedObjects(x);
        }
        if rest.eq_ignore_ascii_case(b"SubExtends") {
            return Kind::ModSubExtends(x);
        }
        if rest.eq_ignore_ascii_case(b"Comments") {
            return Kind::ModComments(x);
        }
        if let Some(t) = strip_prefix_ci(rest, "SubExt")
            && let Some(i) = hex4(t)
        {
            return Kind::ModSubExt(x, i);
        }
        if let Some(t) = strip_prefix_ci(rest, "Fixed")
            && t.len() >= 4
            && let Some(i) = hex4(&t[..4])
        {
            return match classify_object_tail(i, &t[4..]) {
                Kind::Object(i) => Kind::ModFixed(x, i),
                Kind::Sub(i, s) => Kind::ModFixedSub(x, i, s),
                _ => Kind::Malformed,
            };
        }
    }
    Kind::Unknown
}

/// The sections that make one object.
#[derive(Default)]
struct ObjB<'s> {
    main: Option<u32>,
    subs: SubSections<'s>,
    name: Option<u32>,
    value: Option<u32>,
    denotation: Option<u32>,
    links: Option<u32>,
}

/// Where an object section belongs: owner (0 the device, m + 1 module m's fixed objects),
/// object index, role, sub-index, packed so that sorting the sections by it groups each
/// object's sections, roles in order, sub-objects by sub-index. All object sections of a file
/// go into one vector that is sorted once (files list them in order, so it usually already
/// is): no map and no vector per object.
fn section_key(owner: u32, index: u16, role: u8, sub: u8) -> u64 {
    (u64::from(owner) << 32) | (u64::from(index) << 16) | (u64::from(role) << 8) | u64::from(sub)
}

const ROLE_MAIN: u8 = 0;
const ROLE_SUB: u8 = 1;
const ROLE_NAME: u8 = 2;
const ROLE_VALUE: u8 = 3;
const ROLE_DENOTATION: u8 = 4;
const ROLE_LINKS: u8 = 5;

/// The sub-object sections of one object: a run of the sorted section vector, `(key,
/// section)` by sub-index. A sub-index given twice (spelt differently: `sub1`, `sub01`) is
/// the later section.
#[derive(Default, Clone, Copy)]
struct SubSections<'s>(&'s [(u64, u32)]);

impl<'s> SubSections<'s> {
    fn is_empty(&self) -> bool {
        self.0.is_empty()
    }

    /// `(sub-index, section)` in sub-index order, the last of a repeated sub-index only.
    fn iter(&self) -> impl Iterator<Item = (u8, u32)> + 's {
        let v = self.0;
        v.iter()
            .enumerate()
            .filter(move |&(j, p)| v.get(j + 1).is_none_or(|q| q.0 != p.0))
            .map(|(_, &(k, i))| (k as u8, i))
    }

    fn len(&self) -> usize {
        self.iter().count()
    }

    /// The sections in sub-index order.
    fn values(&self) -> impl Iterator<Item = u32> + 's {
        self.iter().map(|(_, i)| i)
    }
}

/// Sorts the object sections (stable: among equal keys the later section comes last) and
/// calls `each(owner, index, sections)` per object, in key order.
fn group_objects<'s>(secs: &'s mut [(u64, u32)], mut each: impl FnMut(u32, u16, ObjB<'s>)) {
    if !secs.is_sorted_by_key(|p| p.0) {
        secs.sort_by_key(|p| p.0);
    }
    let secs: &'s [(u64, u32)] = secs;
    let mut rest = secs;
    while let Some(&(k, _)) = rest.first() {
        let n = rest.iter().position(|p| p.0 >> 16 != k >> 16).unwrap_or(rest.len());
        let (group, tail) = rest.split_at(n);
        rest = tail;
        let mut b = ObjB::default();
        let (mut sub_start, mut sub_end) = (0, 0);
        for (j, &(key, i)) in group.iter().enumerate() {
            match (key >> 8) as u8 {
                ROLE_MAIN => b.main = Some(i),
                ROLE_SUB => {
                    if sub_end == 0 {
                        sub_start = j;
                    }
                    sub_end = j + 1;
                }
                ROLE_NAME => b.name = Some(i),
                ROLE_VALUE => b.value = Some(i),
                ROLE_DENOTATION => b.denotation = Some(i),
                _ => b.links = Some(i),
            }
        }
        b.subs = SubSections(&group[sub_start..sub_end]);
        each((k >> 32) as u32, (k >> 16) as u16, b);
    }
}

#[derive(Default)]
struct ModB<'s> {
    info: Option<u32>,
    fixed_list: Option<u32>,
    fixed: BTreeMap<u16, ObjB<'s>>,
    sub_ext_list: Option<u32>,
    sub_ext: BTreeMap<u16, u32>,
    comments: Option<u32>,
}

/// Keys of object and sub-object sections.
#[derive(Clone, Copy, PartialEq, Eq)]
enum K {
    ParameterName,
    ObjectType,
    DataType,
    AccessType,
    PdoMapping,
    DefaultValue,
    LowLimit,
    HighLimit,
    ParameterValue,
    Denotation,
    ObjFlags,
    UploadFile,
    DownloadFile,
    SubNumber,
    CompactSubObj,
    Count,
    ObjExtend,
}

const N_KEYS: usize = 17;

/// The keys of a CompactSubObj object's section that every implied sub-object takes.
const COMPACT_TEMPLATE: [K; 10] = [
    K::DataType,
    K::AccessType,
    K::PdoMapping,
    K::DefaultValue,
    K::LowLimit,
    K::HighLimit,
    K::ParameterValue,
    K::ObjFlags,
    K::UploadFile,
    K::DownloadFile,
];

/// Whether `key` is one of [`COMPACT_TEMPLATE`]'s (the writer keeps those on the template).
pub(crate) fn is_compact_template_key(key: &str) -> bool {
    obj_key(key).is_some_and(|k| COMPACT_TEMPLATE.contains(&k))
}

fn obj_key(key: &str) -> Option<K> {
    let b = key.as_bytes();
    if b.len() < 5 {
        return None;
    }
    // Dispatch on length and first letter; at most two candidates to compare.
    let (name, k): (&str, K) = match (b.len(), b[0] | 0x20) {
        (13, b'p') => ("parametername", K::ParameterName),
        (10, b'o') => ("objecttype", K::ObjectType),
        (8, b'd') => ("datatype", K::DataType),
        (10, b'a') => ("accesstype", K::AccessType),
        (10, b'p') => ("pdomapping", K::PdoMapping),
        (12, b'd') if b[1] | 0x20 == b'o' => ("downloadfile", K::DownloadFile),
        (12, b'd') => ("defaultvalue", K::DefaultValue),
        (8, b'l') => ("lowlimit", K::LowLimit),
        (9, b'h') => ("highlimit", K::HighLimit),
        (14, b'p') => ("parametervalue", K::ParameterValue),
        (10, b'd') => ("denotation", K::Denotation),
        (8, b'o') => ("objflags", K::ObjFlags),
        (10, b'u') => ("uploadfile", K::UploadFile),
        (9, b's') => ("subnumber", K::SubNumber),
        (13, b'c') => ("compactsubobj", K::CompactSubObj),
        (5, b'c') => ("count", K::Count),
        (9, b'o') => ("objextend", K::ObjExtend),
        _ => return None,
    };
    // The names are all letters, so `b | 0x20 == lower` is a case-insensitive comparison. Keys
    // of eight bytes or more: compare the first and the last eight bytes (overlapping) as words.
    let l = name.as_bytes();
    let n = b.len();
    let eq = if n >= 8 {
        const CASE: u64 = 0x2020_2020_2020_2020;
        (le64(b, 0) | CASE) == le64(l, 0) && (le64(b, n - 8) | CASE) == le64(l, n - 8)
    } else {
        b.iter().zip(l).fold(0u8, |acc, (&x, &l)| acc | ((x | 0x20) ^ l)) == 0
    };
    eq.then_some(k)
}

/// The eight bytes of `b` at `at` as a little-endian word.
#[inline]
fn le64(b: &[u8], at: usize) -> u64 {
    let mut w = [0u8; 8];
    w.copy_from_slice(&b[at..at + 8]);
    u64::from_le_bytes(w)
}

/// The known keys of one (possibly repeated) section, last occurrence winning, and the rest.
struct Keys<'e, 'a> {
    k: [Option<&'e Entry<'a>>; N_KEYS],
    extra: Vec<&'e Entry<'a>>,
    /// Known keys given again later (in the same section or a repeat of it, `F106`/`F105`):
    /// the earlier entry and the one that replaced it. Their values are not used but still
    /// read for diagnostics ([`Lower::check_shadowed`]), so that an error in a merged section
    /// is not lost.
    shadowed: Vec<(K, &'e Entry<'a>, &'e Entry<'a>)>,
}

impl<'e, 'a> Keys<'e, 'a> {
    fn get(&self, k: K) -> Option<&'e Entry<'a>> {
        self.k[k as usize]
    }
    fn take(&mut self, k: K) -> Option<&'e Entry<'a>> {
        self.k[k as usize].take()
    }
    /// Moves the known key `k` (if present) into `extra`.
    fn move_to_extra(&mut self, k: K) {
        if let Some(e) = self.take(k) {
            self.extra.push(e);
        }
    }
}

pub(crate) struct Lower<'r, 'a> {
    raw: &'r RawFile<'a>,
    file: FileId,
    pub(crate) diags: odc_model::Capped,
    dcf_hint: bool,
    /// Report unreadable header numbers as warnings ([FileInfo]: metadata only).
    soft: bool,
    /// The next sub-object read is that of a NULL object (no AccessType needed).
    null_object: bool,
    /// Sub-objects implied by CompactSubObj so far (see [`crate::MAX_IMPLIED_SUB_OBJECTS`]).
    implied_subs: usize,
    /// The data type indexes (0x0001..=0x025F) the file has an object section for, sorted.
    defined_types: Vec<u16>,
}

fn raw_entry(e: &Entry<'_>, file: FileId) -> RawEntry {
    RawEntry { key: e.key.to_owned(), value: e.value.to_owned(), span: e.line_pos.span(file) }
}

impl<'r, 'a> Lower<'r, 'a> {
    pub(crate) fn new(raw: &'r RawFile<'a>, diags: odc_model::Capped) -> Self {
        Lower {
            raw,
            file: raw.file,
            diags,
            dcf_hint: false,
            soft: false,
            null_object: false,
            implied_subs: 0,
            defined_types: Vec::new(),
        }
    }

    fn sec(&self, i: u32) -> &'r Section<'a> {
        // Indexes come from enumerating `raw.sections`.
        &self.raw.sections[i as usize]
    }

    /// Entries of a section and of its repeats, in file order.
    fn entries(&self, first: u32) -> impl Iterator<Item = &'r Entry<'a>> + 'r {
        let raw = self.raw;
        raw.chain(first).flat_map(move |s| raw.entries_of(s).iter())
    }

    fn keys(&self, first: u32) -> Keys<'r, 'a> {
        let mut keys = Keys { k: [None; N_KEYS], extra: Vec::new(), shadowed: Vec::new() };
        // Plain loops over the section and its repeats (a closure here was not inlined).
        let mut next = Some(first);
        while let Some(i) = next {
            let s = self.sec(i);
            for e in self.raw.entries_of(s) {
                match obj_key(e.key) {
                    Some(k) => {
                        if let Some(old) = keys.k[k as usize].replace(e) {
                            keys.shadowed.push((k, old, e));
                        }
                    }
                    None => keys.extra.push(e),
                }
            }
            next = s.next_same;
        }
        keys
    }

    fn span(&self, p: crate::raw::Pos) -> Span {
        p.span(self.file)
    }

    fn raw_section(&self, first: u32) -> RawSection {
        let s = self.sec(first);
        RawSection {
            name: s.name.to_owned(),
            entries: self.entries(first).map(|e| raw_entry(e, self.file)).collect(),
            span: self.span(s.header_pos),
        }
    }

    // ----- value readers -------------------------------------------------------------------

    fn warn(&mut self, code: &'static str, msg: impl Into<String>, span: Span, label: &str) {
        self.diags.push(Diagnostic::warning(code, msg).with_label(span, label));
    }

    /// Warns about how an integer was written, if [`num::WARN_FLAGS`] says there is anything
    /// to say (rarely: the check is inlined, the warnings are not).
    #[inline(always)]
    fn int_flags(&mut self, flags: u8, e: &Entry<'_>) {
        if flags & num::WARN_FLAGS != 0 {
            self.int_flag_warnings(flags, e);
        }
    }

    fn int_flag_warnings(&mut self, flags: u8, e: &Entry<'_>) {
        let span = self.span(e.value_pos);
        if flags & num::OCTAL != 0 {
            self.warn(
                codes::OCTAL_NUMBER,
                format!("`{}` has a leading zero and is read as octal", e.value),
                span,
                "read as octal",
            );
        }
        if flags & num::SUFFIX != 0 {
            self.warn(
                codes::INTEGER_SUFFIX,
                format!("C integer suffix in `{}` ignored", e.value),
                span,
                "suffix ignored",
            );
        }
        if flags & num::NODEID_ORDER != 0 {
            self.warn(
                codes::NODEID_ORDER,
                format!("`{}`: write `$NODEID` first", e.value),
                span,
                "read as $NODEID+offset",
            );
        }
    }

    /// Runs `read` on the value; when it fails and the value has a trailing comment, runs it on
    /// the value without the comment (with a warning).
    fn with_comment_fallback<T>(
        &mut self,
        e: &Entry<'_>,
        mut read: impl FnMut(&str) -> Option<T>,
    ) -> Option<T> {
        if let Some(v) = read(e.value) {
            return Some(v);
        }
        let stripped = num::strip_inline_comment(e.value)?;
        let v = read(stripped)?;
        self.warn(
            codes::INLINE_COMMENT,
            format!("comment after the value of `{}`", e.key),
            self.span(e.value_pos),
            "comment ignored",
        );
        Some(v)
    }

    /// Reads an unsigned header number of at most `max`. `Ok(None)`: empty (warned);
    /// `Err(())`: unreadable (reported; the caller keeps the raw entry).
    fn uint(&mut self, e: &Entry<'_>, max: u64) -> Result<Option<Spanned<u64>>, ()> {
        if e.value.is_empty() {
            self.empty(e);
            return Ok(None);
        }
        let span = self.span(e.value_pos);
        let Some((v, flags)) = self.with_comment_fallback(e, num::parse_plain) else {
            let sev = if self.soft { Severity::Warning } else { Severity::Error };
            self.diags.push(
                Diagnostic::new(
                    sev,
                    codes::INVALID_VALUE,
                    format!("`{}` is not a number", e.value),
                )
                .with_label(span, format!("expected a number for `{}`", e.key))
                .with_note("numbers are decimal, 0x-hex or 0-octal"),
            );
            return Err(());
        };
        if v < 0 || v > i128::from(max) {
            self.diags.push(
                Diagnostic::new(
                    if self.soft { Severity::Warning } else { Severity::Error },
                    codes::OUT_OF_RANGE,
                    format!("`{}` does not fit `{}` (0..={max})", e.value, e.key),
                )
                .with_label(span, "out of range"),
            );
            return Err(());
        }
        self.int_flags(flags, e);
        Ok(Some(Spanned::new(v as u64, span)))
    }

    fn boolean(&mut self, e: &Entry<'_>) -> Result<Option<Spanned<bool>>, ()> {
        if e.value.is_empty() {
            self.empty(e);
            return Ok(None);
        }
        let span = self.span(e.value_pos);
        match self.with_comment_fallback(e, num::parse_bool) {
            Some(b) => Ok(Some(Spanned::new(b, span))),
            None => {
                self.diags.push(
                    Diagnostic::error(
                        codes::INVALID_VALUE,
                        format!("`{}` is not a boolean", e.value),
                    )
                    .with_label(span, format!("expected 0 or 1 for `{}`", e.key)),
                );
                Err(())
            }
        }
    }

    fn empty(&mut self, e: &Entry<'_>) {
        self.warn(
            codes::EMPTY_VALUE,
            concat(&["`", e.key, "=` has no value; treated as absent"]),
            self.span(e.line_pos),
            "empty value",
        );
    }

    fn text(&self, e: &Entry<'_>) -> Spanned<String> {
        Spanned::new(e.value.to_owned(), self.span(e.value_pos))
    }

    /// Reads a value typed by `dt`.
    fn value(&mut self, e: &Entry<'_>, dt: DataType) -> Option<Spanned<Value>> {
        let span = self.span(e.value_pos);
        let class = dt.class();
        if e.value.is_empty() {
            return match class {
                ValueClass::Text => Some(Spanned::new(Value::Text(Box::default()), span)),
                ValueClass::Bytes => Some(Spanned::new(Value::Bytes(Box::default()), span)),
                ValueClass::Unicode => Some(Spanned::new(Value::Unicode(Box::default()), span)),
                _ => {
                    self.empty(e);
                    None
                }
            };
        }
        let mut problem = Problem::Invalid;
        let read = |s: &str, problem: &mut Problem| read_value(s, dt, problem);
        let got = match read(e.value, &mut problem) {
            Some(v) => Some(v),
            None if problem == Problem::Invalid => {
                let mut p2 = Problem::Invalid;
                let r = num::strip_inline_comment(e.value).and_then(|s| read(s, &mut p2));
                if r.is_some() {
                    self.warn(
                        codes::INLINE_COMMENT,
                        format!("comment after the value of `{}`", e.key),
                        span,
                        "comment ignored",
                    );
                }
                r
            }
            None => None,
        };
        match got {
            Some((v, flags)) => {
                self.int_flags(flags, e);
                if class == ValueClass::Bytes && num::hex_has_odd_group(e.value) {
                    self.odd_hex(e, &v, dt);
                }
                Some(Spanned::new(v, span))
            }
            None => {
                let d = match problem {
                    Problem::Range => Diagnostic::error(
                        codes::OUT_OF_RANGE,
                        format!("`{}` does not fit {}", e.value, dt.name()),
                    )
                    .with_label(span, format!("out of range for {}", dt.name())),
                    Problem::Invalid => Diagnostic::new(
                        if class == ValueClass::Bytes {
                            Severity::Warning
                        } else {
                            Severity::Error
                        },
                        codes::INVALID_VALUE,
                        format!("`{}` is not a valid {} value", e.value, dt.name()),
                    )
                    .with_label(span, format!("expected {}", expected(class))),
                };
                self.diags.push(d.with_note(KEPT_AS_WRITTEN));
                Some(Spanned::new(Value::Invalid(e.value.into()), span))
            }
        }
    }

    /// Warns that an OCTET_STRING/DOMAIN value has a group of an odd number of hex digits,
    /// saying how it was read (a zero nibble in front of the group: `ABC` is `0A BC`). No note:
    /// CANopenNode files write `DefaultValue=0` on every DOMAIN, and the message says it all.
    #[cold]
    fn odd_hex(&mut self, e: &Entry<'_>, v: &Value, dt: DataType) {
        let read = match v {
            Value::Bytes(b) => b.iter().map(|x| format!("{x:02X}")).collect::<Vec<_>>().join(" "),
            _ => return,
        };
        self.diags.push(
            Diagnostic::warning(
                codes::ODD_HEX_DIGITS,
                format!(
                    "`{}` has an odd number of hex digits for {}; read as `{read}`",
                    e.value,
                    dt.name()
                ),
            )
            .with_label(self.span(e.value_pos), format!("read as `{read}`")),
        );
    }

    /// Reads a `LowLimit`/`HighLimit`: an empty one is absent whatever the type (with
    /// [`codes::EMPTY_VALUE`], as for numbers); only a value is the empty string.
    fn limit(&mut self, e: &Entry<'_>, dt: DataType) -> Option<Box<Spanned<Value>>> {
        if e.value.is_empty() {
            self.empty(e);
            return None;
        }
        self.value(e, dt).map(Box::new)
    }

    fn data_type(&mut self, e: &Entry<'_>) -> Result<Option<DataType>, ()> {
        if let Some(dt) = type_by_name(e.value) {
            self.diags.push(
                Diagnostic::error(
                    codes::INVALID_VALUE,
                    format!("DataType `{}` is a name, not a data type index", e.value),
                )
                .with_label(self.span(e.value_pos), format!("did you mean 0x{:04X}?", dt.code()))
                .with_note(format!(
                    "DataType is the index of the type's object: {} is 0x{:04X}",
                    dt.name(),
                    dt.code()
                )),
            );
            return Err(());
        }
        let Some(v) = self.uint(e, 0xFFFF)? else { return Ok(None) };
        // CiA 301 §7.4.7: data types are the objects 0x0001..=0x025F.
        if v.value == 0 || v.value > 0x025F {
            self.diags.push(
                Diagnostic::error(
                    codes::OUT_OF_RANGE,
                    format!("`{}` is not a data type index (0x0001..=0x025F)", e.value),
                )
                .with_label(v.span, "kept as written"),
            );
            return Err(());
        }
        let dt = DataType::from_code(v.value as u16);
        if let DataType::Profile(code) = dt
            && self.defined_types.binary_search(&code).is_err()
        {
            let what = match code {
                0x0040..=0x005F => "a manufacturer-specific data type",
                0x0060..=0x025F => "a device-profile data type",
                _ => "reserved",
            };
            self.diags.push(
                Diagnostic::warning(
                    codes::NOT_A_DATA_TYPE,
                    format!("`{}` is not a data type index", e.value),
                )
                .with_label(v.span, "not a data type")
                .with_note(format!(
                    "CiA 301 defines no data type 0x{code:04X} ({what}), and the file has no \
                     object [{code:04X}] defining one; values are read as plain numbers or text"
                )),
            );
        }
        Ok(Some(dt))
    }

    fn access(&mut self, e: &Entry<'_>) -> Option<Access> {
        let span = self.span(e.value_pos);
        if e.value.is_empty() {
            self.empty(e);
            return None;
        }
        let read = |s: &str| -> Option<(Access, bool)> {
            if let Some(a) = Access::parse(s) {
                Some((a, false))
            } else if s.trim().eq_ignore_ascii_case("r") {
                Some((Access::Ro, true))
            } else {
                None
            }
        };
        match self.with_comment_fallback(e, read) {
            Some((a, nonstandard)) => {
                if nonstandard {
                    self.warn(
                        codes::NONSTANDARD_ACCESS,
                        format!("AccessType `{}` is not CiA 306; read as `ro`", e.value),
                        span,
                        "read as ro",
                    );
                }
                Some(a)
            }
            None => {
                self.diags.push(
                    Diagnostic::error(
                        codes::UNKNOWN_ACCESS,
                        format!("unknown AccessType `{}`", e.value),
                    )
                    .with_label(span, "expected ro, wo, rw, rwr, rww or const")
                    .with_note("assumed ro"),
                );
                None
            }
        }
    }

    /// Reads the values that a later entry of the same key replaced (see [`Keys::shadowed`])
    /// for their diagnostics only: each diagnostic gets a note and a label at the entry that
    /// replaced the value; only errors are kept. Values typed by the data type are read with
    /// `dt` when it is known.
    #[cold]
    fn check_shadowed(&mut self, keys: &mut Keys<'r, 'a>, dt: Option<DataType>) {
        for (k, e, by) in std::mem::take(&mut keys.shadowed) {
            let outer = std::mem::take(&mut self.diags);
            match k {
                K::DataType => {
                    let _ = self.data_type(e);
                }
                K::AccessType => {
                    let _ = self.access(e);
                }
                K::PdoMapping => {
                    let _ = self.boolean(e);
                }
                K::ObjectType => {
                    let _ = self.object_kind(e);
                }
                K::ObjFlags => {
                    let _ = self.uint(e, u64::from(u32::MAX));
                }
                K::SubNumber => {
                    let _ = self.uint(e, 0xFFFF);
                }
                K::CompactSubObj => {
                    let _ = self.uint(e, 0xFF);
                }
                K::DefaultValue | K::ParameterValue => {
                    if let Some(dt) = dt {
                        let _ = self.value(e, dt);
                    }
                }
                K::LowLimit | K::HighLimit => {
                    if let Some(dt) = dt {
                        let _ = self.limit(e, dt);
                    }
                }
                K::ParameterName
                | K::Denotation
                | K::UploadFile
                | K::DownloadFile
                | K::Count
                | K::ObjExtend => {}
            }
            let found = std::mem::replace(&mut self.diags, outer).finish();
            let by = self.span(by.key_pos);
            // Errors only: how a replaced value was written (octal, a suffix) is noise.
            for mut d in found.into_iter().filter(Diagnostic::is_error) {
                d.notes.retain(|n| n != KEPT_AS_WRITTEN);
                self.diags.push(
                    d.with_secondary(by, "replaced by this later value").with_note(format!(
                        "the value is not used: a later `{}=` replaces it",
                        e.key
                    )),
                );
            }
        }
    }

    // ----- sections --------------------------------------------------------------------------

    pub(crate) fn run(mut self, name: &str) -> (Device, Vec<Diagnostic>) {
        let lname = name.as_bytes();
        self.dcf_hint = lname.len() >= 4 && lname[lname.len() - 4..].eq_ignore_ascii_case(b".dcf");
        let mut dev = Device::default();
        let mut secs: Vec<(u64, u32)> = Vec::with_capacity(self.raw.sections.len());
        let mut objects = 0usize;
        let mut modules: BTreeMap<u16, ModB<'_>> = BTreeMap::new();
        let mut extra: Vec<(u32, RawSection)> = Vec::new();
        let mut has_value_sections = false;

        for (i, s) in self.raw.sections.iter().enumerate() {
            if s.is_duplicate {
                continue;
            }
            let i = i as u32;
            let kind = classify(s.name);
            match kind {
                Kind::FileInfo => self.file_info(i, &mut dev),
                Kind::DeviceInfo => self.device_info(i, &mut dev),
                Kind::DummyUsage => self.dummy_usage(i, &mut dev, &mut extra),
                Kind::Comments => {
                    dev.comments = self.comments(i, &mut extra);
                }
                Kind::ObjList(n) => {
                    let list = self.object_list(i, "SupportedObjects", &mut extra);
                    let slot = match n {
                        0 => &mut dev.object_lists.mandatory,
                        1 => &mut dev.object_lists.optional,
                        _ => &mut dev.object_lists.manufacturer,
                    };
                    *slot = Some(list);
                }
                Kind::Commissioning => self.commissioning(i, &mut dev),
                Kind::SupportedModules => {
                    // The modules are the [MxModuleInfo] sections; NrOfEntries is kept for
                    // odc-check to compare with them.
                    let count = self
                        .entries(i)
                        .filter(|e| e.key.eq_ignore_ascii_case("NrOfEntries"))
                        .last()
                        .and_then(|e| self.uint(e, 0xFFFF).ok().flatten());
                    dev.modules.nr_of_entries = count.map(|v| Spanned::new(v.value as u16, v.span));
                    self.list_section(i, "NrOfEntries", &mut extra);
                }
                Kind::ConnectedModules => {
                    let l = self.list_section(i, "NrOfEntries", &mut extra);
                    dev.modules.connected = l
                        .into_iter()
                        .filter_map(|(e, _)| self.uint(e, 0xFFFF).ok().flatten())
                        .map(|v| Spanned::new(v.value as u16, v.span))
                        .collect();
                }
                Kind::Object(x) => {
                    objects += 1;
                    if x <= 0x025F {
                        self.defined_types.push(x);
                    }
                    secs.push((section_key(0, x, ROLE_MAIN, 0), i));
                }
                Kind::Sub(x, s) => secs.push((section_key(0, x, ROLE_SUB, s), i)),
                Kind::Name(x) => secs.push((section_key(0, x, ROLE_NAME, 0), i)),
                Kind::Value(x) => {
                    has_value_sections = true;
                    secs.push((section_key(0, x, ROLE_VALUE, 0), i));
                }
                Kind::Denotation(x) => secs.push((section_key(0, x, ROLE_DENOTATION, 0), i)),
                Kind::Links(x) => secs.push((section_key(0, x, ROLE_LINKS, 0), i)),
                Kind::ModInfo(m) => modules.entry(m).or_default().info = Some(i),
                Kind::ModFixedObjects(m) => modules.entry(m).or_default().fixed_list = Some(i),
                Kind::ModFixed(m, x) => {
                    modules.entry(m).or_default();
                    secs.push((section_key(u32::from(m) + 1, x, ROLE_MAIN, 0), i));
                }
                Kind::ModFixedSub(m, x, s) => {
                    modules.entry(m).or_default();
                    secs.push((section_key(u32::from(m) + 1, x, ROLE_SUB, s), i));
                }
                Kind::ModSubExtends(m) => modules.entry(m).or_default().sub_ext_list = Some(i),
                Kind::ModSubExt(m, x) => {
                    modules.entry(m).or_default().sub_ext.insert(x, i);
                }
                Kind::ModComments(m) => modules.entry(m).or_default().comments = Some(i),
                Kind::Malformed => {
                    self.warn(
                        codes::MALFORMED_OBJECT_SECTION,
                        format!(
                            "section name [{}] looks like an object but does not parse",
                            s.name
                        ),
                        self.span(s.name_pos),
                        "kept as an unknown section",
                    );
                    extra.push((i, self.raw_section(i)));
                }
                Kind::Unknown => {
                    // `[$NODEID+0x2000]`, `[Obj 2000]`: object keys under a name that is no
                    // object index.
                    let object_like = self.entries(i).any(|e| {
                        e.key.eq_ignore_ascii_case("ParameterName")
                            || e.key.eq_ignore_ascii_case("ObjectType")
                    });
                    if object_like {
                        self.warn(
                            codes::MALFORMED_OBJECT_SECTION,
                            format!(
                                "section [{}] has object keys but its name is not an object index",
                                s.name
                            ),
                            self.span(s.name_pos),
                            "kept as an unknown section",
                        );
                    }
                    extra.push((i, self.raw_section(i)));
                }
            }
        }

        self.defined_types.sort_unstable();
        let mut built: Vec<(u16, Object)> = Vec::with_capacity(objects);
        group_objects(&mut secs, |owner, index, b| {
            if owner > 0 {
                // Module fixed objects are read with their module, below.
                let m = (owner - 1) as u16;
                modules.entry(m).or_default().fixed.insert(index, b);
                return;
            }
            match self.object(index, &b, &mut extra) {
                Some(o) => built.push((index, o)),
                None => {
                    // Orphan companions: kept as unknown sections.
                    let orphans = b
                        .subs
                        .values()
                        .chain(b.name)
                        .chain(b.value)
                        .chain(b.denotation)
                        .chain(b.links);
                    for i in orphans {
                        let s = self.sec(i);
                        self.warn(
                            codes::ORPHAN_SECTION,
                            format!("[{}] has no object section [{:04X}]", s.name, index),
                            self.span(s.name_pos),
                            "kept as an unknown section",
                        );
                        extra.push((i, self.raw_section(i)));
                    }
                }
            }
        });

        // In index order: built in bulk.
        dev.objects = built.into_iter().collect();

        for (number, b) in &modules {
            let m = self.module(*number, b, &mut extra);
            dev.modules.supported.push(m);
        }

        extra.sort_by_key(|(i, _)| *i);
        dev.extra_sections = extra.into_iter().map(|(_, s)| s).collect();

        // ParameterValue, Denotation and [ConnectedModules] exist in DCFs only (the EDS writer
        // leaves them out), in the objects and in the modules' objects.
        let dcf_sub =
            |s: &odc_model::SubObject| s.parameter_value.is_some() || s.rare().denotation.is_some();
        let dcf_object = |o: &Object| o.denotation.is_some() || o.subs.any_ignoring_names(dcf_sub);
        let has_pv = dev.objects.values().any(dcf_object)
            || dev.modules.supported.iter().any(|m| {
                m.fixed_objects.values().any(dcf_object)
                    || m.sub_extends.values().any(|x| dcf_sub(&x.template))
            });
        let dcf_only = !dev.modules.connected.is_empty();
        dev.format = Some(
            if dev.commissioning.is_some()
                || has_pv
                || has_value_sections
                || dcf_only
                || self.dcf_hint
            {
                Format::Dcf
            } else {
                Format::Eds
            },
        );
        dev.device_info.baud_rates.sort_unstable();
        dev.device_info.baud_rates.dedup();
        crate::compact_pdo::synthesise(&mut dev);
        dev.pdos = odc_model::pdo::resolve_canopen_pdos(&dev);
        (dev, self.diags.finish())
    }

    fn file_info(&mut self, first: u32, dev: &mut Device) {
        self.soft = true;
        self.file_info_inner(first, dev);
        self.soft = false;
    }

    fn file_info_inner(&mut self, first: u32, dev: &mut Device) {
        let fi = &mut dev.file_info;
        for e in self.entries(first) {
            let k = e.key;
            let is = |n: &str| k.eq_ignore_ascii_case(n);
            if is("FileName") {
                fi.file_name = Some(self.text(e));
            } else if is("FileVersion") || is("FileRevision") {
                match self.uint(e, 0xFF) {
                    Ok(v) => {
                        let v = v.map(|v| Spanned::new(v.value as u8, v.span));
                        if is("FileVersion") {
                            fi.file_version = v;
                        } else {
                            fi.file_revision = v;
                        }
                    }
                    Err(()) => fi.extra.push(raw_entry(e, self.file)),
                }
            } else if is("EDSVersion") {
                fi.eds_version = Some(self.text(e));
            } else if is("Description") {
                fi.description = Some(self.text(e));
            } else if is("CreationTime") {
                fi.creation_time = Some(self.text(e));
            } else if is("CreationDate") {
                fi.creation_date = Some(self.text(e));
            } else if is("CreatedBy") {
                fi.created_by = Some(self.text(e));
            } else if is("ModificationTime") {
                fi.modification_time = Some(self.text(e));
            } else if is("ModificationDate") {
                fi.modification_date = Some(self.text(e));
            } else if is("ModifiedBy") {
                fi.modified_by = Some(self.text(e));
            } else {
                fi.extra.push(raw_entry(e, self.file));
            }
        }
    }

    fn device_info(&mut self, first: u32, dev: &mut Device) {
        let file = self.file;
        for e in self.entries(first) {
            let k = e.key;
            let is = |n: &str| k.eq_ignore_ascii_case(n);
            let di = &mut dev.device_info;
            macro_rules! num_field {
                ($field:ident, $t:ty) => {
                    match self.uint(e, <$t>::MAX as u64) {
                        Ok(v) => {
                            dev.device_info.$field = v.map(|v| Spanned::new(v.value as $t, v.span))
                        }
                        Err(()) => dev.device_info.extra.push(raw_entry(e, file)),
                    }
                };
            }
            macro_rules! bool_field {
                ($field:ident) => {
                    match self.boolean(e) {
                        Ok(v) => dev.device_info.$field = v,
                        Err(()) => dev.device_info.extra.push(raw_entry(e, file)),
                    }
                };
            }
            if is("VendorName") {
                di.vendor_name = Some(self.text(e));
            } else if is("ProductName") {
                di.product_name = Some(self.text(e));
            } else if is("OrderCode") {
                di.order_code = Some(self.text(e));
            } else if is("VendorNumber") {
                num_field!(vendor_number, u32);
            } else if is("ProductNumber") {
                num_field!(product_number, u32);
            } else if is("RevisionNumber") {
                num_field!(revision_number, u32);
            } else if is("Granularity") {
                num_field!(granularity, u8);
            } else if is("DynamicChannelsSupported") {
                num_field!(dynamic_channels_supported, u8);
            } else if is("NrOfRXPDO") {
                num_field!(nr_of_rx_pdo, u16);
            } else if is("NrOfTXPDO") {
                num_field!(nr_of_tx_pdo, u16);
            } else if is("CompactPDO") {
                num_field!(compact_pdo, u8);
            } else if is("SimpleBootUpMaster") {
                bool_field!(simple_boot_up_master);
            } else if is("SimpleBootUpSlave") {
                bool_field!(simple_boot_up_slave);
            } else if is("GroupMessaging") {
                bool_field!(group_messaging);
            } else if is("LSS_Supported") {
                bool_field!(lss_supported);
            } else if let Some(rate) = strip_prefix_ci(k.as_bytes(), "BaudRate_").and_then(dec_u16)
            {
                match self.boolean(e) {
                    Ok(Some(b)) => {
                        if b.value {
                            dev.device_info.baud_rates.push(u32::from(rate));
                        }
                    }
                    Ok(None) => {}
                    Err(()) => dev.device_info.extra.push(raw_entry(e, file)),
                }
            } else {
                di.extra.push(raw_entry(e, file));
            }
        }
    }

    fn unexpected(&mut self, e: &Entry<'_>, section: &str) {
        self.warn(
            codes::UNEXPECTED_KEY,
            format!("key `{}` does not belong in [{}]", e.key, section),
            self.span(e.key_pos),
            "kept, not interpreted",
        );
    }

    /// Keeps entries a section without an `extra` slot cannot hold, as an unknown section of
    /// the same name.
    fn keep_unexpected(
        &self,
        first: u32,
        kept: Vec<&Entry<'_>>,
        extra: &mut Vec<(u32, RawSection)>,
    ) {
        if kept.is_empty() {
            return;
        }
        let s = self.sec(first);
        extra.push((
            first,
            RawSection {
                name: s.name.to_owned(),
                entries: kept.into_iter().map(|e| raw_entry(e, self.file)).collect(),
                span: self.span(s.header_pos),
            },
        ));
    }

    fn dummy_usage(&mut self, first: u32, dev: &mut Device, extra: &mut Vec<(u32, RawSection)>) {
        let mut kept = Vec::new();
        let name = self.sec(first).name;
        for e in self.entries(first) {
            let idx = strip_prefix_ci(e.key.as_bytes(), "Dummy").and_then(hex4);
            match idx {
                Some(idx) => match self.boolean(e) {
                    Ok(Some(b)) => {
                        dev.dummy_usage.insert(idx, b);
                    }
                    Ok(None) => {}
                    Err(()) => kept.push(e),
                },
                None => {
                    self.unexpected(e, name);
                    kept.push(e);
                }
            }
        }
        self.keep_unexpected(first, kept, extra);
    }

    fn comments(&mut self, first: u32, extra: &mut Vec<(u32, RawSection)>) -> Vec<String> {
        let mut lines: BTreeMap<u16, String> = BTreeMap::new();
        let mut kept = Vec::new();
        let name = self.sec(first).name;
        for e in self.entries(first) {
            if e.key.eq_ignore_ascii_case("Lines") {
                continue; // implied by the LineN keys
            }
            match strip_prefix_ci(e.key.as_bytes(), "Line").and_then(dec_u16) {
                Some(n) => {
                    lines.insert(n, e.value.to_owned());
                }
                None => {
                    self.unexpected(e, name);
                    kept.push(e);
                }
            }
        }
        self.keep_unexpected(first, kept, extra);
        lines.into_values().collect()
    }

    /// A list section: the count key (ignored, implied) and `n=value` entries in order of n.
    fn list_section(
        &mut self,
        first: u32,
        count_key: &str,
        extra: &mut Vec<(u32, RawSection)>,
    ) -> Vec<(&'r Entry<'a>, u16)> {
        let mut items: BTreeMap<u16, &'r Entry<'a>> = BTreeMap::new();
        let mut kept = Vec::new();
        let name = self.sec(first).name;
        for e in self.entries(first) {
            if e.key.eq_ignore_ascii_case(count_key) {
                continue;
            }
            match dec_u16(e.key.as_bytes()) {
                Some(n) => {
                    items.insert(n, e);
                }
                None => {
                    self.unexpected(e, name);
                    kept.push(e);
                }
            }
        }
        self.keep_unexpected(first, kept, extra);
        items.into_iter().map(|(n, e)| (e, n)).collect()
    }

    fn object_list(
        &mut self,
        first: u32,
        count_key: &str,
        extra: &mut Vec<(u32, RawSection)>,
    ) -> ObjectList {
        let mut list =
            ObjectList { span: self.span(self.sec(first).header_pos), ..Default::default() };
        if let Some(e) =
            self.entries(first).filter(|e| e.key.eq_ignore_ascii_case(count_key)).last()
        {
            match self.uint(e, 0xFFFF) {
                Ok(v) => list.supported_objects = v.map(|v| Spanned::new(v.value as u16, v.span)),
                Err(()) => self.keep_unexpected(first, vec![e], extra),
            }
        }
        for (e, _) in self.list_section(first, count_key, extra) {
            match self.uint(e, 0xFFFF) {
                Ok(Some(v)) => list.entries.push(Spanned::new(v.value as u16, v.span)),
                Ok(None) => {}
                Err(()) => self.keep_unexpected(first, vec![e], extra),
            }
        }
        list
    }

    fn commissioning(&mut self, first: u32, dev: &mut Device) {
        let file = self.file;
        let mut c =
            Commissioning { span: self.span(self.sec(first).header_pos), ..Default::default() };
        for e in self.entries(first) {
            let is = |n: &str| e.key.eq_ignore_ascii_case(n);
            macro_rules! num_field {
                ($field:ident, $t:ty) => {
                    match self.uint(e, <$t>::MAX as u64) {
                        Ok(v) => c.$field = v.map(|v| Spanned::new(v.value as $t, v.span)),
                        Err(()) => c.extra.push(raw_entry(e, file)),
                    }
                };
            }
            if is("NodeID") {
                num_field!(node_id, u8);
            } else if is("NodeName") {
                c.node_name = Some(self.text(e));
            } else if is("Baudrate") {
                num_field!(baudrate, u32);
            } else if is("NetNumber") {
                num_field!(net_number, u32);
            } else if is("NetworkName") {
                c.network_name = Some(self.text(e));
            } else if is("CANopenManager") {
                match self.boolean(e) {
                    Ok(v) => c.canopen_manager = v,
                    Err(()) => c.extra.push(raw_entry(e, file)),
                }
            } else if is("LSS_SerialNumber") {
                num_field!(lss_serial_number, u32);
            } else if is("NodeRefd") {
                c.node_refd = Some(self.text(e));
            } else if is("NetRefd") {
                c.net_refd = Some(self.text(e));
            } else {
                c.extra.push(raw_entry(e, file));
            }
        }
        if dev.commissioning.is_none() {
            dev.commissioning = Some(c);
        } else if let Some(old) = dev.commissioning.as_mut() {
            // Both spellings present: merge, later keys win.
            macro_rules! merge {
                ($($f:ident),*) => { $( if c.$f.is_some() { old.$f = c.$f; } )* };
            }
            merge!(
                node_id,
                node_name,
                baudrate,
                net_number,
                network_name,
                canopen_manager,
                lss_serial_number,
                node_refd,
                net_refd
            );
            old.extra.extend(c.extra);
        }
    }

    // ----- objects ---------------------------------------------------------------------------

    /// Fills a sub-object from known keys; leftovers go to `extra`.
    fn sub_from_keys(
        &mut self,
        keys: &mut Keys<'r, 'a>,
        sub_index: u8,
        header: Span,
        default_dt: Option<DataType>,
        what: &dyn std::fmt::Display,
    ) -> SubObject {
        let mut sub = blank_sub(sub_index);
        self.fill_sub(keys, &mut sub, header, default_dt, what);
        sub
    }

    /// Fills `sub` (fresh from [`blank_sub`]) from known keys; leftovers go to its `extra`.
    /// In place: a sub-object is large, and building it elsewhere to move it into its
    /// object's vector was a copy per sub-object.
    fn fill_sub(
        &mut self,
        keys: &mut Keys<'r, 'a>,
        sub: &mut SubObject,
        header: Span,
        default_dt: Option<DataType>,
        what: &dyn std::fmt::Display,
    ) {
        let sub_index = sub.sub_index;
        let what_is_null = std::mem::take(&mut self.null_object);
        let file = self.file;
        sub.name = match keys.take(K::ParameterName) {
            Some(e) => Name::from(e.value),
            None => {
                self.warn(
                    codes::MISSING_NAME,
                    format!("{what} has no ParameterName"),
                    header,
                    "here",
                );
                Name::default()
            }
        };
        let mut extra_entries: Vec<&Entry<'_>> = Vec::new();
        let mut unreadable = None;
        let data_type = match keys.take(K::DataType) {
            Some(e) => match self.data_type(e) {
                Ok(Some(dt)) => {
                    sub.data_type_span = self.span(e.line_pos);
                    Some(dt)
                }
                Ok(None) => None,
                Err(()) => {
                    extra_entries.push(e);
                    unreadable = Some(self.span(e.value_pos));
                    None
                }
            },
            None => None,
        };
        let data_type = match data_type.or(default_dt) {
            Some(dt) => dt,
            None => {
                let d = match unreadable {
                    Some(at) => Diagnostic::error(
                        codes::MISSING_DATA_TYPE,
                        format!("{what} has no readable DataType"),
                    )
                    .with_label(at, "not a DataType"),
                    None => Diagnostic::error(
                        codes::MISSING_DATA_TYPE,
                        format!("{what} has no DataType"),
                    )
                    .with_label(header, "DataType missing"),
                };
                self.diags.push(d.with_note("assumed DOMAIN"));
                DataType::Domain
            }
        };
        let access = match keys.take(K::AccessType) {
            Some(e) => self.access(e).unwrap_or_else(|| {
                if !e.value.is_empty() {
                    extra_entries.push(e);
                }
                Access::Ro
            }),
            None if default_dt == Some(DataType::Domain) && sub_index == 0 && what_is_null => {
                Access::Ro
            }
            None => {
                self.warn(
                    codes::MISSING_ACCESS_TYPE,
                    format!("{what} has no AccessType; assumed ro"),
                    header,
                    "AccessType missing",
                );
                Access::Ro
            }
        };
        let pdo_mapping = match keys.take(K::PdoMapping) {
            Some(e) => match self.boolean(e) {
                Ok(Some(b)) => {
                    if b.value {
                        PdoMapping::Yes
                    } else {
                        PdoMapping::No
                    }
                }
                Ok(None) => PdoMapping::No,
                Err(()) => {
                    extra_entries.push(e);
                    PdoMapping::No
                }
            },
            None => PdoMapping::No,
        };
        sub.data_type = data_type;
        sub.access = access;
        sub.pdo_mapping = pdo_mapping;
        sub.span = header;
        if let Some(e) = keys.take(K::ObjectType) {
            match self.object_kind(e) {
                Some(k) => sub.kind = Some(k),
                None => extra_entries.push(e),
            }
        }
        sub.default = keys.take(K::DefaultValue).and_then(|e| self.value(e, data_type));
        sub.low_limit = keys.take(K::LowLimit).and_then(|e| self.limit(e, data_type));
        sub.high_limit = keys.take(K::HighLimit).and_then(|e| self.limit(e, data_type));
        sub.parameter_value = keys.take(K::ParameterValue).and_then(|e| self.value(e, data_type));
        let denotation = keys.take(K::Denotation).map(|e| self.text(e));
        let mut obj_flags = None;
        if let Some(e) = keys.take(K::ObjFlags) {
            match self.uint(e, u64::from(u32::MAX)) {
                Ok(v) => obj_flags = v.map(|v| Spanned::new(v.value as u32, v.span)),
                Err(()) => extra_entries.push(e),
            }
        }
        let upload_file = keys.take(K::UploadFile).map(|e| self.text(e));
        let download_file = keys.take(K::DownloadFile).map(|e| self.text(e));
        for k in [K::SubNumber, K::CompactSubObj, K::Count, K::ObjExtend] {
            keys.move_to_extra(k);
        }
        if !keys.shadowed.is_empty() {
            self.check_shadowed(keys, Some(data_type));
        }
        let has_extra = !(extra_entries.is_empty() && keys.extra.is_empty());
        let has_rare = denotation.is_some()
            || obj_flags.is_some()
            || upload_file.is_some()
            || download_file.is_some()
            || has_extra;
        // Most sub-objects have none of these: no box is made for them.
        if has_rare || !sub.rare().is_empty() {
            let r = sub.rare_mut();
            r.denotation = denotation;
            r.obj_flags = obj_flags;
            r.upload_file = upload_file;
            r.download_file = download_file;
            if has_extra {
                r.extra = extra_entries
                    .into_iter()
                    .chain(keys.extra.drain(..))
                    .map(|e| raw_entry(e, file))
                    .collect();
            }
        }
    }

    fn object_kind(&mut self, e: &Entry<'_>) -> Option<ObjectKind> {
        let span = self.span(e.value_pos);
        let v = self.uint(e, 0xFF).ok().flatten()?;
        match ObjectKind::from_code(v.value as u8) {
            Some(k) => Some(k),
            None => {
                self.diags.push(
                    Diagnostic::error(
                        codes::INVALID_OBJECT_TYPE,
                        format!("ObjectType `{}` is not a CiA 301 object code", e.value),
                    )
                    .with_label(span, "expected 0x0, 0x2, 0x5, 0x6, 0x7, 0x8 or 0x9"),
                );
                None
            }
        }
    }

    fn object(
        &mut self,
        index: u16,
        b: &ObjB,
        extra: &mut Vec<(u32, RawSection)>,
    ) -> Option<Object> {
        let main = b.main?;
        let file = self.file;
        let header = self.span(self.sec(main).header_pos);
        let mut keys = self.keys(main);
        let mut obj_extra: Vec<&Entry<'_>> = Vec::new();
        let kind = match keys.take(K::ObjectType) {
            Some(e) => self.object_kind(e).unwrap_or_else(|| {
                obj_extra.push(e);
                // Sub-objects, explicit or implied by CompactSubObj, make it a RECORD (the writer
                // may turn explicit ones into implied ones).
                if b.subs.is_empty() && keys.get(K::CompactSubObj).is_none() {
                    ObjectKind::Var
                } else {
                    ObjectKind::Record
                }
            }),
            None => ObjectKind::Var,
        };
        let name = match keys.get(K::ParameterName) {
            Some(e) => e.value.to_owned(),
            // A VAR's sub-object 0 reports the missing name.
            None if !kind.has_subs() => String::new(),
            None => {
                self.warn(
                    codes::MISSING_NAME,
                    format!("object {index:04X} has no ParameterName"),
                    header,
                    "here",
                );
                String::new()
            }
        };
        let mut obj = Object::new(index, name, kind, header);
        if let Some(e) = keys.take(K::SubNumber) {
            match self.uint(e, 0xFFFF) {
                Ok(v) => obj.sub_number = v.map(|v| Spanned::new(v.value as u16, v.span)),
                Err(()) => obj_extra.push(e),
            }
        }
        if let Some(e) = keys.take(K::ObjFlags) {
            match self.uint(e, u64::from(u32::MAX)) {
                Ok(v) => obj.obj_flags = v.map(|v| Spanned::new(v.value as u32, v.span)),
                Err(()) => obj_extra.push(e),
            }
        }
        if kind.has_subs() {
            obj.denotation = keys.take(K::Denotation).map(|e| self.text(e));
            let compact = match keys.take(K::CompactSubObj) {
                Some(e) => match self.uint(e, 0xFF) {
                    Ok(v) => v.map(|v| Spanned::new(v.value as u8, v.span)),
                    Err(()) => {
                        obj_extra.push(e);
                        None
                    }
                },
                None => None,
            };
            obj.compact_sub_obj = compact.clone();
            let compact = compact.filter(|n| {
                self.implied_subs += usize::from(n.value);
                let over = self.implied_subs > crate::MAX_IMPLIED_SUB_OBJECTS;
                // Reported at the first object past the limit.
                if over
                    && self.implied_subs - usize::from(n.value) <= crate::MAX_IMPLIED_SUB_OBJECTS
                {
                    self.diags.push(
                        Diagnostic::error(
                            codes::COMPACT_LIMIT,
                            format!(
                                "more than {} sub-objects implied by CompactSubObj in this file; \
                                 this object and the later ones are not expanded",
                                crate::MAX_IMPLIED_SUB_OBJECTS
                            ),
                        )
                        .with_label(n.span, "the limit is crossed here"),
                    );
                }
                !over
            });
            match compact.filter(|n| n.value > 0) {
                Some(n) => self.compact_subs(&mut obj, &mut keys, n, b),
                None => obj.subs.reserve_exact(b.subs.len()),
            }
            keys.take(K::ParameterName);
            // Keys that only a VAR or a compact object uses are kept as written.
            for k in [
                K::DataType,
                K::AccessType,
                K::PdoMapping,
                K::DefaultValue,
                K::LowLimit,
                K::HighLimit,
                K::ParameterValue,
                K::UploadFile,
                K::DownloadFile,
                K::Count,
                K::ObjExtend,
            ] {
                keys.move_to_extra(k);
            }
            for (s, si) in b.subs.iter() {
                let sheader = self.span(self.sec(si).header_pos);
                let mut skeys = self.keys(si);
                let implied = obj.subs.contains_key(&s);
                let sub = obj.subs.entry(s).or_insert_with(|| blank_sub(s));
                if implied {
                    *sub = blank_sub(s);
                }
                self.fill_sub(
                    &mut skeys,
                    sub,
                    sheader,
                    None,
                    &format_args!("sub-object {index:04X}sub{s:X}"),
                );
                if implied {
                    self.warn(
                        codes::COMPACT_CONFLICT,
                        format!(
                            "[{}] overrides a sub-object implied by CompactSubObj",
                            self.sec(si).name
                        ),
                        self.span(self.sec(si).name_pos),
                        "explicit section wins",
                    );
                }
            }
        } else {
            keys.move_to_extra(K::CompactSubObj);
            self.null_object = kind == ObjectKind::Null;
            let default_dt = match kind {
                ObjectKind::Domain => Some(DataType::Domain),
                ObjectKind::Null => Some(DataType::Domain),
                ObjectKind::DefType => Some(DataType::Unsigned32),
                _ => None,
            };
            obj.subs.reserve_exact(1 + b.subs.len());
            let sub = obj.subs.entry(0).or_insert_with(|| blank_sub(0));
            self.fill_sub(&mut keys, sub, header, default_dt, &format_args!("object {index:04X}"));
            sub.kind = None;
            // Unknown keys of a VAR section belong to the object.
            if !sub.rare().extra.is_empty() {
                obj.extra.append(&mut sub.rare_mut().extra);
            }
            for (s, si) in b.subs.iter() {
                let sec = self.sec(si);
                self.warn(
                    codes::SUBS_ON_VAR,
                    format!("[{}] belongs to a {:?} object", sec.name, kind),
                    self.span(sec.name_pos),
                    "kept as a sub-object",
                );
                if s == 0 {
                    extra.push((si, self.raw_section(si)));
                    continue;
                }
                let sheader = self.span(sec.header_pos);
                let mut skeys = self.keys(si);
                let sub = obj.subs.entry(s).or_insert_with(|| blank_sub(s));
                self.fill_sub(
                    &mut skeys,
                    sub,
                    sheader,
                    None,
                    &format_args!("sub-object {index:04X}sub{s:X}"),
                );
            }
        }
        if let Some(li) = b.links {
            for (e, _) in self.list_section(li, "ObjectLinks", extra) {
                match self.uint(e, 0xFFFF) {
                    Ok(Some(v)) => obj.links.push(Spanned::new(v.value as u16, v.span)),
                    Ok(None) => {}
                    Err(()) => {}
                }
            }
        }
        self.companions(&mut obj, b);
        if !keys.shadowed.is_empty() {
            // A structured object's own keys (a VAR's went through `fill_sub`); values typed
            // by the object's DataType are those of a compact object's sub-objects.
            let dt = obj.sub(1).filter(|_| obj.compact_sub_obj.is_some()).map(|s| s.data_type);
            self.check_shadowed(&mut keys, dt);
        }
        let mut all_extra: Vec<RawEntry> =
            obj_extra.into_iter().chain(keys.extra.drain(..)).map(|e| raw_entry(e, file)).collect();
        all_extra.append(&mut obj.extra);
        obj.extra = all_extra;
        Some(obj)
    }

    fn compact_subs(
        &mut self,
        obj: &mut Object,
        keys: &mut Keys<'r, 'a>,
        n: Spanned<u8>,
        b: &ObjB,
    ) {
        let what = format_args!("compact object {:04X}", obj.index);
        // The template: DataType, AccessType, PDOMapping and values of the object section.
        let mut tkeys = Keys { k: [None; N_KEYS], extra: Vec::new(), shadowed: Vec::new() };
        for k in COMPACT_TEMPLATE {
            tkeys.k[k as usize] = keys.take(k);
        }
        tkeys.k[K::ParameterName as usize] = keys.get(K::ParameterName);
        let mut template = self.sub_from_keys(&mut tkeys, 1, obj.span, None, &what);
        // Every implied sub-object gets its own name: do not clone the template's.
        template.name = Name::default();
        template.span = n.span;
        let mut sub0 = SubObject::new(0, COMPACT_SUB0_NAME, DataType::Unsigned8, Access::Ro);
        sub0.default = Some(Spanned::new(Value::Unsigned(u64::from(n.value)), n.span));
        sub0.span = n.span;
        // Explicit sub sections are read after this, so `obj.subs` is empty here.
        obj.subs.reserve_exact(1 + b.subs.len());
        obj.subs.insert(0, sub0);
        obj.subs.set_implied(template, n.value, &obj.name);
    }

    /// `[IIIIName]`, `[IIIIValue]`, `[IIIIDenotation]`.
    fn companions(&mut self, obj: &mut Object, b: &ObjB) {
        for (sec, which) in [(b.name, 0u8), (b.value, 1), (b.denotation, 2)] {
            let Some(first) = sec else { continue };
            for e in self.entries(first) {
                if e.key.eq_ignore_ascii_case("NrOfEntries") {
                    continue;
                }
                // Companions name and set sub-objects of an ARRAY or RECORD: a VAR's sub-index 0
                // is the object itself, whose name is its own `ParameterName`.
                // `get_mut` makes only this one of a compact object's implied sub-objects.
                let sub = dec_u16(e.key.as_bytes())
                    .and_then(|n| u8::try_from(n).ok())
                    .filter(|_| obj.kind.has_subs())
                    .and_then(|n| obj.subs.get_mut(&n));
                let Some(s) = sub else {
                    self.warn(
                        codes::BAD_COMPACT_ENTRY,
                        format!(
                            "`{}` in [{}] is not a sub-index of object {:04X}",
                            e.key,
                            self.sec(first).name,
                            obj.index
                        ),
                        self.span(e.key_pos),
                        "ignored",
                    );
                    continue;
                };
                match which {
                    0 => s.name = Name::from(e.value),
                    1 => s.parameter_value = self.value(e, s.data_type),
                    _ => s.rare_mut().denotation = Some(self.text(e)),
                }
            }
        }
    }

    fn module(&mut self, number: u16, b: &ModB, extra: &mut Vec<(u32, RawSection)>) -> Module {
        let file = self.file;
        let mut m = Module { number, ..Default::default() };
        if let Some(i) = b.info {
            m.has_info = true;
            m.span = self.span(self.sec(i).header_pos);
            for e in self.entries(i) {
                let is = |n: &str| e.key.eq_ignore_ascii_case(n);
                if is("ProductName") {
                    m.product_name = Some(self.text(e));
                } else if is("OrderCode") {
                    m.order_code = Some(self.text(e));
                } else if is("ProductVersion") || is("ProductRevision") {
                    match self.uint(e, 0xFFFF) {
                        Ok(v) => {
                            let v = v.map(|v| Spanned::new(v.value as u16, v.span));
                            if is("ProductVersion") {
                                m.product_version = v;
                            } else {
                                m.product_revision = v;
                            }
                        }
                        Err(()) => m.extra.push(raw_entry(e, file)),
                    }
                } else {
                    m.extra.push(raw_entry(e, file));
                }
            }
        }
        if let Some(i) = b.fixed_list {
            // The list is implied by the [MxFixedIIII] sections; read it for diagnostics only.
            let _ = self.list_section(i, "NrOfEntries", extra);
        }
        for (&index, ob) in &b.fixed {
            match self.object(index, ob, extra) {
                Some(o) => {
                    std::sync::Arc::make_mut(&mut m.fixed_objects).insert(index, o);
                }
                None => {
                    for i in ob.subs.values() {
                        let s = self.sec(i);
                        self.warn(
                            codes::ORPHAN_SECTION,
                            format!("[{}] has no object section", s.name),
                            self.span(s.name_pos),
                            "kept as an unknown section",
                        );
                        extra.push((i, self.raw_section(i)));
                    }
                }
            }
        }
        if let Some(i) = b.sub_ext_list {
            let _ = self.list_section(i, "NrOfEntries", extra);
        }
        for (&index, &i) in &b.sub_ext {
            let header = self.span(self.sec(i).header_pos);
            let mut keys = self.keys(i);
            let count = keys.take(K::Count).map(|e| self.text(e));
            let obj_extend = keys.take(K::ObjExtend).and_then(|e| match self.uint(e, 0xFFFF) {
                Ok(v) => v.map(|v| Spanned::new(v.value as u16, v.span)),
                Err(()) => None,
            });
            let template = self.sub_from_keys(
                &mut keys,
                0,
                header,
                None,
                &format_args!("module {number} sub-extension {index:04X}"),
            );
            m.sub_extends.insert(index, SubExtend { template, count, obj_extend });
        }
        if let Some(i) = b.comments {
            m.comments = self.comments(i, extra);
        }
        m
    }
}

/// The type a `DataType` value names when it is written as a name (`UNSIGNED16`,
/// `visible_string`) instead of an index; case and `_` are ignored.
fn type_by_name(s: &str) -> Option<DataType> {
    let s = s.trim();
    if !s.starts_with(|c: char| c.is_ascii_alphabetic()) {
        return None;
    }
    let same = |name: &str| {
        let mut a = s.bytes().filter(|&c| c != b'_');
        let mut b = name.bytes().filter(|&c| c != b'_');
        loop {
            match (a.next(), b.next()) {
                (None, None) => return true,
                (Some(x), Some(y)) if x.eq_ignore_ascii_case(&y) => {}
                _ => return false,
            }
        }
    };
    (0x0001..=0x0023)
        .map(DataType::from_code)
        .filter(|dt| !matches!(dt, DataType::Profile(_)))
        .find(|dt| same(&dt.name()))
}

/// A sub-object with nothing read yet, for [`Lower::fill_sub`].
fn blank_sub(sub_index: u8) -> SubObject {
    SubObject::new(sub_index, String::new(), DataType::Domain, Access::Ro)
}

/// The pieces joined into one exactly sized string: for the messages of diagnostics that real
/// files trigger by the thousand (`F112`), cheaper than `format!`.
fn concat(parts: &[&str]) -> String {
    let mut s = String::with_capacity(parts.iter().map(|p| p.len()).sum());
    parts.iter().for_each(|p| s.push_str(p));
    s
}

#[derive(Clone, Copy, PartialEq, Eq)]
enum Problem {
    Invalid,
    Range,
}

fn expected(class: ValueClass) -> &'static str {
    match class {
        ValueClass::Bool => "0 or 1",
        ValueClass::Unsigned(_) | ValueClass::Signed(_) => {
            "a decimal, 0x-hex or 0-octal number, optionally $NODEID+"
        }
        ValueClass::Real32 | ValueClass::Real64 => "a decimal float or a 0x bit pattern",
        ValueClass::Bytes => "hex bytes",
        ValueClass::Time => "milliseconds and days",
        _ => "a value",
    }
}

/// Reads `s` as a value of `dt`. `flags` are [`num`] warning flags.
fn read_value(s: &str, dt: DataType, problem: &mut Problem) -> Option<(Value, u8)> {
    let s = trim(s);
    match dt.class() {
        ValueClass::Bool => num::parse_bool(s).map(|b| (Value::Bool(b), 0)),
        ValueClass::Unsigned(bits) => {
            let n = num::parse_int(s)?;
            if n.node_id {
                let v = i64::try_from(n.value).ok()?;
                return Some((Value::NodeIdPlus(v), n.flags));
            }
            let max = if bits >= 64 { u128::from(u64::MAX) } else { (1u128 << bits) - 1 };
            if n.value < 0 || n.value as u128 > max {
                *problem = Problem::Range;
                return None;
            }
            Some((Value::Unsigned(n.value as u64), n.flags & !num::HEX))
        }
        ValueClass::Signed(bits) => {
            let n = num::parse_int(s)?;
            if n.node_id {
                let v = i64::try_from(n.value).ok()?;
                return Some((Value::NodeIdPlus(v), n.flags));
            }
            let bits = bits.min(64);
            let smax = (1i128 << (bits - 1)) - 1;
            let smin = -(1i128 << (bits - 1));
            let umax = (1i128 << bits) - 1;
            let mut v = n.value;
            if n.flags & num::HEX != 0 && v > smax && v <= umax {
                v -= 1i128 << bits; // two's complement bit pattern
            }
            if v < smin || v > smax {
                *problem = Problem::Range;
                return None;
            }
            Some((Value::Signed(v as i64), n.flags & !num::HEX))
        }
        ValueClass::Real32 => {
            if is_hex(s) {
                let (v, flags) = num::parse_plain(s)?;
                if !(0..=i128::from(u32::MAX)).contains(&v) {
                    *problem = Problem::Range;
                    return None;
                }
                Some((Value::Real32(v as u32), flags & !num::HEX))
            } else {
                let (s, flags) = strip_float_suffix(s);
                num::parse_f32(s).map(|f| (Value::Real32(f.to_bits()), flags))
            }
        }
        ValueClass::Real64 => {
            if is_hex(s) {
                let (v, flags) = num::parse_plain(s)?;
                if !(0..=i128::from(u64::MAX)).contains(&v) {
                    *problem = Problem::Range;
                    return None;
                }
                Some((Value::Real64(v as u64), flags & !num::HEX))
            } else {
                let (s, flags) = strip_float_suffix(s);
                num::parse_f64(s).map(|f| (Value::Real64(f.to_bits()), flags))
            }
        }
        ValueClass::Text => Some((Value::Text(s.into()), 0)),
        ValueClass::Bytes => {
            num::parse_hex_bytes(s).map(|b| (Value::Bytes(b.into_boxed_slice()), 0))
        }
        ValueClass::Unicode => Some((Value::Unicode(s.encode_utf16().collect()), 0)),
        ValueClass::Time => {
            let mut it = s.split_ascii_whitespace();
            let a = it.next()?;
            match (it.next(), it.next()) {
                (None, _) => {
                    let (v, flags) = num::parse_plain(a)?;
                    if !(0..=0xFFFF_FFFF_FFFF).contains(&v) {
                        *problem = Problem::Range;
                        return None;
                    }
                    let v = v as u64;
                    Some((Value::Time { ms: v as u32, days: (v >> 32) as u16 }, flags & !num::HEX))
                }
                (Some(b), None) => {
                    let (days, f1) = num::parse_plain(a)?;
                    let (ms, f2) = num::parse_plain(b)?;
                    let ms = u32::try_from(ms).ok()?;
                    let days = u16::try_from(days).ok()?;
                    Some((Value::Time { ms, days }, (f1 | f2) & !num::HEX))
                }
                _ => None,
            }
        }
        ValueClass::Structured => match num::parse_int(s) {
            Some(n) if n.node_id => {
                Some((Value::NodeIdPlus(i64::try_from(n.value).ok()?), n.flags))
            }
            Some(n) if n.value >= 0 => Some((Value::Unsigned(n.value as u64), n.flags & !num::HEX)),
            Some(n) => Some((Value::Signed(i64::try_from(n.value).ok()?), n.flags & !num::HEX)),
            None => Some((Value::Text(s.into()), 0)),
        },
    }
}

/// Cuts a C float suffix (`1.0f`, `2.5F`, `1.0L`).
fn strip_float_suffix(s: &str) -> (&str, u8) {
    match s.strip_suffix(['f', 'F', 'l', 'L']) {
        Some(t) if t.ends_with(|c: char| c.is_ascii_digit() || c == '.') => (t, num::SUFFIX),
        _ => (s, 0),
    }
}

fn is_hex(s: &str) -> bool {
    let b = s.as_bytes();
    b.len() > 2 && b[0] == b'0' && (b[1] == b'x' || b[1] == b'X')
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn obj_key_is_case_insensitive_and_exact() {
        let names = [
            "ParameterName",
            "ObjectType",
            "DataType",
            "AccessType",
            "PDOMapping",
            "DefaultValue",
            "LowLimit",
            "HighLimit",
            "ParameterValue",
            "Denotation",
            "ObjFlags",
            "UploadFile",
            "DownloadFile",
            "SubNumber",
            "CompactSubObj",
            "Count",
            "ObjExtend",
        ];
        let mut seen = Vec::new();
        for n in names {
            let k = obj_key(n).map(|k| k as usize);
            assert!(k.is_some(), "{n}");
            assert_eq!(obj_key(&n.to_ascii_lowercase()).map(|k| k as usize), k, "{n}");
            assert_eq!(obj_key(&n.to_ascii_uppercase()).map(|k| k as usize), k, "{n}");
            assert!(!seen.contains(&k), "{n}");
            seen.push(k);
            // One character off (also a non-letter whose bit 5 is the only difference).
            let mut b = n.as_bytes().to_vec();
            b[n.len() - 1] = b'@';
            assert!(obj_key(std::str::from_utf8(&b).unwrap_or("")).is_none(), "{n}");
            assert!(obj_key(&format!("{n}x")).is_none(), "{n}");
        }
        assert!(obj_key("Parameter_Name").is_none());
        assert!(obj_key("Cou t").is_none());
    }
}
