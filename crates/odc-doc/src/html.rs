//! The sheet as one self-contained HTML page: styles and the filter script inline, diagrams as
//! inline SVG, nothing fetched, so it works from a `file://` URL and offline.

use std::fmt::Write;

use crate::escape;
use crate::sheet::{Diagram, Sheet};
use crate::svg;

const STYLE: &str = "\
body{font:14px/1.4 system-ui,sans-serif;margin:2em auto;max-width:1200px;padding:0 1em;color:#222}\
h1{margin-bottom:.2em}.file{color:#666;margin-top:0}\
table{border-collapse:collapse;margin:.5em 0 1.5em}th,td{border:1px solid #ccc;padding:2px 6px;text-align:left;vertical-align:top}\
th{background:#f0f0f0}td.num{font-family:monospace}tr.object td{background:#f7f7fb;font-weight:600}\
tr:target td{background:#fff3b0}section.pdo{margin-bottom:1.5em}.detail{color:#555}\
svg.bits rect{fill:#dbe8f6;stroke:#3a6ea5}svg.bits g.gap rect{fill:#eee;stroke:#999}\
svg.bits rect.free{fill:#fafafa;stroke:#ddd;stroke-dasharray:3 3}svg.bits line.byte-edge{stroke:#c33;stroke-width:1;stroke-opacity:.6}\
svg.bits text{font:11px sans-serif}svg.bits text.label{text-anchor:middle}svg.bits text.offset{font-size:9px;fill:#555}\
svg.bits text.byte{font-size:10px;fill:#555}.error{color:#b00}.warning{color:#a60}\
#filter{font-size:14px;padding:3px 6px;width:24em}";

const SCRIPT: &str = "\
document.getElementById('filter').addEventListener('input',function(e){\
var q=e.target.value.toLowerCase();\
document.querySelectorAll('#objects tbody tr').forEach(function(r){\
r.style.display=!q||r.textContent.toLowerCase().indexOf(q)>=0?'':'none';});});";

/// The page.
pub fn page(sheet: &Sheet) -> String {
    let mut s = String::new();
    let title = escape(&sheet.title);
    let _ = write!(
        s,
        "<!DOCTYPE html>\n<html lang=\"en\">\n<head>\n<meta charset=\"utf-8\">\n\
         <meta name=\"generator\" content=\"odc doc\">\n<title>{title}</title>\n\
         <style>{STYLE}</style>\n</head>\n<body>\n<h1>{title}</h1>\n<p class=\"file\">{}</p>\n",
        escape(&sheet.file)
    );
    s.push_str(
        "<nav><a href=\"#identity\">Identity</a> · <a href=\"#capabilities\">Capabilities</a>",
    );
    if !sheet.modes.is_empty() {
        s.push_str(" · <a href=\"#modes\">CiA 402 modes</a>");
    }
    s.push_str(" · <a href=\"#pdos\">PDOs</a>");
    if !sheet.schemes.is_empty() {
        s.push_str(" · <a href=\"#schemes\">Parameter schemes</a>");
    }
    s.push_str(
        " · <a href=\"#diagnostics\">Diagnostics</a> · <a href=\"#objects\">Objects</a></nav>\n",
    );
    pairs(&mut s, "identity", "Identity", &sheet.identity);
    pairs(&mut s, "capabilities", "Capabilities", &sheet.capabilities);
    if !sheet.modes.is_empty() {
        s.push_str("<h2 id=\"modes\">CiA 402 modes of operation</h2>\n<table><tr><th>0x6060</th><th>mode</th></tr>\n");
        for (v, name) in &sheet.modes {
            let _ = writeln!(s, "<tr><td class=\"num\">{v}</td><td>{}</td></tr>", escape(name));
        }
        s.push_str("</table>\n");
    }
    s.push_str("<h2 id=\"pdos\">PDOs</h2>\n");
    if sheet.diagrams.is_empty() {
        s.push_str("<p>The file defines no PDO.</p>\n");
    }
    for d in &sheet.diagrams {
        diagram(&mut s, d);
    }
    if !sheet.schemes.is_empty() {
        s.push_str("<h2 id=\"schemes\">Parameter schemes</h2>\n");
        for sc in &sheet.schemes {
            let _ = writeln!(
                s,
                "<h3>{}</h3>\n<p>{}</p>\n<p class=\"detail\">{}</p>",
                escape(&sc.module),
                escape(&sc.doc),
                escape(&sc.rule)
            );
            if let Some(e) = &sc.error {
                let _ = writeln!(s, "<p class=\"error\">{}</p>", escape(e));
            }
            if !sc.entries.is_empty() {
                s.push_str("<table><tr><th>name</th><th>object</th><th>what</th></tr>\n");
                for (name, anchor, address, what) in &sc.entries {
                    let _ = writeln!(
                        s,
                        "<tr><td class=\"num\">{}</td><td class=\"num\"><a href=\"#{anchor}\">{address}</a></td><td>{}</td></tr>",
                        escape(name),
                        escape(what)
                    );
                }
                s.push_str("</table>\n");
            }
        }
    }
    s.push_str("<h2 id=\"diagnostics\">Diagnostics</h2>\n");
    if sheet.findings.is_empty() {
        s.push_str("<p><code>odc check</code> finds nothing to report.</p>\n");
    } else {
        s.push_str("<table><tr><th>level</th><th>code</th><th>message</th><th>where</th><th>object</th></tr>\n");
        for f in &sheet.findings {
            let object = f
                .anchor
                .as_ref()
                .map_or(String::new(), |a| format!("<a href=\"#{a}\">{}</a>", object_label(a)));
            let _ = writeln!(
                s,
                "<tr><td class=\"{0}\">{0}</td><td class=\"num\">{1}</td><td>{2}</td><td>{3}</td><td class=\"num\">{object}</td></tr>",
                escape(&f.severity),
                escape(&f.code),
                escape(&f.message),
                escape(&f.at)
            );
        }
        s.push_str("</table>\n");
    }
    objects(&mut s, sheet);
    let _ = write!(s, "<script>{SCRIPT}</script>\n</body>\n</html>\n");
    s
}

/// `o1018-01` → `0x1018:01`.
fn object_label(anchor: &str) -> String {
    let a = anchor.trim_start_matches('o');
    match a.split_once('-') {
        Some((i, sub)) => format!("0x{i}:{sub}"),
        None => format!("0x{a}"),
    }
}

fn pairs(s: &mut String, id: &str, heading: &str, rows: &[(String, String)]) {
    let _ = writeln!(s, "<h2 id=\"{id}\">{heading}</h2>");
    if rows.is_empty() {
        s.push_str("<p>The file says nothing here.</p>\n");
        return;
    }
    s.push_str("<table>\n");
    for (k, v) in rows {
        let _ = writeln!(s, "<tr><th>{}</th><td>{}</td></tr>", escape(k), escape(v));
    }
    s.push_str("</table>\n");
}

fn diagram(s: &mut String, d: &Diagram) {
    let _ = writeln!(
        s,
        "<section class=\"pdo\" id=\"{}\">\n<h3>{}</h3>\n<p class=\"detail\">{}</p>",
        d.anchor,
        escape(&d.title),
        escape(&d.detail)
    );
    if d.fields.is_empty() {
        s.push_str("<p>No entries are mapped by default.</p>\n</section>\n");
        return;
    }
    s.push_str(&svg::diagram(d));
    s.push_str(
        "\n<table><tr><th>bit</th><th>bits</th><th>object</th><th>name</th><th>type</th></tr>\n",
    );
    for f in &d.fields {
        let object = match &f.anchor {
            Some(a) => format!("<a href=\"#{a}\">{}</a>", escape(&f.address)),
            None => escape(&f.address),
        };
        let _ = writeln!(
            s,
            "<tr><td class=\"num\">{}</td><td class=\"num\">{}</td><td class=\"num\">{object}</td><td>{}</td><td>{}</td></tr>",
            f.offset,
            f.bits,
            escape(&f.name),
            escape(&f.data_type)
        );
    }
    s.push_str("</table>\n</section>\n");
}

fn objects(s: &mut String, sheet: &Sheet) {
    let with_value = sheet.objects.iter().any(|r| !r.value.is_empty());
    let with_denotation = sheet.objects.iter().any(|r| !r.denotation.is_empty());
    s.push_str("<h2 id=\"objects\">Objects</h2>\n<p><input id=\"filter\" type=\"search\" placeholder=\"Filter objects by index, name, type…\"></p>\n");
    s.push_str("<table id=\"objects\"><thead><tr><th>index</th><th>sub</th><th>name</th><th>object</th><th>type</th><th>access</th><th>PDO</th><th>default</th>");
    if with_value {
        s.push_str("<th>value</th>");
    }
    s.push_str("<th>low</th><th>high</th>");
    if with_denotation {
        s.push_str("<th>denotation</th>");
    }
    s.push_str("</tr></thead>\n<tbody>\n");
    for r in &sheet.objects {
        let class =
            if r.sub.is_none() && r.data_type.is_empty() { " class=\"object\"" } else { "" };
        let sub = r.sub.map_or(String::new(), |s| format!("{s:02X}"));
        let _ = write!(
            s,
            "<tr id=\"{}\"{class}><td class=\"num\">{:04X}{}</td><td class=\"num\">{sub}</td><td>{}</td><td>{}</td><td>{}</td><td>{}</td><td>{}</td><td class=\"num\">{}</td>",
            r.anchor,
            r.index,
            r.made.marker(),
            escape(&r.name),
            escape(&r.kind),
            escape(&r.data_type),
            escape(&r.access),
            escape(&r.pdo),
            escape(&r.default)
        );
        if with_value {
            let _ = write!(s, "<td class=\"num\">{}</td>", escape(&r.value));
        }
        let _ = write!(
            s,
            "<td class=\"num\">{}</td><td class=\"num\">{}</td>",
            escape(&r.low),
            escape(&r.high)
        );
        if with_denotation {
            let _ = write!(s, "<td>{}</td>", escape(&r.denotation));
        }
        s.push_str("</tr>\n");
    }
    s.push_str("</tbody></table>\n");
    for (mark, what) in crate::sheet::legend(&sheet.objects) {
        let _ = writeln!(s, "<p class=\"legend\">{mark} {}</p>", escape(what));
    }
}
