//! The odc intermediate model: one object dictionary for CANopen (EDS/DCF) and EtherCAT (ESI)
//! devices, the spans that tie it to its source file, and the diagnostic type every stage uses.
//!
//! The model is plain owned data: front-ends (`odc-eds`, `odc-esi`) build it, the checker
//! (`odc-check`) reads it, back-ends (`odc-codegen`, the EDS writer) render it. Collections are
//! ordered (`BTreeMap` by index), so dumps and generated code are deterministic.
//!
//! Policies fixed here:
//! - a VAR is an object with one sub-object at sub-index 0 (one shape for every kind);
//! - `$NODEID` stays symbolic ([`Value::NodeIdPlus`]);
//! - `rwr` and `rww` stay distinct ([`Access`]); PDO direction follows from them ([`PdoMapping::allows`]);
//! - spans compare equal ([`Span`]), so round trips compare content with `==`.
// Bad input is a diagnostic, never a panic: no unwrap, expect or panic outside tests. A
// proven invariant may opt out with an `#[allow]` and a comment saying why.
#![cfg_attr(not(test), deny(clippy::unwrap_used, clippy::expect_used, clippy::panic))]

mod device;
pub mod diag;
pub mod ethercat;
mod hex;
pub mod pdo;
mod registry;
mod span;
pub mod subs;
pub mod trim;
mod types;
mod value;
pub mod wire;

pub use device::{
    Commissioning, Device, DeviceInfo, FileInfo, Format, Module, Modules, Object, ObjectList,
    ObjectLists, Origin, RawEntry, RawSection, SubExtend, SubObject, SubRare, ValueName, XmlExtra,
};
pub use diag::{Capped, Diagnostic, Label, RuleInfo, Severity, Sources};
pub use pdo::{Pdo, PdoEntry};
pub use registry::Registry;
pub use span::{FileId, Span, Spanned};
pub use subs::SubObjects;
pub use types::{Access, DataType, Direction, ObjectKind, PdoMapping, ValueClass};
pub use value::Value;

/// The name of a sub-object: a string stored inline up to 24 bytes (`compact_str`), so that
/// the thousands of sub-objects a DCF implies through `CompactSubObj` (`<object name><n>`)
/// mostly cost no allocation. It derefs to `str`; `Debug` and `Serialize` are those of a
/// `String`.
pub type Name = compact_str::CompactString;
