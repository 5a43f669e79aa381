//! SDO: the frame codec, a server and a client ([`SdoAbort`], the abort codes, lives in the
//! crate root with the rest of the vocabulary).
//!
//! Everything works on [`CanFrame`](crate::can::CanFrame)s as plain data and on the
//! caller's clock ([`Instant`](crate::time::Instant)s it passes in), so the same code runs in firmware (an interrupt
//! handler feeding [`Server::handle`]) and on a PC master (a [`Bus`] with the blocking
//! [`Client`] calls). Expedited, segmented and block transfers in both directions; block
//! transfers check the CRC of CiA 301 and repeat lost segments from the acknowledged one
//! ([`block`] has the frames).

pub mod block;
mod client;
pub mod frame;
#[cfg(test)]
mod protocol_tests;
mod server;

pub use crate::transport::Bus;
pub use client::{Client, SdoError, Step};
pub use server::{DEFAULT_TIMEOUT, Server};

pub use crate::SdoAbort;
