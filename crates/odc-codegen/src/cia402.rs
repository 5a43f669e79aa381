//! `cia402`: the modes of operation a CiA 402 drive supports.

use odc_model::{Device, Value};
use proc_macro2::{Ident, Literal, Span, TokenStream};
use quote::quote;

use crate::{Ctx, doc};

/// Standard modes: bit of 0x6502, value of 0x6060, variant name, description.
const MODES: &[(u32, i8, &str, &str)] = &[
    (0, 1, "ProfilePosition", "Profile position mode (pp)."),
    (1, 2, "Velocity", "Velocity mode (vl)."),
    (2, 3, "ProfileVelocity", "Profile velocity mode (pv)."),
    (3, 4, "ProfileTorque", "Profile torque mode (tq)."),
    (5, 6, "Homing", "Homing mode (hm)."),
    (6, 7, "InterpolatedPosition", "Interpolated position mode (ip)."),
    (7, 8, "CyclicSyncPosition", "Cyclic synchronous position mode (csp)."),
    (8, 9, "CyclicSyncVelocity", "Cyclic synchronous velocity mode (csv)."),
    (9, 10, "CyclicSyncTorque", "Cyclic synchronous torque mode (cst)."),
    (
        10,
        11,
        "CyclicSyncTorqueWithCommutation",
        "Cyclic synchronous torque mode with commutation angle (cstca).",
    ),
];

/// Whether the device declares the CiA 402 profile.
pub fn is_cia402(device: &Device) -> bool {
    let device_type = device.sub(0x1000, 0).and_then(|s| s.initial_value()).map(|v| &v.value);
    let by_type = matches!(device_type, Some(Value::Unsigned(v)) if v & 0xFFFF == 402);
    let by_profile = device
        .ethercat
        .as_ref()
        .is_some_and(|e| e.profiles.iter().any(|p| p.profile_no == Some(402)));
    by_type || by_profile
}

/// The standard modes the device supports: (value of 0x6060, name, description), from the
/// default of 0x6502 (every standard mode when it has none, as the generated `Mode` lists).
pub fn supported_modes(device: &Device) -> Vec<(i8, &'static str, &'static str)> {
    let supported = supported_bits(device);
    MODES
        .iter()
        .filter(|(bit, ..)| supported.is_none_or(|s| s & (1 << bit) != 0))
        .map(|&(_, v, name, text)| (v, name, text))
        .collect()
}

/// The default of 0x6502, if it is a number.
fn supported_bits(device: &Device) -> Option<u32> {
    device.sub(0x6502, 0).and_then(|s| s.initial_value()).and_then(|v| match v.value {
        Value::Unsigned(u) => u32::try_from(u).ok(),
        _ => None,
    })
}

/// The `cia402` module, or nothing.
pub fn generate(ctx: &Ctx<'_>) -> TokenStream {
    if !ctx.names.cia402 {
        return TokenStream::new();
    }
    let rt = &ctx.rt;
    let supported = supported_bits(ctx.device);
    let modes: Vec<_> =
        MODES.iter().filter(|(bit, ..)| supported.is_none_or(|s| s & (1 << bit) != 0)).collect();
    let source = match supported {
        Some(s) => format!("the default of 0x6502 (supported drive modes) is `0x{s:08X}`"),
        None => "the device has no 0x6502 default, so every standard mode is listed".to_string(),
    };
    let variants = modes.iter().map(|(_, v, name, text)| {
        let name = Ident::new(name, Span::call_site());
        let v = Literal::i8_unsuffixed(*v);
        let text = format!(" {text}");
        quote!(#[doc = #text] #name = #v,)
    });
    let arms = modes.iter().map(|(_, v, name, _)| {
        let name = Ident::new(name, Span::call_site());
        let v = Literal::i8_unsuffixed(*v);
        quote!(#v => Some(Mode::#name),)
    });
    let all = modes.iter().map(|(_, _, name, _)| {
        let name = Ident::new(name, Span::call_site());
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
    quote! {
        #docs
        pub mod cia402 {
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
