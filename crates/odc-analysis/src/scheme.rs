//! Vendor parameter schemes: how a maker numbers its own parameters, as data.
//!
//! Drive makers address their parameters by their own numbers and map them onto object
//! indexes by a rule: LXM23A keypad parameter `P1-44` is object `0x212C` (`0x2000 + 0x100·a +
//! bc`, the decimal `bc` taken as a binary number), ServoOne parameter `P 455` is `0x21C7`
//! (`0x2000 + n`), Lenze code `C00011` is `0x5FF4` (`0x5FFF − n`), a LinMot UPID `0x1CA4` is
//! `0x3CA4` with the sub-index choosing RAM, ROM, min, max or default. A device declares its
//! rule in the overlay beside its file (`<stem>.odc.toml`, the file that also holds its quirk
//! allowances), and the generator turns it into a module (a data sheet lists its entries); no per-vendor code
//! exists anywhere:
//!
//! ```toml
//! [[scheme]]
//! module = "lenze"                        # the generated module
//! function = "code"                       # lenze::code(11) -> Some(0x5FF4:00)
//! doc = "Lenze code Cnnnnn at 0x5FFF - nnnnn, subcode = sub-index (manual p. 65)."
//! index = "0x5FFF - code"                 # linear: constants, arguments, constant * argument
//! args = [{ name = "code", range = "0..=16383" }]
//! const-name = "C{code:05}"               # a typed alias per object the file defines
//! # Optional: the sub-index of an ARRAY/RECORD object's elements, sub = element + offset:
//! element = { name = "subcode", range = "1..=255", offset = 0, function = "code_sub", const-name = "C{code:05}_{subcode}" }
//! # Or instead: sub-indexes with a meaning of their own, as an enum argument:
//! # selector = { type = "Sub", values = [{ name = "ram", sub = 1, doc = "RAM value" }] }
//! # Optional: the device takes every write at this width (bytes), whatever the type:
//! # write-size = 4
//! ```
//!
//! For each scheme the module holds:
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
//! The generator checks a scheme before using it: expressions parse and name only declared
//! arguments, every argument range keeps the index within `0..=0xFFFF` and the element's
//! sub-index within `0..=0xFF`, names are Rust identifiers and unique (`G604`).

use std::collections::{BTreeMap, BTreeSet};

use odc_model::Device;
use serde::Deserialize;

use crate::names::is_ident;
use crate::slave::typed_subs;

mod check;
mod expr;

pub use check::{Alias, Checked, RESERVED_ITEMS, RESERVED_MODULES, aliases, check};
pub use expr::{Linear, Placeholder, number, parse_range, render};

/// An entry of the device a scheme reaches, under the name the generated code gives it
/// (`C00011` for the Lenze code 11): for a data sheet or a listing of the scheme.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct SchemeEntry {
    /// The alias (the scheme's `const-name` pattern, filled in).
    pub name: String,
    /// Object index.
    pub index: u16,
    /// Sub-index.
    pub sub: u8,
    /// The object's name, and the sub-object's for an element.
    pub what: String,
}

/// The entries of `device` that `scheme` reaches, as the generated module names them; none
/// when the scheme has no `const-name`.
///
/// # Errors
///
/// What is wrong with the scheme (the same text as its `G604` diagnostic).
pub fn scheme_entries(device: &Device, scheme: &Scheme) -> Result<Vec<SchemeEntry>, String> {
    let checked = check(scheme)?;
    let aliases = aliases(device, &checked)?;
    Ok(aliases
        .into_iter()
        .map(|a| SchemeEntry { name: a.name, index: a.index, sub: a.sub, what: a.what })
        .collect())
}

/// One vendor numbering rule (see the module documentation for the TOML form).
#[derive(Clone, Debug, PartialEq, Eq, Deserialize)]
#[serde(rename_all = "kebab-case", deny_unknown_fields)]
pub struct Scheme {
    /// The generated module's name (snake case).
    pub module: String,
    /// The name of the function that maps a parameter number to its object.
    pub function: String,
    /// What the scheme is, for the module's documentation (say where the manual states it).
    #[serde(default)]
    pub doc: String,
    /// The object index as a linear expression of the arguments.
    pub index: String,
    /// The arguments of the index, in the order the functions take them.
    pub args: Vec<Arg>,
    /// The name pattern of the typed aliases of objects (`C{code:05}`); none when absent.
    #[serde(default)]
    pub const_name: Option<String>,
    /// The numbering of the elements (sub-indexes) of ARRAY and RECORD objects.
    #[serde(default)]
    pub element: Option<Element>,
    /// Sub-indexes that choose an operation on the parameter rather than an element.
    #[serde(default)]
    pub selector: Option<Selector>,
    /// Indexes the rule reaches that hold other objects (`"0x4F01..=0x4F08"` or `"0x2000"`):
    /// the functions answer `None` for them and no alias is made.
    #[serde(default)]
    pub exclude: Vec<String>,
    /// The width in bytes (1..=4) at which the device takes every write of these parameters,
    /// whatever their type (LinMot: command 23h, 4 bytes, "size depends on the UPID"):
    /// generated as `WRITE_SIZE`, for the SDO client's `write_widened`.
    #[serde(default)]
    pub write_size: Option<u8>,
}

/// An argument of a scheme and the values it may take.
#[derive(Clone, Debug, PartialEq, Eq, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Arg {
    /// Its name (snake case), as the expressions and name patterns use it.
    pub name: String,
    /// `LOW..=HIGH`, non-negative.
    pub range: String,
}

/// Elements of ARRAY/RECORD parameters: `sub = element + offset`.
#[derive(Clone, Debug, PartialEq, Eq, Deserialize)]
#[serde(rename_all = "kebab-case", deny_unknown_fields)]
pub struct Element {
    /// The element argument's name.
    pub name: String,
    /// `LOW..=HIGH` of the element number.
    pub range: String,
    /// Added to the element number to give the sub-index.
    #[serde(default)]
    pub offset: i64,
    /// The function's name; `<function>_<name>` when absent.
    #[serde(default)]
    pub function: Option<String>,
    /// The name pattern of element aliases; the object pattern plus `_{<name>}` when absent.
    #[serde(default)]
    pub const_name: Option<String>,
}

/// Sub-indexes with a meaning (LinMot: 1 RAM value, 2 ROM value, …), as a generated enum.
#[derive(Clone, Debug, PartialEq, Eq, Deserialize)]
#[serde(rename_all = "kebab-case", deny_unknown_fields)]
pub struct Selector {
    /// The enum's name (camel case).
    #[serde(rename = "type")]
    pub type_name: String,
    /// The name of the function argument; `sel` when absent.
    #[serde(default)]
    pub arg: Option<String>,
    /// The values.
    pub values: Vec<SelectorValue>,
}

/// One value of a [`Selector`].
#[derive(Clone, Debug, PartialEq, Eq, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SelectorValue {
    /// Its name (snake case); the variant is its camel case, aliases use its upper case.
    pub name: String,
    /// The sub-index it selects.
    pub sub: u8,
    /// What it is.
    #[serde(default)]
    pub doc: String,
}

#[cfg(test)]
mod tests {
    #![allow(clippy::unwrap_used)]
    use super::*;

    fn vals(pairs: &[(&'static str, i64)]) -> BTreeMap<&'static str, i64> {
        pairs.iter().copied().collect()
    }

    #[test]
    fn linear_expressions() {
        let e = Linear::parse("0x2000 + 0x100 * group + number").unwrap();
        assert_eq!(e.eval(&vals(&[("group", 1), ("number", 44)])), 0x212C);
        let e = Linear::parse("0x5FFF - code").unwrap();
        assert_eq!(e.eval(&vals(&[("code", 11)])), 0x5FF4);
        assert_eq!(e.eval(&vals(&[("code", 13382)])), 0x2BB9);
        let e = Linear::parse(" - 2 * a + 7 * 3 ").unwrap();
        assert_eq!(e.eval(&vals(&[("a", 4)])), 13);
        assert!(Linear::parse("a * b").is_err());
        assert!(Linear::parse("0x20 + ").is_err());
        assert!(Linear::parse("2 / a").is_err());
        assert!(Linear::parse("").is_err());
    }

    #[test]
    fn name_patterns() {
        let mut v = BTreeMap::new();
        v.insert("code", Placeholder::Number(11));
        v.insert("upid", Placeholder::Number(0x1CA4));
        v.insert("sel", Placeholder::Text("RAM".into()));
        assert_eq!(render("C{code:05}", &v).unwrap(), "C00011");
        assert_eq!(render("U{upid:04X}_{sel}", &v).unwrap(), "U1CA4_RAM");
        assert_eq!(render("P{code}", &v).unwrap(), "P11");
        assert!(render("C{nope}", &v).is_err());
        assert!(render("C{code:5q}", &v).is_err());
        assert!(render("C{code", &v).is_err());
    }

    fn scheme(index: &str, range: &str) -> Scheme {
        Scheme {
            module: "vendor".into(),
            function: "param".into(),
            doc: String::new(),
            index: index.into(),
            args: vec![Arg { name: "n".into(), range: range.into() }],
            const_name: None,
            element: None,
            selector: None,
            exclude: Vec::new(),
            write_size: None,
        }
    }

    #[test]
    fn checks_refuse_bad_schemes() {
        assert!(check(&scheme("0x2000 + n", "0..=0x3FFF")).is_ok());
        let widths = |n| {
            let s = Scheme { write_size: Some(n), ..scheme("0x2000 + n", "0..=9") };
            check(&s).err()
        };
        assert_eq!(widths(4), None);
        assert!(widths(0).unwrap().contains("write-size"));
        assert!(widths(5).unwrap().contains("write-size"));
        let e = check(&scheme("0x2000 + n", "0..=0xFFFF")).err().unwrap();
        assert!(e.contains("beyond 0..=0xFFFF"), "{e}");
        assert!(check(&scheme("0x2000 + m", "0..=5")).err().unwrap().contains("no argument"));
        assert!(check(&scheme("0x2000 + n", "5..=1")).err().unwrap().contains("empty"));
        let mut s = scheme("0x2000 + n", "0..=5");
        s.module = "od".into();
        assert!(check(&s).is_err());
        let mut s = scheme("0x2000 + n", "0..=5");
        s.element = Some(Element {
            name: "e".into(),
            range: "0..=255".into(),
            offset: 1,
            function: None,
            const_name: None,
        });
        assert!(check(&s).err().unwrap().contains("sub-index range"));
    }
}
