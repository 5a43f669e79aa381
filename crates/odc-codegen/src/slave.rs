//! `slave`: a heap-free object dictionary for the device's own firmware, as a table.
//!
//! The module is data: one `odc::slave::Row` per typed entry, `row!(od::X)` from its
//! descriptor in `od` (address, access, and the type, limits and default in a `Spec` that
//! entries alike share), in a `const` `odc::slave::Table` that lays the values out as bytes. `Dictionary` holds those bytes and hands every SDO
//! transfer to the table's one read and one write path in the runtime, so an entry costs a
//! row in flash and its encoded size in RAM, and no code: the per-type work is linked once
//! per value type (see `odc::slave`).

use proc_macro2::{Literal, TokenStream};
use quote::quote;

use crate::{Ctx, doc};

/// The `slave` module.
pub fn generate(ctx: &Ctx<'_>) -> TokenStream {
    let rt = &ctx.rt;
    let rows: Vec<_> = ctx
        .names
        .entries
        .values()
        .map(|name| {
            let k = &name.konst;
            match &name.module {
                Some(m) => quote!(row!(od::#m::#k)),
                None => quote!(row!(od::#k)),
            }
        })
        .collect();
    let n = Literal::usize_unsuffixed(rows.len());
    // Without rows, the imports would be unused.
    let imports = if rows.is_empty() {
        TokenStream::new()
    } else {
        quote! {
            use super::od;
            use #rt::slave::row;
        }
    };
    let docs = doc(&format!(
        "The object dictionary of {}, for the device's own firmware: `no_std`, no heap.\n\n\
         `TABLE` has one row per typed entry of `od`, in address order; `Dictionary` holds \
         their values and answers SDO reads and writes with the CiA 301 abort codes (access, \
         existence, length, limits). The firmware reads and writes the values typed: \
         `dict.get(od::X)`, `dict.set(od::X, value)`.",
        ctx.device.name()
    ));
    quote! {
        #docs
        pub mod slave {
            #imports

            /// The entries of the dictionary, sorted by (index, sub-index): each one's
            /// address, access, limits and default (from its descriptor in `od`) and where its
            /// value is stored.
            pub static TABLE: #rt::slave::Table<#n> = LAYOUT;

            const LAYOUT: #rt::slave::Table<#n> = #rt::slave::Table::new([#(#rows),*]);

            /// The values of the dictionary, each in its SDO encoding at its place in `TABLE`.
            #[derive(Clone, PartialEq, Eq, Hash)]
            pub struct Dictionary {
                values: [u8; LAYOUT.size()],
            }

            impl Dictionary {
                /// The dictionary of node `node_id`, every entry at its default (`$NODEID`
                /// applied); entries without default start at zero, or at the limit nearest
                /// to it.
                pub fn new(node_id: u8) -> Self {
                    let mut values = [0; LAYOUT.size()];
                    TABLE.init(&mut values, node_id);
                    Dictionary { values }
                }

                /// The value of `entry`, one of `od`'s descriptors.
                ///
                /// # Errors
                ///
                /// `NoSuchObject`, `NoSuchSub` or `LengthMismatch` when `entry` is not one
                /// of this dictionary's.
                pub fn get<T: #rt::ObjValue>(&self, entry: #rt::Entry<T>) -> Result<T, #rt::SdoAbort> {
                    TABLE.get(&self.values, &entry)
                }

                /// Stores `value` for `entry`, without the access and limit checks of an SDO
                /// write (the firmware sets its read-only values this way).
                ///
                /// # Errors
                ///
                /// As for [`Dictionary::get`].
                pub fn set<T: #rt::ObjValue>(
                    &mut self,
                    entry: #rt::Entry<T>,
                    value: T,
                ) -> Result<(), #rt::SdoAbort> {
                    TABLE.set(&mut self.values, &entry, value)
                }

                /// SDO upload of `index:sub` into `buf`; returns the number of bytes.
                ///
                /// # Errors
                ///
                /// The abort code: no such object or sub-index, read of a write-only entry,
                /// `buf` too short.
                pub fn read(&self, index: u16, sub: u8, buf: &mut [u8]) -> Result<usize, #rt::SdoAbort> {
                    TABLE.read(&self.values, index, sub, buf)
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
                    TABLE.write(&mut self.values, index, sub, data, hook)
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

            /// Every entry's address and value, shown by its CiA 301 data type.
            impl ::core::fmt::Debug for Dictionary {
                fn fmt(&self, f: &mut ::core::fmt::Formatter<'_>) -> ::core::fmt::Result {
                    TABLE.fmt_values(&self.values, f)
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
