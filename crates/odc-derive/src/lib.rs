//! `#[derive(Pdo)]` and `#[derive(PdoValue)]` for the [`odc`](https://docs.rs/odc) runtime.
//!
//! Use them through `odc` (`odc::Pdo`, feature `derive`, on by default); the expansion names the
//! runtime as `::odc`, or the path given with `#[pdo(crate = "path")]`.
//!
//! # `#[derive(Pdo)]`
//!
//! Layout is LSB0 little-endian, fields in declaration order, any bit offset (CiA 301 mapping
//! rules); it is computed by `odc-layout` and checked while the macro runs.
//!
//! | key | where | meaning |
//! |---|---|---|
//! | `bits = N` / `bytes = N` | struct | total size; the fields must fit, the rest is zero padding |
//! | `max_bits = N` | struct | size limit, default 64 (classic CAN); EtherCAT code sets more |
//! | `crate = "path"` | struct | path of the runtime, default `::odc` |
//! | `index = 0x6040` | field | mapped object index (required) |
//! | `sub = N` | field | mapped sub-index, default 0 |
//! | `bits = N` / `bytes = N` | field | mapped width; inferred for `bool`, integers and floats |
//! | `pad_bits = N` / `pad_bytes = N` | field | gap before the field (CiA dummy mapping) |
//! | `offset = N` | field | absolute bit offset (ESI `BitOffs`); must not overlap the previous field |
//!
//! ```
//! use odc::Pdo;
//!
//! #[derive(Debug, PartialEq, odc::PdoValue)]
//! #[repr(i8)]
//! enum Mode {
//!     ProfilePosition = 1,
//!     CyclicSyncPosition = 8,
//!     #[pdo(other)]
//!     Other(i8),
//! }
//!
//! #[derive(Debug, PartialEq, odc::Pdo)]
//! #[pdo(bytes = 8)]
//! struct DriveRx {
//!     #[pdo(index = 0x6040)]
//!     controlword: u16,
//!     #[pdo(index = 0x6060, bits = 8)]
//!     mode: Mode,
//!     #[pdo(index = 0x607A)]
//!     target_position: i32,
//! }
//!
//! let rx = DriveRx { controlword: 0x000F, mode: Mode::CyclicSyncPosition, target_position: -1 };
//! let bytes = rx.pack()?;
//! assert_eq!(bytes, [0x0F, 0x00, 0x08, 0xFF, 0xFF, 0xFF, 0xFF, 0x00]);
//! assert_eq!(DriveRx::unpack(&bytes)?, rx);
//! # Ok::<(), Box<dyn std::error::Error>>(())
//! ```
//!
//! ```compile_fail
//! #[derive(odc::Pdo)]
//! struct TooLong {
//!     #[pdo(index = 0x6064)]
//!     position: i64,
//!     #[pdo(index = 0x6041)]
//!     statusword: u16, // bit 80 > 64: needs `#[pdo(max_bits = ...)]`
//! }
//! ```
//!
//! Errors (overlaps, size over the limit, `u8` with `bits = 9`, unknown keys, a field without
//! `index`) point at the offending key or field; a do-nothing impl is still emitted so the
//! error is not followed by a cascade.
//!
//! # `#[derive(PdoValue)]`
//!
//! For enums with `#[repr(u8 | u16 | u32 | u64 | i8 | i16 | i32 | i64)]`. One tuple variant
//! marked `#[pdo(other)]` catches every other value; without it, unknown values fail to unpack.
//! `#[pdo(bits = N)]` on the enum sets its natural width (for sub-byte enums).
// Bad input is a diagnostic, never a panic: no unwrap, expect or panic outside tests. A
// proven invariant may opt out with an `#[allow]` and a comment saying why.
#![cfg_attr(not(test), deny(clippy::unwrap_used, clippy::expect_used, clippy::panic))]

mod attr;
mod pdo;
mod value;

use proc_macro::TokenStream;

/// Implements `odc::Pdo` (pack, unpack, mapping) for a struct of mapped fields.
#[proc_macro_derive(Pdo, attributes(pdo))]
pub fn derive_pdo(input: TokenStream) -> TokenStream {
    let input = syn::parse_macro_input!(input as syn::DeriveInput);
    pdo::derive(&input).into()
}

/// Implements `odc::PdoValue` for a `#[repr(int)]` enum.
#[proc_macro_derive(PdoValue, attributes(pdo))]
pub fn derive_pdo_value(input: TokenStream) -> TokenStream {
    let input = syn::parse_macro_input!(input as syn::DeriveInput);
    value::derive(&input).into()
}
