//! `cia402`: the modes of operation a CiA 402 drive supports.

use odc_analysis::cia402::{MODES, supported_mode_bits};

use crate::types::RustTy;
use proc_macro2::{Ident, Literal, Span, TokenStream};
use quote::quote;

use crate::{Ctx, doc};

/// The `cia402` module, or nothing.
pub fn generate(ctx: &Ctx<'_>) -> TokenStream {
    if !ctx.names.cia402 {
        return TokenStream::new();
    }
    let rt = &ctx.rt;
    let supported = supported_mode_bits(ctx.device);
    let modes: Vec<_> =
        MODES.iter().filter(|m| supported.is_none_or(|s| s & (1 << m.bit) != 0)).collect();
    let source = match supported {
        Some(s) => format!("the default of 0x6502 (supported drive modes) is `0x{s:08X}`"),
        None => "the device has no 0x6502 default, so every standard mode is listed".to_string(),
    };
    let variants = modes.iter().map(|m| {
        let name = Ident::new(m.name, Span::call_site());
        let v = Literal::i8_unsuffixed(m.value);
        let text = format!(" {}", m.text);
        quote!(#[doc = #text] #name = #v,)
    });
    let arms = modes.iter().map(|m| {
        let name = Ident::new(m.name, Span::call_site());
        let v = Literal::i8_unsuffixed(m.value);
        quote!(#v => Some(Mode::#name),)
    });
    let all = modes.iter().map(|m| {
        let name = Ident::new(m.name, Span::call_site());
        quote!(Mode::#name)
    });
    let n = Literal::usize_unsuffixed(modes.len());
    // 0x6502 may announce manufacturer-specific modes only: `Mode` is then empty, which cannot
    // have a `repr` nor be cast.
    let (repr, from_body, to_body) = if modes.is_empty() {
        (quote!(), quote!(let _ = v; None), quote!(match self {}))
    } else {
        (quote!(#[repr(i8)]), quote!(match v { #(#arms)* _ => None, }), quote!(self as i8))
    };
    let mode_doc = doc(&format!(
        "A mode of operation (0x6060, 0x6061) this device supports: {source}.\n\n\
         `Mode::from_i8` refuses the others, so a mode the drive cannot run is not written."
    ));
    let docs = doc(&format!(
        "CiA 402 drive profile of {}.\n\n\
         The controlword and statusword are the runtime's `odc::cia402::Controlword` and\n\
         `Statusword`: `od` and the PDO structs type 0x6040 and 0x6041 with them.",
        ctx.device.name()
    ));
    let pdos = drive_pdos(ctx);
    quote! {
        #docs
        pub mod cia402 {
            #pdos

            #mode_doc
            #[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
            #repr
            pub enum Mode {
                #(#variants)*
            }

            impl Mode {
                /// Every supported mode.
                pub const ALL: [Mode; #n] = [#(#all),*];

                /// The mode for a value of 0x6060/0x6061, if the device supports it.
                pub const fn from_i8(v: i8) -> Option<Mode> {
                    #from_body
                }

                /// The value of 0x6060/0x6061.
                pub const fn to_i8(self) -> i8 {
                    #to_body
                }
            }

            impl From<Mode> for i8 {
                fn from(m: Mode) -> i8 {
                    m.to_i8()
                }
            }

            impl TryFrom<i8> for Mode {
                type Error = i8;
                fn try_from(v: i8) -> Result<Mode, i8> {
                    Mode::from_i8(v).ok_or(v)
                }
            }

            impl #rt::PdoValue for Mode {
                const BITS: u32 = 8;
                const SIGNED: bool = true;
                fn to_raw(&self) -> u64 {
                    self.to_i8() as i64 as u64
                }
                fn from_raw(raw: u64, bits: u32) -> Option<Mode> {
                    <i8 as #rt::PdoValue>::from_raw(raw, bits).and_then(Mode::from_i8)
                }
            }

            impl #rt::ObjValue for Mode {
                const DATA_TYPE: #rt::DataType = #rt::DataType::Integer8;
                const MAX_LEN: usize = 1;
                fn encode(&self, buf: &mut [u8]) -> Result<usize, #rt::ValueError> {
                    <i8 as #rt::ObjValue>::encode(&self.to_i8(), buf)
                }
                fn decode(buf: &[u8]) -> Result<Mode, #rt::ValueError> {
                    Mode::from_i8(<i8 as #rt::ObjValue>::decode(buf)?).ok_or(#rt::ValueError::Invalid)
                }
            }
        }
    }
}

/// `cia402::Pdos`: the device's default RPDO with the controlword and TPDO with the statusword
/// as `odc::cia402::DrivePdos`, so the runtime's driver runs the device with its own PDO
/// structs. The RPDO chosen is the one that carries the most targets and nothing else the
/// driver does not set (a field it cannot fill would be sent as 0 every cycle: such an RPDO
/// is not chosen); the TPDO the
/// one that carries the most actual values. CANopen PDOs only (they have a COB-ID); nothing
/// when the default mapping has no such pair.
fn drive_pdos(ctx: &Ctx<'_>) -> TokenStream {
    let rt = &ctx.rt;
    let names = crate::pdo::pdo_names(ctx);
    let ty = |index: u16, sub: u8| {
        ctx.device
            .pdos
            .iter()
            .flat_map(|p| p.entries.iter())
            .find(|e| e.index == index && e.sub == sub)
            .and_then(|e| crate::pdo::field_type(ctx, e))
    };
    let mut best_rx: Option<(usize, usize, Vec<TokenStream>)> = None;
    let mut best_tx: Option<(usize, usize, Vec<TokenStream>)> = None;
    for (k, pdo) in ctx.device.pdos.iter().enumerate() {
        if pdo.entries.is_empty() || pdo.comm_index.is_none() || pdo.cob_id.is_none() {
            continue;
        }
        let (fields, _) = crate::pdo::fields(ctx, pdo, &mut Vec::new());
        match pdo.direction {
            odc_model::Direction::Rx => {
                let mut exprs = Vec::new();
                let mut ok = fields.iter().any(|f| f.index == 0x6040);
                for f in &fields {
                    let name = &f.name;
                    let e = match (f.index, f.sub, ty(f.index, f.sub)) {
                        (0x6040, 0, Some(RustTy::Controlword)) => quote!(#name: o.controlword),
                        (0x607A, 0, Some(RustTy::Signed(32))) => {
                            quote!(#name: o.target_position.unwrap_or(0))
                        }
                        (0x60FF, 0, Some(RustTy::Signed(32))) => {
                            quote!(#name: o.target_velocity.unwrap_or(0))
                        }
                        (0x6071, 0, Some(RustTy::Signed(16))) => {
                            quote!(#name: o.target_torque.unwrap_or(0))
                        }
                        _ => {
                            ok = false;
                            break;
                        }
                    };
                    exprs.push(e);
                }
                if ok && best_rx.as_ref().is_none_or(|b| exprs.len() > b.1) {
                    best_rx = Some((k, exprs.len(), exprs));
                }
            }
            odc_model::Direction::Tx => {
                let Some(sw) = fields.iter().find(|f| f.index == 0x6041 && f.sub == 0) else {
                    continue;
                };
                if ty(0x6041, 0) != Some(RustTy::Statusword) {
                    continue;
                }
                let sw = &sw.name;
                let mut exprs = vec![quote!(#rt::cia402::Inputs::new(t.#sw))];
                for f in &fields {
                    let name = &f.name;
                    let e = match (f.index, f.sub, ty(f.index, f.sub)) {
                        (0x6064, 0, Some(RustTy::Signed(32))) => {
                            quote!(i.position = Some(t.#name);)
                        }
                        (0x606C, 0, Some(RustTy::Signed(32))) => {
                            quote!(i.velocity = Some(t.#name);)
                        }
                        (0x6077, 0, Some(RustTy::Signed(16))) => quote!(i.torque = Some(t.#name);),
                        (0x6061, 0, Some(RustTy::Signed(8))) => quote!(i = i.with_mode(t.#name);),
                        _ => continue,
                    };
                    exprs.push(e);
                }
                if best_tx.as_ref().is_none_or(|b| exprs.len() > b.1) {
                    best_tx = Some((k, exprs.len(), exprs));
                }
            }
        }
    }
    let (Some((rx, _, command)), Some((tx, _, status))) = (best_rx, best_tx) else {
        return TokenStream::new();
    };
    let (Some(rx_name), Some(tx_name)) = (names.get(rx), names.get(tx)) else {
        return TokenStream::new();
    };
    let (r, t) = (&rx_name.ty, &tx_name.ty);
    // `Inputs::new(statusword)` alone, or bound to `i` when actual values follow (a `let mut`
    // with nothing after it would be a warning in the user's crate).
    let status = match status.split_first() {
        Some((new, [])) => quote!(#new),
        Some((new, rest)) => quote! {
            let mut i = #new;
            #(#rest)*
            i
        },
        None => return TokenStream::new(),
    };
    let text = doc(&format!(
        "The process data the runtime's CiA 402 driver runs this drive with: `{r}` (controlword\n\
         and targets) out, `{t}` (statusword and actual values) in, as the default mapping has\n\
         them (`odc::master::axis::Axis::with_pdos::<Pdos>`)."
    ));
    quote! {
        #text
        pub struct Pdos;

        impl #rt::cia402::DrivePdos for Pdos {
            type Command = super::pdo::#r;
            type Status = super::pdo::#t;

            fn command_cob_id(node_id: #rt::cob::NodeId) -> #rt::cob::CobId {
                #rt::cob::CobId(super::pdo::#r::cob_id(node_id))
            }

            fn status_cob_id(node_id: #rt::cob::NodeId) -> #rt::cob::CobId {
                #rt::cob::CobId(super::pdo::#t::cob_id(node_id))
            }

            fn command(o: &#rt::cia402::Outputs) -> super::pdo::#r {
                super::pdo::#r { #(#command,)* }
            }

            fn status(t: &super::pdo::#t) -> #rt::cia402::Inputs {
                #status
            }
        }
    }
}
