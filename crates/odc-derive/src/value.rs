//! `#[derive(PdoValue)]` for `#[repr(int)]` enums, with an optional `#[pdo(other)]` catch-all.

use crate::attr::{self, Errors};
use proc_macro2::{Span, TokenStream};
use quote::{format_ident, quote};
use syn::{Data, DeriveInput, Fields, Ident, Path};

const REPRS: &[(&str, u32)] = &[
    ("u8", 8),
    ("u16", 16),
    ("u32", 32),
    ("u64", 64),
    ("i8", 8),
    ("i16", 16),
    ("i32", 32),
    ("i64", 64),
];

fn repr_of(input: &DeriveInput) -> Option<(Ident, u32)> {
    let mut found = None;
    for a in input.attrs.iter().filter(|a| a.path().is_ident("repr")) {
        let _ = a.parse_nested_meta(|meta| {
            if let Some(id) = meta.path.get_ident()
                && let Some((_, bits)) = REPRS.iter().find(|(n, _)| id == n)
            {
                found = Some((id.clone(), *bits));
            }
            Ok(())
        });
    }
    found
}

pub(crate) fn derive(input: &DeriveInput) -> TokenStream {
    let mut errors = Errors::default();
    let cont = attr::enum_container(&input.attrs, &mut errors);
    let krate: Path = cont.krate.clone().unwrap_or_else(|| syn::parse_quote!(::odc));
    let name = &input.ident;

    let Data::Enum(data) = &input.data else {
        errors.push(syn::Error::new(name.span(), "`#[derive(PdoValue)]` supports enums only"));
        return finish(errors, TokenStream::new());
    };
    let Some((repr, repr_bits)) = repr_of(input) else {
        errors.push(syn::Error::new(
            name.span(),
            "`#[derive(PdoValue)]` needs an integer representation such as `#[repr(u8)]` or `#[repr(i8)]`",
        ));
        return finish(errors, TokenStream::new());
    };
    let bits = match cont.bits {
        Some(b) if b.value == 0 || b.value > repr_bits => {
            errors.push(syn::Error::new(
                b.span,
                format!("`bits` must be between 1 and {repr_bits} for `{repr}`"),
            ));
            repr_bits
        }
        Some(b) => b.value,
        None => repr_bits,
    };

    let mut consts = Vec::new();
    let mut to_arms = Vec::new();
    let mut from_arms = Vec::new();
    let mut other: Option<Ident> = None;
    let mut prev: Option<Ident> = None;
    for (i, v) in data.variants.iter().enumerate() {
        let vid = &v.ident;
        let is_other = attr::variant_other(&v.attrs, &mut errors);
        if let Some(span) = is_other {
            let one_field = matches!(&v.fields, Fields::Unnamed(u) if u.unnamed.len() == 1);
            if !one_field {
                errors.push(syn::Error::new(
                    span,
                    format!("`#[pdo(other)]` needs a tuple variant with one `{repr}` field"),
                ));
            } else if other.is_some() {
                errors.push(syn::Error::new(span, "only one variant can be `#[pdo(other)]`"));
            } else {
                other = Some(vid.clone());
                to_arms.push(quote!(Self::#vid(v) => *v,));
            }
            continue;
        }
        if !matches!(v.fields, Fields::Unit) {
            errors.push(syn::Error::new(
                vid.span(),
                "variants with data need `#[pdo(other)]` (one catch-all tuple variant)",
            ));
            continue;
        }
        let c = format_ident!("__D{}", i, span = Span::mixed_site());
        let value = match (&v.discriminant, &prev) {
            (Some((_, e)), _) => quote!(#e),
            (None, Some(p)) => quote!(#p + 1),
            (None, None) => quote!(0),
        };
        consts.push(quote!(const #c: #repr = #value;));
        to_arms.push(quote!(Self::#vid => #c,));
        from_arms.push(quote!(#c => Self::#vid,));
        prev = Some(c);
    }
    let fallthrough = match &other {
        Some(o) => quote!(v => Self::#o(v),),
        None => quote!(_ => return ::core::option::Option::None,),
    };
    let bits_lit = proc_macro2::Literal::u32_suffixed(bits);
    let (ig, tg, wc) = input.generics.split_for_impl();
    let body = quote! {
        const _: () = {
            #(#consts)*
            #[automatically_derived]
            impl #ig #krate::PdoValue for #name #tg #wc {
                const BITS: u32 = #bits_lit;
                const SIGNED: bool = <#repr as #krate::PdoValue>::SIGNED;
                #[inline(always)]
                fn to_raw(&self) -> u64 {
                    let v: #repr = match self { #(#to_arms)* };
                    <#repr as #krate::PdoValue>::to_raw(&v)
                }
                #[inline(always)]
                fn from_raw(raw: u64, bits: u32) -> ::core::option::Option<Self> {
                    let v: #repr = <#repr as #krate::PdoValue>::from_raw(raw, bits)?;
                    ::core::option::Option::Some(match v { #(#from_arms)* #fallthrough })
                }
            }
        };
    };
    finish(errors, body)
}

fn finish(errors: Errors, body: TokenStream) -> TokenStream {
    match errors.take() {
        Some(e) => e.into_compile_error(),
        None => body,
    }
}
