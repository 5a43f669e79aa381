//! `master`: the configuration plan of the default PDO mapping, as SDO writes.

use odc_model::{Direction, Pdo};
use proc_macro2::{Ident, Literal, TokenStream};
use quote::{format_ident, quote};

use crate::pdo::{enabled_by_default, pdo_names, sm_layout};
use crate::types::index_literal;
use crate::{Ctx, doc};

/// The `PdoConfig` of one CANopen PDO: what the runtime's CiA 301 procedure
/// (`odc::plan::PdoConfig`) writes for it.
pub(crate) fn canopen_config(pdo: &Pdo, ty: &Ident, rt: &TokenStream) -> TokenStream {
    let map = index_literal(pdo.mapping_index);
    let mut e = quote!(#rt::plan::PdoConfig::new(#map, &super::pdo::#ty::MAPPING_VALUES));
    if let Some(c) = pdo.comm_index {
        let c = index_literal(c);
        let has_cob = pdo.cob_id.is_some();
        e.extend(quote!(.with_comm(#c, #has_cob)));
        if let Some(tt) = pdo.transmission_type {
            let tt = Literal::u8_unsuffixed(tt);
            e.extend(quote!(.with_transmission_type(#tt)));
        }
        if let (Direction::Tx, Some(t)) = (pdo.direction, pdo.inhibit_time) {
            let t = Literal::u16_unsuffixed(t);
            e.extend(quote!(.with_inhibit_time(#t)));
        }
        if let Some(t) = pdo.event_timer {
            let t = Literal::u16_unsuffixed(t);
            e.extend(quote!(.with_event_timer(#t)));
        }
        if let (Direction::Tx, Some(s)) = (pdo.direction, pdo.sync_start) {
            let s = Literal::u8_unsuffixed(s);
            e.extend(quote!(.with_sync_start(#s)));
        }
    }
    e
}

/// Whether the procedure of `pdo` uses its COB-ID (it has a communication object and one).
fn uses_cob_id(pdo: &Pdo) -> bool {
    pdo.cob_id.is_some() && pdo.comm_index.is_some()
}

fn canopen(ctx: &Ctx<'_>) -> TokenStream {
    let rt = &ctx.rt;
    let names = pdo_names(ctx);
    let mut items = Vec::new();
    let (mut all, mut all_cobs) = (Vec::new(), Vec::new());
    for (pdo, name) in ctx.device.pdos.iter().zip(&names) {
        let f = &name.func;
        let ty = &name.ty;
        let config = format_ident!("{}_CONFIG", f.to_string().to_ascii_uppercase());
        let value = canopen_config(pdo, ty, rt);
        let (param, cob) = if uses_cob_id(pdo) {
            (quote!(node_id), quote!(super::pdo::#ty::cob_id(node_id)))
        } else {
            (quote!(_node_id), quote!(0))
        };
        let config_doc = doc(&format!(
            "[`{ty}`](super::pdo::{ty})'s default mapping and communication parameters, as \
             the CiA 301 PDO mapping procedure (`odc::plan::PdoConfig`) writes them."
        ));
        let text = doc(&format!(
            "The writes that set [`{ty}`](super::pdo::{ty})'s default mapping on node `node_id` \
             and leave it valid: invalidate the COB-ID, clear the mapping count, write each \
             entry, set the count, the communication parameters, then re-validate the COB-ID."
        ));
        items.push(quote! {
            #config_doc
            pub const #config: #rt::plan::PdoConfig<'static> = #value;

            #text
            pub const fn #f(#param: #rt::cob::NodeId) -> [#rt::plan::SdoWrite; #config.len()] {
                #config.writes(#cob)
            }
        });
        if enabled_by_default(pdo) {
            all.push(config);
            all_cobs.push(cob);
        }
    }
    let uses_node = ctx.device.pdos.iter().any(|p| enabled_by_default(p) && uses_cob_id(p));
    let param = if uses_node { quote!(node_id) } else { quote!(_node_id) };
    quote! {
        /// The writes that set the default mapping of every PDO that is valid by default, for
        /// node `node_id`, in order (CiA 301 PDO mapping procedure).
        pub const fn plan(#param: #rt::cob::NodeId) -> [#rt::plan::SdoWrite; #rt::plan::plan_len(&[#(#all),*])] {
            #rt::plan::plan(&[#(#all),*], &[#(#all_cobs),*])
        }

        #(#items)*
    }
}

fn ethercat(ctx: &Ctx<'_>) -> TokenStream {
    let rt = &ctx.rt;
    let pdos = &ctx.device.pdos;
    let names = pdo_names(ctx);
    let (_, sms) = sm_layout(ctx.device);
    let mut steps = Vec::new();
    for (sm, (_, members)) in &sms {
        let assign = index_literal(0x1C10 + u16::from(*sm));
        steps.push(quote!(.push(#rt::plan::SdoWrite::u8(#assign, 0x00, 0))));
        for (pdo, name) in members.iter().filter_map(|&i| Some((pdos.get(i)?, names.get(i)?))) {
            if pdo.fixed {
                continue;
            }
            let map = index_literal(pdo.mapping_index);
            let ty = &name.ty;
            steps.push(quote!(.pdo(
                &#rt::plan::PdoConfig::new(#map, &super::pdo::#ty::MAPPING_VALUES),
                0
            )));
        }
        let maps =
            members.iter().filter_map(|&i| pdos.get(i)).map(|p| index_literal(p.mapping_index));
        steps.push(quote!(.assign(#assign, &[#(#maps),*])));
    }
    quote! {
        /// The CoE writes that set the default process data: per sync manager, clear its
        /// assignment (0x1C1x:00 = 0), write the mapping of each PDO that is not fixed (the
        /// runtime's CiA 301 procedure, `odc::plan::PdoConfig`), assign the PDOs and set the
        /// count. Execute them in PREOP.
        pub const PLAN: [#rt::plan::SdoWrite; build::<0>().len()] = build().finish();

        /// [`PLAN`] built into `N` slots (`N = 0` counts its writes).
        const fn build<const N: usize>() -> #rt::plan::PlanBuilder<N> {
            #rt::plan::PlanBuilder::new() #(#steps)*
        }
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
