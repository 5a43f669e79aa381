//! Vendor parameter schemes as generated modules.
//!
//! What a scheme is, its TOML form and its checks are [`odc_analysis::scheme`]'s; this module
//! reads the overlay file that declares schemes and renders each checked scheme as a module:
//! - `index(args) -> Option<u16>`: the rule itself, `None` outside the declared ranges;
//! - `<function>(args) -> Option<ObjectAddr>`: the object (sub-index 0), or with a selector
//!   `<function>(args, sel)` at the selected sub-index;
//! - with an element, `<element function>(args, element) -> Option<ObjectAddr>`;
//! - one typed `Entry<T>` alias per object (and element or selected sub-object) of the device
//!   file that the rule reaches, named by `const-name`, so `sdo.write(lenze::C00088, 102)` is
//!   type-checked against the file's data type;
//! - `ENTRIES` and `lookup(addr)`: the file's description (data type, access, name) of an
//!   address computed at run time;
//! - with `write-size`, `WRITE_SIZE`: the width to give `Client::write_widened`.
//!
//! A scheme that fails its check is reported (`G604`) and generates nothing.

use odc_analysis::scheme::{Alias, Checked, aliases, check};
pub use odc_analysis::scheme::{
    Arg, Element, Scheme, SchemeEntry, Selector, SelectorValue, scheme_entries,
};
use odc_model::Diagnostic;
use proc_macro2::{Ident, Literal, TokenStream};
use quote::quote;
use serde::Deserialize;

use crate::types::{RustTyTokens, int_literal};
use crate::{Ctx, doc};

mod expr;
mod render;

pub(crate) use render::generate;

/// The part of a device's overlay file (`<stem>.odc.toml`) that code generation reads; the
/// checker's keys (`strict`, `[rules]`, `[allow-object]`) in the same file are ignored here.
#[derive(Clone, Debug, Default, PartialEq, Eq, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub struct Overlay {
    /// The vendor parameter schemes, one generated module each.
    #[serde(default)]
    pub scheme: Vec<Scheme>,
    /// PDO layouts the device file cannot map (`[[process-data]]`, see
    /// [`ProcessData`](crate::ProcessData)), in a generated module `process`.
    #[serde(default)]
    pub process_data: Vec<crate::ProcessData>,
}

impl Overlay {
    /// Reads an overlay from TOML text.
    ///
    /// # Errors
    ///
    /// The TOML error, with its position, when the text is not TOML or a `[[scheme]]` table
    /// has an unknown key or a value of the wrong type.
    pub fn from_toml(text: &str) -> Result<Overlay, toml::de::Error> {
        toml::from_str(text)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn overlay_reads_schemes_and_ignores_check_keys() {
        let text = r#"
            strict = false
            [allow-object]
            D504 = ["0x6502"]
            [[scheme]]
            module = "lenze"
            function = "code"
            index = "0x5FFF - code"
            args = [{ name = "code", range = "0..=16383" }]
            element = { name = "subcode", range = "1..=255" }
        "#;
        let o = Overlay::from_toml(text).unwrap();
        assert_eq!(o.scheme.len(), 1);
        assert_eq!(o.scheme[0].element.as_ref().map(|e| e.offset), Some(0));
        let typo =
            "[[scheme]]\nmodule = \"a\"\nfunction = \"b\"\nindex = \"1\"\nargs = []\nconst = 1\n";
        assert!(Overlay::from_toml(typo).is_err());
    }
}
