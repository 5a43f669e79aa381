//! `slave`: a heap-free object dictionary with typed storage, for the device's own firmware.
//!
//! The code is laid out for small flash: the lookup reads a table of 4-byte keys and a table
//! of 1-byte access rights (the names of `ENTRIES` stay out of the image unless the firmware
//! uses them), the initial values are one `const` struct copied by `new` (the
//! `$NODEID`-relative ones patched after), and each read or write arm is a call of the one
//! `upload`/`download` of its value type; arms that the access check rules out are left out.

use odc_model::Value;
use proc_macro2::{Literal, TokenStream};
use quote::quote;

use crate::od::EntryName;
use crate::types::hex_literal;
use crate::{Ctx, doc};

/// What the slave code needs to know of one entry beyond its name.
struct Slot<'a> {
    name: &'a EntryName,
    key: u32,
    readable: bool,
    writable: bool,
    /// Whether the descriptor has a low or high limit (the write arm passes them).
    limited: bool,
    /// Whether `new` computes the initial value at run time (`odc::slave::initial`): a
    /// `$NODEID`-relative default, or no usable default but limits that zero may be outside
    /// of; the others start as in `DEFAULTS`.
    patched: bool,
}

fn slots<'a>(ctx: &'a Ctx<'_>) -> Vec<Slot<'a>> {
    let rt = &ctx.rt;
    ctx.names
        .entries
        .iter()
        .filter_map(|(&(index, sub), name)| {
            let s = ctx.device.objects.get(&index)?.subs.get(&sub)?;
            let limit = |v: Option<&odc_model::Spanned<Value>>| {
                v.and_then(|v| name.ty.option_expr(&v.value, rt)).is_some()
            };
            let limited = limit(s.low_limit.as_deref()) || limit(s.high_limit.as_deref());
            let default =
                s.initial_value().filter(|v| name.ty.default_expr(&v.value, rt).is_some());
            let patched = match default {
                Some(v) => matches!(v.value, Value::NodeIdPlus(_)),
                None => limited,
            };
            Some(Slot {
                name,
                key: u32::from(index) << 8 | u32::from(sub),
                readable: s.access.readable(),
                writable: s.access.writable(),
                limited,
                patched,
            })
        })
        .collect()
}

/// The `slave` module.
pub fn generate(ctx: &Ctx<'_>) -> TokenStream {
    let rt = &ctx.rt;
    let slots = slots(ctx);
    let n = Literal::usize_unsuffixed(slots.len());
    let infos = slots.iter().map(|s| {
        let p = s.name.path();
        quote!(#p.info())
    });
    let keys = slots.iter().map(|s| hex_literal(u64::from(s.key), 6));
    let access = slots.iter().map(|s| {
        let p = s.name.path();
        quote!(#p.access)
    });
    let fields = slots.iter().map(|s| {
        let (f, ty, p) = (&s.name.field, s.name.ty.tokens(rt), s.name.path());
        let text = format!(" The value of [`{}`].", p.to_string().replace(' ', ""));
        quote! {
            #[doc = #text]
            pub #f: #ty,
        }
    });
    let defaults = slots.iter().map(|s| {
        let (f, p, zero) = (&s.name.field, s.name.path(), s.name.ty.zero_expr(rt));
        quote!(#f: #rt::slave::fixed_default(&#p, #zero),)
    });
    let patched: Vec<_> = slots.iter().filter(|s| s.patched).collect();
    let patches = patched.iter().map(|s| {
        let (f, p, zero) = (&s.name.field, s.name.path(), s.name.ty.zero_expr(rt));
        quote!(#f: #rt::slave::initial(&#p, node_id, #zero),)
    });
    let reads: Vec<_> = slots
        .iter()
        .enumerate()
        .filter(|(_, s)| s.readable)
        .map(|(i, s)| {
            let f = &s.name.field;
            let i = Literal::usize_unsuffixed(i);
            quote!(#i => #rt::slave::upload(&self.#f, buf),)
        })
        .collect();
    let writes: Vec<_> = slots
        .iter()
        .enumerate()
        .filter(|(_, s)| s.writable)
        .map(|(i, s)| {
            let (f, p) = (&s.name.field, s.name.path());
            let i = Literal::usize_unsuffixed(i);
            let limits = if s.limited { quote!(#p.low, #p.high) } else { quote!(None, None) };
            quote!(#i => #rt::slave::download(&mut self.#f, data, #limits, addr, hook),)
        })
        .collect();
    // The access check has answered every request for which no arm exists; with no arm at
    // all, the match would be a lint and the arguments unused.
    let read_match = if reads.is_empty() {
        quote! {
            let _ = (pos, buf);
            Err(#rt::SdoAbort::ReadOfWriteOnly)
        }
    } else {
        quote! {
            match pos {
                #(#reads)*
                _ => Err(#rt::SdoAbort::NoSuchObject),
            }
        }
    };
    let write_match = if writes.is_empty() {
        quote! {
            let _ = (pos, data, hook);
            Err(#rt::SdoAbort::WriteOfReadOnly)
        }
    } else {
        quote! {
            let addr = #rt::ObjectAddr::new(index, sub);
            match pos {
                #(#writes)*
                _ => Err(#rt::SdoAbort::NoSuchObject),
            }
        }
    };
    // One statement per field: `#[derive(PartialEq)]` joins the comparisons with `&&` into
    // one expression nested as deep as the struct has fields, and rustc's recursive passes
    // overflow their stack on it for big dictionaries (Beckhoff ELM37xx: 9,246 entries).
    let compares = slots.iter().map(|s| {
        let f = &s.name.field;
        quote! {
            if self.#f != other.#f {
                return false;
            }
        }
    });
    // A device without typed entries (an EtherCAT coupler, say) answers every request with
    // "no such object"; the match-based bodies would leave `node_id` unused and `Ok(())`
    // unreachable.
    let (eq_body, new_body, read_body, write_body) = if slots.is_empty() {
        (
            quote! {
                let _ = other;
                true
            },
            quote! {
                let _ = node_id;
                DEFAULTS
            },
            quote! {
                let _ = (index, sub, buf);
                Err(#rt::SdoAbort::NoSuchObject)
            },
            quote! {
                let _ = (index, sub, data, hook);
                Err(#rt::SdoAbort::NoSuchObject)
            },
        )
    } else {
        let new_body = if patched.is_empty() {
            quote! {
                let _ = node_id;
                DEFAULTS
            }
        } else if patched.len() == slots.len() {
            quote!(Dictionary { #(#patches)* })
        } else {
            quote!(Dictionary { #(#patches)* ..DEFAULTS })
        };
        (
            quote! {
                #(#compares)*
                true
            },
            new_body,
            quote! {
                let pos = #rt::slave::find(&KEYS, index, sub)?;
                #rt::slave::check_read(&ACCESS, pos)?;
                #read_match
            },
            quote! {
                let pos = #rt::slave::find(&KEYS, index, sub)?;
                #rt::slave::check_write(&ACCESS, pos)?;
                #write_match
            },
        )
    };
    let docs = doc(&format!(
        "The object dictionary of {}, for the device's own firmware: `no_std`, no heap.\n\n\
         `ENTRIES` lists every typed sub-object in address order; `Dictionary` holds their \
         values and answers SDO reads and writes with the CiA 301 abort codes (access, \
         existence, length, limits).",
        ctx.device.name()
    ));
    quote! {
        #docs
        pub mod slave {
            /// Every entry of the dictionary, sorted by (index, sub-index), with its name, data
            /// type and access. `Dictionary` does not read it: a firmware that does not use it
            /// does not link it.
            pub static ENTRIES: [#rt::EntryInfo; #n] = [#(#infos),*];

            /// The search key (`index << 8 | sub`, see `odc::slave::key`) of each entry, in the
            /// order of `ENTRIES`.
            pub static KEYS: [u32; #n] = [#(#keys),*];

            /// The access right of each entry, in the order of `ENTRIES`.
            pub static ACCESS: [#rt::Access; #n] = [#(#access),*];

            /// The values of the dictionary, one field per entry.
            #[derive(Clone, Debug)]
            pub struct Dictionary {
                #(#fields)*
            }

            impl PartialEq for Dictionary {
                fn eq(&self, other: &Self) -> bool {
                    #eq_body
                }
            }

            /// Every entry at its default, those relative to the node id (and those without
            /// default) at zero.
            const DEFAULTS: Dictionary = Dictionary {
                #(#defaults)*
            };

            impl Dictionary {
                /// The dictionary of node `node_id`, every entry at its default (`$NODEID`
                /// applied); entries without default start at zero.
                pub fn new(node_id: u8) -> Self {
                    #new_body
                }

                /// SDO upload of `index:sub` into `buf`; returns the number of bytes.
                ///
                /// # Errors
                ///
                /// The abort code: no such object or sub-index, read of a write-only entry,
                /// `buf` too short.
                pub fn read(&self, index: u16, sub: u8, buf: &mut [u8]) -> Result<usize, #rt::SdoAbort> {
                    #read_body
                }

                /// SDO download of `data` into `index:sub`, telling `hook` before and after
                /// the value is stored.
                ///
                /// # Errors
                ///
                /// The abort code: no such object or sub-index, write of a read-only entry,
                /// length mismatch, value out of range, or what `hook` answered.
                pub fn write_with<H: #rt::slave::WriteHook>(
                    &mut self,
                    index: u16,
                    sub: u8,
                    data: &[u8],
                    hook: &mut H,
                ) -> Result<(), #rt::SdoAbort> {
                    #write_body
                }

                /// SDO download of `data` into `index:sub`.
                ///
                /// # Errors
                ///
                /// As for [`Dictionary::write_with`].
                pub fn write(&mut self, index: u16, sub: u8, data: &[u8]) -> Result<(), #rt::SdoAbort> {
                    self.write_with(index, sub, data, &mut ())
                }
            }

            impl #rt::slave::ObjectDictionary for Dictionary {
                fn read(&self, index: u16, sub: u8, buf: &mut [u8]) -> Result<usize, #rt::SdoAbort> {
                    Dictionary::read(self, index, sub, buf)
                }
                fn write(&mut self, index: u16, sub: u8, data: &[u8]) -> Result<(), #rt::SdoAbort> {
                    Dictionary::write(self, index, sub, data)
                }
            }
        }
    }
}
