//! Process data a device file cannot map: PDO content a manual lays out by name and size
//! without naming objects for it, declared in the device's overlay.
//!
//! LinMot's manual gives RxPDO 1 as "Control Word (16), Motion Cmd Header (16), Motion Cmd
//! Par Bytes 0..3 (32)" but no object index for these built-in items, so its EDS maps nothing
//! and the generated `pdo` module is empty. The overlay can declare such a layout:
//!
//! ```toml
//! [[process-data]]
//! name = "RxPdo1"                 # the generated struct, in module `process`
//! cob-id = "0x200"                # $NODEID + this
//! doc = "RxPDO 1 of the default mapping (manual 5.1)."
//! fields = [
//!     { name = "control_word", type = "u16" },
//!     { name = "mc_header", type = "u16" },
//!     { name = "mc_par_bytes_0_3", type = "u32" },
//! ]
//! ```
//!
//! and the generator emits, in a module `process`, a struct with those fields in that order,
//! little-endian and byte-packed as CiA 301 packs PDOs, with `pack`, `unpack`, `LEN` and
//! `cob_id(node)`. There is no `MAPPING`: no object stands behind the fields.

use odc_model::Diagnostic;
use proc_macro2::{Ident, Literal, TokenStream};
use quote::quote;
use serde::Deserialize;

use crate::{Ctx, doc};

/// A PDO layout declared in the overlay (`[[process-data]]`).
#[derive(Clone, Debug, PartialEq, Eq, Deserialize)]
#[serde(rename_all = "kebab-case", deny_unknown_fields)]
pub struct ProcessData {
    /// The struct's name (camel case).
    pub name: String,
    /// The COB-ID's offset from the node id (`"0x200"` for `$NODEID + 0x200`).
    pub cob_id: String,
    /// What it is, and where the manual gives it.
    #[serde(default)]
    pub doc: String,
    /// The fields, in wire order.
    pub fields: Vec<ProcessField>,
}

/// One field of a [`ProcessData`].
#[derive(Clone, Debug, PartialEq, Eq, Deserialize)]
#[serde(rename_all = "kebab-case", deny_unknown_fields)]
pub struct ProcessField {
    /// Its name (snake case).
    pub name: String,
    /// `u8`, `u16`, `u32`, `i8`, `i16` or `i32`.
    #[serde(rename = "type")]
    pub ty: String,
    /// What it is.
    #[serde(default)]
    pub doc: String,
}

fn width(ty: &str) -> Option<(u32, bool)> {
    Some(match ty {
        "u8" => (8, false),
        "u16" => (16, false),
        "u32" => (32, false),
        "i8" => (8, true),
        "i16" => (16, true),
        "i32" => (32, true),
        _ => return None,
    })
}

fn ident(s: &str) -> Result<Ident, String> {
    syn::parse_str::<Ident>(s).map_err(|_| format!("`{s}` is not a Rust identifier"))
}

fn parse_number(s: &str) -> Option<u32> {
    let s = s.trim().replace('_', "");
    match s.strip_prefix("0x").or_else(|| s.strip_prefix("0X")) {
        Some(h) => u32::from_str_radix(h, 16).ok(),
        None => s.parse().ok(),
    }
}

fn layout(ctx: &Ctx<'_>, p: &ProcessData) -> Result<TokenStream, String> {
    let rt = &ctx.rt;
    let name = ident(&p.name)?;
    let cob = parse_number(&p.cob_id)
        .filter(|c| *c <= 0x780)
        .ok_or_else(|| format!("cob-id `{}` is not a CAN-ID base", p.cob_id))?;
    let mut offset = 0u32;
    let mut fields = Vec::new();
    let mut packs = Vec::new();
    let mut unpacks = Vec::new();
    for f in &p.fields {
        let fname = ident(&f.name)?;
        let (bits, signed) = width(&f.ty)
            .ok_or_else(|| format!("field `{}`: type `{}` is not u8..i32", f.name, f.ty))?;
        let ty = ident(&f.ty)?;
        let fdoc = doc(&if f.doc.is_empty() {
            format!("`{}`, {bits} bits.", f.name)
        } else {
            f.doc.clone()
        });
        fields.push(quote!(#fdoc pub #fname: #ty,));
        let off = Literal::usize_unsuffixed(offset as usize);
        let b = Literal::u32_unsuffixed(bits);
        let raw =
            if signed { quote!(self.#fname as i64 as u64) } else { quote!(self.#fname as u64) };
        packs.push(quote!(#rt::bits::write_bits(&mut buf, #off, #b, #raw);));
        let value = if signed {
            quote!(#rt::bits::sign_extend(#rt::bits::read_bits(buf, #off, #b), #b) as #ty)
        } else {
            quote!(#rt::bits::read_bits(buf, #off, #b) as #ty)
        };
        unpacks.push(quote!(#fname: #value,));
        offset += bits;
    }
    if offset == 0 || offset > 64 {
        return Err(format!("{} bits; a PDO carries 8 to 64", offset));
    }
    let len = Literal::usize_unsuffixed(offset.div_ceil(8) as usize);
    let cob = crate::types::int_literal(u64::from(cob));
    let sdoc = doc(&format!(
        "{}\n\nDeclared in the device's overlay: no object of the file stands behind these \
         fields. {offset} bits, little-endian, in field order.",
        if p.doc.is_empty() { p.name.clone() } else { p.doc.clone() }
    ));
    Ok(quote! {
        #sdoc
        #[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
        pub struct #name {
            #(#fields)*
        }
        impl #name {
            /// Bytes on the wire.
            pub const LEN: usize = #len;
            /// The CAN-ID for node `node_id`.
            pub const fn cob_id(node_id: #rt::cob::NodeId) -> u32 {
                #cob + node_id.get() as u32
            }
            /// The bytes on the wire.
            pub fn pack(&self) -> [u8; #len] {
                let mut buf = [0u8; #len];
                #(#packs)*
                buf
            }
            /// The fields of `buf`; `None` when it is shorter than [`Self::LEN`].
            pub fn unpack(buf: &[u8]) -> Option<Self> {
                if buf.len() < Self::LEN {
                    return None;
                }
                Some(Self { #(#unpacks)* })
            }
        }
    })
}

/// The `process` module, or nothing when the overlay declares no layout; `G605` for a layout
/// that cannot be generated.
pub(crate) fn generate(
    ctx: &Ctx<'_>,
    layouts: &[ProcessData],
    errors: &mut Vec<Diagnostic>,
) -> TokenStream {
    if layouts.is_empty() {
        return TokenStream::new();
    }
    let mut items = Vec::new();
    for p in layouts {
        match layout(ctx, p) {
            Ok(t) => items.push(t),
            Err(e) => errors.push(
                Diagnostic::error("G605", format!("process data `{}`: {e}", p.name)).with_note(
                    "process data are declared in the `<stem>.odc.toml` beside the device file",
                ),
            ),
        }
    }
    quote! {
        /// PDO content the device file cannot map (its manual names no objects for it), as the
        /// device's overlay declares it.
        pub mod process {
            #(#items)*
        }
    }
}
