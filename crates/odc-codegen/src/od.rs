//! `od`: one typed descriptor per object and sub-object.

use std::collections::BTreeMap;

use odc_model::{Access, Device, SubObject, Value};
use proc_macro2::{Ident, Span, TokenStream};
use quote::quote;

use crate::names::{self, Namer};
use crate::standard;
use odc_analysis::{typed_subs, value_text};

use crate::types::{RustTy, RustTyTokens, index_literal, sub_literal};
use crate::{Ctx, doc};

/// The name of one typed sub-object in the generated code.
pub struct EntryName {
    /// The module of its record or array, when it has one.
    pub module: Option<Ident>,
    /// The constant.
    pub konst: Ident,
    /// Its Rust type.
    pub ty: RustTy,
}

impl EntryName {
    /// The descriptor's path from a sibling module of `od` (`super::od::…`).
    pub fn path(&self) -> TokenStream {
        let k = &self.konst;
        match &self.module {
            Some(m) => quote!(super::od::#m::#k),
            None => quote!(super::od::#k),
        }
    }
}

/// Names of every typed sub-object, by (index, sub).
pub struct OdNames {
    /// The entries, in address order.
    pub entries: BTreeMap<(u16, u8), EntryName>,
    /// The module of each record or array that has typed sub-objects.
    pub modules: BTreeMap<u16, Ident>,
    /// Whether the device declares the CiA 402 profile (its controlword and statusword are
    /// typed, and the code has a `cia402` module).
    pub cia402: bool,
}

fn ident(s: &str) -> Ident {
    Ident::new(s, Span::call_site())
}

impl OdNames {
    /// Names the device's objects.
    pub fn new(device: &Device) -> Self {
        let cia402 = odc_analysis::is_cia402(device);
        // Objects: VARs get a constant, records and arrays a module; two namespaces.
        let mut consts = Namer::new();
        let mut mods = Namer::new();
        let mut var_pos = BTreeMap::new();
        let mut mod_pos = BTreeMap::new();
        for (&index, object) in &device.objects {
            if typed_subs(object, cia402).next().is_none() {
                continue;
            }
            let rank = standard::rank(index, &object.name);
            if object.kind.has_subs() {
                let base = names::snake(&object.name);
                let p = mods.propose_ranked(base, format!("obj_{index:04x}"), rank);
                mod_pos.insert(index, p);
            } else {
                let base = names::screaming(&object.name);
                let p = consts.propose_ranked(base, format!("OBJ_{index:04X}"), rank);
                var_pos.insert(index, p);
            }
        }
        let consts = consts.finish("_", &[]);
        let mods = mods.finish("_", &[]);
        let modules: BTreeMap<u16, Ident> =
            mod_pos.iter().map(|(&i, &p)| (i, ident(&mods[p]))).collect();

        let mut entries = BTreeMap::new();
        for (&index, object) in &device.objects {
            if let Some(&p) = var_pos.get(&index) {
                let Some((sub, ty)) = typed_subs(object, cia402).next() else { continue };
                let konst = ident(&consts[p]);
                entries.insert((index, sub.sub_index), EntryName { module: None, konst, ty });
            } else if let Some(module) = modules.get(&index) {
                let mut subs = Namer::new();
                let typed: Vec<_> = typed_subs(object, cia402).collect();
                for (sub, _) in &typed {
                    subs.propose(names::screaming(&sub.name), format!("SUB_{:02X}", sub.sub_index));
                }
                for ((sub, ty), name) in typed.iter().zip(subs.finish("_", &[])) {
                    let name =
                        EntryName { module: Some(module.clone()), konst: ident(&name), ty: *ty };
                    entries.insert((index, sub.sub_index), name);
                }
            }
        }
        OdNames { entries, modules, cia402 }
    }
}

fn access_tokens(a: Access, rt: &TokenStream) -> TokenStream {
    match a {
        Access::Ro => quote!(#rt::Access::Ro),
        Access::Wo => quote!(#rt::Access::Wo),
        Access::Rw => quote!(#rt::Access::Rw),
        Access::Rwr => quote!(#rt::Access::Rwr),
        Access::Rww => quote!(#rt::Access::Rww),
        Access::Const => quote!(#rt::Access::Const),
    }
}

/// The doc comment of a descriptor: name, then in one paragraph address, type, access,
/// limits, default. (The source file is named once, in the `od` module's documentation.)
fn entry_doc(index: u16, sub: &SubObject, ty: RustTy) -> String {
    let mut facts = vec![
        format!("`0x{index:04X}:{:02X}`", sub.sub_index),
        sub.data_type.name().into_owned(),
        sub.access.as_str().to_string(),
    ];
    if sub.pdo_mapping.is_mappable() {
        facts.push("PDO-mappable".to_string());
    }
    let mut facts = vec![facts.join(", ") + "."];
    let rt = quote!(::odc);
    let mut notes = Vec::new();
    let limit = |v: Option<&odc_model::Spanned<Value>>| {
        v.map(|v| (value_text(&v.value), ty.option_expr(&v.value, &rt).is_some()))
    };
    match (limit(sub.low_limit.as_deref()), limit(sub.high_limit.as_deref())) {
        (None, None) => {}
        (lo, hi) => {
            let lo_t = lo.as_ref().map(|l| l.0.clone()).unwrap_or_default();
            let hi_t = hi.as_ref().map(|h| h.0.clone()).unwrap_or_default();
            notes.push(format!("Range: `{lo_t}..={hi_t}`."));
            if lo.is_some_and(|l| !l.1) || hi.is_some_and(|h| !h.1) {
                notes.push("(A limit that is no value of the type is not checked.)".to_string());
            }
        }
    }
    // The capacity of a string is the file's: its bit size, else its default's length
    // (CiA 306 gives a string no other length); the slave dictionary stores that much.
    let from = if sub.bit_size.is_some() { "the file's bit size" } else { "its default's length" };
    match ty {
        RustTy::Text(n) | RustTy::Unicode(n) => notes.push(format!(
            "At most {n} bytes ({from}): a longer download is refused with 0x06070012."
        )),
        RustTy::Bytes(n) => notes.push(format!(
            "Exactly {n} bytes ({from}): another length is refused with 0x06070012 or \
             0x06070013."
        )),
        _ => {}
    }
    if let Some(d) = sub.initial_value() {
        let ok = ty.default_expr(&d.value, &rt).is_some();
        notes.push(format!(
            "Default: `{}`{}",
            value_text(&d.value),
            if ok { "." } else { " (not a value of the type; not used)." }
        ));
    }
    facts.extend(notes);
    format!("{}\n\n{}", sub.name, facts.join(" "))
}

fn descriptor(ctx: &Ctx<'_>, index: u16, sub: &SubObject, name: &EntryName) -> TokenStream {
    let rt = &ctx.rt;
    let ty = name.ty.tokens(rt);
    let konst = &name.konst;
    let idx = index_literal(index);
    let sidx = sub_literal(sub.sub_index);
    let pname = sub.name.as_str();
    let access = access_tokens(sub.access, rt);
    let mappable = sub.pdo_mapping.is_mappable();
    let low = sub.low_limit.as_ref().and_then(|v| name.ty.option_expr(&v.value, rt));
    let high = sub.high_limit.as_ref().and_then(|v| name.ty.option_expr(&v.value, rt));
    let default = sub.initial_value().and_then(|v| name.ty.default_builder(&v.value, rt));
    // Only what the file says: limits and a default are added to the plain descriptor when
    // there are any.
    let limits = (low.is_some() || high.is_some()).then(|| {
        let none = quote!(None);
        let (low, high) = (low.unwrap_or_else(|| none.clone()), high.unwrap_or(none));
        quote!(.with_limits(#low, #high))
    });
    let docs = doc(&entry_doc(index, sub, name.ty));
    quote! {
        #docs
        pub const #konst: #rt::Entry<#ty> =
            #rt::Entry::new(#idx, #sidx, #pname, #access, #mappable) #limits #default;
    }
}

/// The `od` module.
pub fn generate(ctx: &Ctx<'_>) -> TokenStream {
    let mut items = Vec::new();
    for (&index, object) in &ctx.device.objects {
        if let Some(module) = ctx.names.modules.get(&index) {
            let consts = typed_subs(object, ctx.names.cia402).filter_map(|(sub, _)| {
                let name = ctx.names.entries.get(&(index, sub.sub_index))?;
                Some(descriptor(ctx, index, sub, name))
            });
            let kind = format!("{:?}", object.kind).to_ascii_uppercase();
            let docs = doc(&format!("{}\n\n`0x{index:04X}`, {kind}.", object.name));
            items.push(quote! {
                #docs
                pub mod #module {
                    #(#consts)*
                }
            });
        } else if let Some((sub, name)) = typed_subs(object, ctx.names.cia402)
            .next()
            .and_then(|(sub, _)| Some((sub, ctx.names.entries.get(&(index, sub.sub_index))?)))
        {
            items.push(descriptor(ctx, index, sub, name));
        }
    }
    let name = ctx.device.name();
    let docs = doc(&format!(
        "Object descriptors of {name}: one typed `Entry` per object and sub-object.\n\n\
         Sub-objects of records and arrays are in a module named after the object."
    ));
    quote! {
        #docs
        pub mod od {
            #(#items)*
        }
    }
}
