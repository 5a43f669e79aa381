//! The candump log reader (`odc_monitor::candump::parse_line`) against the format as its
//! module documents it, written out here independently:
//!
//! ```text
//! line      = blank | "#" anything | "(" seconds ")" ws interface ws frame   (ws around)
//! seconds   = digits [ "." digits ]                  (a finite number)
//! interface = any run of non-whitespace
//! frame     = id "#" ( hex-pairs{0..8} | ("R" | "r") [ "0".."8" ] )
//! id        = 3 hex digits <= 7FF (11-bit) | 8 hex digits <= 1FFFFFFF (29-bit)
//! ```
//!
//! On any text, each line is read exactly as this grammar says: a valid line gives its frame
//! (identifier, format, remote, length, bytes, time, interface), a blank or comment line
//! nothing, and every other line an error with a message; never a panic. And a line built
//! from random frames in every spelling the format allows (upper and lower case hex, `R`
//! with and without its length, tabs and spaces) is read back to the frame it was built
//! from: the reader never loses a valid line.
#![no_main]

use arbitrary::{Arbitrary, Unstructured};
use libfuzzer_sys::fuzz_target;
use odc::can::CanFrame;
use odc_monitor::candump::{LogFrame, parse_line};

/// The one call into the reader, and the frame's fields read through its accessors (only
/// here needs adapting when the frame type changes).
fn read(line: &str) -> Result<Option<(f64, String, CanFrame)>, String> {
    parse_line(line).map(|o| o.map(|LogFrame { time, interface, frame }| (time, interface, frame)))
}

/// (id, extended, remote, len) of a frame.
fn fields(f: &CanFrame) -> (u32, bool, bool, u8) {
    (f.id(), f.is_extended(), f.is_remote(), f.len())
}

/// What a frame field says, by the grammar: (id, extended, remote, len, bytes).
type Expect = (u32, bool, bool, u8, Vec<u8>);

fn hex(s: &str) -> bool {
    !s.is_empty() && s.bytes().all(|b| b.is_ascii_hexdigit())
}

fn digits(s: &str) -> bool {
    !s.is_empty() && s.bytes().all(|b| b.is_ascii_digit())
}

fn seconds(t: &str) -> Option<f64> {
    let t = t.strip_prefix('(')?.strip_suffix(')')?;
    let ok = match t.split_once('.') {
        Some((a, b)) => digits(a) && digits(b),
        None => digits(t),
    };
    let v: f64 = if ok { t.parse().ok()? } else { return None };
    v.is_finite().then_some(v)
}

fn frame_field(f: &str) -> Option<Expect> {
    let (id, data) = f.split_once('#')?;
    if !hex(id) || !(id.len() == 3 || id.len() == 8) {
        return None;
    }
    let extended = id.len() == 8;
    let id = u32::from_str_radix(id, 16).ok()?;
    if id > if extended { 0x1FFF_FFFF } else { 0x7FF } {
        return None;
    }
    if let Some(len) = data.strip_prefix(['R', 'r']) {
        let len = match len.as_bytes() {
            [] => 0,
            [d @ b'0'..=b'8'] => d - b'0',
            _ => return None,
        };
        return Some((id, extended, true, len, Vec::new()));
    }
    if data.len() % 2 != 0 || data.len() > 16 || !(data.is_empty() || hex(data)) {
        return None;
    }
    let bytes: Vec<u8> = (0..data.len() / 2)
        .map(|i| u8::from_str_radix(&data[2 * i..2 * i + 2], 16).expect("two hex digits, checked"))
        .collect();
    Some((id, extended, false, bytes.len() as u8, bytes))
}

/// `Ok(None)`: blank or comment; `Ok(Some)`: a frame; `Err(())`: not a candump line.
fn grammar(line: &str) -> Result<Option<(f64, String, Expect)>, ()> {
    let t = line.trim();
    if t.is_empty() || t.starts_with('#') {
        return Ok(None);
    }
    let fields: Vec<&str> = t.split_whitespace().collect();
    let [time, iface, frame] = fields[..] else { return Err(()) };
    let time = seconds(time).ok_or(())?;
    let e = frame_field(frame).ok_or(())?;
    Ok(Some((time, iface.to_owned(), e)))
}

fn check(line: &str) {
    let got = read(line);
    match (grammar(line), &got) {
        (Ok(None), Ok(None)) => {}
        (Ok(Some((time, iface, (id, ext, remote, len, bytes)))), Ok(Some((t, i, f)))) => {
            assert_eq!((*t, i.as_str()), (time, iface.as_str()), "{line:?}");
            assert_eq!(fields(f), (id, ext, remote, len), "{line:?}");
            assert_eq!(f.bytes(), &bytes[..], "{line:?}");
            // Bytes past the length are zero (CanFrame's rule).
            let data = f.data();
            assert!(data[usize::from(f.len().min(8))..].iter().all(|&b| b == 0) || f.is_remote());
            assert!(data.iter().all(|&b| b == 0) || !f.is_remote(), "{line:?}");
        }
        (Err(()), Err(msg)) => assert!(!msg.is_empty(), "{line:?}: an error without a message"),
        (want, _) => panic!("{line:?}: the format says {want:?}, the reader {got:?}"),
    }
}

/// A valid line in one of the spellings candump and its users write.
fn valid_line(u: &mut Unstructured<'_>) -> arbitrary::Result<(String, f64, String, Expect)> {
    let ws = |u: &mut Unstructured<'_>, min: usize| -> arbitrary::Result<String> {
        let n = u.int_in_range(min..=3)?;
        (0..n).map(|_| Ok(if u.ratio(1, 4)? { '\t' } else { ' ' })).collect()
    };
    let secs = u32::arbitrary(u)?;
    let usec = u.int_in_range(0..=999_999u32)?;
    let time = if u.ratio(1, 8)? { format!("{secs}") } else { format!("{secs}.{usec:06}") };
    let iface_len = u.int_in_range(1..=15)?;
    let iface: String = (0..iface_len)
        .map(|_| Ok(*u.choose(b"abcdefghijklmnopqrstuvwxyz0123456789_-.")? as char))
        .collect::<arbitrary::Result<_>>()?;
    let extended = u.ratio(1, 3)?;
    let id = if extended { u32::arbitrary(u)? & 0x1FFF_FFFF } else { u32::arbitrary(u)? & 0x7FF };
    let upper = bool::arbitrary(u)?;
    let mut frame = if extended { format!("{id:08X}#") } else { format!("{id:03X}#") };
    let expect = if u.ratio(1, 5)? {
        let len = u.int_in_range(0..=8u8)?;
        frame.push(if bool::arbitrary(u)? { 'R' } else { 'r' });
        if len > 0 || bool::arbitrary(u)? {
            frame.push(char::from(b'0' + len));
        }
        (id, extended, true, len, Vec::new())
    } else {
        let len = u.int_in_range(0..=8usize)?;
        let bytes = u.bytes(len)?.to_vec();
        for b in &bytes {
            frame.push_str(&if upper { format!("{b:02X}") } else { format!("{b:02x}") });
        }
        (id, extended, false, len as u8, bytes)
    };
    if !upper {
        frame = frame.to_lowercase();
    }
    let line =
        format!("{}({time}){}{iface}{}{frame}{}", ws(u, 0)?, ws(u, 1)?, ws(u, 1)?, ws(u, 0)?);
    Ok((line, time.parse().expect("digits"), iface, expect))
}

fuzz_target!(|data: &[u8]| {
    // Any text, line by line.
    for line in String::from_utf8_lossy(data).split('\n') {
        check(line);
    }
    // Valid lines built from the same bytes: none is lost.
    let mut u = Unstructured::new(data);
    while let Ok((line, time, iface, (id, ext, remote, len, bytes))) = valid_line(&mut u) {
        let Ok(Some((t, i, f))) = read(&line) else {
            panic!("valid line {line:?} refused: {:?}", read(&line))
        };
        assert_eq!((t, i, fields(&f)), (time, iface, (id, ext, remote, len)), "{line:?}");
        assert_eq!(f.bytes(), &bytes[..], "{line:?}");
        check(&line);
        if u.is_empty() {
            break;
        }
    }
});
