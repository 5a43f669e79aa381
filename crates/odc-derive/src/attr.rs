//! `#[pdo(...)]` attribute parsing: every key keeps its span, so later checks can point at the
//! exact key or value that is wrong.

use proc_macro2::Span;
use syn::meta::ParseNestedMeta;
use syn::spanned::Spanned as _;
use syn::{Attribute, LitInt, LitStr, Path};

/// Collects errors so one expansion reports all of them.
#[derive(Default)]
pub(crate) struct Errors(Option<syn::Error>);

impl Errors {
    pub(crate) fn push(&mut self, e: syn::Error) {
        match &mut self.0 {
            Some(all) => all.combine(e),
            None => self.0 = Some(e),
        }
    }

    /// Number of errors so far, to tell whether a step added any.
    pub(crate) fn count(&self) -> usize {
        self.0.as_ref().map_or(0, |e| e.into_iter().count())
    }

    pub(crate) fn take(self) -> Option<syn::Error> {
        self.0
    }
}

/// A value with the span of the literal that gave it.
#[derive(Clone, Copy)]
pub(crate) struct Spanned<T> {
    pub(crate) value: T,
    pub(crate) span: Span,
}

/// Set `slot` once; a second occurrence is an error on the second key.
fn set_once<T>(slot: &mut Option<Spanned<T>>, value: T, span: Span, key: &str) -> syn::Result<()> {
    if slot.is_some() {
        return Err(syn::Error::new(span, format!("duplicate `{key}` key")));
    }
    *slot = Some(Spanned { value, span });
    Ok(())
}

fn int<N>(meta: &ParseNestedMeta<'_>) -> syn::Result<(N, Span)>
where
    N: std::str::FromStr,
    N::Err: std::fmt::Display,
{
    let lit: LitInt = meta.value()?.parse()?;
    Ok((lit.base10_parse()?, lit.span()))
}

/// A did-you-mean hint for an unknown key.
fn unknown(meta: &ParseNestedMeta<'_>, known: &[&str]) -> syn::Error {
    let name = meta.path.get_ident().map(|i| i.to_string()).unwrap_or_default();
    let best = known
        .iter()
        .map(|k| (distance(&name, k), *k))
        .min()
        .filter(|(d, _)| *d <= 2)
        .map(|(_, k)| k);
    let list = known.iter().map(|k| format!("`{k}`")).collect::<Vec<_>>().join(", ");
    let msg = match best {
        Some(k) => {
            format!("unknown `pdo` key `{name}`; did you mean `{k}`? (expected one of {list})")
        }
        None => format!("unknown `pdo` key `{name}` (expected one of {list})"),
    };
    syn::Error::new(meta.path.span(), msg)
}

/// Levenshtein distance, enough for short keys.
fn distance(a: &str, b: &str) -> usize {
    let b: Vec<char> = b.chars().collect();
    let mut prev: Vec<usize> = (0..=b.len()).collect();
    for (i, ca) in a.chars().enumerate() {
        let mut cur = vec![i + 1];
        for (j, cb) in b.iter().enumerate() {
            let sub = prev[j] + usize::from(ca != *cb);
            cur.push(sub.min(prev[j + 1] + 1).min(cur[j] + 1));
        }
        prev = cur;
    }
    prev[b.len()]
}

/// Keys on the struct.
#[derive(Default)]
pub(crate) struct ContainerAttrs {
    /// Declared total size in bits (from `bits` or `bytes`).
    pub(crate) size_bits: Option<Spanned<u32>>,
    pub(crate) max_bits: Option<Spanned<u32>>,
    pub(crate) krate: Option<Path>,
}

const CONTAINER_KEYS: &[&str] = &["bits", "bytes", "max_bits", "crate"];

pub(crate) fn container(attrs: &[Attribute], errors: &mut Errors) -> ContainerAttrs {
    let mut out = ContainerAttrs::default();
    for attr in attrs.iter().filter(|a| a.path().is_ident("pdo")) {
        let r = attr.parse_nested_meta(|meta| {
            if meta.path.is_ident("bits") || meta.path.is_ident("bytes") {
                let per = if meta.path.is_ident("bytes") { 8 } else { 1 };
                let key = if per == 8 { "bytes" } else { "bits" };
                let (n, span): (u32, Span) = int(&meta)?;
                if out.size_bits.is_some() {
                    return Err(syn::Error::new(
                        meta.path.span(),
                        "`bits` and `bytes` give the size twice; keep one",
                    ));
                }
                let bits =
                    n.checked_mul(per).ok_or_else(|| syn::Error::new(span, "size overflows"))?;
                set_once(&mut out.size_bits, bits, span, key)
            } else if meta.path.is_ident("max_bits") {
                let (n, span) = int(&meta)?;
                set_once(&mut out.max_bits, n, span, "max_bits")
            } else if meta.path.is_ident("crate") {
                let s: LitStr = meta.value()?.parse()?;
                if out.krate.is_some() {
                    return Err(syn::Error::new(s.span(), "duplicate `crate` key"));
                }
                out.krate = Some(s.parse()?);
                Ok(())
            } else {
                Err(unknown(&meta, CONTAINER_KEYS))
            }
        });
        if let Err(e) = r {
            errors.push(e);
        }
    }
    out
}

/// Keys on a struct field.
#[derive(Default)]
pub(crate) struct FieldAttrs {
    pub(crate) index: Option<Spanned<u16>>,
    pub(crate) sub: Option<Spanned<u8>>,
    /// Width in bits (from `bits` or `bytes`).
    pub(crate) bits: Option<Spanned<u32>>,
    /// Gap before the field in bits (from `pad_bits` or `pad_bytes`).
    pub(crate) pad: Option<Spanned<u32>>,
    pub(crate) offset: Option<Spanned<u32>>,
}

const FIELD_KEYS: &[&str] = &["index", "sub", "bits", "bytes", "pad_bits", "pad_bytes", "offset"];

pub(crate) fn field(attrs: &[Attribute], errors: &mut Errors) -> FieldAttrs {
    let mut out = FieldAttrs::default();
    for attr in attrs.iter().filter(|a| a.path().is_ident("pdo")) {
        let r = attr.parse_nested_meta(|meta| {
            let p = &meta.path;
            if p.is_ident("index") {
                let (n, span) = int(&meta)?;
                set_once(&mut out.index, n, span, "index")
            } else if p.is_ident("sub") {
                let (n, span) = int(&meta)?;
                set_once(&mut out.sub, n, span, "sub")
            } else if p.is_ident("bits") || p.is_ident("bytes") {
                let per = if p.is_ident("bytes") { 8 } else { 1 };
                let (n, span): (u32, Span) = int(&meta)?;
                if out.bits.is_some() {
                    return Err(syn::Error::new(
                        span,
                        "the width is already given; keep one of `bits` and `bytes`",
                    ));
                }
                let bits =
                    n.checked_mul(per).ok_or_else(|| syn::Error::new(span, "width overflows"))?;
                set_once(&mut out.bits, bits, span, "bits")
            } else if p.is_ident("pad_bits") || p.is_ident("pad_bytes") {
                let per = if p.is_ident("pad_bytes") { 8 } else { 1 };
                let (n, span): (u32, Span) = int(&meta)?;
                if out.pad.is_some() {
                    return Err(syn::Error::new(
                        span,
                        "the gap is already given; keep one of `pad_bits` and `pad_bytes`",
                    ));
                }
                let bits =
                    n.checked_mul(per).ok_or_else(|| syn::Error::new(span, "gap overflows"))?;
                set_once(&mut out.pad, bits, span, "pad_bits")
            } else if p.is_ident("offset") {
                let (n, span) = int(&meta)?;
                set_once(&mut out.offset, n, span, "offset")
            } else {
                Err(unknown(&meta, FIELD_KEYS))
            }
        });
        if let Err(e) = r {
            errors.push(e);
        }
    }
    out
}

/// Keys on a `#[derive(PdoValue)]` enum and its variants.
#[derive(Default)]
pub(crate) struct EnumAttrs {
    pub(crate) bits: Option<Spanned<u32>>,
    pub(crate) krate: Option<Path>,
}

pub(crate) fn enum_container(attrs: &[Attribute], errors: &mut Errors) -> EnumAttrs {
    let mut out = EnumAttrs::default();
    for attr in attrs.iter().filter(|a| a.path().is_ident("pdo")) {
        let r = attr.parse_nested_meta(|meta| {
            if meta.path.is_ident("bits") {
                let (n, span) = int(&meta)?;
                set_once(&mut out.bits, n, span, "bits")
            } else if meta.path.is_ident("crate") {
                let s: LitStr = meta.value()?.parse()?;
                out.krate = Some(s.parse()?);
                Ok(())
            } else {
                Err(unknown(&meta, &["bits", "crate"]))
            }
        });
        if let Err(e) = r {
            errors.push(e);
        }
    }
    out
}

/// Whether a variant carries `#[pdo(other)]`; returns the span of the key.
pub(crate) fn variant_other(attrs: &[Attribute], errors: &mut Errors) -> Option<Span> {
    let mut found = None;
    for attr in attrs.iter().filter(|a| a.path().is_ident("pdo")) {
        let r = attr.parse_nested_meta(|meta| {
            if meta.path.is_ident("other") {
                found = Some(meta.path.span());
                Ok(())
            } else {
                Err(unknown(&meta, &["other"]))
            }
        });
        if let Err(e) = r {
            errors.push(e);
        }
    }
    found
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn edit_distance() {
        assert_eq!(distance("indx", "index"), 1);
        assert_eq!(distance("pad", "pad_bits"), 5);
        assert_eq!(distance("", "sub"), 3);
    }

    #[test]
    fn field_keys_parse_and_reject() {
        let f: syn::Field = syn::parse_quote! {
            #[pdo(index = 0x6040, sub = 1, bytes = 2)]
            #[pdo(pad_bits = 4)]
            x: u16
        };
        let mut errs = Errors::default();
        let a = field(&f.attrs, &mut errs);
        assert!(errs.take().is_none());
        assert_eq!(a.index.map(|s| s.value), Some(0x6040));
        assert_eq!(a.sub.map(|s| s.value), Some(1));
        assert_eq!(a.bits.map(|s| s.value), Some(16));
        assert_eq!(a.pad.map(|s| s.value), Some(4));

        let f: syn::Field =
            syn::parse_quote! { #[pdo(indx = 1)] #[pdo(index = 1, index = 2)] x: u8 };
        let mut errs = Errors::default();
        let _ = field(&f.attrs, &mut errs);
        let msg =
            errs.take().map(|e| e.into_iter().map(|e| e.to_string()).collect::<Vec<_>>()).unwrap();
        assert_eq!(msg.len(), 2);
        assert!(msg[0].contains("did you mean `index`"), "{msg:?}");
        assert!(msg[1].contains("duplicate `index`"), "{msg:?}");
    }
}
