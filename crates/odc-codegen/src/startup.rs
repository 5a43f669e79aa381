//! `startup`: what a master writes to an EtherCAT device in PRE-OP so that it exchanges the
//! default process data of `pdi`, as `odc::ethercat::Startup` data, and the device's
//! distributed-clocks modes.
//!
//! The order is a master's (ETG.2000 `InitCmd`, ETG.1000.6 0x1C10+n): the ESI's CoE init commands of the
//! INIT→PRE-OP transition, then those of PRE-OP→SAFE-OP (`downloads`), then the process data
//! (`pdo_writes`) through the runtime's one procedure, `odc::plan::PlanBuilder`: per sync
//! manager, clear its assignment 0x1C10+n (`@PdoAssign`), map each assigned PDO the device lets
//! the master configure (`Mailbox/CoE@PdoConfig`, not `Fixed`), assign and count.

use odc_model::ethercat::{EtherCat, InitCmd, SmUsage};
use proc_macro2::{Literal, TokenStream};
use quote::quote;

use crate::types::{hex_literal, index_literal, sub_literal};
use crate::{Ctx, doc};
use odc_analysis::image::{self, Assignment};

/// One SDO download as tokens; `data` is an expression of type `&[u8]` (a struct literal
/// field, so that `&0x7000_0101u32.to_le_bytes()` lives as long as the constant).
fn download(rt: &TokenStream, index: u16, sub: u8, ca: bool, data: TokenStream) -> TokenStream {
    let index = index_literal(index);
    let sub = sub_literal(sub);
    quote! {
        #rt::ethercat::SdoDownload { index: #index, sub: #sub, complete_access: #ca, data: #data }
    }
}

/// Bytes as written in the ESI (init commands), or a count.
fn bytes(data: &[u8]) -> TokenStream {
    let bytes = data.iter().map(|b| hex_literal(u64::from(*b), 2));
    quote!(&[#(#bytes),*])
}

/// The init commands of one transition, in file order; those without an index or sub-index
/// are malformed and left out (the front-end reports them).
fn init_cmds<'a>(cmds: &'a [InitCmd], transition: &'a str) -> impl Iterator<Item = &'a InitCmd> {
    cmds.iter().filter(move |c| c.transitions.iter().any(|t| t.trim() == transition))
}

/// The ESI's CoE init commands of INIT→PRE-OP, then PRE-OP→SAFE-OP.
fn downloads(ctx: &Ctx<'_>, ec: &EtherCat) -> Vec<TokenStream> {
    let rt = &ctx.rt;
    let mut out = Vec::new();
    let Some(coe) = ec.mailbox.as_ref().and_then(|m| m.coe.as_ref()) else {
        return out;
    };
    for transition in ["IP", "PS"] {
        for c in init_cmds(&coe.init_cmds, transition) {
            let index = c.index.and_then(|i| u16::try_from(i).ok());
            let sub = c.sub_index.and_then(|s| u8::try_from(s).ok());
            if let (Some(index), Some(sub)) = (index, sub) {
                out.push(download(rt, index, sub, c.complete_access, bytes(&c.data)));
            }
        }
    }
    out
}

/// The process-data writes of `assignment` as the steps of an `odc::plan::PlanBuilder`, the
/// runtime's one procedure: per process-data sync manager, clear its assignment 0x1C1x (when
/// the ESI lets the master assign, `@PdoAssign`), the CiA 301 mapping procedure of each
/// assigned PDO that is not fixed (when it lets the master map, `@PdoConfig`), then the
/// assignment and its count.
fn pdo_steps(ctx: &Ctx<'_>, ec: &EtherCat, assignment: &Assignment) -> Vec<TokenStream> {
    let rt = &ctx.rt;
    let mut steps = Vec::new();
    let Some(coe) = ec.mailbox.as_ref().and_then(|m| m.coe.as_ref()) else {
        return steps;
    };
    let map = |steps: &mut Vec<TokenStream>, indexes: &[u16]| {
        for &index in indexes {
            let Some(pdo) = ctx.device.pdos.iter().find(|p| p.mapping_index == index) else {
                continue;
            };
            if pdo.fixed {
                continue;
            }
            let values = pdo.entries.iter().map(|e| hex_literal(u64::from(e.mapping_value()), 8));
            let index = index_literal(index);
            steps.push(quote!(.pdo(&#rt::plan::PdoConfig::new(#index, &[#(#values),*]), 0)));
        }
    };
    let mut mapped = Vec::new();
    for sm in &ec.sync_managers {
        // A virtual sync manager is ESC registers, not a sync manager with a 0x1C1x.
        if sm.virtual_sm || !matches!(sm.usage, SmUsage::Outputs | SmUsage::Inputs) {
            continue;
        }
        let Some(object) = 0x1C10u16.checked_add(u16::from(sm.number)) else { continue };
        let indexes = assignment.get(&sm.number).map(Vec::as_slice).unwrap_or_default();
        let object = index_literal(object);
        if coe.pdo_assign {
            steps.push(quote!(.push(#rt::plan::SdoWrite::u8(#object, 0x00, 0))));
        }
        if coe.pdo_config {
            map(&mut steps, indexes);
            mapped.push(sm.number);
        }
        if coe.pdo_assign && !indexes.is_empty() {
            let pdos = indexes.iter().map(|i| index_literal(*i));
            steps.push(quote!(.assign(#object, &[#(#pdos),*])));
        }
    }
    // PDOs assigned to a sync manager the ESI does not list: mapped all the same.
    if coe.pdo_config {
        for (_, indexes) in assignment.iter().filter(|(sm, _)| !mapped.contains(*sm)) {
            map(&mut steps, indexes);
        }
    }
    steps
}

/// `const fn #name<const N: usize>() -> PlanBuilder<N>` of `steps` and the array of its
/// writes, `#array`.
fn pdo_writes(rt: &TokenStream, name: &str, array: &str, steps: &[TokenStream]) -> TokenStream {
    let f = proc_macro2::Ident::new(name, proc_macro2::Span::call_site());
    let a = proc_macro2::Ident::new(array, proc_macro2::Span::call_site());
    quote! {
        /// The process-data writes, built into `N` slots (`N = 0` counts them).
        const fn #f<const N: usize>() -> #rt::plan::PlanBuilder<N> {
            #rt::plan::PlanBuilder::new() #(#steps)*
        }
        /// The process-data writes of the start-up, in order.
        const #a: [#rt::plan::SdoWrite; #f::<0>().len()] = #f().finish();
    }
}

/// The distributed-clocks modes as `odc::ethercat::DcOpMode` values.
fn dc_modes(ctx: &Ctx<'_>, ec: &EtherCat) -> Vec<TokenStream> {
    let rt = &ctx.rt;
    let Some(dc) = &ec.dc else { return Vec::new() };
    dc.op_modes
        .iter()
        .map(|m| {
            let name = &m.name;
            let aa = hex_literal(u64::from(m.assign_activate.unwrap_or(0) & 0xFFFF), 4);
            let c0 = Literal::u32_unsuffixed(m.cycle_time_sync0.unwrap_or(0));
            let s0 = Literal::i32_unsuffixed(
                m.shift_time_sync0.and_then(|v| i32::try_from(v).ok()).unwrap_or(0),
            );
            let c1 = Literal::u32_unsuffixed(m.cycle_time_sync1.unwrap_or(0));
            quote! {
                #rt::ethercat::DcOpMode {
                    name: #name,
                    assign_activate: #aa,
                    cycle_time_sync0: #c0,
                    shift_time_sync0: #s0,
                    cycle_time_sync1: #c1,
                }
            }
        })
        .collect()
}

/// The `startup` module; nothing for a CANopen device, a device without identity (vendor,
/// product code and revision are what the master checks), or one whose image `pdi` lacks.
pub(crate) fn generate(ctx: &Ctx<'_>) -> TokenStream {
    let Some(ec) = ctx.device.ethercat.as_deref() else { return TokenStream::new() };
    let (Some(vendor), Some(product), Some(revision)) =
        (ec.vendor_id, ec.product_code, ec.revision)
    else {
        return TokenStream::new();
    };
    if image::default_images(ctx.device).is_err() {
        return TokenStream::new();
    }
    let rt = &ctx.rt;
    let assignment = image::default_assignment(ctx.device);
    let default_downloads = downloads(ctx, ec);
    let default_writes = pdo_writes(rt, "pdo_plan", "PDO_WRITES", &pdo_steps(ctx, ec, &assignment));
    let modes = dc_modes(ctx, ec);
    let vendor = hex_literal(u64::from(vendor), 8);
    let product = hex_literal(u64::from(product), 8);
    let revision = hex_literal(u64::from(revision), 8);
    let check_attr = ec.type_attributes.iter().find(|a| a.name == "CheckRevisionNo");
    let (check, unknown_check) = match check_attr.map(|a| a.value.trim()) {
        None | Some("EQ") => (quote!(Equal), None),
        Some("EQ_OR_G") => (quote!(EqualOrGreater), None),
        Some("LW_EQ") => (quote!(LowWordEqual), None),
        Some("LW_EQ_HW_EQ_OR_G") => (quote!(LowWordEqualHighWordEqualOrGreater), None),
        Some(other) => (quote!(Equal), Some(other.to_string())),
    };
    let identity = quote! {
        #rt::ethercat::Identity {
            vendor_id: #vendor,
            product_code: #product,
            revision: #revision,
            revision_check: #rt::ethercat::RevisionCheck::#check,
        }
    };
    let plan_doc = doc(&match unknown_check {
        None => "The identity, the SDO downloads and the image sizes.".to_string(),
        Some(v) => format!(
            "The identity, the SDO downloads and the image sizes. The ESI's CheckRevisionNo \
             `{v}` is not one odc knows: the revision must be equal."
        ),
    });
    // One plan per variant `pdi` has a module for, named after it.
    let (variants, _) = image::variants(ctx.device);
    let names = crate::pdi::variant_names(&variants);
    let variant_plans = variants.iter().zip(&names).filter_map(|(v, module)| {
        image::image(ctx.device, &v.assignment, odc_model::Direction::Rx).ok()?;
        image::image(ctx.device, &v.assignment, odc_model::Direction::Tx).ok()?;
        let downloads = downloads(ctx, ec);
        let screaming = crate::names::screaming(&module.to_string());
        let name = proc_macro2::Ident::new(&screaming, proc_macro2::Span::call_site());
        let writes_name = format!("{screaming}_PDO_WRITES");
        let writes = pdo_writes(
            rt,
            &format!("pdo_plan_{}", module.to_string().to_lowercase()),
            &writes_name,
            &pdo_steps(ctx, ec, &v.assignment),
        );
        let writes_ident = proc_macro2::Ident::new(&writes_name, proc_macro2::Span::call_site());
        let docs = doc(&format!(
            "The start-up for `pdi::{module}`, {}: run it with the runtime's \
             `ethercat::ethercrab::configure(subdevice, &startup::{name})`.",
            crate::pdi::variant_text(v)
        ));
        Some(quote! {
            #writes
            #docs
            pub const #name: #rt::ethercat::Startup = #rt::ethercat::Startup {
                identity: PLAN.identity,
                downloads: &[#(#downloads),*],
                pdo_writes: &#writes_ident,
                output_len: super::pdi::#module::OUTPUT_LEN,
                input_len: super::pdi::#module::INPUT_LEN,
            };
        })
    });
    let docs = doc(&format!(
        "Start-up of {} for the default process data of `pdi`: the SDO downloads a master \
         sends in PRE-OP, in order (the ESI's init commands of IP and PS, the mapping of \
         each configurable PDO, the sync managers' assignment). With the runtime's feature \
         `ethercrab`, `configure(subdevice)` checks the identity and sends them.",
        ctx.device.name()
    ));
    quote! {
        #docs
        pub mod startup {
            #default_writes
            #plan_doc
            pub const PLAN: #rt::ethercat::Startup = #rt::ethercat::Startup {
                identity: #identity,
                downloads: &[#(#default_downloads),*],
                pdo_writes: &PDO_WRITES,
                output_len: super::pdi::OUTPUT_LEN,
                input_len: super::pdi::INPUT_LEN,
            };
            /// The distributed-clocks operation modes of the ESI (`Dc/OpMode`), in file order.
            pub const DC_OP_MODES: &[#rt::ethercat::DcOpMode] = &[#(#modes),*];
            #(#variant_plans)*
            #rt::configure_fn!(PLAN);
        }
    }
}
