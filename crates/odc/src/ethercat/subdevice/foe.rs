//! File access over EtherCAT (FoE, ETG.1000.6 §5.8), handed to the application's
//! [`Application`] `foe_*` methods: a master writes a file (a firmware
//! image in BOOT, as the ServoOne's manual has it) or reads one, in packets as long as the
//! mailbox allows, each acknowledged.
//!
//! The FoE header: opcode (1 read request, 2 write request, 3 data, 4 ack, 5 error, 6 busy),
//! a reserved byte, then a u32: the password of a request, the packet number of data and ack,
//! the error code of an error; then the file name of a request, the data of a packet, the
//! error text. A data packet shorter than the largest the mailbox holds is the last.

use super::Application;
use super::coe::Out;

const READ: u8 = 1;
const WRITE: u8 = 2;
const DATA: u8 = 3;
const ACK: u8 = 4;
const ERROR: u8 = 5;

/// FoE error codes (ETG.1000.6 Table 92).
pub mod error {
    /// Not defined.
    pub const NOT_DEFINED: u32 = 0x8000;
    /// Not found.
    pub const NOT_FOUND: u32 = 0x8001;
    /// Access denied.
    pub const ACCESS_DENIED: u32 = 0x8002;
    /// Illegal operation.
    pub const ILLEGAL: u32 = 0x8004;
    /// Packet number wrong.
    pub const PACKET_NUMBER: u32 = 0x8005;
}

/// A transfer under way.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub(super) enum Transfer {
    #[default]
    None,
    /// Receiving: the packet number expected next, the offset of its data.
    Writing { next: u32, offset: u32 },
    /// Sending: the packet last sent, the offset after it, whether it was the last.
    Reading { packet: u32, offset: u32, done: bool },
}

fn header(out: &mut Out<'_>, opcode: u8, value: u32) {
    out.push(&[opcode, 0]);
    out.push(&value.to_le_bytes());
}

fn fail(t: &mut Transfer, out: &mut Out<'_>, code: u32) {
    *t = Transfer::None;
    out.len = 0;
    header(out, ERROR, code);
}

/// Sends data packet `packet` from `offset`; returns the transfer after it.
fn send<D: ?Sized, A: Application<D> + ?Sized>(
    app: &mut A,
    packet: u32,
    offset: u32,
    out: &mut Out<'_>,
) -> Result<Transfer, u32> {
    header(out, DATA, packet);
    let room = out.buf.len().saturating_sub(out.len);
    let at = out.len;
    let area = out.buf.get_mut(at..).unwrap_or(&mut []);
    let n = app.foe_read(offset, area)?.min(room);
    out.len += n;
    let offset = offset.saturating_add(u32::try_from(n).unwrap_or(u32::MAX));
    Ok(Transfer::Reading { packet, offset, done: n < room })
}

/// Answers FoE request `data` into `out`; `max_in`: the most data a packet from the master
/// carries (its mailbox less the headers).
pub(super) fn handle<D: ?Sized, A: Application<D> + ?Sized>(
    t: &mut Transfer,
    data: &[u8],
    max_in: usize,
    app: &mut A,
    out: &mut Out<'_>,
) {
    let (opcode, value, rest) = match data {
        [op, _, a, b, c, d, rest @ ..] => (*op, u32::from_le_bytes([*a, *b, *c, *d]), rest),
        _ => return fail(t, out, error::ILLEGAL),
    };
    let result = match (opcode, *t) {
        (WRITE, _) => app.foe_open_write(rest, value).map(|()| {
            *t = Transfer::Writing { next: 1, offset: 0 };
            header(out, ACK, 0);
        }),
        (READ, _) => app.foe_open_read(rest, value).and_then(|()| {
            *t = send(app, 1, 0, out)?;
            Ok(())
        }),
        (DATA, Transfer::Writing { next, offset }) if value == next => {
            app.foe_write(offset, rest).and_then(|()| {
                let offset = offset.saturating_add(u32::try_from(rest.len()).unwrap_or(u32::MAX));
                *t = Transfer::Writing { next: next + 1, offset };
                if rest.len() < max_in {
                    app.foe_close(true)?;
                    *t = Transfer::None;
                }
                header(out, ACK, value);
                Ok(())
            })
        }
        (DATA, Transfer::Writing { .. }) => Err(error::PACKET_NUMBER),
        (ACK, Transfer::Reading { packet, offset, done }) if value == packet => {
            if done {
                *t = Transfer::None;
                app.foe_close(false)
            } else {
                send(app, packet + 1, offset, out).map(|next| *t = next)
            }
        }
        (ERROR, was) => {
            *t = Transfer::None;
            // The master gave up: nothing to answer, whatever the application says.
            let _ = app.foe_close(matches!(was, Transfer::Writing { .. }));
            return;
        }
        _ => Err(error::ILLEGAL),
    };
    if let Err(code) = result {
        fail(t, out, code);
    }
}
