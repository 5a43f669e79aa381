//! Tokens of the scheme's expressions and argument types.

use odc_analysis::scheme::Linear;
use proc_macro2::{Ident, Span, TokenStream};
use quote::quote;

use crate::types::int_literal;

/// `0x2000 + 0x100 * (group as i64) + (number as i64)` as tokens, in `i64`.
pub(super) fn linear_tokens(l: &Linear) -> TokenStream {
    let c = signed_literal(l.constant);
    let terms = l.terms.iter().map(|(coef, v)| {
        let v = ident(v);
        match *coef {
            1 => quote!(+ (#v as i64)),
            -1 => quote!(- (#v as i64)),
            c if c < 0 => {
                let m = signed_literal(c.saturating_neg());
                quote!(- #m * (#v as i64))
            }
            c => {
                let m = signed_literal(c);
                quote!(+ #m * (#v as i64))
            }
        }
    });
    quote!(#c #(#terms)*)
}

pub(super) fn signed_literal(v: i64) -> TokenStream {
    if v < 0 {
        let m = int_literal(v.unsigned_abs());
        quote!(-#m)
    } else {
        let m = int_literal(v.unsigned_abs());
        quote!(#m)
    }
}

pub(super) fn ident(s: &str) -> Ident {
    Ident::new(s, Span::call_site())
}

/// The narrowest unsigned Rust type for values up to `hi`.
pub(super) fn arg_type(hi: i64) -> (TokenStream, i64) {
    if hi <= i64::from(u8::MAX) {
        (quote!(u8), i64::from(u8::MAX))
    } else if hi <= i64::from(u16::MAX) {
        (quote!(u16), i64::from(u16::MAX))
    } else {
        (quote!(u32), i64::from(u32::MAX))
    }
}
