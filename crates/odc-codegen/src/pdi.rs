//! `pdi`: the process data image of an EtherCAT device as the master maps it, one struct per
//! direction (`Outputs`, `Inputs`), laid out by [`odc_analysis::image`].
//!
//! Where `pdo` has one struct per PDO, a master sees the SubDevice's bytes as one block per
//! direction (ethercrab's `inputs_raw()`/`outputs_raw()`): these structs unpack that block
//! whole. They are `#[derive(odc::Pdo)]` structs (`LEN`, `pack`, `pack_into`, `unpack` with a
//! length check), and with the runtime's feature `ethercrab` they implement `ethercrab_wire`'s
//! read, write and sized traits.

use odc_model::{Direction, Pdo};
use proc_macro2::{Ident, Literal, Span, TokenStream};
use quote::quote;

use crate::names::Namer;
use crate::pdo::{FieldName, field_name, field_type};
use crate::types::{RustTyTokens, index_literal, sub_literal};
use crate::{Ctx, doc};
use odc_analysis::image::{self, Image};

/// [`field_name`], without the object's name where the sub-object's repeats it (a dictionary
/// synthesised from the PDOs names object and sub-object alike: `Output 1`, `Output 1`).
fn short_name(ctx: &Ctx<'_>, entry: &odc_model::PdoEntry) -> FieldName {
    let mut name = field_name(ctx, entry);
    let synthesised = ctx.device.ethercat.as_ref().is_some_and(|e| e.dictionary_synthesised);
    if let (true, Some(n)) = (synthesised, &entry.name) {
        // The objects were made from the entries: the entry's own name is the better one.
        name.base = crate::names::snake(n);
        name.label.clone_from(n);
        return name;
    }
    let object = ctx.device.objects.get(&entry.index);
    let sub = ctx.device.sub(entry.index, entry.sub);
    if let (Some(o), Some(s)) = (object, sub) {
        let (o_snake, s_snake) = (crate::names::snake(&o.name), crate::names::snake(&s.name));
        if o.kind.has_subs() && !o_snake.is_empty() && s_snake.starts_with(&o_snake) {
            name.base = s_snake;
            name.label = s.name.to_string();
        }
    }
    name
}

/// The struct for one image, or nothing when no PDO is assigned; `assignment` says which
/// assignment it is of, for the doc.
fn image_struct(ctx: &Ctx<'_>, name: &Ident, img: &Image, assignment: &str) -> TokenStream {
    if img.is_empty() {
        return TokenStream::new();
    }
    let rt = &ctx.rt;
    let pdos: &[Pdo] = &ctx.device.pdos;
    // (entry, placed, segment's sync manager, type, name), gaps and untyped entries aside.
    let mut typed = Vec::new();
    let mut untyped = Vec::new();
    for seg in &img.segments {
        for placed in &seg.entries {
            let Some(pdo) = pdos.get(placed.pdo) else { continue };
            let Some(entry) = pdo.entries.get(placed.entry) else { continue };
            if entry.is_gap() {
                continue;
            }
            match field_type(ctx, entry) {
                Some(ty) => typed.push((pdo, entry, placed, seg.sm, ty, short_name(ctx, entry))),
                None => untyped.push(format!(
                    "`0x{:04X}:{:02X}` ({} bits at bit {}) is wider than any field type and is \
                     skipped.",
                    entry.index, entry.sub, entry.bits, placed.range.offset
                )),
            }
        }
    }
    // Channels of one terminal map objects of one name ("Output" in each of 16 PDOs): where a
    // name repeats, the PDO's name ("Channel 1") goes in front.
    let mut seen = std::collections::HashMap::<&str, usize>::new();
    for t in &typed {
        *seen.entry(t.5.base.as_str()).or_default() += 1;
    }
    let repeated: std::collections::HashSet<String> =
        seen.into_iter().filter(|(_, n)| *n > 1).map(|(b, _)| b.to_string()).collect();
    let mut namer = Namer::new();
    let mut out = Vec::new();
    let mut end = 0u32;
    for (pdo, entry, placed, sm, ty, name) in typed {
        let FieldName { base, label, rank } = name;
        let base = if repeated.contains(&base) && !pdo.name.is_empty() {
            crate::names::snake(&format!(
                "{} {}",
                pdo.name,
                entry.name.as_deref().unwrap_or(&label)
            ))
        } else {
            base
        };
        let suffix = format!("obj_{:04x}_{:02x}", entry.index, entry.sub);
        let slot = namer.propose_ranked(base, suffix, rank);
        let width =
            if entry.bits == 1 { "1 bit".to_string() } else { format!("{} bits", entry.bits) };
        let text = format!(
            "{label} (`0x{:04X}:{:02X}`, {width}; PDO `0x{:04X}`, sync manager {sm}, bit {}).",
            entry.index, entry.sub, pdo.mapping_index, placed.range.offset
        );
        out.push((slot, ty.tokens(rt), entry, placed.range.offset - end, text));
        end = placed.range.end();
    }
    let names = namer.finish("_", &[]);
    let total = Literal::usize_unsuffixed(img.len() * 8);
    let fields = out.iter().map(|(slot, ty, entry, gap, text)| {
        let name = Ident::new(&names[*slot], Span::call_site());
        let docs = doc(text);
        let idx = index_literal(entry.index);
        let sub = sub_literal(entry.sub);
        let bits = Literal::u16_unsuffixed(entry.bits);
        let pad = (*gap > 0).then(|| {
            let p = Literal::u32_unsuffixed(*gap);
            quote!(pad_bits = #p,)
        });
        quote! {
            #docs
            #[pdo(#pad index = #idx, sub = #sub, bits = #bits)]
            pub #name: #ty,
        }
    });
    let (what, raw) = match img.direction {
        Direction::Rx => ("Outputs (master → device)", "outputs_raw_mut()"),
        Direction::Tx => ("Inputs (device → master)", "inputs_raw()"),
    };
    let layout: Vec<String> = img
        .segments
        .iter()
        .map(|s| {
            let list: Vec<String> = s
                .pdos
                .iter()
                .filter_map(|&p| pdos.get(p))
                .map(|p| format!("`0x{:04X}`", p.mapping_index))
                .collect();
            format!(
                "- sync manager {}: bytes {}..{}, PDOs {}",
                s.sm,
                s.byte_offset,
                s.byte_offset + s.bytes,
                list.join(", ")
            )
        })
        .collect();
    let mut text = format!(
        "{what} of {assignment}, {} bytes, as the master maps them (ethercrab's `{raw}`):\n\n{}",
        img.len(),
        layout.join("\n")
    );
    for u in &untyped {
        text.push_str(&format!("\n\n{u}"));
    }
    let docs = doc(&text);
    let crate_path = rt.to_string().replace(' ', "");
    let krate = (crate_path != "::odc").then(|| quote!(, crate = #crate_path));
    // The derive's limit is a CAN frame's 64 bits unless raised.
    let max = (img.len() * 8 > 64).then(|| quote!(, max_bits = #total));
    quote! {
        #docs
        #[derive(Clone, Copy, Debug, Default, PartialEq, #rt::Pdo)]
        #[pdo(bits = #total #max #krate)]
        pub struct #name {
            #(#fields)*
        }
        #rt::impl_wire!(#name);
    }
}

/// `OUTPUT_LEN`, `INPUT_LEN`, `Outputs` and `Inputs` of one assignment; where `default`
/// (the default assignment's images) has the same image, a variant re-exports it.
fn image_items(
    ctx: &Ctx<'_>,
    assignment: &image::Assignment,
    what: &str,
    default: Option<&(Image, Image)>,
) -> Option<TokenStream> {
    let outputs = image::image(ctx.device, assignment, Direction::Rx).ok()?;
    let inputs = image::image(ctx.device, assignment, Direction::Tx).ok()?;
    let one = |img: &Image, default: Option<&Image>, name: &str, len_name: &str| {
        let ident = Ident::new(name, Span::call_site());
        let len_ident = Ident::new(len_name, Span::call_site());
        let (dir, kind) =
            if img.direction == Direction::Rx { ("outputs", "RxPDO") } else { ("inputs", "TxPDO") };
        if default == Some(img) {
            let docs = doc(&format!("Bytes of the {dir}: the default assignment's."));
            let reuse = (!img.is_empty()).then(|| quote!(pub use super::#ident;));
            return quote! {
                #docs
                pub const #len_ident: usize = super::#len_ident;
                #reuse
            };
        }
        let len = Literal::usize_unsuffixed(img.len());
        let docs = doc(&format!("Bytes of the {dir} (0 when no {kind} is assigned)."));
        let item = image_struct(ctx, &ident, img, what);
        quote! {
            #docs
            pub const #len_ident: usize = #len;
            #item
        }
    };
    let out_items = one(&outputs, default.map(|d| &d.0), "Outputs", "OUTPUT_LEN");
    let in_items = one(&inputs, default.map(|d| &d.1), "Inputs", "INPUT_LEN");
    Some(quote! { #out_items #in_items })
}

/// The module names of the variants, in [`image::variants`] order.
pub(crate) fn variant_names(variants: &[image::Variant]) -> Vec<Ident> {
    let mut namer = Namer::new();
    for (i, v) in variants.iter().enumerate() {
        let base = crate::names::snake(&v.name);
        let base = if base.is_empty() { format!("mapping_{}", i + 1) } else { base };
        namer.propose(base, format!("{}", i + 1));
    }
    namer
        .finish("_", &["outputs", "inputs"])
        .iter()
        .map(|n| Ident::new(n, Span::call_site()))
        .collect()
}

/// How a variant's doc names it.
pub(crate) fn variant_text(v: &image::Variant) -> String {
    match v.origin {
        image::Origin::DcOpMode => format!("the PDO assignment of DC op-mode `{}`", v.name),
        image::Origin::AlternativeSmMapping => {
            format!("the alternative PDO assignment `{}` (TwinCAT `AlternativeSmMapping`)", v.name)
        }
    }
}

/// The `pdi` module of an EtherCAT device; nothing for a CANopen device, or when the default
/// assignment names PDOs the device lacks (the checker reports that).
pub(crate) fn generate(ctx: &Ctx<'_>) -> TokenStream {
    if ctx.device.ethercat.is_none() {
        return TokenStream::new();
    }
    let default = image::default_assignment(ctx.device);
    let Some(items) = image_items(ctx, &default, "the default PDO assignment", None) else {
        return TokenStream::new();
    };
    let Ok(default_images) = image::default_images(ctx.device) else {
        return TokenStream::new();
    };
    let (variants, skipped) = image::variants(ctx.device);
    let names = variant_names(&variants);
    let modules = variants.iter().zip(&names).filter_map(|(v, name)| {
        let what = variant_text(v);
        let items = image_items(ctx, &v.assignment, &what, Some(&default_images))?;
        let docs = doc(&format!("The process image with {what}."));
        Some(quote! {
            #docs
            pub mod #name {
                #items
            }
        })
    });
    let mut text = format!(
        "Process data image of {} as an EtherCAT master maps it: sync managers in index \
         order, PDOs in assignment order, entries bit-packed, each sync manager rounded up to \
         whole bytes. The default assignment here; one module per DC op-mode or alternative \
         mapping of the ESI that assigns other PDOs.",
        ctx.device.name()
    );
    for s in &skipped {
        text.push_str(&format!("\n\nNo module for `{}`: {}.", s.name, s.reason));
    }
    let docs = doc(&text);
    quote! {
        #docs
        pub mod pdi {
            #items
            #(#modules)*
        }
    }
}
