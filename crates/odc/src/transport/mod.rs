//! Transports: how [`CanFrame`](crate::can::CanFrame)s reach a bus.
//!
//! MERGE: stub of helper C's branch; helper A's `transport/mod.rs` (the `Bus` trait moved here,
//! the in-memory, embedded-can and SocketCAN adapters) replaces it and keeps the `tcp` line.

#[cfg(feature = "std")]
pub mod tcp;

pub use crate::sdo::Bus;
