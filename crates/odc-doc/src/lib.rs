//! A device description as a data sheet (`odc doc`): one self-contained HTML page with the
//! PDOs and EtherCAT process images drawn bit by bit, and the same content as Markdown.
//!
//! - [`mod@sheet`]: what the sheet says, gathered once from the model (identity, capabilities,
//!   CiA 402 modes, objects, PDOs, parameter schemes, diagnostics);
//! - [`html`]: the page (inline styles, a filter box, inline SVG diagrams from [`svg`]);
//! - [`markdown`]: the Markdown file.
//!
//! Output is deterministic: the same device gives the same bytes.
#![cfg_attr(not(test), deny(clippy::unwrap_used, clippy::expect_used, clippy::panic))]

pub mod html;
pub mod markdown;
pub mod sheet;
pub mod svg;

pub use sheet::{Input, Sheet, sheet};

/// The HTML page of a device.
pub fn render_html(input: &Input<'_>) -> String {
    html::page(&sheet(input))
}

/// The Markdown file of a device.
pub fn render_markdown(input: &Input<'_>) -> String {
    markdown::markdown(&sheet(input))
}

/// Text for HTML and SVG: `&`, `<`, `>` and `"` escaped.
pub(crate) fn escape(s: &str) -> String {
    let mut out = String::with_capacity(s.len());
    for c in s.chars() {
        match c {
            '&' => out.push_str("&amp;"),
            '<' => out.push_str("&lt;"),
            '>' => out.push_str("&gt;"),
            '"' => out.push_str("&quot;"),
            c => out.push(c),
        }
    }
    out
}
