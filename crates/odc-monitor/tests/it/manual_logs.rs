//! candump logs of the five manuals' printed frames, decoded with the device files.
//!
//! The logs in `tests/devices/logs/` are made from the frames the tests of `tests/devices`
//! compare with the manuals (their `"ID / bytes"` literals, test by test, with the
//! test's first doc line naming where the manual prints it): no byte is placed by hand, and
//! this test fails when a log and the tests part ways (`ODC_UPDATE_LOGS=1` writes them
//! again). Each log is then decoded with its device file (snapshot, reviewed).
#![allow(clippy::unwrap_used, clippy::expect_used, clippy::panic)]

use std::path::Path;

use odc_monitor::{Decoder, candump};

fn root() -> &'static Path {
    Path::new(concat!(env!("CARGO_MANIFEST_DIR"), "/../.."))
}

/// The tests' sections: (test name, its first doc line, the printed frames).
fn sections(source: &str) -> Vec<(String, String, Vec<String>)> {
    let mut out: Vec<(String, String, Vec<String>)> = Vec::new();
    let mut pending_doc = String::new();
    for line in source.lines() {
        let t = line.trim();
        if let Some(d) = t.strip_prefix("///") {
            // The first line of the doc comment (later paragraphs do not replace it).
            if pending_doc.is_empty() {
                pending_doc = d.trim().to_owned();
            }
            continue;
        }
        if let Some(rest) = t.strip_prefix("fn ").filter(|_| !line.starts_with(' ')) {
            let name = rest.split('(').next().unwrap_or("").to_owned();
            out.push((name, std::mem::take(&mut pending_doc), Vec::new()));
            continue;
        }
        if !t.starts_with("#[") {
            pending_doc.clear();
        }
        // Every string literal that is a printed frame (`printed("…")`, `mode_response("…")`,
        // whatever helper carries it).
        let mut rest = line;
        while let Some(at) = rest.find('"') {
            let after = &rest[at + 1..];
            let Some(end) = after.find('"') else { break };
            let lit = &after[..end];
            if is_frame(lit)
                && let Some(section) = out.last_mut()
            {
                section.2.push(lit.to_owned());
            }
            rest = &after[end + 1..];
        }
    }
    out.retain(|s| !s.2.is_empty());
    out
}

/// `ID / bytes` (hex, up to 8) or `ID RTR`.
fn is_frame(lit: &str) -> bool {
    let hex = |t: &str, n: usize| {
        t.len() <= n && !t.is_empty() && t.chars().all(|c| c.is_ascii_hexdigit())
    };
    if let Some(id) = lit.strip_suffix(" RTR") {
        return hex(id, 3);
    }
    let Some((id, data)) = lit.split_once(" / ") else { return false };
    let bytes: Vec<&str> = data.split(' ').collect();
    hex(id, 3) && bytes.len() <= 8 && bytes.iter().all(|b| b.len() == 2 && hex(b, 2))
}

/// `ID / bytes` (or `ID RTR`) as a candump frame.
fn candump_frame(printed: &str) -> String {
    if let Some(id) = printed.strip_suffix(" RTR") {
        return format!("{:03X}#R1", u32::from_str_radix(id.trim(), 16).unwrap());
    }
    let (id, data) = printed.split_once('/').unwrap();
    let id = u32::from_str_radix(id.trim(), 16).unwrap();
    format!("{id:03X}#{}", data.split_whitespace().collect::<String>())
}

fn log_of(tests: &[&str], manual: &str) -> String {
    let mut log = format!(
        "# {manual}: the frames the manual prints, as the tests of tests/devices compare them\n\
         # ({}); made by crates/odc-monitor/tests/it/manual_logs.rs.\n",
        tests.join(", ")
    );
    let mut t = 0.0f64;
    for file in tests {
        let source =
            std::fs::read_to_string(root().join(format!("tests/devices/tests/it/{file}.rs")))
                .unwrap();
        for (name, doc, frames) in sections(&source) {
            log.push_str(&format!("# {file}::{name}: {doc}\n"));
            t = t.floor() + 1.0;
            for f in frames {
                log.push_str(&format!("({t:.6}) can0 {}\n", candump_frame(&f)));
                t += 0.001;
            }
        }
    }
    log
}

const LOGS: [(&str, &[&str], &str, &str); 5] = [
    ("lxm23a", &["lxm23a"], "eds/lxm23a.eds", "Schneider LXM23A CANopen manual"),
    (
        "lexium-mdrive",
        &["lexium_mdrive", "lexium_mdrive_lss"],
        "eds/lexium-mdrive.eds",
        "Lexium MDrive CANopen manual",
    ),
    ("servoone", &["servoone"], "eds/servoone.eds", "LTI ServoOne CANopen/EtherCAT manual"),
    (
        "lenze-e94aycca",
        &["lenze"],
        "eds/lenze-e94aycca.eds",
        "Lenze E94AYCCA CANopen module manual",
    ),
    ("linmot-e1200", &["linmot"], "eds/linmot-e1200.eds", "LinMot E1200 CANopen manual"),
];

#[test]
fn the_logs_are_the_tests_frames_and_decode() {
    let update = std::env::var_os("ODC_UPDATE_LOGS").is_some();
    for (name, tests, eds, manual) in LOGS {
        let want = log_of(tests, manual);
        let path = root().join(format!("tests/devices/logs/{name}.log"));
        if update {
            std::fs::write(&path, &want).unwrap();
        }
        let have = std::fs::read_to_string(&path).unwrap_or_default();
        assert_eq!(have, want, "{name}.log differs from the tests' frames (ODC_UPDATE_LOGS=1)");
        // Decode with the device at every node-ID the frames use.
        let loaded = odc_pipeline::load(&root().join(eds), &odc_pipeline::Options::new()).unwrap();
        let mut lines = Vec::new();
        let mut frames = Vec::new();
        for line in have.lines() {
            if let Some(f) = candump::parse_line(line).unwrap() {
                frames.push(f);
            }
        }
        let nodes: std::collections::BTreeSet<u8> = frames
            .iter()
            .filter(|f| f.frame.id() > 0x80 && f.frame.id() < 0x780)
            .map(|f| (f.frame.id() & 0x7F) as u8)
            .filter(|n| *n > 0)
            .collect();
        let layouts: Vec<odc_monitor::ProcessLayout> = loaded
            .codegen
            .process_data
            .iter()
            .map(|p| odc_monitor::ProcessLayout {
                name: p.name.clone(),
                cob_base: u32::from_str_radix(p.cob_id.trim_start_matches("0x"), 16).unwrap(),
                fields: p.fields.iter().map(|f| (f.name.clone(), f.ty.clone())).collect(),
            })
            .collect();
        let mut d = Decoder::new(nodes.iter().map(|n| (*n, loaded.devices[0].clone())).collect());
        for n in &nodes {
            d = d.with_process_data(*n, layouts.clone());
        }
        for f in &frames {
            lines.push(d.decode(&f.frame, Some(f.time)).to_string());
        }
        println!("{name}: {} frames, nodes {nodes:?}", frames.len());
        insta::assert_snapshot!(name, lines.join("\n"));
    }
}
