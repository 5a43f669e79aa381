//! Parses one ESI file and reports its size and the peak resident set (VmHWM) before and after.
//! `cargo run --release -p odc-esi --example peak_rss -- FILE`
#![allow(missing_docs, clippy::unwrap_used, clippy::expect_used, clippy::print_stdout)]

fn hwm_kib() -> u64 {
    let s = std::fs::read_to_string("/proc/self/status").unwrap_or_default();
    s.lines()
        .find_map(|l| l.strip_prefix("VmHWM:"))
        .and_then(|v| v.trim().trim_end_matches("kB").trim().parse().ok())
        .unwrap_or(0)
}

fn main() {
    let path = std::env::args().nth(1).expect("usage: peak_rss FILE");
    let base = hwm_kib();
    let bytes = std::fs::read(&path).expect("read");
    let with_file = hwm_kib();
    let mut sources = odc_model::Sources::new();
    let parsed = odc_esi::parse(&mut sources, &path, &bytes);
    let peak = hwm_kib();
    let size = bytes.len() as f64 / 1024.0;
    let used = peak.saturating_sub(base) as f64;
    println!(
        "file {size:.0} KiB, devices {}, baseline {base} KiB, after read {with_file} KiB, peak {peak} KiB, peak-baseline {used:.0} KiB = {:.2}x file size",
        parsed.devices.len(),
        used / size
    );
}
