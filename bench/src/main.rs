//! `odc-bench eds|esi LIST [ACCEPTED_DIR]`: times, in this process, each Rust parser of the
//! comparison over the files named in LIST (one path a line), and prints one line per tool:
//! `tool<TAB>files it accepted<TAB>CPU seconds per pass over all the files`. With
//! ACCEPTED_DIR, it only writes there, per tool, the list of files the tool reads without an
//! error (`compare.sh` times every tool on the files all of them read).
//!
//! Each tool runs whole passes over the files (read into memory first: disk time is not in
//! any figure) until it has run for a second and at least three passes; the figure is the
//! median pass. Every tool gets the same bytes; decoding them to text is part of each tool's
//! work (odc decodes UTF-8 or Windows-1252 itself; the others are given `from_utf8_lossy`).

use std::hint::black_box;
use std::time::Duration;

use odc_bench::cpu_ns;
use quick_xml::Reader;
use quick_xml::events::Event;

fn main() {
    let args: Vec<String> = std::env::args().collect();
    let (Some(kind), Some(list)) = (args.get(1), args.get(2)) else {
        eprintln!("usage: odc-bench eds|esi LIST");
        std::process::exit(2);
    };
    let Ok(list) = std::fs::read_to_string(list) else {
        eprintln!("cannot read {list}");
        std::process::exit(2);
    };
    let accepted_dir = args.get(3).cloned();
    let files: Vec<(String, Vec<u8>)> = list
        .lines()
        .filter(|l| !l.is_empty())
        .filter_map(|p| Some((p.to_owned(), std::fs::read(p).ok()?)))
        .collect();
    type Tool = (&'static str, Box<dyn FnMut(&str, &[u8]) -> bool>);
    let mut tools: Vec<Tool> = match kind.as_str() {
        "eds" => vec![
            (
                "odc",
                Box::new(|name, b| {
                    let mut s = odc_model::Sources::new();
                    // A file odc reads with error diagnostics is still read (tolerant parse).
                    black_box(odc_eds::parse(&mut s, name, b));
                    true
                }),
            ),
            (
                // The same, then the sub-objects of every object made: those a `CompactSubObj`
                // implies are made on first read (python-canopen also makes them on access,
                // canopen-host never), so this is the cost once all of them are used. Asking
                // for the last one makes them without timing a walk over them.
                "odc-all-subs",
                Box::new(|name, b| {
                    let mut s = odc_model::Sources::new();
                    let dev = odc_eds::parse(&mut s, name, b).device;
                    let fixed = dev.modules.supported.iter().flat_map(|m| m.fixed_objects.values());
                    for o in dev.objects.values().chain(fixed) {
                        black_box(o.subs.last_key_value());
                    }
                    true
                }),
            ),
            (
                "canopen-host",
                Box::new(|_, b| {
                    let text = String::from_utf8_lossy(b);
                    black_box(canopen_host::eds::Eds::parse(&text)).is_ok()
                }),
            ),
        ],
        "esi" => vec![
            (
                "odc",
                Box::new(|name, b| {
                    let mut s = odc_model::Sources::new();
                    black_box(odc_esi::parse(&mut s, name, b));
                    true
                }),
            ),
            (
                "ethercat-esi",
                Box::new(|_, b| {
                    let text = String::from_utf8_lossy(b);
                    black_box(ethercat_esi::EtherCatInfo::from_xml_str(&text)).is_ok()
                }),
            ),
            (
                "quick-xml",
                Box::new(|_, b| {
                    // The ceiling for any XML parser: every event of the document, nothing built,
                    // nothing copied (events borrow the input; `read_event_into` would copy each
                    // into a buffer and take about 12% longer).
                    let mut reader = Reader::from_reader(b);
                    loop {
                        match reader.read_event() {
                            Ok(Event::Eof) => break true,
                            Err(_) => break false,
                            Ok(e) => {
                                black_box(e);
                            }
                        }
                    }
                }),
            ),
        ],
        _ => {
            eprintln!("usage: odc-bench eds|esi LIST [ACCEPTED_DIR]");
            std::process::exit(2);
        }
    };
    // The physical floor: touch every byte once and count the lines.
    tools.push((
        "floor",
        Box::new(|_, b| {
            black_box(memchr::memchr_iter(b'\n', black_box(b)).count());
            true
        }),
    ));
    if let Some(dir) = accepted_dir {
        for (tool, f) in &mut tools {
            let ok: String =
                files.iter().filter(|(n, b)| f(n, b)).map(|(n, _)| format!("{n}\n")).collect();
            let path = format!("{dir}/{tool}");
            if std::fs::write(&path, ok).is_err() {
                eprintln!("cannot write {path}");
                std::process::exit(2);
            }
        }
        return;
    }
    // ODC_BENCH_ONLY=TOOL times that tool alone (for profiling one parser).
    let only = std::env::var("ODC_BENCH_ONLY").ok();
    for (tool, f) in &mut tools {
        if only.as_deref().is_none_or(|o| o == *tool) {
            report(tool, time(&files, f));
        }
    }
}

/// Files accepted, and the median CPU time of a pass over all files.
fn time(files: &[(String, Vec<u8>)], mut f: impl FnMut(&str, &[u8]) -> bool) -> (usize, f64) {
    let mut passes = Vec::new();
    let mut accepted = 0;
    let start = cpu_ns();
    while passes.len() < 3 || cpu_ns() - start < Duration::from_secs(1).as_nanos() as u64 {
        let t = cpu_ns();
        accepted = files.iter().filter(|(n, b)| f(n, b)).count();
        passes.push((cpu_ns() - t) as f64 / 1e9);
    }
    passes.sort_by(f64::total_cmp);
    (accepted, passes[passes.len() / 2])
}

fn report(tool: &str, (accepted, secs): (usize, f64)) {
    println!("{tool}\t{accepted}\t{secs:.9}");
}
