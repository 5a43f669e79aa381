//! `pdo`: one struct per PDO of the default mapping.

use std::collections::BTreeMap;

use odc_model::{Diagnostic, Direction, Pdo, PdoEntry, Value};
use proc_macro2::{Ident, Literal, Span, TokenStream};
use quote::quote;

use crate::names::{self, Namer};
use crate::od::value_text;
use crate::standard;
use crate::types::{RustTy, hex_literal, index_literal, int_literal, sub_literal};
use crate::{Ctx, doc};

/// The COB-ID's "PDO not valid" bit.
pub const COB_INVALID: u64 = 0x8000_0000;

/// A PDO as the generated code names it.
pub struct PdoName {
    /// The struct.
    pub ty: Ident,
    /// A snake-case name, for functions of the master plan.
    pub func: Ident,
}

/// Names of the PDOs, in `device.pdos` order.
pub fn pdo_names(ctx: &Ctx<'_>) -> Vec<PdoName> {
    let mut namer = Namer::new();
    for pdo in &ctx.device.pdos {
        let (prefix, base) = match pdo.direction {
            Direction::Rx => ("Rpdo", 0x1600),
            Direction::Tx => ("Tpdo", 0x1A00),
        };
        let canopen = pdo.comm_index.is_some() || pdo.sync_manager.is_none();
        let proposed = if canopen && (base..base + 0x200).contains(&pdo.mapping_index) {
            format!("{prefix}{}", pdo.mapping_index - base + 1)
        } else {
            names::camel(&pdo.name)
        };
        namer.propose(proposed, format!("{prefix}{:04X}", pdo.mapping_index));
    }
    namer
        .finish("", &[])
        .into_iter()
        .map(|t| PdoName {
            func: Ident::new(&names::snake(&t), Span::call_site()),
            ty: Ident::new(&t, Span::call_site()),
        })
        .collect()
}

/// One field of a PDO struct.
pub(crate) struct Field {
    pub(crate) name: Ident,
    ty: TokenStream,
    pub(crate) index: u16,
    pub(crate) sub: u8,
    bits: u16,
    pad_before: u32,
    doc: String,
}

/// The fields of a PDO (gaps folded into `pad_before`) and the padding after the last one.
pub(crate) fn fields(ctx: &Ctx<'_>, pdo: &Pdo, errors: &mut Vec<Diagnostic>) -> (Vec<Field>, u32) {
    let rt = &ctx.rt;
    let mut namer = Namer::new();
    let mut out = Vec::new();
    let mut pad = 0u32;
    for entry in &pdo.entries {
        if entry.is_gap() {
            pad += u32::from(entry.bits);
            continue;
        }
        let bits = u32::from(entry.bits);
        let Some(ty) = field_type(ctx, entry) else {
            errors.push(
                Diagnostic::error(
                    "G603",
                    format!(
                        "PDO 0x{:04X} maps 0x{:04X}:{:02X} with {bits} bits: wider than any field type",
                        pdo.mapping_index, entry.index, entry.sub
                    ),
                )
                .with_label(entry.span, "this mapping entry")
                .with_object(pdo.mapping_index, None),
            );
            continue;
        };
        let FieldName { base, label, rank } = field_name(ctx, entry);
        let sub = ctx.device.sub(entry.index, entry.sub);
        let suffix = format!("obj_{:04x}_{:02x}", entry.index, entry.sub);
        let name = namer.propose_ranked(base, suffix, rank);
        let mut doc = format!("{label} (`0x{:04X}:{:02X}`, {bits} bits", entry.index, entry.sub);
        if let Some(s) = sub {
            doc.push_str(&format!(", {}", s.data_type.name()));
        }
        doc.push_str(").");
        out.push((name, ty.tokens(rt), entry.index, entry.sub, entry.bits, pad, doc));
        pad = 0;
    }
    let names = namer.finish("_", &[]);
    let fields = out
        .into_iter()
        .map(|(p, ty, index, sub, bits, pad_before, doc)| Field {
            name: Ident::new(&names[p], Span::call_site()),
            ty,
            index,
            sub,
            bits,
            pad_before,
            doc,
        })
        .collect();
    (fields, pad)
}

/// The Rust type of a mapped entry: the descriptor's type when `od` has one (so the field and
/// `od::X` agree, CiA 402 words included), else the data type's, else an unsigned integer of
/// the mapped width; `None` for an entry wider than 64 bits.
pub(crate) fn field_type(ctx: &Ctx<'_>, entry: &PdoEntry) -> Option<RustTy> {
    let sub = ctx.device.sub(entry.index, entry.sub);
    let bits = u32::from(entry.bits);
    let declared = ctx
        .names
        .entries
        .get(&(entry.index, entry.sub))
        .map(|e| e.ty)
        .or_else(|| sub.and_then(RustTy::of))
        .or_else(|| {
            entry
                .data_type
                .map(|dt| odc_model::SubObject::new(0, "", dt, odc_model::Access::Rw))
                .as_ref()
                .and_then(RustTy::of)
        });
    let natural = declared.and_then(RustTy::natural_bits);
    match (declared, natural) {
        (Some(t), Some(n)) if t.is_pdo_value() && bits <= n && (bits == n || t != RustTy::Bool) => {
            Some(t)
        }
        _ => RustTy::raw(bits),
    }
}

/// How a field for a mapped entry is named: a snake-case base, the label for its doc, and the
/// rank that decides who keeps a name two entries share.
pub(crate) struct FieldName {
    pub base: String,
    pub label: String,
    pub rank: u8,
}

/// The name of the field for `entry`: object and sub-object name, else the ESI entry name.
pub(crate) fn field_name(ctx: &Ctx<'_>, entry: &PdoEntry) -> FieldName {
    let sub = ctx.device.sub(entry.index, entry.sub);
    let object = ctx.device.objects.get(&entry.index);
    let (base, label) = match (object, sub) {
        (Some(o), Some(s)) if o.kind.has_subs() => {
            (names::snake(&format!("{} {}", o.name, s.name)), format!("{}: {}", o.name, s.name))
        }
        (Some(o), _) => (names::snake(&o.name), o.name.clone()),
        (None, _) => {
            let n = entry.name.clone().unwrap_or_default();
            (names::snake(&n), n)
        }
    };
    let rank = match object {
        Some(o) if !o.kind.has_subs() => standard::rank(entry.index, &o.name),
        _ => u8::from(standard::is_standard_area(entry.index)),
    };
    FieldName { base, label, rank }
}

/// `cob_id(node_id)` for a CANopen PDO, with the text of its rule.
fn cob_id_fn(cob: &Value, rt: &TokenStream) -> Option<(TokenStream, String)> {
    Some(match cob {
        Value::NodeIdPlus(off) => {
            let off = u32::try_from(*off).ok()?;
            let lit = int_literal(u64::from(off));
            (
                quote! {
                    pub const fn cob_id(node_id: #rt::cob::NodeId) -> u32 {
                        #lit + node_id.get() as u32
                    }
                },
                value_text(cob),
            )
        }
        Value::Unsigned(v) => {
            let v = u32::try_from(*v).ok()?;
            let lit = int_literal(u64::from(v));
            (
                quote! {
                    pub const fn cob_id(_node_id: #rt::cob::NodeId) -> u32 {
                        #lit
                    }
                },
                value_text(cob),
            )
        }
        _ => return None,
    })
}

/// Whether the PDO is valid by default (COB-ID bit 31 clear); unknown COB-IDs count as valid.
pub fn enabled_by_default(pdo: &Pdo) -> bool {
    match &pdo.cob_id {
        Some(Value::NodeIdPlus(off)) => (*off as u64) & COB_INVALID == 0,
        Some(Value::Unsigned(v)) => v & COB_INVALID == 0,
        _ => true,
    }
}

/// Per sync manager: the image size in bytes and the positions of its PDOs in `device.pdos`.
pub type SmImages = BTreeMap<u8, (usize, Vec<usize>)>;

/// Bit offset of each PDO in its sync manager's image, and each image, for the default
/// assignment as [`crate::image`] lays it out (PDOs bit-packed, the sync manager rounded up
/// to whole bytes): the `pdi` structs and these constants agree.
pub fn sm_layout(device: &odc_model::Device) -> (Vec<Option<u32>>, SmImages) {
    let mut offsets = vec![None; device.pdos.len()];
    let mut sms = SmImages::new();
    let Ok((outputs, inputs)) = crate::image::default_images(device) else {
        return (offsets, sms);
    };
    for seg in outputs.segments.iter().chain(&inputs.segments) {
        let start = seg.byte_offset * 8;
        for placed in &seg.entries {
            if let Some(slot @ None) = offsets.get_mut(placed.pdo) {
                *slot = Some(placed.range.offset - start);
            }
        }
        // A PDO without entries takes no bits: it starts where the segment ends.
        for &p in &seg.pdos {
            if let Some(slot @ None) = offsets.get_mut(p) {
                *slot = Some(seg.bits);
            }
        }
        sms.insert(seg.sm, (seg.bytes as usize, seg.pdos.clone()));
    }
    (offsets, sms)
}

/// The `pdo` module.
pub fn generate(ctx: &Ctx<'_>, errors: &mut Vec<Diagnostic>) -> TokenStream {
    let rt = &ctx.rt;
    let pdos = &ctx.device.pdos;
    let names = pdo_names(ctx);
    let (offsets, sms) = sm_layout(ctx.device);
    let crate_path = ctx.rt.to_string().replace(' ', "");
    let mut items = Vec::new();
    for (i, ((pdo, name), offset)) in pdos.iter().zip(&names).zip(&offsets).enumerate() {
        let (fields, trailing) = fields(ctx, pdo, errors);
        let ty = &name.ty;
        let total = Literal::u32_unsuffixed(pdo.bits());
        let mut keys = Vec::new();
        if trailing > 0 {
            keys.push(quote!(bits = #total));
        }
        if pdo.bits() > 64 {
            keys.push(quote!(max_bits = #total));
        }
        if crate_path != "::odc" {
            keys.push(quote!(crate = #crate_path));
        }
        let container = (!keys.is_empty()).then(|| quote!(#[pdo(#(#keys),*)]));
        let field_tokens = fields.iter().map(|f| {
            let docs = doc(&f.doc);
            let (n, t) = (&f.name, &f.ty);
            let idx = index_literal(f.index);
            let sub = sub_literal(f.sub);
            let bits = Literal::u16_unsuffixed(f.bits);
            let pad = (f.pad_before > 0).then(|| {
                let p = Literal::u32_unsuffixed(f.pad_before);
                quote!(pad_bits = #p,)
            });
            quote! {
                #docs
                #[pdo(#pad index = #idx, sub = #sub, bits = #bits)]
                pub #n: #t,
            }
        });
        let dir = match pdo.direction {
            Direction::Rx => "Receive PDO (master → device)",
            Direction::Tx => "Transmit PDO (device → master)",
        };
        let mut text = format!(
            "{}\n\n{dir}, mapping object `0x{:04X}`, {} bits.",
            pdo.name,
            pdo.mapping_index,
            pdo.bits()
        );
        if !ctx.source.is_empty() {
            text.push_str(&format!(" From `{}`.", ctx.source));
        }
        let docs = doc(&text);

        let mut consts = Vec::new();
        let map_idx = index_literal(pdo.mapping_index);
        consts.push(quote! {
            /// The mapping object.
            pub const MAPPING_INDEX: u16 = #map_idx;
        });
        let values = pdo.entries.iter().map(|e| hex_literal(u64::from(e.mapping_value()), 8));
        let n = Literal::usize_unsuffixed(pdo.entries.len());
        consts.push(quote! {
            /// The mapping entries as written to the mapping object's sub-indexes 1.., in wire
            /// order (gaps as the file maps them).
            pub const MAPPING_VALUES: [u32; #n] = [#(#values),*];
        });
        if let Some(comm) = pdo.comm_index {
            let c = index_literal(comm);
            consts.push(quote! {
                /// The communication parameter object.
                pub const COMM_INDEX: u16 = #c;
            });
        }
        if let Some(tt) = pdo.transmission_type {
            let lit = Literal::u8_unsuffixed(tt);
            consts.push(quote! {
                /// The default transmission type (communication sub-index 2).
                pub const TRANSMISSION_TYPE: u8 = #lit;
            });
        }
        if let Some(t) = pdo.inhibit_time {
            let lit = Literal::u16_unsuffixed(t);
            consts.push(quote! {
                /// The default inhibit time in 100 µs (communication sub-index 3).
                pub const INHIBIT_TIME: u16 = #lit;
            });
        }
        if let Some(t) = pdo.event_timer {
            let lit = Literal::u16_unsuffixed(t);
            consts.push(quote! {
                /// The default event timer in ms (communication sub-index 5).
                pub const EVENT_TIMER: u16 = #lit;
            });
        }
        if let Some((f, rule)) = pdo.cob_id.as_ref().and_then(|c| cob_id_fn(c, rt)) {
            let enabled = enabled_by_default(pdo);
            let d = doc(&format!(
                "The COB-ID (communication sub-index 1) for node `node_id`: `{rule}`{}.",
                if enabled { "" } else { " (bit 31 set: not valid by default)" }
            ));
            consts.push(quote! {
                /// Whether the PDO is valid by default (COB-ID bit 31 clear).
                pub const ENABLED: bool = #enabled;
                #d
                #f
            });
        }
        let sm = sms.iter().find(|(_, (_, members))| members.contains(&i)).map(|(sm, _)| *sm);
        if let (Some(sm), Some(offset)) = (sm, offset) {
            let sm = Literal::u8_unsuffixed(sm);
            let offset = Literal::u32_unsuffixed(*offset);
            consts.push(quote! {
                /// The sync manager that carries the PDO by default.
                pub const SYNC_MANAGER: u8 = #sm;
                /// Bit offset of the PDO in its sync manager's process image (PDOs are
                /// bit-packed: a multiple of 8 unless PDOs before it have a few bits).
                pub const SM_BIT_OFFSET: u32 = #offset;
            });
        }
        items.push(quote! {
            #docs
            #[derive(Clone, Copy, Debug, Default, PartialEq, #rt::Pdo)]
            #container
            pub struct #ty {
                #(#field_tokens)*
            }

            impl #ty {
                #(#consts)*
            }
        });
    }
    for (sm, (size, members)) in &sms {
        let module = Ident::new(&format!("sm{sm}"), Span::call_site());
        let size = Literal::usize_unsuffixed(*size);
        let indexes =
            members.iter().filter_map(|&i| pdos.get(i)).map(|p| index_literal(p.mapping_index));
        let n = Literal::usize_unsuffixed(members.len());
        let docs = doc(&format!("Process image of sync manager {sm} with the default assignment."));
        items.push(quote! {
            #docs
            pub mod #module {
                /// Size of the image in bytes: the PDOs' bits, rounded up to whole bytes.
                pub const SIZE: usize = #size;
                /// The PDOs assigned by default, in image order (0x1C1x sub-indexes 1..).
                pub const ASSIGNED: [u16; #n] = [#(#indexes),*];
            }
        });
    }
    let docs = doc(&format!(
        "Process data of {}: one struct per PDO of the default mapping.",
        ctx.device.name()
    ));
    quote! {
        #docs
        pub mod pdo {
            #(#items)*
        }
    }
}
