//! Serialising indexes, sub-indexes and identity numbers in hex, as device files write them
//! (`odc dump` shows `0x1A00:0x01`, not `6656` and `1`).

use std::collections::BTreeMap;

use serde::Serializer;

use crate::span::Spanned;

/// A 16-bit object index: `0x1A00`.
pub(crate) fn index<S: Serializer>(v: &u16, s: S) -> Result<S::Ok, S::Error> {
    s.collect_str(&format_args!("0x{v:04X}"))
}

/// An optional object index.
pub(crate) fn index_opt<S: Serializer>(v: &Option<u16>, s: S) -> Result<S::Ok, S::Error> {
    match v {
        Some(v) => index(v, s),
        None => s.serialize_none(),
    }
}

/// An 8-bit sub-index: `0x01`.
pub(crate) fn sub<S: Serializer>(v: &u8, s: S) -> Result<S::Ok, S::Error> {
    s.collect_str(&format_args!("0x{v:02X}"))
}

/// A map keyed by object index.
pub(crate) fn index_map<S: Serializer, T: serde::Serialize>(
    map: &BTreeMap<u16, T>,
    s: S,
) -> Result<S::Ok, S::Error> {
    s.collect_map(map.iter().map(|(k, v)| (format!("0x{k:04X}"), v)))
}

/// A list of object indexes.
pub(crate) fn index_list<S: Serializer>(list: &[Spanned<u16>], s: S) -> Result<S::Ok, S::Error> {
    s.collect_seq(list.iter().map(|v| format!("0x{:04X}", v.value)))
}

/// A 32-bit identity number (vendor, product, revision, serial): `0x000001DD`.
pub(crate) fn ident<S: Serializer>(v: &Option<Spanned<u32>>, s: S) -> Result<S::Ok, S::Error> {
    match v {
        Some(v) => s.collect_str(&format_args!("0x{:08X}", v.value)),
        None => s.serialize_none(),
    }
}
