//! The text formats: candump's (compact `-l` and screen lines, CAN FD included) and Vector's
//! ASC. Line shapes after can-utils' `lib.c` (`sprint_canframe`, `sprint_long_canframe`,
//! which candump, log2long and log2asc share) and python-can's `ASCWriter`.

use super::{Entry, Format, Location, Log, Problem, classic, fd, fd_len};
use crate::candump;

/// The text format of a log's first lines.
pub fn detect(text: &str) -> Option<Format> {
    // An empty file is an empty log (of any format: candump's, the simplest).
    let Some(line) = text.lines().map(str::trim).find(|l| !l.is_empty() && !l.starts_with("//"))
    else {
        return Some(Format::Candump);
    };
    let lower = line.to_ascii_lowercase();
    if ["date ", "base ", "begin triggerblock", "no internal events", "internal events"]
        .iter()
        .any(|p| lower.starts_with(p))
    {
        return Some(Format::Asc);
    }
    (candump_line(line).is_ok() || line.starts_with('#')).then_some(Format::Candump)
}

/// Reads candump lines into `log`.
pub fn candump(text: &str, log: &mut Log) {
    for (n, line) in text.lines().enumerate() {
        let line = line.trim();
        if line.is_empty() || line.starts_with('#') {
            continue;
        }
        match candump_line(line) {
            Ok(entry) => log.entries.push(entry),
            Err(message) => log.problems.push(Problem { at: Location::Line(n + 1), message }),
        }
    }
}

fn candump_line(line: &str) -> Result<Entry, String> {
    let tokens: Vec<&str> = line.split_whitespace().collect();
    // A compact line may end with the direction, ` R` or ` T` (python-can's
    // CanutilsLogWriter, newer candump).
    let compact = match tokens[..] {
        [time, iface, frame] | [time, iface, frame, "R" | "T"] if time.starts_with('(') => {
            Some((time, iface, frame))
        }
        _ => None,
    };
    match compact {
        Some((time, _, frame)) if frame.contains("##") => compact_fd(time, frame),
        Some((time, iface, frame)) if frame.contains('#') => {
            let f =
                candump::parse_line(&format!("{time} {iface} {frame}"))?.ok_or("an empty line")?;
            Ok(Entry { time: Some(f.time), frame: super::Frame::Can(f.frame) })
        }
        _ => screen(&tokens),
    }
}

/// `(SECONDS)` as candump writes it.
fn seconds(token: &str) -> Result<f64, String> {
    token
        .strip_prefix('(')
        .and_then(|t| t.strip_suffix(')'))
        .and_then(|t| t.parse::<f64>().ok())
        .filter(|t| t.is_finite() && *t >= 0.0)
        .ok_or_else(|| format!("`{token}` is not a time `(SECONDS)`"))
}

fn hex_id(id: &str) -> Result<(u32, bool), String> {
    let extended = id.len() == 8;
    if !(id.len() == 3 || extended) || !id.bytes().all(|b| b.is_ascii_hexdigit()) {
        return Err(format!("`{id}` is not a CAN-ID (3 hex digits, or 8 for an extended one)"));
    }
    u32::from_str_radix(id, 16).map(|id| (id, extended)).map_err(|e| e.to_string())
}

fn hex_bytes(digits: &str) -> Result<Vec<u8>, String> {
    if !digits.len().is_multiple_of(2) || !digits.bytes().all(|b| b.is_ascii_hexdigit()) {
        return Err(format!("`{digits}` is not bytes in hex"));
    }
    (0..digits.len())
        .step_by(2)
        .map(|i| {
            let pair = digits.get(i..i + 2).ok_or("odd digits")?;
            u8::from_str_radix(pair, 16).map_err(|e| e.to_string())
        })
        .collect()
}

/// `(SECONDS) IFACE ID##FDATA`: `F` is the FD flags digit (1 = bit rate switch, 2 = error
/// state indicator).
fn compact_fd(time: &str, frame: &str) -> Result<Entry, String> {
    let time = seconds(time)?;
    let (id, rest) = frame.split_once("##").ok_or("no `##`")?;
    let (id, extended) = hex_id(id)?;
    let mut chars = rest.chars();
    let flags = chars
        .next()
        .and_then(|c| c.to_digit(16))
        .ok_or_else(|| format!("`{frame}`: a CAN FD frame has a flags digit after `##`"))?;
    let data = hex_bytes(chars.as_str())?;
    let frame = fd(id, extended, flags & 1 != 0, flags & 2 != 0, &data)?;
    Ok(Entry { time: Some(time), frame })
}

/// candump's screen line: `[(SECONDS)] IFACE [RX|TX FLAG FLAG] ID [LEN] BYTES… ['ASCII']` or
/// `… [LEN] remote request`. A two-digit length (`[08]`, `[12]`) is a CAN FD frame's.
fn screen(tokens: &[&str]) -> Result<Entry, String> {
    let shape = "expected candump's `(SECONDS) IFACE ID#DATA` or `IFACE ID [LEN] BYTES`";
    let (time, rest) = match tokens.split_first() {
        Some((t, rest)) if t.starts_with('(') => (Some(seconds(t)?), rest),
        _ => (None, tokens),
    };
    // The interface, then with `-x` the direction and two flags.
    let rest = match rest {
        [_, "RX" | "TX", _, _, rest @ ..] | [_, rest @ ..] => rest,
        [] => return Err(shape.into()),
    };
    let [id, len, data @ ..] = rest else { return Err(shape.into()) };
    let (id, extended) = hex_id(id)?;
    let inner = len.strip_prefix('[').and_then(|l| l.strip_suffix(']')).ok_or(shape)?;
    let n: u8 = inner.parse().map_err(|_| format!("`{len}` is not a length `[N]`"))?;
    let is_fd = inner.len() == 2;
    if let ["remote", "request", ..] = data {
        return Ok(Entry { time, frame: classic(id, extended, true, n, &[])? });
    }
    let bytes = data
        .iter()
        .take_while(|t| !t.starts_with('\''))
        .map(|t| {
            hex_bytes(t).and_then(|b| {
                if b.len() == 1 { Ok(b[0]) } else { Err(format!("`{t}` is not a byte")) }
            })
        })
        .collect::<Result<Vec<u8>, String>>()?;
    if bytes.len() != usize::from(n) {
        return Err(format!("length [{n}] but {} bytes", bytes.len()));
    }
    let frame = if is_fd {
        fd(id, extended, false, false, &bytes)?
    } else {
        classic(id, extended, false, n, &bytes)?
    };
    Ok(Entry { time, frame })
}

/// Reads ASC lines into `log`: `TIME CHANNEL ID[x] Rx|Tx d|r DLC BYTES…` and `TIME CANFD
/// CHANNEL Rx|Tx ID [NAME] BRS ESI DLC LEN BYTES…`, in hex or decimal (`base dec`); the
/// header, events (`Start of measurement`, `ErrorFrame`, statistics) and comments are
/// skipped.
pub fn asc(text: &str, log: &mut Log) {
    let mut radix = 16;
    for (n, line) in text.lines().enumerate() {
        let tokens: Vec<&str> = line.split_whitespace().collect();
        if let ["base", base, ..] = tokens[..] {
            radix = if base.eq_ignore_ascii_case("dec") { 10 } else { 16 };
            continue;
        }
        let Some(time) = tokens.first().and_then(|t| t.parse::<f64>().ok()) else { continue };
        let result = match tokens.get(1..).unwrap_or(&[]) {
            ["CANFD", _channel, "Rx" | "Tx", rest @ ..] => asc_fd(rest, radix),
            [channel, id, "Rx" | "Tx", kind @ ("d" | "r" | "D" | "R"), rest @ ..]
                if channel.bytes().all(|b| b.is_ascii_digit()) =>
            {
                asc_classic(id, kind, rest, radix)
            }
            // Events and objects this reader has no use for.
            _ => continue,
        };
        match result {
            Ok(frame) => log.entries.push(Entry { time: Some(time), frame }),
            Err(message) => log.problems.push(Problem { at: Location::Line(n + 1), message }),
        }
    }
}

fn asc_id(id: &str, radix: u32) -> Result<(u32, bool), String> {
    let (digits, extended) = match id.strip_suffix(['x', 'X']) {
        Some(d) => (d, true),
        None => (id, false),
    };
    u32::from_str_radix(digits, radix)
        .map(|v| (v, extended))
        .map_err(|_| format!("`{id}` is not a CAN-ID"))
}

fn asc_byte(t: &str, radix: u32) -> Result<u8, String> {
    u8::from_str_radix(t, radix).map_err(|_| format!("`{t}` is not a byte"))
}

fn asc_classic(id: &str, kind: &str, rest: &[&str], radix: u32) -> Result<super::Frame, String> {
    let (id, extended) = asc_id(id, radix)?;
    // Old remote lines have no length: `r` alone.
    let dlc = match rest.first() {
        Some(d) => u8::from_str_radix(d, 16).map_err(|_| format!("`{d}` is not a length"))?,
        None => 0,
    };
    if kind.eq_ignore_ascii_case("r") {
        return classic(id, extended, true, dlc.min(8), &[]);
    }
    let data = rest
        .get(1..=usize::from(dlc.min(8)))
        .ok_or_else(|| format!("length {dlc} but fewer bytes"))?
        .iter()
        .map(|t| asc_byte(t, radix))
        .collect::<Result<Vec<u8>, String>>()?;
    classic(id, extended, false, dlc, &data)
}

fn asc_fd(rest: &[&str], radix: u32) -> Result<super::Frame, String> {
    let [id, tail @ ..] = rest else { return Err("a CANFD line without ID".into()) };
    let (id, extended) = asc_id(id, radix)?;
    // A symbolic name may stand between the ID and the BRS flag.
    let flag = |t: &&str| *t == "0" || *t == "1";
    let tail = match tail {
        [brs, esi, ..] if flag(brs) && flag(esi) => tail,
        [_name, rest @ ..] => rest,
        [] => tail,
    };
    let [brs, esi, dlc, len, data @ ..] = tail else {
        return Err("a CANFD line cut short".into());
    };
    // The data length counts the bytes (as python-can's reader takes it); the DLC must
    // still be one.
    u8::from_str_radix(dlc, 16).ok().and_then(fd_len).ok_or("a bad CANFD DLC")?;
    let len: usize = len.parse().map_err(|_| format!("`{len}` is not a data length"))?;
    let data = data
        .get(..len)
        .ok_or("a CANFD line with fewer bytes than its length")?
        .iter()
        .map(|t| asc_byte(t, radix))
        .collect::<Result<Vec<u8>, String>>()?;
    fd(id, extended, *brs == "1", *esi == "1", &data)
}
