//! `master`: the configuration plan of the default PDO mapping, as SDO writes.

use odc_model::{Direction, Pdo};
use proc_macro2::{Ident, Literal, TokenStream};
use quote::quote;

use crate::pdo::{COB_INVALID, enabled_by_default, pdo_names, sm_layout};
use crate::types::{hex_literal, index_literal, sub_literal};
use crate::{Ctx, doc};

/// The CiA 301 writes for one CANopen PDO; `ty` is its struct, for `cob_id`.
fn canopen_writes(pdo: &Pdo, ty: &Ident, rt: &TokenStream) -> Vec<TokenStream> {
    let mut w = Vec::new();
    let map = index_literal(pdo.mapping_index);
    let comm = pdo.comm_index.map(index_literal);
    let has_cob = pdo.cob_id.is_some() && comm.is_some();
    let invalid = hex_literal(COB_INVALID, 8);
    let valid_mask = hex_literal(!COB_INVALID & 0xFFFF_FFFF, 8);
    if let (true, Some(c)) = (has_cob, &comm) {
        w.push(
            quote!(#rt::plan::SdoWrite::u32(#c, 0x01, super::pdo::#ty::cob_id(node_id) | #invalid)),
        );
    }
    if !pdo.entries.is_empty() {
        w.push(quote!(#rt::plan::SdoWrite::u8(#map, 0x00, 0)));
    }
    for (i, e) in pdo.entries.iter().enumerate() {
        let sub = sub_literal(u8::try_from(i + 1).unwrap_or(u8::MAX));
        let v = hex_literal(u64::from(e.mapping_value()), 8);
        w.push(quote!(#rt::plan::SdoWrite::u32(#map, #sub, #v)));
    }
    let n = Literal::u8_unsuffixed(u8::try_from(pdo.entries.len()).unwrap_or(u8::MAX));
    w.push(quote!(#rt::plan::SdoWrite::u8(#map, 0x00, #n)));
    if let Some(c) = &comm {
        if let Some(tt) = pdo.transmission_type {
            let tt = Literal::u8_unsuffixed(tt);
            w.push(quote!(#rt::plan::SdoWrite::u8(#c, 0x02, #tt)));
        }
        if let (Direction::Tx, Some(t)) = (pdo.direction, pdo.inhibit_time) {
            let t = Literal::u16_unsuffixed(t);
            w.push(quote!(#rt::plan::SdoWrite::u16(#c, 0x03, #t)));
        }
        if let Some(t) = pdo.event_timer {
            let t = Literal::u16_unsuffixed(t);
            w.push(quote!(#rt::plan::SdoWrite::u16(#c, 0x05, #t)));
        }
        if let (Direction::Tx, Some(s)) = (pdo.direction, pdo.sync_start) {
            let s = Literal::u8_unsuffixed(s);
            w.push(quote!(#rt::plan::SdoWrite::u8(#c, 0x06, #s)));
        }
        if has_cob {
            w.push(quote!(#rt::plan::SdoWrite::u32(#c, 0x01, super::pdo::#ty::cob_id(node_id) & #valid_mask)));
        }
    }
    w
}

fn canopen(ctx: &Ctx<'_>) -> TokenStream {
    let rt = &ctx.rt;
    let names = pdo_names(ctx);
    let mut items = Vec::new();
    let mut all = Vec::new();
    for (pdo, name) in ctx.device.pdos.iter().zip(&names) {
        let writes = canopen_writes(pdo, &name.ty, rt);
        let n = Literal::usize_unsuffixed(writes.len());
        let f = &name.func;
        let ty = &name.ty;
        let uses_node = pdo.cob_id.is_some() && pdo.comm_index.is_some();
        let param = if uses_node { quote!(node_id) } else { quote!(_node_id) };
        let text = format!(
            "The writes that set [`{ty}`](super::pdo::{ty})'s default mapping on node `node_id` \
             and leave it valid: invalidate the COB-ID, clear the mapping count, write each \
             entry, set the count, the communication parameters, then re-validate the COB-ID."
        );
        let d = doc(&text);
        items.push(quote! {
            #d
            pub const fn #f(#param: #rt::cob::NodeId) -> [#rt::plan::SdoWrite; #n] {
                [#(#writes),*]
            }
        });
        if enabled_by_default(pdo) {
            all.extend(writes);
        }
    }
    let n = Literal::usize_unsuffixed(all.len());
    let uses_node = ctx
        .device
        .pdos
        .iter()
        .any(|p| enabled_by_default(p) && p.cob_id.is_some() && p.comm_index.is_some());
    let param = if uses_node { quote!(node_id) } else { quote!(_node_id) };
    quote! {
        /// The writes that set the default mapping of every PDO that is valid by default, for
        /// node `node_id`, in order (CiA 301 PDO mapping procedure).
        pub const fn plan(#param: #rt::cob::NodeId) -> [#rt::plan::SdoWrite; #n] {
            [#(#all),*]
        }

        #(#items)*
    }
}

fn ethercat(ctx: &Ctx<'_>) -> TokenStream {
    let rt = &ctx.rt;
    let pdos = &ctx.device.pdos;
    let (_, sms) = sm_layout(ctx.device);
    let mut w = Vec::new();
    for (sm, (_, members)) in &sms {
        let assign = index_literal(0x1C10 + u16::from(*sm));
        w.push(quote!(#rt::plan::SdoWrite::u8(#assign, 0x00, 0)));
        for pdo in members.iter().filter_map(|&i| pdos.get(i)).filter(|p| !p.fixed) {
            let map = index_literal(pdo.mapping_index);
            w.push(quote!(#rt::plan::SdoWrite::u8(#map, 0x00, 0)));
            for (i, e) in pdo.entries.iter().enumerate() {
                let sub = sub_literal(u8::try_from(i + 1).unwrap_or(u8::MAX));
                let v = hex_literal(u64::from(e.mapping_value()), 8);
                w.push(quote!(#rt::plan::SdoWrite::u32(#map, #sub, #v)));
            }
            let n = Literal::u8_unsuffixed(u8::try_from(pdo.entries.len()).unwrap_or(u8::MAX));
            w.push(quote!(#rt::plan::SdoWrite::u8(#map, 0x00, #n)));
        }
        for (i, pdo) in members.iter().filter_map(|&i| pdos.get(i)).enumerate() {
            let sub = sub_literal(u8::try_from(i + 1).unwrap_or(u8::MAX));
            let map = index_literal(pdo.mapping_index);
            w.push(quote!(#rt::plan::SdoWrite::u16(#assign, #sub, #map)));
        }
        let n = Literal::u8_unsuffixed(u8::try_from(members.len()).unwrap_or(u8::MAX));
        w.push(quote!(#rt::plan::SdoWrite::u8(#assign, 0x00, #n)));
    }
    let n = Literal::usize_unsuffixed(w.len());
    quote! {
        /// The CoE writes that set the default process data: per sync manager, clear its
        /// assignment (0x1C1x:00 = 0), write the mapping of each PDO that is not fixed, assign
        /// the PDOs and set the count. Execute them in PREOP.
        pub const PLAN: [#rt::plan::SdoWrite; #n] = [#(#w),*];
    }
}

/// The `master` module.
pub fn generate(ctx: &Ctx<'_>) -> TokenStream {
    let is_ethercat = ctx.device.format == Some(odc_model::Format::Esi)
        || ctx.device.pdos.iter().any(|p| p.sync_manager.is_some());
    let body = if is_ethercat { ethercat(ctx) } else { canopen(ctx) };
    let docs = doc(&format!(
        "The configuration plan of {}: the SDO writes that set its default PDO mapping, as \
         data for any SDO client.",
        ctx.device.name()
    ));
    quote! {
        #docs
        pub mod master {
            #body
        }
    }
}
