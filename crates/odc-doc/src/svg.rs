//! A bit diagram as inline SVG: 32 bits a row, byte 0 first, bit 0 of each byte on the left,
//! each field a box labelled with its object's name and its first bit marked above it.
//!
//! Written by hand: a diagram is a few rectangles and texts, which no SVG crate makes shorter,
//! and the output must be byte-for-byte deterministic.

use std::fmt::Write;

use crate::escape;
use crate::sheet::Diagram;

/// Bits in a row.
const ROW_BITS: u32 = 32;
/// Width of one bit.
const BIT: u32 = 22;
/// Left margin (the row's byte offset).
const LEFT: u32 = 64;
/// Height of a row, with the bit offsets above its boxes.
const ROW: u32 = 50;
/// Height of a box.
const BOX: u32 = 30;

/// The diagram. Each field is a `<g class="field">` (`gap` added for gaps) holding one box per
/// row it spans and a `<title>` with its object, type and bits.
pub fn diagram(d: &Diagram) -> String {
    let rows = d.bits.div_ceil(ROW_BITS).max(1);
    let width = LEFT + ROW_BITS * BIT + 8;
    let height = rows * ROW + 8;
    let mut s = String::new();
    let _ = write!(
        s,
        "<svg class=\"bits\" id=\"svg-{}\" xmlns=\"http://www.w3.org/2000/svg\" width=\"{width}\" \
         height=\"{height}\" viewBox=\"0 0 {width} {height}\" role=\"img\" aria-label=\"{}\">",
        d.anchor,
        escape(&d.title)
    );
    for row in 0..rows {
        let y = row * ROW + 16;
        let _ = write!(
            s,
            "<text class=\"byte\" x=\"4\" y=\"{}\">byte {}</text>",
            y + BOX / 2 + 4,
            row * ROW_BITS / 8
        );
        // The bits of this row that no field covers.
        let (from, to) = (row * ROW_BITS, ((row + 1) * ROW_BITS).min(d.bits));
        if to < (row + 1) * ROW_BITS {
            let x = LEFT + (to - from) * BIT;
            let w = ((row + 1) * ROW_BITS - to) * BIT;
            let _ = write!(
                s,
                "<rect class=\"free\" x=\"{x}\" y=\"{y}\" width=\"{w}\" height=\"{BOX}\"/>"
            );
        }
    }
    for (k, f) in d.fields.iter().enumerate() {
        let class = if f.is_gap() { "field gap" } else { "field" };
        let _ = write!(s, "<g class=\"{class}\" data-field=\"{k}\"");
        if !f.address.is_empty() {
            let _ = write!(s, " data-object=\"{}\"", escape(&f.address));
        }
        let last = f.offset + f.bits.max(1) - 1;
        let ty = if f.data_type.is_empty() { String::new() } else { format!(", {}", f.data_type) };
        let _ = write!(
            s,
            "><title>{} {}{ty}, bits {}–{last} ({} bits)</title>",
            escape(&f.address),
            escape(&f.name),
            f.offset,
            f.bits
        );
        // One box per row the field spans.
        let mut at = f.offset;
        let end = f.offset + f.bits;
        let mut first = true;
        while at < end || (first && f.bits == 0) {
            let row = at / ROW_BITS;
            let row_end = ((row + 1) * ROW_BITS).min(end);
            let x = LEFT + (at % ROW_BITS) * BIT;
            let y = row * ROW + 16;
            let w = (row_end.saturating_sub(at)).max(1) * BIT;
            let _ =
                write!(s, "<rect x=\"{x}\" y=\"{y}\" width=\"{w}\" height=\"{BOX}\" rx=\"3\"/>");
            if first {
                let _ = write!(
                    s,
                    "<text class=\"offset\" x=\"{}\" y=\"{}\">{}</text>",
                    x + 2,
                    y - 4,
                    f.offset
                );
            }
            let label = fit(&f.name, w);
            if !label.is_empty() {
                let _ = write!(
                    s,
                    "<text class=\"label\" x=\"{}\" y=\"{}\">{}</text>",
                    x + w / 2,
                    y + BOX / 2 + 4,
                    escape(&label)
                );
            }
            first = false;
            if row_end == at {
                break;
            }
            at = row_end;
        }
        s.push_str("</g>");
    }
    // Byte boundaries, over the boxes.
    for row in 0..rows {
        let y = row * ROW + 16;
        for b in 1..ROW_BITS / 8 {
            let x = LEFT + b * 8 * BIT;
            let _ = write!(
                s,
                "<line class=\"byte-edge\" x1=\"{x}\" y1=\"{}\" x2=\"{x}\" y2=\"{}\"/>",
                y - 2,
                y + BOX + 2
            );
        }
    }
    s.push_str("</svg>");
    s
}

/// The label that fits a box `width` pixels wide (about 6.5 pixels a character), cut with `…`.
fn fit(name: &str, width: u32) -> String {
    let room = (width.saturating_sub(6) * 2 / 13) as usize;
    let n = name.chars().count();
    if n <= room {
        name.to_owned()
    } else if room >= 2 {
        let mut cut: String = name.chars().take(room - 1).collect();
        cut.push('…');
        cut
    } else {
        String::new()
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::sheet::Field;

    fn field(offset: u32, bits: u32, name: &str) -> Field {
        Field {
            offset,
            bits,
            address: "0x6041:00".into(),
            name: name.into(),
            data_type: "UNSIGNED16".into(),
            anchor: None,
        }
    }

    #[test]
    fn a_field_across_rows_has_one_box_per_row() {
        let d = Diagram {
            anchor: "pdo-1A00".into(),
            title: "TPDO".into(),
            detail: String::new(),
            bits: 64,
            fields: vec![
                field(0, 16, "Statusword"),
                field(16, 32, "Position actual value"),
                field(48, 16, "x"),
            ],
        };
        let svg = diagram(&d);
        assert_eq!(svg.matches("<g class=\"field\"").count(), 3);
        // Bits 16..48 cross the row boundary at 32: two boxes, 16 bits each (352 px).
        let second = svg.split("data-field=\"1\"").nth(1).unwrap().split("</g>").next().unwrap();
        assert_eq!(second.matches("<rect").count(), 2, "{second}");
        assert_eq!(second.matches("width=\"352\"").count(), 2, "{second}");
        assert!(second.contains("bits 16–47 (32 bits)"));
        // Two rows, nothing free.
        assert!(!svg.contains("class=\"free\""));
        assert!(svg.contains(">byte 4<"));
    }

    #[test]
    fn labels_are_cut_to_fit() {
        assert_eq!(fit("Statusword", 16 * BIT), "Statusword");
        // 4 bits: 88 px, room for 12 characters.
        assert_eq!(fit("Position actual value", 4 * BIT), "Position ac…");
        assert_eq!(fit("x", 4), "");
    }
}
