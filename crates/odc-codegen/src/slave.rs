//! `slave`: a heap-free object dictionary with typed storage, for the device's own firmware.

use proc_macro2::{Literal, TokenStream};
use quote::quote;

use crate::{Ctx, doc};

/// The `slave` module.
pub fn generate(ctx: &Ctx<'_>) -> TokenStream {
    let rt = &ctx.rt;
    let entries: Vec<_> = ctx.names.entries.values().collect();
    let n = Literal::usize_unsuffixed(entries.len());
    let infos = entries.iter().map(|e| {
        let p = e.path();
        quote!(#p.info())
    });
    let fields = entries.iter().map(|e| {
        let (f, ty, p) = (&e.field, e.ty.tokens(rt), e.path());
        let text = format!(" The value of [`{}`].", p.to_string().replace(' ', ""));
        quote! {
            #[doc = #text]
            pub #f: #ty,
        }
    });
    let inits = entries.iter().map(|e| {
        let (f, p, zero) = (&e.field, e.path(), e.ty.zero_expr(rt));
        quote!(#f: #rt::slave::initial(&#p, node_id, #zero),)
    });
    let reads = entries.iter().enumerate().map(|(i, e)| {
        let (f, p) = (&e.field, e.path());
        let i = Literal::usize_unsuffixed(i);
        quote!(#i => #p.encode_upload(&self.#f, buf),)
    });
    let writes = entries.iter().enumerate().map(|(i, e)| {
        let (f, p) = (&e.field, e.path());
        let i = Literal::usize_unsuffixed(i);
        quote! {
            #i => {
                let value = #p.decode_download(data)?;
                hook.before_write(#p.addr, data)?;
                self.#f = value;
                hook.after_write(#p.addr);
            }
        }
    });
    // One statement per field: `#[derive(PartialEq)]` joins the comparisons with `&&` into
    // one expression nested as deep as the struct has fields, and rustc's recursive passes
    // overflow their stack on it for big dictionaries (Beckhoff ELM37xx: 9,246 entries).
    let eq_body = if entries.is_empty() {
        quote! {
            let _ = other;
            true
        }
    } else {
        let stmts = entries.iter().map(|e| {
            let f = &e.field;
            quote! {
                if self.#f != other.#f {
                    return false;
                }
            }
        });
        quote! {
            #(#stmts)*
            true
        }
    };
    // A device without typed entries (an EtherCAT coupler, say) answers every request with
    // "no such object"; the match-based bodies would leave `node_id` unused and `Ok(())`
    // unreachable.
    let (new_body, read_body, write_body) = if entries.is_empty() {
        (
            quote! {
                let _ = node_id;
                Dictionary {}
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
        (
            quote! {
                Dictionary {
                    #(#inits)*
                }
            },
            quote! {
                match #rt::slave::locate(&ENTRIES, index, sub)? {
                    #(#reads)*
                    _ => Err(#rt::SdoAbort::NoSuchObject),
                }
            },
            quote! {
                match #rt::slave::locate(&ENTRIES, index, sub)? {
                    #(#writes)*
                    _ => return Err(#rt::SdoAbort::NoSuchObject),
                }
                Ok(())
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
            /// Every entry of the dictionary, sorted by (index, sub-index).
            pub static ENTRIES: [#rt::EntryInfo; #n] = [#(#infos),*];

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
