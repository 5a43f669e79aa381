//! What changed between two device descriptions (`odc diff`), object by object, whatever
//! formats they were read from: both sides are [`Device`](odc_model::Device)s of the one model, so an EDS
//! compares with its DCF, its XDD or an ESI revision as readily as with another EDS.
//!
//! The comparison is by meaning, not by text: objects by index, sub-objects by sub-index,
//! PDOs by mapping index, sync managers by number; values by what they are (`0x0A` and `10`
//! are the same default). Spans, file order and spelling are not compared.
#![cfg_attr(not(test), deny(clippy::unwrap_used, clippy::expect_used, clippy::panic))]

mod compare;
mod render;

use serde::Serialize;

pub use compare::diff;
pub use render::{human, json};

/// What to leave out of the comparison.
#[derive(Clone, Copy, Debug, Default)]
pub struct Options {
    /// Names of objects, sub-objects and PDOs.
    pub ignore_names: bool,
    /// Comments, descriptions, denotations and the file's own information (creator, dates).
    pub ignore_comments: bool,
    /// Default values and configured values (DCF `ParameterValue`, XDC `actualValue`).
    pub ignore_defaults: bool,
}

/// Where a change is.
#[derive(Clone, Debug, PartialEq, Eq, Serialize)]
#[serde(tag = "in", rename_all = "snake_case")]
pub enum Place {
    /// Identity: vendor, product, revision, format.
    Identity,
    /// The file's own information (version, creator, dates, description).
    File,
    /// Capabilities: bit rates, PDO counts, LSS, sync managers, FMMUs, mailbox, DC.
    Capabilities,
    /// An object as a whole.
    Object {
        /// Its index.
        index: u16,
    },
    /// A sub-object.
    Sub {
        /// The object's index.
        index: u16,
        /// The sub-index.
        sub: u8,
    },
    /// A default PDO, by its mapping object.
    Pdo {
        /// The mapping object's index.
        mapping_index: u16,
    },
    /// One direction of the default EtherCAT process image.
    Image {
        /// `outputs` or `inputs`.
        direction: &'static str,
    },
    /// The `[Comments]` of the file.
    Comments,
}

/// One difference.
#[derive(Clone, Debug, PartialEq, Eq, Serialize)]
pub struct Change {
    /// Where.
    #[serde(flatten)]
    pub place: Place,
    /// What.
    #[serde(flatten)]
    pub what: What,
    /// On which side the object is odc's rather than the file's (`"a"`, `"b"`, `"a, b"`): an
    /// ESI's object odc synthesised from its sync managers and PDOs, or the file's object
    /// whose defaults odc took from its PDO elements. Such a change is no edit of the file's
    /// dictionary, but what odc derives from its other elements. `None` for the file's own.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub odc: Option<&'static str>,
}

/// What kind of difference.
#[derive(Clone, Debug, PartialEq, Eq, Serialize)]
#[serde(tag = "change", rename_all = "snake_case")]
pub enum What {
    /// Only in the second file; `text` says what it is.
    Added {
        /// What it is.
        text: String,
    },
    /// Only in the first file.
    Removed {
        /// What it was.
        text: String,
    },
    /// In both, with another value.
    Changed {
        /// The property (`name`, `access`, `default`, …).
        field: String,
        /// In the first file (empty: absent).
        a: String,
        /// In the second file (empty: absent).
        b: String,
    },
}

/// The object names of a change, for the human output's group headings: the name in the
/// second file, else in the first.
pub(crate) fn object_name<'d>(
    a: &'d odc_model::Device,
    b: &'d odc_model::Device,
    index: u16,
) -> &'d str {
    b.objects.get(&index).or_else(|| a.objects.get(&index)).map_or("", |o| o.name.as_str())
}
