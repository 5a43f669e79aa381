//! The SDO protocol (CiA 301 7.2.4.3): an unknown command specifier, the toggle bit, the
//! server's timeout, segmented and block transfer.

use std::fmt::Display;

use odc::transport::Bus;

use crate::session::{SdoFail, Session, le};
use crate::{Group, Outcome};

/// An abort frame's code, if `answer` is one.
fn abort_code(answer: &[u8; 8]) -> Option<u32> {
    (answer[0] == 0x80).then(|| le(&answer[4..8]) as u32)
}

/// A readable entry whose value takes a segmented transfer (more than 4 bytes), and its value;
/// the first writable one when `writable`.
fn long_entry<B: Bus>(s: &mut Session<'_, B>, writable: bool) -> Option<(u16, u8, Vec<u8>)>
where
    B::Error: Display,
{
    let candidates: Vec<(u16, u8)> = s
        .dev
        .objects
        .values()
        .flat_map(|o| o.subs.values().map(move |sub| (o.index, sub)))
        .filter(|(_, so)| so.access.readable() && so.data_type.bit_size().is_none_or(|b| b > 32))
        .filter(|(_, so)| !writable || so.access.writable())
        .map(|(i, so)| (i, so.sub_index))
        .collect();
    candidates
        .into_iter()
        .find_map(|(i, sub)| s.read(i, sub).ok().filter(|v| v.len() > 4).map(|v| (i, sub, v)))
}

fn initiate_upload(index: u16, sub: u8) -> [u8; 8] {
    let [lo, hi] = index.to_le_bytes();
    [0x40, lo, hi, sub, 0, 0, 0, 0]
}

pub(crate) fn run<B: Bus>(s: &mut Session<'_, B>)
where
    B::Error: Display,
{
    s.check(
        "sdo.unknown-command",
        Group::Sdo,
        "CiA 301 7.2.4.3.17 (0x05040001)",
        "a request with command specifier 7 is aborted with 0x05040001",
        |s| match s.raw_sdo([0xE0, 0x00, 0x10, 0, 0, 0, 0, 0]) {
            Ok(Some(a)) if abort_code(&a) == Some(0x0504_0001) => {
                Outcome::pass("aborted with 0x05040001")
            }
            Ok(Some(a)) => Outcome::fail(format!("answered {a:02X?}, not abort 0x05040001")),
            Ok(None) => Outcome::fail("no answer (CiA 301 wants abort 0x05040001)"),
            Err(e) => Outcome::fail(e),
        },
    );
    let long = long_entry(s, false);
    s.check(
        "sdo.toggle",
        Group::Sdo,
        "CiA 301 7.2.4.3.6 (0x05030000)",
        "an upload segment request with the wrong toggle bit is aborted with 0x05030000",
        |s| {
            let Some((index, sub, _)) = long else {
                return Outcome::na("no readable entry of more than 4 bytes");
            };
            match s.raw_sdo(initiate_upload(index, sub)) {
                Ok(Some(a)) if a[0] & 0xE2 == 0x40 => {}
                Ok(a) => return Outcome::fail(format!("initiate upload answered {a:02X?}")),
                Err(e) => return Outcome::fail(e),
            }
            // The first segment request must have toggle 0: send 1.
            match s.raw_sdo([0x70, 0, 0, 0, 0, 0, 0, 0]) {
                Ok(Some(a)) if abort_code(&a) == Some(0x0503_0000) => {
                    Outcome::pass("aborted with 0x05030000")
                }
                Ok(Some(a)) => {
                    // Leave no transfer open.
                    let _ = s.send(s.node.sdo_request().raw(), &abort(index, sub));
                    Outcome::fail(format!("answered {a:02X?}, not abort 0x05030000"))
                }
                Ok(None) => Outcome::fail("no answer (CiA 301 wants abort 0x05030000)"),
                Err(e) => Outcome::fail(e),
            }
        },
    );
    s.check(
        "sdo.timeout",
        Group::Sdo,
        "CiA 301 7.2.4.3.17 (0x05040000)",
        "a transfer the client leaves is ended by the server (abort 0x05040000) and the next \
         one is served",
        |s| {
            let Some((index, sub, _)) = long else {
                return Outcome::na("no readable entry of more than 4 bytes");
            };
            match s.raw_sdo(initiate_upload(index, sub)) {
                Ok(Some(a)) if a[0] & 0xE2 == 0x40 => {}
                Ok(a) => return Outcome::fail(format!("initiate upload answered {a:02X?}")),
                Err(e) => return Outcome::fail(e),
            }
            let wait = s.opt.sdo_timeout_ms;
            let response = s.node.sdo_response().raw();
            let aborted = s
                .listen(wait)
                .iter()
                .find(|(_, f)| f.is_data(response) && f.bytes().first() == Some(&0x80))
                .map(|(_, f)| le(f.bytes().get(4..8).unwrap_or(&[])) as u32);
            let next = s.read(0x1000, 0);
            match (aborted, next) {
                (Some(0x0504_0000), Ok(_)) => {
                    Outcome::pass("aborted with 0x05040000; the next transfer was served")
                }
                (Some(c), Ok(_)) => Outcome::fail(format!(
                    "aborted with 0x{c:08X}, not 0x05040000 (SDO protocol timed out)"
                )),
                (None, Ok(_)) => Outcome::pass(format!(
                    "no abort within {wait} ms (the timeout is the device's choice); the next \
                     transfer was served"
                )),
                (_, Err(e)) => Outcome::fail(format!("the next transfer after the wait: {e}")),
            }
        },
    );
    s.check(
        "sdo.segmented",
        Group::Sdo,
        "CiA 301 7.2.4.3.3-7",
        "segmented download and upload of a writable entry of more than 4 bytes",
        |s| {
            let Some((index, sub, value)) = long_entry(s, true) else {
                return Outcome::na("no writable entry holding more than 4 bytes");
            };
            if let Err(e) = s.write(index, sub, &value) {
                return Outcome::fail(format!("0x{index:04X}:{sub:02X} download: {e}"));
            }
            match s.read(index, sub) {
                Ok(v) if v == value => Outcome::pass(format!(
                    "0x{index:04X}:{sub:02X}, {} bytes, written back and read",
                    value.len()
                )),
                Ok(v) => Outcome::fail(format!("read back {v:02X?}, wrote {value:02X?}")),
                Err(e) => Outcome::fail(format!("read back: {e}")),
            }
        },
    );
    s.check(
        "sdo.block",
        Group::Sdo,
        "CiA 301 7.2.4.3.9-16",
        "block upload (and block download where writable) gives the segmented transfer's value",
        |s| {
            let Some((index, sub, value)) = long else {
                return Outcome::na("no readable entry of more than 4 bytes");
            };
            match s.master.upload_block(s.node, index, sub) {
                Err(odc::master::Error::Sdo { error: odc::sdo::SdoError::Remote(a), .. })
                    if a.to_u32() == 0x0504_0001 =>
                {
                    return Outcome::na(
                        "the device has no block transfer (aborted 0x05040001); CiA 306 has no \
                         key to declare it",
                    );
                }
                Err(e) => return Outcome::fail(format!("block upload: {e}")),
                Ok(v) if v != value => {
                    return Outcome::fail(format!("block upload {v:02X?}, segmented {value:02X?}"));
                }
                Ok(_) => {}
            }
            let Some((wi, ws, wv)) = long_entry(s, true) else {
                return Outcome::pass(format!(
                    "block upload of 0x{index:04X}:{sub:02X} ({} bytes); nothing to download",
                    value.len()
                ));
            };
            match s.master.download_block(s.node, wi, ws, &wv) {
                Err(odc::master::Error::Sdo { error: odc::sdo::SdoError::Remote(a), .. })
                    if a.to_u32() == 0x0504_0001 =>
                {
                    return Outcome::pass(format!(
                        "block upload of 0x{index:04X}:{sub:02X}; block download refused \
                         (0x05040001: the device has none, as CiA 301 allows)"
                    ));
                }
                Err(e) => {
                    return Outcome::fail(format!("block download 0x{wi:04X}:{ws:02X}: {e}"));
                }
                Ok(()) => {}
            }
            match s.read(wi, ws) {
                Ok(v) if v == wv => Outcome::pass(format!(
                    "block upload of 0x{index:04X}:{sub:02X}, block download of \
                     0x{wi:04X}:{ws:02X}"
                )),
                Ok(v) => Outcome::fail(format!("read back {v:02X?}, block-wrote {wv:02X?}")),
                Err(e) => Outcome::fail(format!("read back: {}", SdoFail::to_string(&e))),
            }
        },
    );
}

/// A client's abort of the transfer on `index:sub` (general error).
fn abort(index: u16, sub: u8) -> [u8; 8] {
    let [lo, hi] = index.to_le_bytes();
    [0x80, lo, hi, sub, 0, 0, 0, 0x08]
}
