//! The mailbox (ETG.1000.4 §5.6): a 6-byte header — length of the data after it (2 bytes),
//! address (2), channel and priority (1), type (bits 0–3) and counter (bits 4–6) (1) — then
//! the protocol's data. The device serves CoE (type 3); any other type is answered with a
//! mailbox error (type 0, service 1, detail 2 "unsupported protocol").

use odc_model::Device;

use super::coe::{CoeServer, Request};
use crate::ModelDictionary;

/// Bytes of the mailbox header.
pub const HEADER: usize = 6;
/// Mailbox type: error reply.
pub const TYPE_ERROR: u8 = 0x00;
/// Mailbox type: CoE.
pub const TYPE_COE: u8 = 0x03;

/// Mailbox error details (ETG.1000.4 Table 30).
pub mod error {
    /// Syntax of the 6-byte header is wrong.
    pub const SYNTAX: u16 = 0x0001;
    /// The protocol is not supported.
    pub const UNSUPPORTED_PROTOCOL: u16 = 0x0002;
    /// Length of the data is shorter than the protocol's header.
    pub const SIZE_TOO_SHORT: u16 = 0x0006;
    /// Length of the data is inconsistent.
    pub const INVALID_SIZE: u16 = 0x0008;
}

/// The device's side of the mailbox.
#[derive(Debug)]
pub struct Mailbox {
    coe: Option<CoeServer>,
    /// The counter of the last reply (1–7, 0 before the first).
    counter: u8,
}

impl Mailbox {
    /// The mailbox of `device`: CoE when its ESI has `Mailbox/CoE`.
    pub fn new(device: &Device) -> Self {
        let coe = device
            .ethercat
            .as_ref()
            .and_then(|e| e.mailbox.as_ref())
            .and_then(|m| m.coe.as_ref())
            .map(|coe| CoeServer::new(device, coe));
        Self { coe, counter: 0 }
    }

    /// Forgets transfers under way (leaving PRE-OP for INIT).
    pub fn reset(&mut self) {
        if let Some(coe) = &mut self.coe {
            coe.reset();
        }
        self.counter = 0;
    }

    /// The replies to the mailbox `request` (headers included), each at most `max` bytes
    /// long, in the order the master is to read them (none when it takes none).
    pub fn handle(
        &mut self,
        request: &[u8],
        max: usize,
        od: &mut ModelDictionary,
        writable: &dyn Fn(u16) -> bool,
    ) -> Vec<Vec<u8>> {
        let (len, kind) = match request.get(..HEADER) {
            Some(&[l0, l1, _, _, _, t]) => (usize::from(u16::from_le_bytes([l0, l1])), t & 0x0F),
            _ => return vec![self.error(error::SYNTAX)],
        };
        let Some(data) = request.get(HEADER..HEADER + len) else {
            return vec![self.error(error::INVALID_SIZE)];
        };
        let replies = match (kind, &mut self.coe) {
            (TYPE_COE, Some(coe)) => {
                let room = max.saturating_sub(HEADER);
                match coe.handle(Request { data, room }, od, writable) {
                    Ok(replies) => replies,
                    Err(detail) => return vec![self.error(detail)],
                }
            }
            _ => return vec![self.error(error::UNSUPPORTED_PROTOCOL)],
        };
        replies.iter().map(|r| self.frame(TYPE_COE, r)).collect()
    }

    fn frame(&mut self, kind: u8, data: &[u8]) -> Vec<u8> {
        // The counter runs 1..=7 (ETG.1000.4 §5.6: 0 is reserved for the first mailbox).
        self.counter = self.counter % 7 + 1;
        let mut out = Vec::with_capacity(HEADER + data.len());
        let len = u16::try_from(data.len()).unwrap_or(u16::MAX);
        out.extend_from_slice(&len.to_le_bytes());
        out.extend_from_slice(&[0, 0, 0, kind | self.counter << 4]);
        out.extend_from_slice(data);
        out
    }

    fn error(&mut self, detail: u16) -> Vec<u8> {
        let mut data = [0u8; 4];
        data[..2].copy_from_slice(&1u16.to_le_bytes());
        data[2..].copy_from_slice(&detail.to_le_bytes());
        self.frame(TYPE_ERROR, &data)
    }
}
