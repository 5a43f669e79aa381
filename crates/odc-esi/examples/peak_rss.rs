//! Peak memory of reading one ESI file, as a multiple of the file's size.
//!
//! `cargo run --release -p odc-esi --example peak_rss -- FILE [--by-ref]`
//!
//! Reads the file and parses it as `odc` does (`parse_vec`: the bytes become the source text),
//! or with `--by-ref` through `parse(&bytes)` while the caller keeps the bytes. The figure is the
//! kernel's high-water mark of the resident set (VmHWM) minus the resident set before the file
//! was read, so the file's bytes, the decoded text, the element tree and the devices all count.
#![allow(missing_docs, clippy::unwrap_used, clippy::expect_used, clippy::print_stdout)]

fn hwm_kib() -> u64 {
    let s = std::fs::read_to_string("/proc/self/status").unwrap_or_default();
    s.lines()
        .find_map(|l| l.strip_prefix("VmHWM:"))
        .and_then(|v| v.trim().trim_end_matches("kB").trim().parse().ok())
        .unwrap_or(0)
}

fn main() {
    let path = std::env::args().nth(1).expect("usage: peak_rss FILE [--by-ref]");
    let by_ref = std::env::args().nth(2).as_deref() == Some("--by-ref");
    let base = hwm_kib();
    let bytes = std::fs::read(&path).expect("read");
    let size = bytes.len() as f64 / 1024.0;
    let mut sources = odc_model::Sources::new();
    let (how, devices) = if by_ref {
        let parsed = odc_esi::parse(&mut sources, &path, &bytes);
        ("parse(&bytes)", parsed.devices.len())
    } else {
        let parsed = odc_esi::parse_vec(&mut sources, &path, bytes);
        ("parse_vec(bytes)", parsed.devices.len())
    };
    let peak = hwm_kib();
    let used = peak.saturating_sub(base) as f64;
    println!(
        "{path}: {size:.0} KiB, {devices} device(s), {how}: peak RSS {peak} KiB, {used:.0} KiB above the baseline of {base} KiB = {:.2}x the file size",
        used / size
    );
}
