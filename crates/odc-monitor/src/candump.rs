//! candump log lines (`candump -l`, `candump -L`): `(1700000000.000000) can0 185#4006`.
//!
//! Written by hand: the format is one line of four fields, and no crate reads it without
//! pulling in a CAN socket stack. Classic CAN only: an FD frame (`##`) is an error, not
//! skipped; a remote frame is `123#R` (optionally with its length, `123#R4`); an extended
//! frame has an 8-digit identifier.

use odc::can::CanFrame;

/// One frame of a log.
#[derive(Clone, Debug, PartialEq)]
pub struct LogFrame {
    /// Seconds (the log's timestamp).
    pub time: f64,
    /// The interface it was read on.
    pub interface: String,
    /// The frame.
    pub frame: CanFrame,
}

/// Reads one line; `Ok(None)` for a blank line or a `#` comment.
///
/// # Errors
///
/// What is wrong with the line.
pub fn parse_line(line: &str) -> Result<Option<LogFrame>, String> {
    let line = line.trim();
    if line.is_empty() || line.starts_with('#') {
        return Ok(None);
    }
    let mut fields = line.split_whitespace();
    let (Some(time), Some(interface), Some(frame), None) =
        (fields.next(), fields.next(), fields.next(), fields.next())
    else {
        return Err("expected `(SECONDS) INTERFACE ID#DATA`".into());
    };
    let time = time
        .strip_prefix('(')
        .and_then(|t| t.strip_suffix(')'))
        .and_then(|t| t.parse::<f64>().ok())
        .ok_or_else(|| format!("`{time}` is not a timestamp `(SECONDS)`"))?;
    let (id, data) = frame.split_once('#').ok_or_else(|| format!("`{frame}` has no `#`"))?;
    if data.starts_with('#') {
        return Err(format!("`{frame}` is a CAN FD frame; classic CAN only"));
    }
    let extended = id.len() == 8;
    if !(id.len() == 3 || extended) || !id.chars().all(|c| c.is_ascii_hexdigit()) {
        return Err(format!("`{id}` is not a CAN-ID (3 hex digits, or 8 for an extended one)"));
    }
    let id = u32::from_str_radix(id, 16).map_err(|e| e.to_string())?;
    if (extended && id > 0x1FFF_FFFF) || (!extended && id > 0x7FF) {
        return Err(format!("CAN-ID 0x{id:X} is out of range"));
    }
    let frame = if let Some(len) = data.strip_prefix('R').or_else(|| data.strip_prefix('r')) {
        let len = if len.is_empty() { 0 } else { len.parse::<u8>().map_err(|e| e.to_string())? };
        if len > 8 {
            return Err(format!("remote frame of {len} bytes"));
        }
        let f =
            if extended { CanFrame::remote_extended(id, len) } else { CanFrame::remote(id, len) };
        f.ok_or_else(|| format!("remote frame 0x{id:X} of {len} bytes"))?
    } else {
        if data.len() % 2 != 0 || data.len() > 16 || !data.chars().all(|c| c.is_ascii_hexdigit()) {
            return Err(format!("`{data}` is not 0 to 8 bytes in hex"));
        }
        let bytes: Vec<u8> = (0..data.len())
            .step_by(2)
            .map(|i| u8::from_str_radix(data.get(i..i + 2).unwrap_or("00"), 16).unwrap_or(0))
            .collect();
        let f = if extended {
            CanFrame::extended(id, &bytes)
        } else {
            CanFrame::from_slice(id, &bytes)
        };
        f.ok_or_else(|| format!("`{frame}` is not a CAN frame"))?
    };
    Ok(Some(LogFrame { time, interface: interface.to_owned(), frame }))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn lines_of_candump() {
        let f = parse_line("(1700000000.000000) can0 185#4006").unwrap().unwrap();
        assert_eq!(
            (f.time, f.interface.as_str(), f.frame.id(), f.frame.bytes()),
            (1_700_000_000.0, "can0", 0x185, &[0x40, 0x06][..])
        );
        let r = parse_line("(1.5) vcan0 701#R1").unwrap().unwrap();
        assert!(r.frame.is_remote() && r.frame.len() == 1);
        let x = parse_line("(2.0) can0 18FF0001#01").unwrap().unwrap();
        assert!(x.frame.is_extended() && x.frame.id() == 0x18FF_0001);
        assert_eq!(parse_line("  "), Ok(None));
        assert_eq!(parse_line("# the manual's figure 11"), Ok(None));
        for bad in [
            "(x) can0 185#40",
            "(1.0) can0 185#4",
            "(1.0) can0 1850#40",
            "(1.0) can0 185##140",
            "(1.0) can0 800#",
            "(1.0) can0 185#001122334455667788",
            "185#40",
        ] {
            assert!(parse_line(bad).is_err(), "{bad}");
        }
    }
}
