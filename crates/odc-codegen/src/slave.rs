//! `slave`: a heap-free object dictionary for the device's own firmware, as a table.
//!
//! The module is data: one `odc::slave::Row` per typed entry, `row!(od::X)` from its
//! descriptor in `od` (address, access, and the type, limits and default in a `Spec` that
//! entries alike share), in a `const` `odc::slave::Table` that lays the values out as bytes. `Dictionary` holds those bytes and hands every SDO
//! transfer to the table's one read and one write path in the runtime, so an entry costs a
//! row in flash and its encoded size in RAM, and no code: the per-type work is linked once
//! per value type (see `odc::slave`).
//!
//! The generator also writes the initial values as one `INITIAL` image (`storage_image`) that
//! `new` and `reset` copy, with the `$NODEID` defaults written over it for the node
//! (`NODE_ID_DEFAULTS`); the rows then keep only the limits (`row_limits!`), or nothing but the
//! type where no entry of that type has limits (`row_unlimited!`), and no typed initial value
//! is linked. A file whose initial values `storage_image` cannot work out keeps `row!` and the
//! run-time initialisation (`Table::init`).

use proc_macro2::{Literal, TokenStream};
use quote::quote;

use crate::storage_image::Image;
use crate::types::{RustTy, RustTyTokens};
use crate::{Ctx, doc};

/// `impl odc::cia402::DriveObjects for Dictionary` when the device is a CiA 402 drive whose
/// controlword and statusword are typed as the profile types them; the optional objects are
/// implemented for those the file has as VARs with the profile's type (the trait's defaults
/// say "absent" for the others).
fn drive_objects(ctx: &Ctx<'_>) -> TokenStream {
    let rt = &ctx.rt;
    // The descriptor of a VAR at `index` with type `ty`, as the slave module names it.
    let var = |index: u16, ty: RustTy| {
        let name = ctx.names.entries.get(&(index, 0))?;
        let k = &name.konst;
        (name.module.is_none() && name.ty == ty).then(|| quote!(od::#k))
    };
    let (Some(cw), Some(sw)) = (var(0x6040, RustTy::Controlword), var(0x6041, RustTy::Statusword))
    else {
        return TokenStream::new();
    };
    let mut methods = vec![
        quote! {
            fn controlword(&self) -> #rt::cia402::Controlword {
                self.get(#cw).unwrap_or_default()
            }
        },
        quote! {
            fn set_statusword(&mut self, statusword: #rt::cia402::Statusword) {
                let _ = self.set(#sw, statusword);
            }
        },
    ];
    if let Some(e) = var(0x6060, RustTy::Signed(8)) {
        methods.push(quote! {
            fn modes_of_operation(&self) -> Option<#rt::cia402::ModeOfOperation> {
                self.get(#e).ok().map(#rt::cia402::ModeOfOperation::from_i8)
            }
        });
    }
    if let Some(e) = var(0x6061, RustTy::Signed(8)) {
        methods.push(quote! {
            fn set_modes_of_operation_display(&mut self, mode: #rt::cia402::ModeOfOperation) {
                let _ = self.set(#e, mode.to_i8());
            }
        });
    }
    for (index, ty, method) in [
        (0x607A, RustTy::Signed(32), quote!(target_position)),
        (0x60FF, RustTy::Signed(32), quote!(target_velocity)),
        (0x6081, RustTy::Unsigned(32), quote!(profile_velocity)),
    ] {
        if let Some(e) = var(index, ty) {
            let t = ty.tokens(rt);
            methods.push(quote! {
                fn #method(&self) -> Option<#t> {
                    self.get(#e).ok()
                }
            });
        }
    }
    for (index, ty, method) in [
        (0x6098, RustTy::Signed(8), quote!(homing_method)),
        (0x607C, RustTy::Signed(32), quote!(home_offset)),
        (0x6071, RustTy::Signed(16), quote!(target_torque)),
    ] {
        if let Some(e) = var(index, ty) {
            let t = ty.tokens(rt);
            methods.push(quote! {
                fn #method(&self) -> Option<#t> {
                    self.get(#e).ok()
                }
            });
        }
    }
    // 0x6099:01, speed during search for switch: a sub-object of the homing speeds.
    if let Some(name) = ctx.names.entries.get(&(0x6099, 1))
        && let (Some(m), RustTy::Unsigned(32)) = (&name.module, name.ty)
    {
        let k = &name.konst;
        methods.push(quote! {
            fn homing_speed(&self) -> Option<u32> {
                self.get(od::#m::#k).ok()
            }
        });
    }
    if let Some(e) = var(0x6077, RustTy::Signed(16)) {
        methods.push(quote! {
            fn set_torque_actual_value(&mut self, torque: i16) {
                let _ = self.set(#e, torque);
            }
        });
    }
    for (index, method, arg) in [
        (0x6064, quote!(set_position_actual_value), quote!(position)),
        (0x606C, quote!(set_velocity_actual_value), quote!(velocity)),
    ] {
        if let Some(e) = var(index, RustTy::Signed(32)) {
            methods.push(quote! {
                fn #method(&mut self, #arg: i32) {
                    let _ = self.set(#e, #arg);
                }
            });
        }
    }
    quote! {
        /// The CiA 402 objects of the drive, for `odc::cia402::Drive` or the firmware's own
        /// state machine. The descriptors are this dictionary's own, so `get` and `set`
        /// cannot fail.
        impl #rt::cia402::DriveObjects for Dictionary {
            #(#methods)*
        }
    }
}

/// `DESCRIPTION`, what EtherCAT's SDO Information serves beyond `TABLE` (names, object codes,
/// PDO directions, backup and setting flags), for an EtherCAT device; nothing for a CANopen
/// one, or when the names would not fit a 64 KiB pool. Data only: a firmware that does not
/// name it in its stack's `Config` does not link it.
fn description(ctx: &Ctx<'_>, n: &Literal) -> TokenStream {
    use odc_model::Direction;
    let rt = &ctx.rt;
    let device = ctx.device;
    let Some(ecat) = device.ethercat.as_deref() else { return TokenStream::new() };
    let flag =
        |index: u16, sub: u8| ecat.object_flags.iter().find(|f| f.index == index && f.sub == sub);
    let mut objects = Vec::new();
    let mut flags = Vec::new();
    let mut object_names = String::new();
    let mut object_ends = Vec::new();
    let mut entry_names = String::new();
    let mut entry_ends = Vec::new();
    let mut last = None;
    for (row, &(index, sub)) in ctx.names.entries.keys().enumerate() {
        let Some(object) = device.objects.get(&index) else { return TokenStream::new() };
        let Some(entry) = object.subs.get(&sub) else { return TokenStream::new() };
        if last != Some(index) {
            last = Some(index);
            let code = object.kind.code();
            let max_sub = object.subs.keys().copied().max().unwrap_or(0);
            let Ok(row) = u16::try_from(row) else { return TokenStream::new() };
            objects
                .push(quote!(#rt::slave::ObjectRow { row: #row, max_sub: #max_sub, code: #code }));
            object_names.push_str(&object.name);
            object_ends.push(object_names.len());
        }
        // An entry named as its object (a VAR's) points at the object's name.
        let same = entry.name == object.name;
        let f = flag(index, sub);
        let bits = u8::from(entry.pdo_mapping.allows(entry.access, Direction::Rx))
            | u8::from(entry.pdo_mapping.allows(entry.access, Direction::Tx)) << 1
            | u8::from(f.and_then(|f| f.backup).unwrap_or(false)) << 2
            | u8::from(f.and_then(|f| f.setting).unwrap_or(false)) << 3
            | u8::from(same) << 4;
        flags.push(Literal::u8_unsuffixed(bits));
        if !same {
            entry_names.push_str(&entry.name);
        }
        entry_ends.push(entry_names.len());
    }
    let base = object_names.len();
    let ends: Option<Vec<u16>> = object_ends
        .into_iter()
        .chain(entry_ends.into_iter().map(|e| base + e))
        .map(|e| u16::try_from(e).ok())
        .collect();
    let Some(ends) = ends else { return TokenStream::new() };
    let n_ends = Literal::usize_unsuffixed(ends.len());
    let ends = ends.into_iter().map(Literal::u16_unsuffixed);
    let names = object_names + &entry_names;
    let n_objects = Literal::usize_unsuffixed(objects.len());
    quote! {
        /// What EtherCAT's SDO Information serves beyond `TABLE`: the name of every object
        /// and entry (one pool), object codes, highest sub-indexes, PDO directions, backup
        /// and setting flags. Name it in the stack's `Config` (`describe:
        /// Some(&slave::DESCRIPTION)`) to serve Get OD List, Get Object Description and Get
        /// Entry Description; unnamed, it is not linked.
        pub static DESCRIPTION: #rt::slave::Description<'static> = #rt::slave::Description::new(
            TABLE.rows(),
            &OBJECTS,
            &FLAGS,
            &ENDS,
            #names,
        );

        const OBJECTS: [#rt::slave::ObjectRow; #n_objects] = [#(#objects),*];
        const FLAGS: [u8; #n] = [#(#flags),*];
        const ENDS: [u16; #n_ends] = [#(#ends),*];
    }
}

/// The value types of the entries whose descriptors have limits (`with_limits`: a limit
/// that is a value of the type).
fn limited_types(ctx: &Ctx<'_>) -> Vec<RustTy> {
    let rt = &ctx.rt;
    ctx.names
        .entries
        .iter()
        .filter(|&(&(index, sub), name)| {
            let Some(sub) = ctx.device.objects.get(&index).and_then(|o| o.subs.get(&sub)) else {
                // Not in the model: take it as limited (the check with limits is right for
                // any entry).
                return true;
            };
            [&sub.low_limit, &sub.high_limit]
                .into_iter()
                .any(|l| l.as_ref().is_some_and(|v| name.ty.option_expr(&v.value, rt).is_some()))
        })
        .map(|(_, name)| name.ty)
        .collect()
}

/// `Dictionary::new` and `reset`, and the `INITIAL` image they copy when there is one.
fn initial(rt: &TokenStream, image: Option<&Image>) -> (TokenStream, TokenStream) {
    let Some(image) = image else {
        let fns = quote! {
            /// The dictionary of node `node_id`, every entry at its default (`$NODEID`
            /// applied); entries without default start at zero, or at the limit nearest
            /// to it. `None`: a node without node-ID (LSS), whose `$NODEID` defaults are
            /// taken as absent.
            pub fn new(node_id: impl Into<Option<#rt::cob::NodeId>>) -> Self {
                let mut dictionary = Dictionary { values: [0; LAYOUT.size()] };
                TABLE.init(&mut dictionary.values, node_id.into());
                dictionary
            }

            /// Every entry back to its default for node `node_id`, as
            /// [`Dictionary::new`] makes it (a reset node or communication), in place:
            /// `*dictionary = Dictionary::new(id)` puts the values on the stack first.
            pub fn reset(&mut self, node_id: impl Into<Option<#rt::cob::NodeId>>) {
                self.values = [0; LAYOUT.size()];
                TABLE.init(&mut self.values, node_id.into());
            }
        };
        return (TokenStream::new(), fns);
    };
    let bytes = image.bytes.iter().map(|&b| Literal::u8_unsuffixed(b));
    let mut items = quote! {
        /// Every entry's initial value at its place in `TABLE`: its default, else zero, or
        /// the limit nearest to it; for a `$NODEID` default, its value without node-ID
        /// (`NODE_ID_DEFAULTS` has the sums). The generator wrote them here, and a new or
        /// reset dictionary is a copy.
        const INITIAL: [u8; LAYOUT.size()] = [#(#bytes),*];
    };
    if image.node_id.is_empty() {
        let fns = quote! {
            /// The dictionary, every entry at its initial value (`INITIAL`); `node_id`
            /// changes nothing (no default of the device depends on it).
            pub fn new(_node_id: impl Into<Option<#rt::cob::NodeId>>) -> Self {
                Dictionary { values: INITIAL }
            }

            /// Every entry back to its initial value, as [`Dictionary::new`] makes it, in
            /// place.
            pub fn reset(&mut self, _node_id: impl Into<Option<#rt::cob::NodeId>>) {
                self.values = INITIAL;
            }
        };
        return (items, fns);
    }
    let defaults = image.node_id.iter().map(|&(at, len, signed, offset)| {
        let (at, len) = (Literal::usize_unsuffixed(at), Literal::usize_unsuffixed(len));
        let offset = crate::types::int_literal(u64::from(offset));
        quote!(#rt::slave::NodeIdDefault::new(#at, #len, #signed, #offset))
    });
    let n = Literal::usize_unsuffixed(image.node_id.len());
    items.extend(quote! {
        /// The entries whose default is `$NODEID + offset`, written over `INITIAL` for the
        /// node.
        const NODE_ID_DEFAULTS: [#rt::slave::NodeIdDefault; #n] = [#(#defaults),*];
    });
    let fns = quote! {
        /// The dictionary of node `node_id`, every entry at its default (`$NODEID`
        /// applied); entries without default start at zero, or at the limit nearest
        /// to it. `None`: a node without node-ID (LSS), whose `$NODEID` defaults are
        /// taken as absent.
        pub fn new(node_id: impl Into<Option<#rt::cob::NodeId>>) -> Self {
            let mut dictionary = Dictionary { values: INITIAL };
            #rt::slave::NodeIdDefault::apply(&NODE_ID_DEFAULTS, &mut dictionary.values, node_id.into());
            dictionary
        }

        /// Every entry back to its default for node `node_id`, as
        /// [`Dictionary::new`] makes it (a reset node or communication), in place.
        pub fn reset(&mut self, node_id: impl Into<Option<#rt::cob::NodeId>>) {
            self.values = INITIAL;
            #rt::slave::NodeIdDefault::apply(&NODE_ID_DEFAULTS, &mut self.values, node_id.into());
        }
    };
    (items, fns)
}

/// The `slave` module.
pub fn generate(ctx: &Ctx<'_>) -> TokenStream {
    let rt = &ctx.rt;
    // With an image of the initial values, the rows keep the limits only (no typed initial
    // value linked) and a new or reset dictionary is a copy of the image.
    let image = crate::storage_image::initial_image(ctx);
    // A value type that no entry limits is checked by its decoding alone (`row_unlimited!`).
    let limited = limited_types(ctx);
    let mut macros = std::collections::BTreeSet::new();
    let rows: Vec<_> = ctx
        .names
        .entries
        .values()
        .map(|name| {
            let row = match (&image, limited.contains(&name.ty)) {
                (None, _) => quote!(row),
                (Some(_), true) => quote!(row_limits),
                (Some(_), false) => quote!(row_unlimited),
            };
            macros.insert(row.to_string());
            let k = &name.konst;
            match &name.module {
                Some(m) => quote!(#row!(od::#m::#k)),
                None => quote!(#row!(od::#k)),
            }
        })
        .collect();
    let n = Literal::usize_unsuffixed(rows.len());
    let macros = macros.iter().map(|m| proc_macro2::Ident::new(m, proc_macro2::Span::call_site()));
    // Without rows, the imports would be unused.
    let imports = if rows.is_empty() {
        TokenStream::new()
    } else {
        quote! {
            use super::od;
            use #rt::slave::{#(#macros),*};
        }
    };
    let (initial_const, initial_fns) = initial(rt, image.as_ref());
    let docs = doc(&format!(
        "The object dictionary of {}, for the device's own firmware: `no_std`, no heap.\n\n\
         `TABLE` has one row per typed entry of `od`, in address order; `Dictionary` holds \
         their values and answers SDO reads and writes with the CiA 301 abort codes (access, \
         existence, length, limits). The firmware reads and writes the values typed: \
         `dict.get(od::X)`, `dict.set(od::X, value)`.",
        ctx.device.name()
    ));
    let drive = drive_objects(ctx);
    let description = description(ctx, &n);
    let lss = ctx.device.device_info.lss_supported.as_ref().is_some_and(|v| v.value);
    quote! {
        #docs
        pub mod slave {
            #imports

            /// Whether the device answers LSS (CiA 305): the file's `LSS_Supported` (absent
            /// means no, CiA 306). Give the node its LSS slave (`Node::with_lss`) only when
            /// it is `true`: a device whose file says 0 stays silent on 0x7E5, as
            /// `odc simulate` does.
            pub const LSS_SUPPORTED: bool = #lss;

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

            #initial_const

            impl Dictionary {
                #initial_fns

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
                fn access(&self, index: u16, sub: u8) -> Option<#rt::Access> {
                    TABLE.access(index, sub)
                }
                fn pdo_mappable(&self, index: u16, sub: u8, tx: bool) -> Result<u32, #rt::SdoAbort> {
                    TABLE.pdo_mappable(index, sub, tx)
                }
            }

            impl #rt::slave::Storage for Dictionary {
                fn raw(&self, index: u16, sub: u8) -> Option<&[u8]> {
                    TABLE.raw(&self.values, index, sub)
                }
                fn raw_mut(&mut self, index: u16, sub: u8) -> Option<&mut [u8]> {
                    TABLE.raw_mut(&mut self.values, index, sub)
                }
                fn entry_at(&self, pos: usize) -> Option<#rt::slave::EntryMeta> {
                    TABLE.entry_at(pos)
                }
                fn position(&self, index: u16, sub: u8) -> usize {
                    TABLE.position(index, sub)
                }
            }

            #description

            #drive
        }
    }
}
