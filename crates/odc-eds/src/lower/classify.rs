//! Section names: which object, sub-object, companion or module section each is, and the
//! grouping of an object's sections.

use super::*;

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(super) enum Kind {
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

pub(super) fn hex4(b: &[u8]) -> Option<u16> {
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

pub(super) fn hex_u8(b: &[u8]) -> Option<u8> {
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

pub(super) fn dec_u16(b: &[u8]) -> Option<u16> {
    if b.is_empty() || b.len() > 5 || !b.iter().all(u8::is_ascii_digit) {
        return None;
    }
    b.iter()
        .try_fold(0u32, |v, &c| Some(v * 10 + u32::from(c - b'0')))
        .and_then(|v| u16::try_from(v).ok())
}

pub(super) fn strip_prefix_ci<'b>(b: &'b [u8], p: &str) -> Option<&'b [u8]> {
    if b.len() >= p.len() && b[..p.len()].eq_ignore_ascii_case(p.as_bytes()) {
        Some(&b[p.len()..])
    } else {
        None
    }
}

/// Classifies the part after a 4-hex-digit index: ``, `subN`, `Name`, `Value`, ...
pub(super) fn classify_object_tail(index: u16, tail: &[u8]) -> Kind {
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

pub(super) fn classify(name: &str) -> Kind {
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
pub(super) struct ObjB<'s> {
    pub(super) main: Option<u32>,
    pub(super) subs: SubSections<'s>,
    pub(super) name: Option<u32>,
    pub(super) value: Option<u32>,
    pub(super) denotation: Option<u32>,
    pub(super) links: Option<u32>,
}

/// Where an object section belongs: owner (0 the device, m + 1 module m's fixed objects),
/// object index, role, sub-index, packed so that sorting the sections by it groups each
/// object's sections, roles in order, sub-objects by sub-index. All object sections of a file
/// go into one vector that is sorted once (files list them in order, so it usually already
/// is): no map and no vector per object.
pub(super) fn section_key(owner: u32, index: u16, role: Role, sub: u8) -> u64 {
    let role = role as u8;
    (u64::from(owner) << 32) | (u64::from(index) << 16) | (u64::from(role) << 8) | u64::from(sub)
}

/// What a section is to its object, in the order the key sorts them.
#[derive(Clone, Copy, PartialEq, Eq)]
#[repr(u8)]
pub(super) enum Role {
    /// `[IIII]`.
    Main = 0,
    /// `[IIIIsubS]`.
    Sub = 1,
    /// `[IIIIName]`.
    Name = 2,
    /// `[IIIIValue]`.
    Value = 3,
    /// `[IIIIDenotation]`.
    Denotation = 4,
    /// `[IIIIObjectLinks]`.
    Links = 5,
}

impl Role {
    /// The role a [`section_key`] holds.
    fn of_key(key: u64) -> Role {
        match (key >> 8) as u8 {
            0 => Role::Main,
            1 => Role::Sub,
            2 => Role::Name,
            3 => Role::Value,
            4 => Role::Denotation,
            _ => Role::Links,
        }
    }
}

/// The sub-object sections of one object: a run of the sorted section vector, `(key,
/// section)` by sub-index. A sub-index given twice (spelt differently: `sub1`, `sub01`) is
/// the later section.
#[derive(Default, Clone, Copy)]
pub(super) struct SubSections<'s>(pub(super) &'s [(u64, u32)]);

impl<'s> SubSections<'s> {
    pub(super) fn is_empty(&self) -> bool {
        self.0.is_empty()
    }

    /// `(sub-index, section)` in sub-index order, the last of a repeated sub-index only.
    pub(super) fn iter(&self) -> impl Iterator<Item = (u8, u32)> + 's {
        let v = self.0;
        v.iter()
            .enumerate()
            .filter(move |&(j, p)| v.get(j + 1).is_none_or(|q| q.0 != p.0))
            .map(|(_, &(k, i))| (k as u8, i))
    }

    pub(super) fn len(&self) -> usize {
        self.iter().count()
    }

    /// The sections in sub-index order.
    pub(super) fn values(&self) -> impl Iterator<Item = u32> + 's {
        self.iter().map(|(_, i)| i)
    }
}

/// Sorts the object sections (stable: among equal keys the later section comes last) and
/// calls `each(owner, index, sections)` per object, in key order.
pub(super) fn group_objects<'s>(
    secs: &'s mut [(u64, u32)],
    mut each: impl FnMut(u32, u16, ObjB<'s>),
) {
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
            match Role::of_key(key) {
                Role::Main => b.main = Some(i),
                Role::Sub => {
                    if sub_end == 0 {
                        sub_start = j;
                    }
                    sub_end = j + 1;
                }
                Role::Name => b.name = Some(i),
                Role::Value => b.value = Some(i),
                Role::Denotation => b.denotation = Some(i),
                Role::Links => b.links = Some(i),
            }
        }
        b.subs = SubSections(&group[sub_start..sub_end]);
        each((k >> 32) as u32, (k >> 16) as u16, b);
    }
}

#[derive(Default)]
pub(super) struct ModB<'s> {
    pub(super) info: Option<u32>,
    pub(super) fixed_list: Option<u32>,
    pub(super) fixed: BTreeMap<u16, ObjB<'s>>,
    pub(super) sub_ext_list: Option<u32>,
    pub(super) sub_ext: BTreeMap<u16, u32>,
    pub(super) comments: Option<u32>,
}
