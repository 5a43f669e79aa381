//! The known keys of object and sub-object sections, found without lower-casing.

use super::*;

/// Keys of object and sub-object sections.
#[derive(Clone, Copy, PartialEq, Eq)]
pub(super) enum K {
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

/// How many keys `K` names: the last one's number plus one.
pub(super) const N_KEYS: usize = K::ObjExtend as usize + 1;

/// The keys of a CompactSubObj object's section that every implied sub-object takes. Not
/// `ObjFlags`: in an object's section it is the object's own (read before these).
pub(super) const COMPACT_TEMPLATE: [K; 9] = [
    K::DataType,
    K::AccessType,
    K::PdoMapping,
    K::DefaultValue,
    K::LowLimit,
    K::HighLimit,
    K::ParameterValue,
    K::UploadFile,
    K::DownloadFile,
];

/// Whether `key` is one of [`COMPACT_TEMPLATE`]'s (the writer keeps those on the template).
pub(crate) fn is_compact_template_key(key: &str) -> bool {
    obj_key(key).is_some_and(|k| COMPACT_TEMPLATE.contains(&k))
}

pub(super) fn obj_key(key: &str) -> Option<K> {
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
pub(super) fn le64(b: &[u8], at: usize) -> u64 {
    let mut w = [0u8; 8];
    w.copy_from_slice(&b[at..at + 8]);
    u64::from_le_bytes(w)
}

/// The known keys of one (possibly repeated) section, last occurrence winning, and the rest.
pub(super) struct Keys<'e, 'a> {
    pub(super) k: [Option<&'e Entry<'a>>; N_KEYS],
    pub(super) extra: Vec<&'e Entry<'a>>,
    /// Known keys given again later (in the same section or a repeat of it, `F106`/`F105`):
    /// the earlier entry and the one that replaced it. Their values are not used but still
    /// read for diagnostics ([`Lower::check_shadowed`]), so that an error in a merged section
    /// is not lost.
    pub(super) shadowed: Vec<(K, &'e Entry<'a>, &'e Entry<'a>)>,
}

impl<'e, 'a> Keys<'e, 'a> {
    pub(super) fn get(&self, k: K) -> Option<&'e Entry<'a>> {
        self.k[k as usize]
    }
    pub(super) fn take(&mut self, k: K) -> Option<&'e Entry<'a>> {
        self.k[k as usize].take()
    }
    /// Moves the known key `k` (if present) into `extra`.
    pub(super) fn move_to_extra(&mut self, k: K) {
        if let Some(e) = self.take(k) {
            self.extra.push(e);
        }
    }
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
