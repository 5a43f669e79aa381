//! Tokens for the Rust types of [`RustTy`] and `const` expressions for values of them.

use odc_model::Value;
use proc_macro2::{Literal, TokenStream};
use quote::quote;

pub use odc_analysis::RustTy;

/// What the generator writes for a [`RustTy`]: its tokens and `const` expressions of values.
pub trait RustTyTokens: Copy {
    /// The type's tokens, with `rt` the runtime path.
    fn tokens(self, rt: &TokenStream) -> TokenStream;
    /// A `const` expression of type `Option<Self>` for `value`, or `None` when the value is
    /// not one of this type (it does not fit, or is `$NODEID`-relative, or invalid).
    fn option_expr(self, value: &Value, rt: &TokenStream) -> Option<TokenStream>;
    /// A default expression of type `Option<DefaultValue<Self>>`, or `None` as for
    /// [`RustTyTokens::option_expr`]; `$NODEID`-relative values of integer types stay symbolic.
    fn default_expr(self, value: &Value, rt: &TokenStream) -> Option<TokenStream>;
    /// The builder call that gives a descriptor its default (`.with_default(…)`), or `None` as
    /// for [`RustTyTokens::default_expr`].
    fn default_builder(self, value: &Value, rt: &TokenStream) -> Option<TokenStream>;
}

impl RustTyTokens for RustTy {
    /// The type's tokens, with `rt` the runtime path.
    fn tokens(self, rt: &TokenStream) -> TokenStream {
        match self {
            RustTy::Bool => quote!(bool),
            RustTy::Unsigned(8) => quote!(u8),
            RustTy::Unsigned(16) => quote!(u16),
            RustTy::Unsigned(32) => quote!(u32),
            RustTy::Unsigned(64) => quote!(u64),
            RustTy::Unsigned(24) => quote!(#rt::U24),
            RustTy::Unsigned(40) => quote!(#rt::U40),
            RustTy::Unsigned(48) => quote!(#rt::U48),
            RustTy::Unsigned(_) => quote!(#rt::U56),
            RustTy::Signed(8) => quote!(i8),
            RustTy::Signed(16) => quote!(i16),
            RustTy::Signed(32) => quote!(i32),
            RustTy::Signed(64) => quote!(i64),
            RustTy::Signed(24) => quote!(#rt::I24),
            RustTy::Signed(40) => quote!(#rt::I40),
            RustTy::Signed(48) => quote!(#rt::I48),
            RustTy::Signed(_) => quote!(#rt::I56),
            RustTy::F32 => quote!(f32),
            RustTy::F64 => quote!(f64),
            RustTy::Text(n) => {
                let n = Literal::usize_unsuffixed(n);
                quote!(#rt::VisibleString<#n>)
            }
            RustTy::Bytes(n) => {
                let n = Literal::usize_unsuffixed(n);
                quote!(#rt::OctetString<#n>)
            }
            RustTy::Unicode(n) => {
                let n = Literal::usize_unsuffixed(n);
                quote!(#rt::UnicodeString<#n>)
            }
            RustTy::Domain => quote!(#rt::Domain),
            RustTy::TimeOfDay => quote!(#rt::TimeOfDay),
            RustTy::TimeDifference => quote!(#rt::TimeDifference),
            RustTy::Controlword => quote!(#rt::cia402::Controlword),
            RustTy::Statusword => quote!(#rt::cia402::Statusword),
        }
    }

    /// A `const` expression of type `Option<Self>` for `value`, or `None` when the value is
    /// not one of this type (it does not fit, or is `$NODEID`-relative, or invalid).
    fn option_expr(self, value: &Value, rt: &TokenStream) -> Option<TokenStream> {
        Some(match value_expr(self, value, rt)? {
            ValueExpr::Plain(e) => quote!(Some(#e)),
            ValueExpr::Checked(e) => e,
        })
    }

    /// A default expression of type `Option<DefaultValue<Self>>`, or `None` as for
    /// [`RustTy::option_expr`]; `$NODEID`-relative values of integer types stay symbolic.
    fn default_expr(self, value: &Value, rt: &TokenStream) -> Option<TokenStream> {
        if let Value::NodeIdPlus(off) = value {
            if !matches!(self, RustTy::Unsigned(_) | RustTy::Signed(_)) {
                return None;
            }
            let off = u32::try_from(*off).ok()?;
            let lit = int_literal(u64::from(off));
            return Some(quote!(Some(#rt::DefaultValue::NodeIdPlus(#lit))));
        }
        Some(match value_expr(self, value, rt)? {
            ValueExpr::Plain(e) => quote!(Some(#rt::DefaultValue::Value(#e))),
            ValueExpr::Checked(e) => quote! {
                match #e {
                    Some(v) => Some(#rt::DefaultValue::Value(v)),
                    None => None,
                }
            },
        })
    }
    /// The builder call that gives a descriptor its default (`.with_default(…)`), or `None` as
    /// for [`RustTy::default_expr`].
    fn default_builder(self, value: &Value, rt: &TokenStream) -> Option<TokenStream> {
        if let Value::NodeIdPlus(off) = value {
            if !matches!(self, RustTy::Unsigned(_) | RustTy::Signed(_)) {
                return None;
            }
            let lit = int_literal(u64::from(u32::try_from(*off).ok()?));
            return Some(quote!(.with_default(#rt::DefaultValue::NodeIdPlus(#lit))));
        }
        Some(match value_expr(self, value, rt)? {
            ValueExpr::Plain(e) => quote!(.with_default(#rt::DefaultValue::Value(#e))),
            ValueExpr::Checked(e) => quote!(.with_default_checked(#e)),
        })
    }
}

/// The type's path in expression position (`VisibleString::<8>`).
fn expr_path(this: RustTy, rt: &TokenStream) -> TokenStream {
    match this {
        RustTy::Text(n) => {
            let n = Literal::usize_unsuffixed(n);
            quote!(#rt::VisibleString::<#n>)
        }
        RustTy::Bytes(n) => {
            let n = Literal::usize_unsuffixed(n);
            quote!(#rt::OctetString::<#n>)
        }
        RustTy::Unicode(n) => {
            let n = Literal::usize_unsuffixed(n);
            quote!(#rt::UnicodeString::<#n>)
        }
        _ => this.tokens(rt),
    }
}

/// A `const` expression of type `Self` (plain) or `Option<Self>` (checked constructor).
fn value_expr(this: RustTy, value: &Value, rt: &TokenStream) -> Option<ValueExpr> {
    let ty = expr_path(this, rt);
    Some(match (this, value) {
        (RustTy::Bool, Value::Bool(b)) => ValueExpr::Plain(quote!(#b)),
        (RustTy::Bool, Value::Unsigned(u @ (0 | 1))) => {
            let b = *u == 1;
            ValueExpr::Plain(quote!(#b))
        }
        (RustTy::Unsigned(bits), Value::Unsigned(u)) => {
            if bits < 64 && *u >> bits != 0 {
                return None;
            }
            let lit = int_literal(*u);
            if this.is_native_int() {
                ValueExpr::Plain(quote!(#lit))
            } else {
                ValueExpr::Checked(quote!(#ty::new(#lit)))
            }
        }
        (RustTy::Unsigned(_), Value::Signed(i)) if *i >= 0 => {
            return value_expr(this, &Value::Unsigned(i.unsigned_abs()), rt);
        }
        (RustTy::Signed(bits), Value::Signed(i)) => {
            let min = -(1i128 << (bits - 1));
            let max = (1i128 << (bits - 1)) - 1;
            if i128::from(*i) < min || i128::from(*i) > max {
                return None;
            }
            let lit = Literal::u64_unsuffixed(i.unsigned_abs());
            let e = if *i < 0 { quote!(-#lit) } else { quote!(#lit) };
            if this.is_native_int() {
                ValueExpr::Plain(e)
            } else {
                ValueExpr::Checked(quote!(#ty::new(#e)))
            }
        }
        (RustTy::Signed(_), Value::Unsigned(u)) => {
            let i = i64::try_from(*u).ok()?;
            return value_expr(this, &Value::Signed(i), rt);
        }
        (RustTy::F32, Value::Real32(b)) => {
            let lit = hex_literal(u64::from(*b), 8);
            ValueExpr::Plain(quote!(f32::from_bits(#lit)))
        }
        (RustTy::F64, Value::Real64(b)) => {
            let lit = hex_literal(*b, 16);
            ValueExpr::Plain(quote!(f64::from_bits(#lit)))
        }
        (RustTy::Text(n), Value::Text(s)) => {
            if s.len() > n || !s.bytes().all(|b| (0x20..=0x7E).contains(&b)) {
                return None;
            }
            ValueExpr::Checked(quote!(#ty::new(#s)))
        }
        (RustTy::Bytes(n), Value::Bytes(b)) => {
            if b.len() != n {
                return None;
            }
            let bytes = b.iter().map(|&x| hex_literal(u64::from(x), 2));
            ValueExpr::Plain(quote!(#rt::OctetString([#(#bytes),*])))
        }
        (RustTy::Unicode(n), Value::Unicode(units)) => {
            if units.len() * 2 > n {
                return None;
            }
            let bytes =
                units.iter().flat_map(|u| u.to_le_bytes()).map(|b| hex_literal(b.into(), 2));
            ValueExpr::Checked(quote!(#ty::from_le_bytes(&[#(#bytes),*])))
        }
        (RustTy::Controlword | RustTy::Statusword, Value::Unsigned(u)) => {
            let bits = hex_literal(u16::try_from(*u).ok()?.into(), 4);
            ValueExpr::Plain(quote!(#ty(#bits)))
        }
        (RustTy::Controlword | RustTy::Statusword, Value::Signed(i)) if *i >= 0 => {
            return value_expr(this, &Value::Unsigned(i.unsigned_abs()), rt);
        }
        (RustTy::TimeOfDay | RustTy::TimeDifference, Value::Time { ms, days }) => {
            let ms = Literal::u32_unsuffixed(*ms);
            let days = Literal::u16_unsuffixed(*days);
            ValueExpr::Plain(quote!(#ty { ms: #ms, days: #days }))
        }
        _ => return None,
    })
}

/// A value expression: of the type itself, or of `Option` when a checked constructor builds it.
enum ValueExpr {
    Plain(TokenStream),
    Checked(TokenStream),
}

/// An integer literal: decimal below 0x100, hex above (addresses, COB-IDs, masks read better).
pub fn int_literal(v: u64) -> Literal {
    if v < 0x100 {
        Literal::u64_unsuffixed(v)
    } else {
        let digits = if v <= 0xFFFF {
            4
        } else if v <= 0xFFFF_FFFF {
            8
        } else {
            16
        };
        hex_literal(v, digits)
    }
}

/// `0x…` with at least `digits` digits, and `_` every 4 digits above 4.
pub fn hex_literal(v: u64, digits: usize) -> Literal {
    let raw = format!("{v:0digits$X}");
    let text = if raw.len() > 4 {
        let chunks: Vec<&str> =
            raw.as_bytes().rchunks(4).rev().filter_map(|c| std::str::from_utf8(c).ok()).collect();
        chunks.join("_")
    } else {
        raw
    };
    format!("0x{text}").parse().unwrap_or_else(|_| Literal::u64_unsuffixed(v))
}

/// A 16-bit index as `0x1A00`.
pub fn index_literal(index: u16) -> Literal {
    hex_literal(u64::from(index), 4)
}

/// A sub-index as `0x01`.
pub fn sub_literal(sub: u8) -> Literal {
    hex_literal(u64::from(sub), 2)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn literals() {
        assert_eq!(int_literal(5).to_string(), "5");
        assert_eq!(int_literal(0x180).to_string(), "0x0180");
        assert_eq!(int_literal(0x6040_0010).to_string(), "0x6040_0010");
        assert_eq!(index_literal(0x1A00).to_string(), "0x1A00");
    }

    #[test]
    fn cia402_word_values() {
        let rt = quote!(::odc);
        assert_eq!(
            RustTy::Controlword.option_expr(&Value::Unsigned(6), &rt).map(|t| t.to_string()),
            Some("Some (:: odc :: cia402 :: Controlword (0x0006))".into())
        );
        assert!(RustTy::Statusword.option_expr(&Value::Unsigned(0x1_0000), &rt).is_none());
        assert!(RustTy::Controlword.default_expr(&Value::NodeIdPlus(1), &rt).is_none());
    }

    #[test]
    fn values_fit_their_type() {
        let rt = quote!(::odc);
        let u8t = RustTy::Unsigned(8);
        assert!(u8t.option_expr(&Value::Unsigned(256), &rt).is_none());
        assert_eq!(
            u8t.option_expr(&Value::Unsigned(255), &rt).map(|t| t.to_string()),
            Some("Some (255)".into())
        );
        let i16t = RustTy::Signed(16);
        assert_eq!(
            i16t.option_expr(&Value::Signed(-5), &rt).map(|t| t.to_string()),
            Some("Some (- 5)".into())
        );
        assert!(i16t.option_expr(&Value::Signed(40000), &rt).is_none());
        let d = i16t.default_expr(&Value::Signed(-5), &rt).map(|t| t.to_string());
        assert_eq!(
            d,
            Some(":: odc :: DefaultValue :: Value (- 5)".replace(":: odc", "Some (:: odc") + ")")
        );
        let n = RustTy::Unsigned(32)
            .default_expr(&Value::NodeIdPlus(0x180), &rt)
            .map(|t| t.to_string());
        assert_eq!(n, Some("Some (:: odc :: DefaultValue :: NodeIdPlus (0x0180))".into()));
    }
}
