//! Vector's Binary Logging Format, read after python-can's `can/io/blf.py` (itself after Toby
//! Lorenz's vector_blf library; Vector publishes no specification). No maintained Rust crate
//! reads BLF, and the part a CAN log needs is small:
//!
//! - a file header (`LOGG`, its size at byte 4, the start time as a Windows SYSTEMTIME at
//!   byte 40), then objects;
//! - each object: `LOBJ`, header size (u16), header version (u16), object size (u32), type
//!   (u32), padded to 4 bytes; type 10 is a container whose data (zlib when its method is 2)
//!   holds the inner objects, which may run on into the next container;
//! - an inner object's header v1 (flags u32, client u16, version u16, time u64) or v2 (flags
//!   u32, status u8, pad, version u16, time u64, original time u64); flags 1: the time counts
//!   10 µs, else 1 ns;
//! - CAN_MESSAGE (1) and CAN_MESSAGE2 (86): channel u16, flags u8 (0x80 remote), DLC u8, ID
//!   u32 (bit 31 extended), 8 data bytes; CAN_FD_MESSAGE (100): the same to the ID, then
//!   frame length u32, bit count u8, FD flags u8 at 13 (1 EDL, 2 BRS, 4 ESI), valid bytes u8,
//!   5 bytes, 64 data bytes at 20; CAN_FD_MESSAGE_64 (101): channel u8, DLC u8, valid
//!   bytes u8, …, ID u32 at 4, flags u32 at 12 (0x1000 EDL, 0x2000 BRS, 0x4000 ESI, 0x10
//!   remote), data after 40 bytes.
//!
//! Integers are little-endian. Other object types (error frames, markers, events) are skipped.

use std::io::Read;

use super::{Entry, Frame, Location, Log, Problem, classic, fd, fd_len};

const LOG_CONTAINER: u32 = 10;
const CAN_MESSAGE: u32 = 1;
const CAN_MESSAGE2: u32 = 86;
const CAN_FD_MESSAGE: u32 = 100;
const CAN_FD_MESSAGE_64: u32 = 101;
const CAN_MSG_EXT: u32 = 0x8000_0000;

fn u16_at(b: &[u8], at: usize) -> Option<u16> {
    Some(u16::from_le_bytes(b.get(at..at + 2)?.try_into().ok()?))
}

fn u32_at(b: &[u8], at: usize) -> Option<u32> {
    Some(u32::from_le_bytes(b.get(at..at + 4)?.try_into().ok()?))
}

fn u64_at(b: &[u8], at: usize) -> Option<u64> {
    Some(u64::from_le_bytes(b.get(at..at + 8)?.try_into().ok()?))
}

/// Reads a BLF file into `log`.
pub fn read(bytes: &[u8], log: &mut Log) {
    let problem = |at, message: &str| Problem { at: Location::Offset(at), message: message.into() };
    let Some(header_size) = u32_at(bytes, 4).filter(|_| bytes.starts_with(b"LOGG")) else {
        log.problems.push(problem(0, "no BLF file header (`LOGG`)"));
        return;
    };
    let header_size = usize::try_from(header_size).unwrap_or(usize::MAX);
    if header_size < 56 || header_size > bytes.len() {
        log.problems.push(problem(0, "the BLF file header is cut short"));
        return;
    }
    let start = start_time(bytes);
    let mut pos = header_size;
    // The inner objects' stream, carried from one container to the next.
    let mut inner = Vec::new();
    while pos < bytes.len() {
        let (Some(b"LOBJ"), Some(size), Some(kind)) =
            (bytes.get(pos..pos + 4), u32_at(bytes, pos + 8), u32_at(bytes, pos + 12))
        else {
            log.problems.push(problem(pos, "no BLF object (`LOBJ`) here"));
            return;
        };
        let size = usize::try_from(size).unwrap_or(usize::MAX);
        let Some(body) = bytes.get(pos + 16..pos.saturating_add(size)).filter(|_| size >= 16)
        else {
            log.problems.push(problem(pos, "a BLF object runs past the end of the file"));
            return;
        };
        if kind == LOG_CONTAINER {
            match container(body) {
                Ok(data) => {
                    inner.extend_from_slice(&data);
                    let used = objects(&inner, start, log);
                    inner.drain(..used);
                }
                Err(message) => log.problems.push(problem(pos, &message)),
            }
        }
        pos = pos.saturating_add(size + size % 4);
    }
    if !inner.is_empty() {
        log.problems.push(problem(bytes.len(), "the last object of the log is cut short"));
    }
}

/// The start of the recording in seconds since 1970: the file header's SYSTEMTIME (year,
/// month, weekday, day, hour, minute, second, millisecond), 0 when there is none.
fn start_time(bytes: &[u8]) -> f64 {
    let field = |i: usize| u16_at(bytes, 40 + 2 * i).map_or(0, i64::from);
    let (year, month, day) = (field(0), field(1), field(3));
    if year < 1970 || !(1..=12).contains(&month) || !(1..=31).contains(&day) {
        return 0.0;
    }
    // Days since 1970-01-01 of a proleptic Gregorian date (H. Hinnant's days_from_civil).
    let y = if month <= 2 { year - 1 } else { year };
    let era = y.div_euclid(400);
    let yoe = y - era * 400;
    let mp = (month + 9) % 12;
    let doy = (153 * mp + 2) / 5 + day - 1;
    let doe = yoe * 365 + yoe / 4 - yoe / 100 + doy;
    let days = era * 146_097 + doe - 719_468;
    let seconds = days * 86_400 + field(4) * 3600 + field(5) * 60 + field(6);
    seconds as f64 + field(7) as f64 / 1000.0
}

/// A container's data: method (u16), 6 bytes, uncompressed size (u32), 4 bytes, then the
/// data, raw (method 0) or zlib (method 2).
fn container(body: &[u8]) -> Result<Vec<u8>, String> {
    let method = u16_at(body, 0).ok_or("a BLF container cut short")?;
    let data = body.get(16..).ok_or("a BLF container cut short")?;
    match method {
        0 => Ok(data.to_vec()),
        2 => {
            let mut out = Vec::new();
            flate2::read::ZlibDecoder::new(data)
                .read_to_end(&mut out)
                .map_err(|e| format!("a BLF container's zlib data: {e}"))?;
            Ok(out)
        }
        m => Err(format!("a BLF container compressed with method {m} (0 and 2 are known)")),
    }
}

/// Reads the whole objects at the start of `data` into `log`; how many bytes they took.
fn objects(data: &[u8], start: f64, log: &mut Log) -> usize {
    let mut pos = 0;
    loop {
        // Padding follows an object (python-can's writer adds its size modulo 4 bytes):
        // the next one starts within 8 bytes, as python-can's reader looks for it.
        if data.len() < pos + 16 {
            return pos;
        }
        match data.get(pos..pos + 12).and_then(|w| w.windows(4).position(|s| s == b"LOBJ")) {
            Some(skip) => pos += skip,
            None => {
                log.problems.push(Problem {
                    at: Location::Offset(pos),
                    message: "no BLF object (`LOBJ`) in a container: the rest of it skipped".into(),
                });
                return data.len();
            }
        }
        let Some(size) = u32_at(data, pos + 8) else { return pos };
        let size = usize::try_from(size).unwrap_or(usize::MAX);
        let Some(object) = data.get(pos..pos.saturating_add(size)) else { return pos };
        if size < 16 {
            log.problems.push(Problem {
                at: Location::Offset(pos),
                message: format!("a BLF object of {size} bytes: the rest of the container skipped"),
            });
            return data.len();
        }
        if let Some(result) = object_frame(object, start) {
            match result {
                Ok(entry) => log.entries.push(entry),
                Err(message) => log.problems.push(Problem { at: Location::Offset(pos), message }),
            }
        }
        pos += size;
    }
}

/// The frame of one inner object, `None` for an object that is no frame.
fn object_frame(object: &[u8], start: f64) -> Option<Result<Entry, String>> {
    let header_size = usize::from(u16_at(object, 4)?);
    let version = u16_at(object, 6)?;
    let kind = u32_at(object, 12)?;
    if ![CAN_MESSAGE, CAN_MESSAGE2, CAN_FD_MESSAGE, CAN_FD_MESSAGE_64].contains(&kind) {
        return None;
    }
    let cut = || Some(Err(format!("a BLF object of type {kind} cut short")));
    let (flags, ticks) = match version {
        1 => (u32_at(object, 16)?, u64_at(object, 24)?),
        2 => (u32_at(object, 16)?, u64_at(object, 24)?),
        v => return Some(Err(format!("a BLF object header of version {v} (1 and 2 are known)"))),
    };
    let seconds = if flags == 1 { ticks as f64 * 1e-5 } else { ticks as f64 * 1e-9 };
    let time = Some(start + seconds);
    let Some(m) = object.get(header_size..) else { return cut() };
    let frame = match kind {
        CAN_MESSAGE | CAN_MESSAGE2 => {
            let (Some(&flags), Some(&dlc), Some(id), Some(data)) =
                (m.get(2), m.get(3), u32_at(m, 4), m.get(8..16))
            else {
                return cut();
            };
            let len = dlc.min(8);
            let data = data.get(..usize::from(len)).unwrap_or(&[]);
            classic(id & !CAN_MSG_EXT, id & CAN_MSG_EXT != 0, flags & 0x80 != 0, len, data)
        }
        CAN_FD_MESSAGE => {
            let (Some(&flags), Some(&dlc), Some(id), Some(&fd_flags), Some(&valid)) =
                (m.get(2), m.get(3), u32_at(m, 4), m.get(13), m.get(14))
            else {
                return cut();
            };
            let ext = id & CAN_MSG_EXT != 0;
            if fd_flags & 1 == 0 {
                let len = dlc.min(8);
                let data = m.get(20..20 + usize::from(len)).unwrap_or(&[]);
                classic(id & !CAN_MSG_EXT, ext, flags & 0x80 != 0, len, data)
            } else {
                let Some(data) = m.get(20..20 + usize::from(valid)) else { return cut() };
                fd(id & !CAN_MSG_EXT, ext, fd_flags & 2 != 0, fd_flags & 4 != 0, data)
            }
        }
        _ => {
            let (Some(&dlc), Some(&valid), Some(id), Some(flags)) =
                (m.get(1), m.get(2), u32_at(m, 4), u32_at(m, 12))
            else {
                return cut();
            };
            let ext = id & CAN_MSG_EXT != 0;
            let len = fd_len(dlc).unwrap_or(0).min(usize::from(valid));
            let Some(data) = m.get(40..40 + len) else { return cut() };
            if flags & 0x1000 == 0 {
                let len = u8::try_from(len.min(8)).unwrap_or(8);
                let data = data.get(..usize::from(len)).unwrap_or(&[]);
                classic(id & !CAN_MSG_EXT, ext, flags & 0x10 != 0, dlc.min(8), data)
            } else {
                fd(id & !CAN_MSG_EXT, ext, flags & 0x2000 != 0, flags & 0x4000 != 0, data)
            }
        }
    };
    Some(frame.map(|frame: Frame| Entry { time, frame }))
}
