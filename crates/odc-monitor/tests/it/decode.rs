//! The decoder on the LXM23A manual's frames (tests/devices/logs/lxm23a.log, the literal bytes
//! of its figures), and on transfers and remaps built by hand from CiA 301's protocol.
#![allow(clippy::unwrap_used, clippy::expect_used, clippy::panic)]

use std::path::Path;

use odc::can::CanFrame;
use odc_monitor::{Decoder, candump};

fn root() -> &'static Path {
    Path::new(concat!(env!("CARGO_MANIFEST_DIR"), "/../.."))
}

fn lxm23a() -> Decoder {
    let loaded =
        odc_pipeline::load(&root().join("eds/lxm23a.eds"), &odc_pipeline::Options::new()).unwrap();
    Decoder::new(vec![(1, loaded.devices[0].clone())])
}

fn frame(id: u32, data: &[u8]) -> CanFrame {
    CanFrame::from_slice(id, data).unwrap()
}

#[test]
fn the_manual_log_decodes_with_its_names_and_values() {
    let text = std::fs::read_to_string(root().join("tests/devices/logs/lxm23a.log")).unwrap();
    let mut d = lxm23a();
    let mut lines = Vec::new();
    for line in text.lines() {
        if let Some(f) = candump::parse_line(line).unwrap() {
            lines.push(d.decode(&f.frame, Some(f.time)).to_string());
        }
    }
    let all = lines.join("\n");
    // What the manual names (6.4.1.1 and figures 11/12), each with its value.
    for want in [
        "0x1000:00 Device type = 131474 (0x20192)",
        "Profile acceleration = 2000",
        "Profile deceleration = 4000",
        "Profile velocity = 4000",
        "NMT: Start all nodes",
        "Modes of operation = 1",
        "Modes of operation display = 1",
        "Controlword = 6 (0x6) (Shutdown)",
        "Controlword = 95 (0x5F) (EnableOperation), Target position = 30000",
        "Statusword = 22071 (0x5637) (operation enabled), Position actual value = 30000",
    ] {
        assert!(all.contains(want), "missing `{want}` in:\n{all}");
    }
    // The 94 frames counted in tests/devices/README.md for the LXM23A, less Fig. 33's two
    // heartbeats, whose data byte the print does not give (not in the log).
    assert_eq!(lines.len(), 92, "the 92 frames of tests/devices/logs/lxm23a.log");
    insta::assert_snapshot!(all);
}

#[test]
fn a_segmented_upload_is_put_together() {
    let loaded =
        odc_pipeline::load(&root().join("eds/lexium-mdrive.eds"), &odc_pipeline::Options::new())
            .unwrap();
    let mut d = Decoder::new(vec![(1, loaded.devices[0].clone())]);
    // 0x1008 (device name, VISIBLE_STRING), 11 bytes: initiate answer with size, then two
    // segments, the toggle alternating, the last with c = 1 and 3 unused bytes (CiA 301
    // 7.2.4.3.4/5).
    let frames = [
        (0x601, [0x40, 0x08, 0x10, 0x00, 0, 0, 0, 0]),
        (0x581, [0x41, 0x08, 0x10, 0x00, 11, 0, 0, 0]),
        (0x601, [0x60, 0, 0, 0, 0, 0, 0, 0]),
        (0x581, [0x00, b'L', b'X', b'M', b'2', b'3', b'A', b' ']),
        (0x601, [0x70, 0, 0, 0, 0, 0, 0, 0]),
        (0x581, [0x17, b'd', b'e', b'v', b'1', 0, 0, 0]),
    ];
    let records: Vec<_> = frames.iter().map(|(id, b)| d.decode(&frame(*id, b), None)).collect();
    let last = records.last().unwrap();
    assert_eq!(last.fields.len(), 1, "{last}");
    assert_eq!(last.fields[0].object, "0x1008:00");
    assert_eq!(last.fields[0].name, "Manufacturer device name");
    assert_eq!(last.fields[0].value, "\"LXM23A dev1\"");
    assert!(records[3].fields.is_empty(), "no value before the last segment");
}

#[test]
fn a_remap_on_the_bus_changes_how_a_pdo_reads() {
    let mut d = lxm23a();
    let sdo = |d: &mut Decoder, req: [u8; 8]| {
        d.decode(&frame(0x601, &req), None);
        let mut ok = [0x60, req[1], req[2], req[3], 0, 0, 0, 0];
        ok[0] = 0x60;
        d.decode(&frame(0x581, &ok), None)
    };
    // TPDO2 (0x1A01): one entry, 0x606C velocity actual value, 32 bits (CiA 301: count 0,
    // entry, count 1).
    sdo(&mut d, [0x2F, 0x01, 0x1A, 0x00, 0, 0, 0, 0]);
    sdo(&mut d, [0x23, 0x01, 0x1A, 0x01, 0x20, 0x00, 0x6C, 0x60]);
    sdo(&mut d, [0x2F, 0x01, 0x1A, 0x00, 1, 0, 0, 0]);
    let r = d.decode(&frame(0x281, &(-1234i32).to_le_bytes()), None);
    assert_eq!(r.fields.len(), 1, "{r}");
    assert_eq!((r.fields[0].object.as_str(), r.fields[0].value.as_str()), ("0x606C:00", "-1234"));
    // A frame nothing explains stays, raw.
    let u = d.decode(&frame(0x7F0, &[1, 2]), None);
    assert_eq!((u.kind.as_str(), u.data.as_str()), ("unknown", "01 02"));
}

/// CiA 311 `allowedValues/value` labels name values: the monitor shows the file's name beside
/// the value, in SDO answers and in PDOs; where the file names nothing, CiA 402's names stay.
#[test]
fn values_show_the_names_the_file_gives_them() {
    let file = root().join("crates/odc-monitor/tests/data/value-names.xdd");
    let loaded = odc_pipeline::load(&file, &odc_pipeline::Options::new()).unwrap();
    let mut d = Decoder::new(vec![(1, loaded.devices[0].clone())]);
    let mut line = |id, data: &[u8]| d.decode(&frame(id, data), None).to_string();
    // SDO upload answers (CiA 301 7.2.4.3.3: 4F = expedited, 1 byte), node 1.
    let brake = line(0x581, &[0x4F, 0x00, 0x20, 0x00, 0x01, 0, 0, 0]);
    assert!(brake.contains("Brake mode = 1 (0x1) (Engaged)"), "{brake}");
    let mode = line(0x581, &[0x4F, 0x60, 0x60, 0x00, 0x01, 0, 0, 0]);
    assert!(mode.contains("Modes of operation = 1 (Point to point)"), "{mode}");
    let display = line(0x581, &[0x4F, 0x61, 0x60, 0x00, 0x03, 0, 0, 0]);
    assert!(display.contains("Modes of operation display = 3 (Profile velocity"), "{display}");
    // TPDO1 (0x180 + 1) maps 0x2000 (8 bits) by the file's default.
    let pdo = line(0x181, &[0x00]);
    assert!(pdo.contains("Brake mode = 0 (0x0) (Released)"), "{pdo}");
}
