//! The changes as text for a person (grouped by place, coloured on a terminal) or as JSON.

use std::fmt::Write;

use odc_model::Device;

use crate::{Change, Place, What, object_name};

const GREEN: &str = "\x1b[32m";
const RED: &str = "\x1b[31m";
const YELLOW: &str = "\x1b[33m";
const BOLD: &str = "\x1b[1m";
const RESET: &str = "\x1b[0m";

/// The heading of a place's group.
fn heading(place: &Place, a: &Device, b: &Device) -> String {
    match place {
        Place::Identity => "identity".into(),
        Place::File => "file information".into(),
        Place::Capabilities => "capabilities".into(),
        Place::Object { index } | Place::Sub { index, .. } => {
            format!("object 0x{index:04X} {}", object_name(a, b, *index))
        }
        Place::Pdo { mapping_index } => format!("PDO 0x{mapping_index:04X}"),
        Place::Image { direction } => format!("process image, {direction}"),
        Place::Comments => "comments".into(),
    }
}

/// One line per change under a heading per object (or identity, capabilities, PDO, …); `+`
/// added in B, `-` removed from A, `~` changed, with ANSI colours when `color`.
pub fn human(changes: &[Change], a: &Device, b: &Device, color: bool) -> String {
    let paint = |code: &'static str| if color { code } else { "" };
    let mut s = String::new();
    let mut last: Option<String> = None;
    for c in changes {
        let mut head = heading(&c.place, a, b);
        if let Some(side) = c.odc {
            // Not the file's own object on that side: say so, so nobody reads it as an edit.
            let _ = write!(head, " (odc's in {}, not the file's)", side.to_uppercase());
        }
        if last.as_deref() != Some(head.as_str()) {
            let _ = writeln!(s, "{}{head}{}", paint(BOLD), paint(RESET));
            last = Some(head);
        }
        let sub = match c.place {
            Place::Sub { sub, .. } => format!("sub {sub:02X} "),
            _ => String::new(),
        };
        let _ = match &c.what {
            What::Added { text } => writeln!(s, "  {}+ {sub}{text}{}", paint(GREEN), paint(RESET)),
            What::Removed { text } => writeln!(s, "  {}- {sub}{text}{}", paint(RED), paint(RESET)),
            What::Changed { field, a, b } => {
                let show = |v: &str| if v.is_empty() { "(none)".to_owned() } else { v.to_owned() };
                writeln!(
                    s,
                    "  {}~ {sub}{field}: {} → {}{}",
                    paint(YELLOW),
                    show(a),
                    show(b),
                    paint(RESET)
                )
            }
        };
    }
    s
}

/// The changes as a JSON array: `{"in": "sub", "index": 4096, "sub": 0, "change": "changed",
/// "field": "default", "a": "0", "b": "1"}`.
pub fn json(changes: &[Change]) -> String {
    serde_json::to_string_pretty(changes).unwrap_or_else(|e| format!("{{\"error\": \"{e}\"}}"))
}
