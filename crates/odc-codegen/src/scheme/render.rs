//! The generated module of a checked scheme.

use std::collections::BTreeSet;

use super::expr::{arg_type, ident, linear_tokens, signed_literal};
use super::*;

/// The modules of every scheme, or `G604` diagnostics.
pub(crate) fn generate(
    ctx: &Ctx<'_>,
    schemes: &[Scheme],
    errors: &mut Vec<Diagnostic>,
) -> TokenStream {
    let mut out = TokenStream::new();
    let mut modules = BTreeSet::new();
    for s in schemes {
        let result = check(s).and_then(|c| {
            if !modules.insert(s.module.clone()) {
                return Err(format!("two schemes generate module `{}`", s.module));
            }
            let aliases = aliases(ctx.device, &c)?;
            Ok(module(ctx, &c, &aliases))
        });
        match result {
            Ok(tokens) => out.extend(tokens),
            Err(e) => errors.push(
                Diagnostic::error("G604", format!("parameter scheme `{}`: {e}", s.module))
                    .with_note(
                        "schemes are declared in the `<stem>.odc.toml` beside the device file",
                    ),
            ),
        }
    }
    out
}

pub(super) fn module(ctx: &Ctx<'_>, c: &Checked<'_>, aliases: &[Alias]) -> TokenStream {
    let rt = &ctx.rt;
    let s = c.scheme;
    let m = ident(&s.module);
    let f = ident(&s.function);
    let params: Vec<TokenStream> = c
        .args
        .iter()
        .map(|(n, (_, hi))| {
            let (ty, _) = arg_type(*hi);
            let n = ident(n);
            quote!(#n: #ty)
        })
        .collect();
    let names: Vec<Ident> = c.args.iter().map(|(n, _)| ident(n)).collect();
    let checks: Vec<TokenStream> = c
        .args
        .iter()
        .filter_map(|(n, (lo, hi))| {
            let (_, max) = arg_type(*hi);
            (*lo > 0 || *hi < max).then(|| {
                let n = ident(n);
                let (lo, hi) = (int_literal(lo.unsigned_abs()), int_literal(hi.unsigned_abs()));
                quote!(matches!(#n, #lo..=#hi))
            })
        })
        .collect();
    let guard = match checks.as_slice() {
        [] => TokenStream::new(),
        [one] => quote! {
            if !#one {
                return None;
            }
        },
        many => quote! {
            if !(#(#many)&&*) {
                return None;
            }
        },
    };
    let expr = linear_tokens(&c.index);
    let excluded: Vec<TokenStream> = c
        .exclude
        .iter()
        .map(|(lo, hi)| {
            let (l, h) = (int_literal(lo.unsigned_abs()), int_literal(hi.unsigned_abs()));
            if lo == hi { quote!(#l) } else { quote!(#l..=#h) }
        })
        .collect();
    let result = if excluded.is_empty() {
        quote! {
            // The generator checked that the declared ranges keep the value within 0..=0xFFFF.
            Some((#expr) as u16)
        }
    } else {
        quote! {
            // The generator checked that the declared ranges keep the value within 0..=0xFFFF.
            let index = (#expr) as u16;
            if matches!(index, #(#excluded)|*) {
                return None;
            }
            Some(index)
        }
    };
    let ranges = s
        .args
        .iter()
        .map(|a| format!("`{}` in `{}`", a.name, a.range.trim()))
        .collect::<Vec<_>>()
        .join(", ");
    let excluded_text = if s.exclude.is_empty() {
        String::new()
    } else {
        format!(" and for {} (other objects)", s.exclude.join(", "))
    };
    let index_doc = doc(&format!(
        "The object index of a parameter: `{}`, for {ranges}; `None` outside those ranges{excluded_text}.",
        s.index
    ));
    let mut items = vec![quote! {
        #index_doc
        pub const fn index(#(#params),*) -> Option<u16> {
            #guard
            #result
        }
    }];
    match (&c.element, &s.selector) {
        (Some((ename, (lo, hi), offset, efn)), _) => {
            let fdoc = doc(
                "The object of a parameter (sub-index 0; a VAR's value, an ARRAY's or RECORD's \
                 entry count), or `None` outside the ranges of [`index`].",
            );
            items.push(quote! {
                #fdoc
                pub const fn #f(#(#params),*) -> Option<#rt::ObjectAddr> {
                    match self::index(#(#names),*) {
                        Some(i) => Some(#rt::ObjectAddr::new(i, 0)),
                        None => None,
                    }
                }
            });
            let (ety, emax) = arg_type(*hi);
            let e = ident(ename);
            let efn = ident(efn);
            let echeck = (*lo > 0 || *hi < emax).then(|| {
                let (l, h) = (int_literal(lo.unsigned_abs()), int_literal(hi.unsigned_abs()));
                quote! {
                    if !matches!(#e, #l..=#h) {
                        return None;
                    }
                }
            });
            let (sub, sub_text) = if *offset == 0 {
                (quote!(#e), format!("`{ename}`"))
            } else {
                let off = signed_literal(*offset);
                (quote!(((#e as i64) + #off) as u8), format!("`{ename} + {offset}`"))
            };
            let edoc = doc(&format!(
                "Element `{ename}` ({lo}..={hi}) of an ARRAY or RECORD parameter: sub-index \
                 {sub_text}."
            ));
            items.push(quote! {
                #edoc
                pub const fn #efn(#(#params,)* #e: #ety) -> Option<#rt::ObjectAddr> {
                    #echeck
                    match self::index(#(#names),*) {
                        // The generator checked that the element range plus the offset
                        // stays within 0..=0xFF.
                        Some(i) => Some(#rt::ObjectAddr::new(i, #sub)),
                        None => None,
                    }
                }
            });
        }
        (None, Some(sel)) => {
            let ty = ident(&sel.type_name);
            let arg = ident(sel.arg.as_deref().unwrap_or("sel"));
            let variants: Vec<TokenStream> = sel
                .values
                .iter()
                .map(|v| {
                    let name = ident(&crate::names::camel(&v.name));
                    let lit = Literal::u8_unsuffixed(v.sub);
                    let d = doc(&if v.doc.is_empty() {
                        format!("Sub-index {}.", v.sub)
                    } else {
                        format!("{} (sub-index {}).", v.doc, v.sub)
                    });
                    quote!(#d #name = #lit,)
                })
                .collect();
            let tdoc = doc("What the sub-index of a parameter's object selects.");
            let fdoc = doc(&format!(
                "The sub-object `{}` selects of a parameter, or `None` outside the ranges of \
                 [`index`].",
                sel.arg.as_deref().unwrap_or("sel")
            ));
            items.push(quote! {
                #tdoc
                #[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
                #[repr(u8)]
                pub enum #ty { #(#variants)* }

                #fdoc
                pub const fn #f(#(#params,)* #arg: #ty) -> Option<#rt::ObjectAddr> {
                    match self::index(#(#names),*) {
                        Some(i) => Some(#rt::ObjectAddr::new(i, #arg as u8)),
                        None => None,
                    }
                }
            });
        }
        (None, None) => {
            let fdoc = doc("The object of a parameter, or `None` outside the ranges of [`index`].");
            items.push(quote! {
                #fdoc
                pub const fn #f(#(#params),*) -> Option<#rt::ObjectAddr> {
                    match self::index(#(#names),*) {
                        Some(i) => Some(#rt::ObjectAddr::new(i, 0)),
                        None => None,
                    }
                }
            });
        }
    }
    let mut infos = Vec::new();
    for a in aliases {
        let Some(entry) = ctx.names.entries.get(&(a.index, a.sub)) else { continue };
        let path = entry.path();
        let ty = entry.ty.tokens(rt);
        let name = ident(&a.name);
        let d = doc(&format!("{}: `0x{:04X}:{:02X}`, {}.", a.name, a.index, a.sub, a.what));
        items.push(quote! {
            #d
            pub const #name: #rt::Entry<#ty> = #path;
        });
        infos.push(quote!(#path.info()));
    }
    if let Some(size) = s.write_size {
        let size = Literal::usize_unsuffixed(usize::from(size));
        items.push(quote! {
            /// The width in bytes at which the device takes every write of these parameters,
            /// whatever their type (declared in the overlay): give it to `write_widened` of
            /// the SDO client.
            pub const WRITE_SIZE: usize = #size;
        });
    }
    let n = Literal::usize_unsuffixed(infos.len());
    items.push(quote! {
        /// The entries of the device file that the scheme reaches, sorted by address.
        pub static ENTRIES: [#rt::EntryInfo; #n] = [#(#infos),*];

        /// The device file's description of an address (data type, access, name), if the file
        /// defines it.
        pub fn lookup(addr: #rt::ObjectAddr) -> Option<&'static #rt::EntryInfo> {
            ENTRIES.binary_search_by(|e| e.addr.cmp(&addr)).ok().and_then(|i| ENTRIES.get(i))
        }
    });
    let text = if s.doc.is_empty() {
        format!("Parameters of {} by their vendor numbers.", ctx.device.name())
    } else {
        s.doc.clone()
    };
    let mdoc = doc(&format!(
        "{text}\n\nIndex rule: `{}`. Generated from the `[[scheme]]` of the device's overlay.",
        s.index
    ));
    quote! {
        #mdoc
        pub mod #m {
            #(#items)*
        }
    }
}
