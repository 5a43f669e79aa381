//! The sheet as Markdown (GitHub flavour): the same sections as the page, PDOs as tables of
//! their fields, object rows with an `<a id>` so the diagnostics can link to them.

use std::fmt::Write;

use crate::sheet::Sheet;

/// Text from a device file for a table cell or heading: HTML escaped (a Markdown renderer
/// passes raw HTML through, and a name like `<script>` must show as text), `|` escaped, line
/// ends as spaces.
fn cell(s: &str) -> String {
    s.replace('&', "&amp;")
        .replace('<', "&lt;")
        .replace('>', "&gt;")
        .replace('|', "\\|")
        .replace(['\r', '\n'], " ")
}

/// The Markdown file.
pub fn markdown(sheet: &Sheet) -> String {
    let mut s = String::new();
    let _ = writeln!(s, "# {}\n\n`{}`\n", cell(&sheet.title), sheet.file);
    pairs(&mut s, "Identity", &sheet.identity);
    pairs(&mut s, "Capabilities", &sheet.capabilities);
    if !sheet.modes.is_empty() {
        s.push_str("## CiA 402 modes of operation\n\n| 0x6060 | mode |\n|---:|---|\n");
        for (v, name) in &sheet.modes {
            let _ = writeln!(s, "| {v} | {} |", cell(name));
        }
        s.push('\n');
    }
    s.push_str("## PDOs\n\n");
    if sheet.diagrams.is_empty() {
        s.push_str("The file defines no PDO.\n\n");
    }
    for d in &sheet.diagrams {
        let _ = writeln!(s, "### {}\n\n{}\n", cell(&d.title), cell(&d.detail));
        if d.fields.is_empty() {
            s.push_str("No entries are mapped by default.\n\n");
            continue;
        }
        s.push_str(
            "| bit | byte.bit | bits | object | name | type |\n|---:|---:|---:|---|---|---|\n",
        );
        for f in &d.fields {
            let object = match &f.anchor {
                Some(a) => format!("[{}](#{a})", f.address),
                None => f.address.clone(),
            };
            let _ = writeln!(
                s,
                "| {} | {}.{} | {} | {object} | {} | {} |",
                f.offset,
                f.offset / 8,
                f.offset % 8,
                f.bits,
                cell(&f.name),
                cell(&f.data_type)
            );
        }
        s.push('\n');
    }
    if !sheet.schemes.is_empty() {
        s.push_str("## Parameter schemes\n\n");
        for sc in &sheet.schemes {
            let _ = writeln!(s, "### {}\n\n{}\n\n`{}`\n", cell(&sc.module), sc.doc, sc.rule);
            if let Some(e) = &sc.error {
                let _ = writeln!(s, "**Not listed:** {e}\n");
            }
            if !sc.entries.is_empty() {
                s.push_str("| name | object | what |\n|---|---|---|\n");
                for (name, anchor, address, what) in &sc.entries {
                    let _ = writeln!(s, "| `{name}` | [{address}](#{anchor}) | {} |", cell(what));
                }
                s.push('\n');
            }
        }
    }
    s.push_str("## Diagnostics\n\n");
    if sheet.findings.is_empty() {
        s.push_str("`odc check` finds nothing to report.\n\n");
    } else {
        s.push_str("| level | code | message | where | object |\n|---|---|---|---|---|\n");
        for f in &sheet.findings {
            let object = f.anchor.as_ref().map_or(String::new(), |a| format!("[{a}](#{a})"));
            let _ = writeln!(
                s,
                "| {} | {} | {} | {} | {object} |",
                f.severity,
                f.code,
                cell(&f.message),
                f.at
            );
        }
        s.push('\n');
    }
    s.push_str("## Objects\n\n| index | sub | name | object | type | access | PDO | default | value | low | high | denotation |\n");
    s.push_str("|---|---|---|---|---|---|---|---|---|---|---|---|\n");
    for r in &sheet.objects {
        let sub = r.sub.map_or(String::new(), |s| format!("{s:02X}"));
        let _ = writeln!(
            s,
            "| <a id=\"{}\"></a>{:04X}{} | {sub} | {} | {} | {} | {} | {} | {} | {} | {} | {} | {} |",
            r.anchor,
            r.index,
            r.made.marker(),
            cell(&r.name),
            r.kind,
            r.data_type,
            r.access,
            r.pdo,
            cell(&r.default),
            cell(&r.value),
            cell(&r.low),
            cell(&r.high),
            cell(&r.denotation)
        );
    }
    let legend = crate::sheet::legend(&sheet.objects);
    if !legend.is_empty() {
        s.push('\n');
        for (mark, what) in legend {
            let _ = writeln!(s, "{mark} {what}  ");
        }
    }
    s
}

fn pairs(s: &mut String, heading: &str, rows: &[(String, String)]) {
    let _ = writeln!(s, "## {heading}\n");
    if rows.is_empty() {
        s.push_str("The file says nothing here.\n\n");
        return;
    }
    s.push_str("| | |\n|---|---|\n");
    for (k, v) in rows {
        let _ = writeln!(s, "| {} | {} |", cell(k), cell(v));
    }
    s.push('\n');
}
