//! `#[derive(Pdo)]`: attributes → checked layout (through `odc-layout`) → tokens.

use crate::attr::{self, Errors};
use odc_layout::{BitRange, Cursor, FieldSpec, LayoutError};
use proc_macro2::{Literal, Span, TokenStream};
use quote::{quote, quote_spanned};
use syn::spanned::Spanned;
use syn::{Data, DeriveInput, Fields, Ident, Path, Type};

/// One placed field.
struct Placed {
    ident: Ident,
    ty: Type,
    index: u16,
    sub: u8,
    range: BitRange,
    /// Gap placed before the field (explicit pad or offset jump), for dummy mapping entries.
    gap: u32,
    /// Natural width when the type is a primitive we know.
    natural: Option<u32>,
}

/// Natural width of the primitive types the derive knows without asking `PdoValue`.
fn primitive_bits(ty: &Type) -> Option<(u32, &'static str)> {
    // A type passed through a `macro_rules!` `$t:ty` arrives wrapped in an invisible group.
    let p = match ty {
        Type::Path(p) => p,
        Type::Group(g) => return primitive_bits(&g.elem),
        Type::Paren(p) => return primitive_bits(&p.elem),
        _ => return None,
    };
    if p.qself.is_some() {
        return None;
    }
    let id = p.path.get_ident()?.to_string();
    Some(match id.as_str() {
        "bool" => (1, "bool"),
        "u8" => (8, "u8"),
        "i8" => (8, "i8"),
        "u16" => (16, "u16"),
        "i16" => (16, "i16"),
        "u32" => (32, "u32"),
        "i32" => (32, "i32"),
        "f32" => (32, "f32"),
        "u64" => (64, "u64"),
        "i64" => (64, "i64"),
        "f64" => (64, "f64"),
        _ => return None,
    })
}

/// The largest width a primitive may be mapped with: its own, except BOOLEAN, which some
/// devices map on a whole byte.
fn max_width(name: &str, natural: u32) -> u32 {
    if name == "bool" { 8 } else { natural }
}

pub(crate) fn derive(input: &DeriveInput) -> TokenStream {
    let mut errors = Errors::default();
    let cont = attr::container(&input.attrs, &mut errors);
    let krate: Path = cont.krate.clone().unwrap_or_else(|| syn::parse_quote!(::odc));

    let fields = match &input.data {
        Data::Struct(s) => match &s.fields {
            Fields::Named(n) => Some(n.named.iter().collect::<Vec<_>>()),
            _ => None,
        },
        _ => None,
    };
    let Some(fields) = fields else {
        errors.push(syn::Error::new(
            input.ident.span(),
            "`#[derive(Pdo)]` supports structs with named fields only",
        ));
        return fallback(input, &krate, errors);
    };

    let limit = cont.max_bits.map_or(odc_layout::CLASSIC_CAN_BITS, |m| m.value);
    let mut cursor = Cursor::new();
    let mut placed: Vec<Placed> = Vec::new();
    let mut limit_reported = false;

    for (i, f) in fields.iter().enumerate() {
        let before_attrs = errors.count();
        let a = attr::field(&f.attrs, &mut errors);
        // A malformed attribute may have hidden the index: do not pile a second error on it.
        let attrs_ok = errors.count() == before_attrs;
        let Some(ident) = f.ident.clone() else { continue };
        let prim = primitive_bits(&f.ty);

        let index = match a.index {
            Some(ix) => ix.value,
            None if !attrs_ok => 0,
            None => {
                errors.push(syn::Error::new(
                    ident.span(),
                    format!("field `{ident}` has no object index; add `#[pdo(index = 0x....)]`"),
                ));
                0
            }
        };

        let bits = match (a.bits, prim) {
            (Some(b), Some((natural, name))) => {
                if b.value == 0 || b.value > max_width(name, natural) {
                    errors.push(syn::Error::new(
                        b.span,
                        format!(
                            "`{name}` holds {natural} bits and cannot be mapped with {} bits",
                            b.value
                        ),
                    ));
                } else if name.starts_with('f') && b.value != natural {
                    errors.push(syn::Error::new(
                        b.span,
                        format!("`{name}` must be mapped with exactly {natural} bits"),
                    ));
                }
                b.value
            }
            (Some(b), None) => {
                if b.value == 0 || b.value > 64 {
                    errors.push(syn::Error::new(b.span, "a PDO entry is 1 to 64 bits wide"));
                }
                b.value
            }
            (None, Some((natural, _))) => natural,
            (None, None) => {
                errors.push(syn::Error::new(
                    f.ty.span(),
                    "cannot infer the bit width of this type; add `#[pdo(bits = N)]`",
                ));
                8
            }
        };

        let spec = FieldSpec {
            bits: bits.max(1),
            pad_before: a.pad.map_or(0, |p| p.value),
            offset: a.offset.map(|o| o.value),
        };
        let before = cursor.position();
        let range = match odc_layout::place_one(&mut cursor, &spec, i, i.checked_sub(1)) {
            Ok(r) => r,
            Err(LayoutError::Overlap { .. }) => {
                let (off_span, off) = a.offset.map_or((ident.span(), 0), |o| (o.span, o.value));
                let mut e = syn::Error::new(
                    off_span,
                    format!(
                        "field `{ident}` at bit {off} overlaps the previous field, which ends at bit {before}"
                    ),
                );
                if let Some(prev) = placed.last() {
                    e.combine(syn::Error::new(
                        prev.ident.span(),
                        format!("previous field `{}` is here", prev.ident),
                    ));
                }
                errors.push(e);
                // Keep going as if placed right after, so later fields get sane errors.
                cursor.place(spec.bits).unwrap_or(BitRange::new(before, spec.bits))
            }
            Err(_) => {
                errors.push(syn::Error::new(ident.span(), "bit offset overflows"));
                return fallback(input, &krate, errors);
            }
        };
        if range.end() > limit && !limit_reported {
            limit_reported = true;
            let span = a.bits.map_or(ident.span(), |b| b.span);
            let hint = if cont.max_bits.is_some() {
                String::new()
            } else {
                " (classic CAN); set `#[pdo(max_bits = N)]` for CAN FD or EtherCAT".to_owned()
            };
            errors.push(syn::Error::new(
                span,
                format!(
                    "field `{ident}` ends at bit {}, past the PDO limit of {limit} bits{hint}",
                    range.end()
                ),
            ));
        }
        placed.push(Placed {
            ident,
            ty: f.ty.clone(),
            index,
            sub: a.sub.map_or(0, |s| s.value),
            range,
            gap: range.offset - before,
            natural: prim.map(|p| p.0),
        });
    }

    let used = cursor.position();
    let total_bits = match cont.size_bits {
        Some(declared) => {
            if declared.value < used {
                errors.push(syn::Error::new(
                    declared.span,
                    format!(
                        "the fields need {used} bits but the declared size is {} bits",
                        declared.value
                    ),
                ));
            } else if declared.value > limit && !limit_reported {
                errors.push(syn::Error::new(
                    declared.span,
                    format!(
                        "declared size of {} bits is past the PDO limit of {limit} bits",
                        declared.value
                    ),
                ));
            }
            declared.value.max(used)
        }
        None => used,
    };

    if let Some(e) = errors.take() {
        let mut out = e.into_compile_error();
        out.extend(fallback_impl(input, &krate));
        return out;
    }
    expand(input, &krate, &placed, total_bits)
}

fn fallback(input: &DeriveInput, krate: &Path, errors: Errors) -> TokenStream {
    let mut out = errors.take().map(syn::Error::into_compile_error).unwrap_or_default();
    out.extend(fallback_impl(input, krate));
    out
}

/// A do-nothing impl emitted next to errors, so users see our error and not a cascade of
/// "trait `Pdo` is not implemented" at every use.
fn fallback_impl(input: &DeriveInput, krate: &Path) -> TokenStream {
    let name = &input.ident;
    let (ig, tg, wc) = input.generics.split_for_impl();
    quote! {
        const _: () = {
            #[automatically_derived]
            impl #ig #krate::Pdo for #name #tg #wc {
                const BITS: usize = 0;
                const LEN: usize = 0;
                const MAPPING: &'static [#krate::MappingEntry] = &[];
                type Buffer = [u8; 0];
                fn pack(&self) -> ::core::result::Result<[u8; 0], #krate::PackError> {
                    ::core::result::Result::Ok([])
                }
                fn pack_into(&self, _: &mut [u8]) -> ::core::result::Result<(), #krate::PackError> {
                    ::core::result::Result::Ok(())
                }
                fn unpack(_: &[u8]) -> ::core::result::Result<Self, #krate::UnpackError> {
                    ::core::result::Result::Err(#krate::UnpackError::BufferTooSmall { needed: 0, got: 0 })
                }
            }
        };
    }
}

fn usize_lit(v: u32) -> Literal {
    Literal::usize_unsuffixed(v as usize)
}

fn expand(input: &DeriveInput, krate: &Path, fields: &[Placed], total_bits: u32) -> TokenStream {
    let name = &input.ident;
    let (ig, tg, wc) = input.generics.split_for_impl();
    let len = odc_layout::bytes_for_bits(total_bits);
    let len_lit = usize_lit(len);
    let bits_lit = usize_lit(total_bits);
    // Three ways to move the bits: one load or store per field when every field sits on byte
    // boundaries, as a human writes it (a 6-byte PDO of a u16 and an i32 becomes two plain
    // moves, where a word would be assembled from and split into pieces; an 8-byte u16, i32,
    // i16 three moves, where the word took two shifts and two ORs more); one little-endian
    // word for an image of at most 8 bytes with a field that does not; bit by bit otherwise.
    let aligned = fields
        .iter()
        .all(|f| f.range.offset % 8 == 0 && f.range.bits % 8 == 0 && f.range.bits <= 64);
    let word = len <= 8 && !aligned;
    let covered: u32 = fields.iter().map(|f| f.range.bits).sum();

    let mut mapping = Vec::new();
    let dummy = |gap: u32, mapping: &mut Vec<TokenStream>| {
        let mut d = vec![(0u16, 0u8); odc_layout::dummy_entry_count(gap)];
        let n = odc_layout::dummy_entries(gap, &mut d).unwrap_or(0);
        for (ix, b) in d.iter().take(n) {
            mapping.push(quote!(#krate::MappingEntry::new(#ix, 0, #b)));
        }
    };
    for f in fields {
        dummy(f.gap, &mut mapping);
        let (ix, sub, b) = (f.index, f.sub, f.range.bits as u8);
        mapping.push(quote!(#krate::MappingEntry::new(#ix, #sub, #b)));
    }
    dummy(total_bits - fields.last().map_or(0, |f| f.range.end()), &mut mapping);

    // Pack: raw values, range checks only where the mapped width is narrower than the type.
    let mut raws = Vec::new();
    let mut puts = Vec::new();
    let mut gets = Vec::new();
    for (i, f) in fields.iter().enumerate() {
        let ident = &f.ident;
        let ty = &f.ty;
        let raw = Ident::new(&format!("__raw{i}"), Span::mixed_site());
        let bits = f.range.bits;
        let bits_u32 = Literal::u32_suffixed(bits);
        let off = usize_lit(f.range.offset);
        let mask = Literal::u64_unsuffixed(odc_layout::mask(bits));
        let field_name = ident.to_string();
        let sp = ty.span();
        raws.push(quote_spanned! {sp=>
            let #raw: u64 = <#ty as #krate::PdoValue>::to_raw(&self.#ident);
        });
        let needs_check = f.natural.is_none_or(|n| bits < n);
        if needs_check {
            // Checked even when the type's natural width is the mapped one: a `#[pdo(other)]`
            // variant of a `#[pdo(bits = 4)]` enum can hold any value of its repr (found by
            // the `pdo_pack` fuzz target: `Other(173)` was packed as 13).
            raws.push(quote! {
                if !#krate::bits::fits(#raw, #bits_u32, <#ty as #krate::PdoValue>::SIGNED) {
                    return ::core::result::Result::Err(#krate::PackError::OutOfRange { field: #field_name });
                }
            });
        }
        if aligned {
            let at = usize_lit(f.range.offset / 8);
            let n = usize_lit(bits / 8);
            puts.push(quote!(#krate::bits::put_le(buf, #at, #n, #raw);));
            gets.push(quote! {
                #ident: match <#ty as #krate::PdoValue>::from_raw(#krate::bits::get_le(buf, #at, #n), #bits_u32) {
                    ::core::option::Option::Some(v) => v,
                    ::core::option::Option::None => {
                        return ::core::result::Result::Err(#krate::UnpackError::InvalidValue { field: #field_name })
                    }
                },
            });
        } else if word {
            puts.push(quote!(| ((#raw & #mask) << #off)));
            gets.push(quote! {
                #ident: match <#ty as #krate::PdoValue>::from_raw((__w >> #off) & #mask, #bits_u32) {
                    ::core::option::Option::Some(v) => v,
                    ::core::option::Option::None => {
                        return ::core::result::Result::Err(#krate::UnpackError::InvalidValue { field: #field_name })
                    }
                },
            });
        } else {
            puts.push(quote!(#krate::bits::write_bits(buf, #off, #bits_u32, #raw);));
            gets.push(quote! {
                #ident: match <#ty as #krate::PdoValue>::from_raw(#krate::bits::read_bits(buf, #off, #bits_u32), #bits_u32) {
                    ::core::option::Option::Some(v) => v,
                    ::core::option::Option::None => {
                        return ::core::result::Result::Err(#krate::UnpackError::InvalidValue { field: #field_name })
                    }
                },
            });
        }
    }

    let pack_body = if aligned {
        // Gaps and padding are zero on the wire; fields that tile the image need no clearing.
        let clear = (covered < total_bits).then(|| quote!(buf.fill(0);));
        quote! {
            #clear
            #(#puts)*
        }
    } else if word {
        quote! {
            let __w: u64 = 0u64 #(#puts)*;
            #krate::bits::store_le_u64(buf, __w);
        }
    } else {
        quote! {
            buf.fill(0);
            #(#puts)*
        }
    };
    let unpack_prelude =
        if word { quote!(let __w: u64 = #krate::bits::load_le_u64(buf);) } else { quote!() };

    quote! {
        const _: () = {
            #[automatically_derived]
            #[allow(unused_variables, clippy::identity_op, clippy::erasing_op, clippy::unnecessary_cast, clippy::cast_lossless)]
            impl #ig #krate::Pdo for #name #tg #wc {
                const BITS: usize = #bits_lit;
                const LEN: usize = #len_lit;
                const MAPPING: &'static [#krate::MappingEntry] = &[#(#mapping),*];
                type Buffer = [u8; #len_lit];

                #[inline]
                fn pack(&self) -> ::core::result::Result<[u8; #len_lit], #krate::PackError> {
                    let mut buf = [0u8; #len_lit];
                    #krate::Pdo::pack_into(self, &mut buf)?;
                    ::core::result::Result::Ok(buf)
                }

                #[inline]
                fn pack_into(&self, buf: &mut [u8]) -> ::core::result::Result<(), #krate::PackError> {
                    let got = buf.len();
                    let buf = match buf.get_mut(..#len_lit) {
                        ::core::option::Option::Some(b) => b,
                        ::core::option::Option::None => {
                            return ::core::result::Result::Err(#krate::PackError::BufferTooSmall { needed: #len_lit, got })
                        }
                    };
                    #(#raws)*
                    #pack_body
                    ::core::result::Result::Ok(())
                }

                #[inline]
                fn unpack(buf: &[u8]) -> ::core::result::Result<Self, #krate::UnpackError> {
                    let got = buf.len();
                    let buf = match buf.get(..#len_lit) {
                        ::core::option::Option::Some(b) => b,
                        ::core::option::Option::None => {
                            return ::core::result::Result::Err(#krate::UnpackError::BufferTooSmall { needed: #len_lit, got })
                        }
                    };
                    #unpack_prelude
                    ::core::result::Result::Ok(Self { #(#gets)* })
                }
            }
        };
    }
}
