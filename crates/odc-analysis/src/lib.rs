//! odc analysis: the facts derived from one device of the odc model that several back-ends
//! need, computed once, here.
//!
//! - [`image`]: the process image of an EtherCAT device as a master lays it out;
//! - [`cia402`]: whether a device is a CiA 402 drive (the one rule the generator, the checker,
//!   the data sheet and the simulator share), its axes, and the modes it supports;
//! - [`RustTy`]: which Rust value type holds a sub-object; [`typed_subs`] and
//!   [`slave_entries`]: the typed entries the generated `od` describes and a `slave`
//!   dictionary serves;
//! - [`scheme`]: vendor parameter numbering schemes, checked and resolved to the entries they
//!   reach;
//! - [`names`]: how a name of the file becomes a Rust identifier;
//! - [`value_text`]: a value as text, in the one canonical (CiA 306) spelling.
//!
//! The crate depends on the model and the bit-layout engine only: a data sheet, a diff or a
//! simulator asks it, not the code generator, so none of them compiles `syn` or `quote`.
// Bad input is an error, never a panic: no unwrap, expect or panic outside tests.
#![cfg_attr(not(test), deny(clippy::unwrap_used, clippy::expect_used, clippy::panic))]

pub mod cia402;
pub mod image;
pub mod names;
pub mod scheme;
mod slave;
mod types;
mod value;

pub use cia402::{is_cia402, supported_modes};
pub use scheme::{Scheme, SchemeEntry, scheme_entries};
pub use slave::{SlaveEntry, slave_entries, typed_subs};
pub use types::RustTy;
pub use value::value_text;
