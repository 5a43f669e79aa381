//! odc code generation: typed Rust for both sides of the bus, from one device of the odc model.
//!
//! [`generate`] is pure: a [`Device`] and [`Options`] in, formatted Rust source out; no file
//! I/O, no environment. The output holds the items of one module (include it with `include!`
//! inside a `mod`):
//!
//! - `od`: a typed `::odc::Entry<T>` descriptor per object and sub-object; sub-objects of
//!   records and arrays are grouped in a module named after the object. The controlword
//!   0x6040 and statusword 0x6041 of a CiA 402 drive are `odc::cia402::Controlword` and
//!   `Statusword` (in the PDO structs and the slave dictionary too). Names come from the
//!   file's; when two objects' names give the same identifier, the object CiA 301/402 names
//!   so, else the one in a standard area, keeps it and the others get their index
//!   (`POSITION_ACTUAL_VALUE` is 0x6064, a vendor twin `POSITION_ACTUAL_VALUE_OBJ_2064`);
//! - `pdo`: a `#[derive(::odc::Pdo)]` struct per PDO of the default mapping, with its mapping
//!   index, mapping values, COB-ID rule and transmission type (CANopen) or sync-manager
//!   placement (EtherCAT);
//! - `pdi` (EtherCAT): the process image of the default assignment as a master maps it,
//!   `Outputs` and `Inputs` (see [`image`]), with `ethercrab_wire` traits under the runtime's
//!   feature `ethercrab`;
//! - `cia402`: the modes of operation the device supports, when it declares the profile;
//! - `slave` (role slave): a heap-free object dictionary with SDO checks, as a table: one
//!   `odc::slave::Row` per typed entry naming its descriptor, the values as bytes, and the
//!   runtime's one read and one write path (no code per entry); typed `get`/`set` by
//!   descriptor for the firmware;
//! - `master` (role master): the SDO writes that configure the default PDO mapping;
//! - `startup` (EtherCAT, role master): the SDO downloads of PRE-OP (init commands, PDO
//!   mapping, assignment) and the DC modes; `configure(subdevice)` with feature `ethercrab`;
//! - one module per vendor parameter scheme of the overlay (see [`Scheme`]): the maker's
//!   parameter numbers (`lenze::code(11)`, `lenze::C00011`) mapped to typed entries;
//! - `process`, when the overlay declares PDO layouts the file cannot map (see
//!   [`ProcessData`]).
// Bad input is a diagnostic, never a panic: no unwrap, expect or panic outside tests. A
// proven invariant may opt out with an `#[allow]` and a comment saying why.
#![cfg_attr(not(test), deny(clippy::unwrap_used, clippy::expect_used, clippy::panic))]

//!
//! The output is deterministic, starts with an `@generated` line naming the input file and its
//! hash, and names the runtime by absolute paths (`::odc::…` by default). Its modules allow
//! dead code, and it has no `use` of its own, so a binary crate that includes it and uses a
//! few entries gets no warning.

mod cia402;
mod master;
mod names;
mod od;
mod pdi;
mod pdo;
mod process;
mod scheme;
mod slave;
mod standard;
mod startup;
mod storage_image;
mod types;

pub use odc_analysis::image;
pub use odc_analysis::{RustTy, SlaveEntry, is_cia402, slave_entries, supported_modes};
use odc_model::{Device, Diagnostic, RuleInfo, Severity};
use proc_macro2::TokenStream;
pub use process::{ProcessData, ProcessField};
use quote::quote;
pub use scheme::{
    Arg, Element, Overlay, Scheme, SchemeEntry, Selector, SelectorValue, scheme_entries,
};

/// Which side of the bus the code is for.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
pub enum Role {
    /// The controller: descriptors, PDO structs and the configuration plan.
    Master,
    /// The device itself: descriptors, PDO structs and the object dictionary.
    Slave,
    /// Both.
    #[default]
    Both,
}

impl Role {
    fn master(self) -> bool {
        matches!(self, Role::Master | Role::Both)
    }
    fn slave(self) -> bool {
        matches!(self, Role::Slave | Role::Both)
    }
}

/// What to generate, and the provenance line.
#[derive(Clone, Debug)]
pub struct Options {
    /// Which side of the bus.
    pub role: Role,
    /// The path of the runtime crate, `::odc` by default.
    pub runtime_path: String,
    /// The input file's name, for the `@generated` line and doc comments.
    pub source_name: String,
    /// The SHA-256 of the input file's bytes, in lower-case hex.
    pub source_sha256: String,
    /// What the overlay beside the device file adds: vendor parameter schemes (one module
    /// each) and process data the file cannot map (module `process`).
    pub overlay: Overlay,
}

impl Default for Options {
    fn default() -> Self {
        Options {
            role: Role::Both,
            runtime_path: "::odc".to_string(),
            source_name: String::new(),
            source_sha256: String::new(),
            overlay: Overlay::default(),
        }
    }
}

/// The codes [`generate`] reports.
pub static RULES: &[RuleInfo] = &[
    RuleInfo {
        code: "G601",
        name: "generated-code-invalid",
        group: "codegen",
        default: Severity::Error,
        summary: "the generated code does not parse (a bug in odc-codegen)",
        explanation: "The code generator produced tokens that are not a valid Rust file. This is \
                      a bug in odc-codegen; please report it with the device file.",
    },
    RuleInfo {
        code: "G602",
        name: "invalid-runtime-path",
        group: "codegen",
        default: Severity::Error,
        summary: "the runtime path is not a Rust path",
        explanation: "Options::runtime_path (odc-build `runtime_path`, `odc generate \
                      --runtime-path`) must be a Rust path such as `::odc` or `crate::rt`.",
    },
    RuleInfo {
        code: "G603",
        name: "pdo-entry-too-wide",
        group: "codegen",
        default: Severity::Error,
        summary: "a PDO entry is wider than 64 bits and cannot be a struct field",
        explanation: "PDO fields are integers, booleans or reals of at most 64 bits. A mapping \
                      entry longer than that (a string or domain mapped into process data) has \
                      no field type; fix the mapping in the device file.",
    },
    RuleInfo {
        code: "G604",
        name: "invalid-parameter-scheme",
        group: "codegen",
        default: Severity::Error,
        summary: "a vendor parameter scheme of the device's overlay cannot be generated",
        explanation: "A `[[scheme]]` of the `<stem>.odc.toml` beside the device file maps a \
                      vendor's parameter numbers to object indexes. Its index must be a linear \
                      expression of its declared arguments (`0x5FFF - code`), the argument \
                      ranges must keep the index within 0..=0xFFFF (and an element's sub-index \
                      within 0..=0xFF), and module, function, argument and alias names must be \
                      distinct Rust identifiers. The message says which condition failed.",
    },
    RuleInfo {
        code: "G605",
        name: "invalid-process-data",
        group: "codegen",
        default: Severity::Error,
        summary: "a process-data layout of the device's overlay cannot be generated",
        explanation: "A `[[process-data]]` of the `<stem>.odc.toml` beside the device file lays \
                      out PDO content the file cannot map. Its name and field names must be Rust \
                      identifiers, field types one of u8, u16, u32, i8, i16, i32, the fields \
                      8 to 64 bits in all, and `cob-id` a CAN-ID base up to 0x780.",
    },
];

/// Shared state of one generation run.
pub(crate) struct Ctx<'a> {
    pub device: &'a Device,
    pub rt: TokenStream,
    pub source: &'a str,
    pub names: od::OdNames,
}

/// Generates the Rust source for one device.
///
/// # Errors
///
/// The diagnostics (codes `G6xx`, see [`RULES`]) when something cannot be generated.
pub fn generate(device: &Device, opts: &Options) -> Result<String, Vec<Diagnostic>> {
    let rt: TokenStream = match syn::parse_str::<syn::Path>(&opts.runtime_path) {
        Ok(path) => quote!(#path),
        Err(e) => {
            return Err(vec![Diagnostic::error(
                "G602",
                format!("invalid runtime path `{}`: {e}", opts.runtime_path),
            )]);
        }
    };
    let ctx = Ctx { device, rt, source: &opts.source_name, names: od::OdNames::new(device) };
    let mut errors = Vec::new();
    let od = od::generate(&ctx);
    let pdo = pdo::generate(&ctx, &mut errors);
    let cia402 = cia402::generate(&ctx);
    let pdi = pdi::generate(&ctx);
    let startup = if opts.role.master() { startup::generate(&ctx) } else { TokenStream::new() };
    let slave = if opts.role.slave() { slave::generate(&ctx) } else { TokenStream::new() };
    let master = if opts.role.master() { master::generate(&ctx) } else { TokenStream::new() };
    let schemes = scheme::generate(&ctx, &opts.overlay.scheme, &mut errors);
    let process = process::generate(&ctx, &opts.overlay.process_data, &mut errors);
    if !errors.is_empty() {
        return Err(errors);
    }
    let tokens = quote! { #od #pdo #pdi #cia402 #slave #master #startup #schemes #process };
    let mut file: syn::File = syn::parse2(tokens).map_err(|e| {
        vec![Diagnostic::error("G601", format!("generated code does not parse: {e}"))]
    })?;
    allow_unused(&mut file);
    let body = prettyplease::unparse(&file);
    Ok(format!("{}\n{body}", header(opts)))
}

/// Marks every top-level item `#[allow(dead_code)]`.
///
/// The code describes the whole device, and a program uses a few of its entries: in a binary
/// crate (where an unused `pub` item is dead code) every other descriptor, PDO struct and
/// table would be a warning the user did not write. The allowance stays on the generated
/// modules, so the user's own items keep the lint. The generated code has no `use` that could
/// go unused; the `include!` that places it cannot carry an inner `#![allow]`.
fn allow_unused(file: &mut syn::File) {
    let allow: syn::Attribute = syn::parse_quote!(#[allow(dead_code)]);
    for item in &mut file.items {
        let attrs = match item {
            syn::Item::Mod(m) => &mut m.attrs,
            syn::Item::Const(c) => &mut c.attrs,
            syn::Item::Static(s) => &mut s.attrs,
            syn::Item::Fn(f) => &mut f.attrs,
            syn::Item::Struct(s) => &mut s.attrs,
            syn::Item::Enum(e) => &mut e.attrs,
            syn::Item::Type(t) => &mut t.attrs,
            _ => continue,
        };
        attrs.push(allow.clone());
    }
}

/// The first line: `// @generated by odc <version> from <file> (sha256 <hex>)`.
pub fn header(opts: &Options) -> String {
    let name = if opts.source_name.is_empty() { "<unnamed>" } else { &opts.source_name };
    let hash = if opts.source_sha256.is_empty() { "unknown" } else { &opts.source_sha256 };
    format!(
        "// @generated by odc {} from {name} (sha256 {hash}). Do not edit.",
        env!("CARGO_PKG_VERSION")
    )
}

/// A doc attribute for each line of `text`, with [`escape_brackets`].
pub(crate) fn doc(text: &str) -> TokenStream {
    let lines = text.lines().map(|l| if l.is_empty() { String::new() } else { format!(" {l}") });
    let lines = lines.map(|l| escape_brackets(&l));
    quote!(#(#[doc = #lines])*)
}

/// Square brackets from device files and overlays (`Save device data [0]`, `element [e]`)
/// escaped, so rustdoc does not take them for links it cannot resolve (a warning in the
/// user's `cargo doc`). The generator's own links are left as they are: they name code,
/// `` [`Item`] `` or `` [`Item`](path) ``.
pub(crate) fn escape_brackets(line: &str) -> String {
    let mut out = String::with_capacity(line.len());
    let mut in_code = false;
    let mut prev = None;
    let mut chars = line.chars().peekable();
    while let Some(c) = chars.next() {
        match c {
            '`' => in_code = !in_code,
            // Inside a code span a backslash would show.
            '[' | ']' if in_code => {}
            // `[`Item`]`: opened before a code span, closed right after one.
            '[' if chars.peek() == Some(&'`') => {}
            ']' if prev == Some('`') => {}
            '[' | ']' => out.push('\\'),
            _ => {}
        }
        out.push(c);
        prev = Some(c);
    }
    out
}

#[cfg(test)]
mod tests {
    use super::escape_brackets;

    #[test]
    fn brackets_from_files_are_escaped_links_and_code_kept() {
        assert_eq!(escape_brackets(" Save device data [0]"), " Save device data \\[0\\]");
        assert_eq!(escape_brackets("element [e] at e + 1"), "element \\[e\\] at e + 1");
        assert_eq!(escape_brackets("Run [`plan`] first"), "Run [`plan`] first");
        assert_eq!(
            escape_brackets("[`Rpdo1`](super::pdo::Rpdo1)'s mapping"),
            "[`Rpdo1`](super::pdo::Rpdo1)'s mapping"
        );
        assert_eq!(escape_brackets("under `[rules]` in odc.toml"), "under `[rules]` in odc.toml");
        assert_eq!(escape_brackets("a ] and a ["), "a \\] and a \\[");
    }
}
