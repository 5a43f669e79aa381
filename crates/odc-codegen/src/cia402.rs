//! `cia402`: the modes of operation a CiA 402 drive supports.

use odc_analysis::cia402::{MODES, supported_mode_bits};

use crate::types::{RustTy, hex_literal, index_literal};
use odc_model::{DataType, Device, PdoMapping};
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
    let (pdos, no_pdos) = match drive_pdos(ctx) {
        Ok(pdos) => (pdos, TokenStream::new()),
        Err(why) => (TokenStream::new(), doc(&format!("\n{why}"))),
    };
    quote! {
        #docs
        #no_pdos
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

/// `cia402::Pdos`, `COMMAND_CONFIG`, `STATUS_CONFIG` and `plan`: the PDOs the runtime's
/// CiA 402 driver runs the device with and the SDO writes that map them, so the README's
/// recipe (`plan`, then `Axis::with_pdos::<Pdos>`) works for any CiA 402 drive. From the
/// default mapping when it has a pair: the RPDO that carries the controlword, the most
/// targets (one at least) and nothing else the driver does not set (a field it cannot fill
/// would be sent as 0 every cycle), and the TPDO with the statusword and the most actual
/// values. Otherwise a mapping of its own ([`own_mapping`]); when the device cannot take that
/// either, the reason (for the module's documentation).
fn drive_pdos(ctx: &Ctx<'_>) -> Result<TokenStream, String> {
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
                // The controlword alone moves nothing: a target must come with it.
                if ok && exprs.len() > 1 && best_rx.as_ref().is_none_or(|b| exprs.len() > b.1) {
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
        return own_mapping(ctx);
    };
    let (Some(rx_name), Some(tx_name)) = (names.get(rx), names.get(tx)) else {
        return own_mapping(ctx);
    };
    let (Some(rx_pdo), Some(tx_pdo)) = (ctx.device.pdos.get(rx), ctx.device.pdos.get(tx)) else {
        return own_mapping(ctx);
    };
    let (r, t) = (&rx_name.ty, &tx_name.ty);
    let status = status_body(status);
    let text = doc(&format!(
        "The process data the runtime's CiA 402 driver runs this drive with: `{r}` (controlword\n\
         and targets) out, `{t}` (statusword and actual values) in, as the default mapping has\n\
         them. Run [`plan`] first, then `odc::master::axis::Axis::with_pdos::<Pdos>`."
    ));
    let pdos = DrivePdos {
        text,
        command_ty: quote!(super::pdo::#r),
        status_ty: quote!(super::pdo::#t),
        command_cob: quote!(super::pdo::#r::cob_id(node_id)),
        status_cob: quote!(super::pdo::#t::cob_id(node_id)),
        command: quote!(super::pdo::#r { #(#command,)* }),
        status,
        command_config: crate::master::canopen_config(rx_pdo, r, rt),
        status_config: crate::master::canopen_config(tx_pdo, t, rt),
    };
    Ok(pdos.tokens(rt, TokenStream::new()))
}

/// `Inputs::new(statusword)` alone, or bound to `i` when actual values follow (a `let mut`
/// with nothing after it would be a warning in the user's crate).
fn status_body(status: Vec<TokenStream>) -> TokenStream {
    match status.split_first() {
        Some((new, [])) => quote!(#new),
        Some((new, rest)) => quote! {
            let mut i = #new;
            #(#rest)*
            i
        },
        None => TokenStream::new(),
    }
}

/// What `Pdos`, its two PDO configurations and `plan` are made of.
struct DrivePdos {
    text: TokenStream,
    command_ty: TokenStream,
    status_ty: TokenStream,
    command_cob: TokenStream,
    status_cob: TokenStream,
    command: TokenStream,
    status: TokenStream,
    command_config: TokenStream,
    status_config: TokenStream,
}

impl DrivePdos {
    /// `Pdos`, `COMMAND_CONFIG`, `STATUS_CONFIG` and `plan`, after `extra` (the PDO structs
    /// of [`own_mapping`]).
    fn tokens(self, rt: &TokenStream, extra: TokenStream) -> TokenStream {
        let DrivePdos {
            text,
            command_ty,
            status_ty,
            command_cob,
            status_cob,
            command,
            status,
            command_config,
            status_config,
        } = self;
        quote! {
            #extra

            #text
            pub struct Pdos;

            impl #rt::cia402::DrivePdos for Pdos {
                type Command = #command_ty;
                type Status = #status_ty;

                fn command_cob_id(node_id: #rt::cob::NodeId) -> #rt::cob::CobId {
                    #rt::cob::CobId(#command_cob)
                }

                fn status_cob_id(node_id: #rt::cob::NodeId) -> #rt::cob::CobId {
                    #rt::cob::CobId(#status_cob)
                }

                fn command(o: &#rt::cia402::Outputs) -> #command_ty {
                    #command
                }

                fn status(t: &#status_ty) -> #rt::cia402::Inputs {
                    #status
                }
            }

            /// The mapping and communication parameters of [`Pdos`]' RPDO, as the CiA 301 PDO
            /// mapping procedure (`odc::plan::PdoConfig`) writes them.
            pub const COMMAND_CONFIG: #rt::plan::PdoConfig<'static> = #command_config;

            /// The same for [`Pdos`]' TPDO.
            pub const STATUS_CONFIG: #rt::plan::PdoConfig<'static> = #status_config;

            /// The writes that map [`Pdos`]' two PDOs on node `node_id` and leave them valid
            /// (CiA 301 PDO mapping procedure): run them (`Master::execute`) before
            /// `Axis::with_pdos::<Pdos>`.
            pub const fn plan(
                node_id: #rt::cob::NodeId,
            ) -> [#rt::plan::SdoWrite; #rt::plan::plan_len(&[COMMAND_CONFIG, STATUS_CONFIG])] {
                #rt::plan::plan(&[COMMAND_CONFIG, STATUS_CONFIG], &[#command_cob, #status_cob])
            }
        }
    }
}

/// `cia402::Pdos` for a drive whose default mapping has no RPDO the driver can fill with the
/// controlword and a target, or no TPDO with the statusword (an empty factory mapping, or the
/// controlword and the target in different PDOs): RPDO 1 and TPDO 1 mapped by `plan` as the
/// driver needs them, controlword + target position (else target velocity) out, applied at
/// once (transmission type 255), statusword + position actual value (else velocity actual
/// value) in at every SYNC (type 1), at CiA 301's predefined COB-IDs. When the device cannot
/// take that mapping, nothing, and the reason for the module's documentation.
fn own_mapping(ctx: &Ctx<'_>) -> Result<TokenStream, String> {
    let rt = &ctx.rt;
    if ctx.device.ethercat.is_some() {
        // EtherCAT process data is the sync managers' assignment, not CANopen PDOs.
        return Ok(TokenStream::new());
    }
    let (target, actual) = own_mapping_objects(ctx.device)?;
    let field = |f: &Field, ty: TokenStream| {
        let name = Ident::new(f.name, Span::call_site());
        let index = index_literal(f.index);
        let bits = Literal::u8_unsuffixed(f.bits);
        let text = doc(&format!("{} (`0x{:04X}:00`, {} bits).", f.text, f.index, f.bits));
        quote!(#text #[pdo(index = #index, sub = 0x00, bits = #bits)] pub #name: #ty,)
    };
    let value = |index: u16, bits: u8| hex_literal((u64::from(index) << 16) | u64::from(bits), 8);
    let cw = Field { index: 0x6040, name: "controlword", bits: 16, text: "Controlword" };
    let sw = Field { index: 0x6041, name: "statusword", bits: 16, text: "Statusword" };
    let target_field = field(&target, quote!(i32));
    let target_name = Ident::new(target.name, Span::call_site());
    let command_values = [value(cw.index, cw.bits), value(target.index, target.bits)];
    let (cw_field, sw_field) =
        (field(&cw, quote!(#rt::cia402::Controlword)), field(&sw, quote!(#rt::cia402::Statusword)));
    let mut status_values = vec![value(sw.index, sw.bits)];
    let mut status = vec![quote!(#rt::cia402::Inputs::new(t.statusword))];
    let mut status_fields = vec![sw_field];
    if let Some(a) = &actual {
        status_values.push(value(a.index, a.bits));
        status_fields.push(field(a, quote!(i32)));
        let name = Ident::new(a.name, Span::call_site());
        status.push(if a.index == 0x6064 {
            quote!(i.position = Some(t.#name);)
        } else {
            quote!(i.velocity = Some(t.#name);)
        });
    }
    let (nc, ns) = (Literal::usize_unsuffixed(2), Literal::usize_unsuffixed(status_values.len()));
    let structs = quote! {
        /// RPDO 1 as [`plan`] maps it for the driver: the controlword and a target.
        #[derive(Clone, Copy, Debug, Default, PartialEq, #rt::Pdo)]
        pub struct Command {
            #cw_field
            #target_field
        }

        impl Command {
            /// The mapping entries [`plan`] writes to 0x1600.
            pub const MAPPING_VALUES: [u32; #nc] = [#(#command_values),*];
        }

        /// TPDO 1 as [`plan`] maps it for the driver: the statusword and an actual value.
        #[derive(Clone, Copy, Debug, Default, PartialEq, #rt::Pdo)]
        pub struct Status {
            #(#status_fields)*
        }

        impl Status {
            /// The mapping entries [`plan`] writes to 0x1A00.
            pub const MAPPING_VALUES: [u32; #ns] = [#(#status_values),*];
        }
    };
    let text = doc(
        "The process data the runtime's CiA 402 driver runs this drive with. The default PDO\n\
         mapping has no RPDO with the controlword and a target and nothing the driver cannot\n\
         fill, or no TPDO with the statusword, so [`plan`] maps RPDO 1 ([`Command`]) and\n\
         TPDO 1 ([`Status`]) for it. Run [`plan`] first, then\n\
         `odc::master::axis::Axis::with_pdos::<Pdos>`.",
    );
    let pdos = DrivePdos {
        text,
        command_ty: quote!(Command),
        status_ty: quote!(Status),
        command_cob: quote!(0x200 + node_id.get() as u32),
        status_cob: quote!(0x180 + node_id.get() as u32),
        command: quote!(Command {
            controlword: o.controlword,
            #target_name: o.#target_name.unwrap_or(0),
        }),
        status: status_body(status),
        command_config: quote!(#rt::plan::PdoConfig::new(0x1600, &Command::MAPPING_VALUES)
            .with_comm(0x1400, true)
            .with_transmission_type(255)),
        status_config: quote!(#rt::plan::PdoConfig::new(0x1A00, &Status::MAPPING_VALUES)
            .with_comm(0x1800, true)
            .with_transmission_type(1)),
    };
    Ok(pdos.tokens(rt, structs))
}

/// One object of the driver's own mapping.
struct Field {
    index: u16,
    name: &'static str,
    bits: u8,
    text: &'static str,
}

/// The target and the actual value of the driver's own mapping, or why the device cannot take
/// it and what to do instead.
fn own_mapping_objects(device: &Device) -> Result<(Field, Option<Field>), String> {
    let missing: Vec<String> = [0x1400u16, 0x1600, 0x1800, 0x1A00]
        .into_iter()
        .filter(|&i| !device.objects.contains_key(&i))
        .map(|i| format!("0x{i:04X}"))
        .collect();
    let mappable = |index: u16, ty: DataType| {
        device.sub(index, 0).is_some_and(|s| s.data_type == ty && s.pdo_mapping != PdoMapping::No)
    };
    let why = if !missing.is_empty() {
        Some(format!("the device has no {} (RPDO 1 and TPDO 1)", missing.join(", ")))
    } else if !mappable(0x6040, DataType::Unsigned16) || !mappable(0x6041, DataType::Unsigned16) {
        Some("the controlword and statusword are not both PDO-mappable UNSIGNED16".to_owned())
    } else if device.sub(0x1600, 2).is_none() {
        Some("0x1600 has room for one entry only".to_owned())
    } else {
        None
    };
    let target = [
        Field { index: 0x607A, name: "target_position", bits: 32, text: "Target position" },
        Field { index: 0x60FF, name: "target_velocity", bits: 32, text: "Target velocity" },
    ]
    .into_iter()
    .find(|f| mappable(f.index, DataType::Integer32));
    let (Some(target), None) = (target, why.clone()) else {
        let why = why
            .unwrap_or_else(|| "neither 0x607A nor 0x60FF is a PDO-mappable INTEGER32".to_owned());
        return Err(format!(
            "No `Pdos`: the default PDO mapping has no RPDO with the controlword and a target\n\
             and no other field, or no TPDO with the statusword, and {why}. Map PDOs of your\n\
             own (`#[derive(odc::Pdo)]` structs, `odc::master::mapping_plan`) and run the\n\
             driver with `odc::master::axis::Axis::new` (examples/servoone.rs)."
        ));
    };
    let actual = if device.sub(0x1A00, 2).is_none() {
        None
    } else {
        [
            Field {
                index: 0x6064,
                name: "position_actual_value",
                bits: 32,
                text: "Position actual value",
            },
            Field {
                index: 0x606C,
                name: "velocity_actual_value",
                bits: 32,
                text: "Velocity actual value",
            },
        ]
        .into_iter()
        .find(|f| mappable(f.index, DataType::Integer32))
    };
    Ok((target, actual))
}
