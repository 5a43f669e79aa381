//! Parse throughput over every ESI file of the corpus (`$ODC_CORPUS/MANIFEST.tsv`, kind `esi`)
//! and over the largest one alone, each next to a bare quick-xml tokenize pass over the same
//! text measured in the same run: the ceiling for any XML parser built on quick-xml.
//!
//! `odc_esi::parse` is timed whole: decoding the bytes (a copy into the source text), the
//! element tree, lowering, and dropping the devices it returns; `odc_esi::parse_vec` likewise,
//! with the bytes handed over as `odc` does (their copy made outside the measurement). The
//! tokenize pass reads pre-decoded text and builds nothing.
//!
//! Times are the CPU time of the benchmarking thread (`/proc/thread-self/schedstat`), not wall
//! time: the machines this runs on are shared (two cores, several builds at once), and wall
//! time there measures the neighbours as much as the parser. `ODC_BENCH_WALL=1` measures wall
//! time instead (where that file does not exist, wall time is used too).
#![allow(missing_docs, clippy::unwrap_used, clippy::expect_used, clippy::panic)]

use std::hint::black_box;

#[path = "../../odc-eds/benches/corpus/mod.rs"]
mod corpus;
#[path = "../../odc-eds/benches/cpu_clock/mod.rs"]
mod cpu_clock;
mod tokenize;
use cpu_clock::Clock;
use criterion::{BatchSize, Criterion, Throughput, criterion_group, criterion_main};
use tokenize::tokenize;

fn parse_and_tokenize(c: &mut Criterion<Clock>, group: &str, files: &[&(String, Vec<u8>)]) {
    let bytes: u64 = files.iter().map(|(_, b)| b.len() as u64).sum();
    // The tokenizer works on text; decode once, outside the measurement.
    let texts: Vec<String> =
        files.iter().map(|(_, b)| String::from_utf8_lossy(b).into_owned()).collect();
    let mut g = c.benchmark_group(group);
    g.throughput(Throughput::BytesDecimal(bytes));
    g.sample_size(10);
    g.bench_function("odc_esi::parse", |b| {
        b.iter(|| {
            let mut devices = 0;
            for (name, data) in files {
                let mut sources = odc_model::Sources::new();
                devices += odc_esi::parse(&mut sources, name, black_box(data)).devices.len();
            }
            devices
        })
    });
    // As `odc` calls it: the bytes handed over (copied outside the measurement), decoded in place.
    g.bench_function("odc_esi::parse_vec", |b| {
        b.iter_batched(
            || files.iter().map(|(name, data)| (name.as_str(), data.clone())).collect::<Vec<_>>(),
            |owned| {
                let mut devices = 0;
                for (name, data) in owned {
                    let mut sources = odc_model::Sources::new();
                    devices += odc_esi::parse_vec(&mut sources, name, data).devices.len();
                }
                devices
            },
            BatchSize::PerIteration,
        )
    });
    g.bench_function("quick-xml tokenize", |b| {
        b.iter(|| texts.iter().map(|t| tokenize(black_box(t))).sum::<usize>())
    });
    g.finish();
}

fn bench(c: &mut Criterion<Clock>) {
    let files = corpus::corpus(&["esi"]);
    if files.is_empty() {
        eprintln!("corpus not found (set ODC_CORPUS); nothing to measure");
        return;
    }
    let bytes: usize = files.iter().map(|(_, b)| b.len()).sum();
    eprintln!(
        "{} ESI files, {bytes} bytes; timing {}",
        files.len(),
        if Clock::from_env().cpu { "thread CPU time" } else { "wall time" }
    );
    let all: Vec<&(String, Vec<u8>)> = files.iter().collect();
    parse_and_tokenize(c, "esi-corpus", &all);
    if let Some(largest) = files.iter().max_by_key(|(_, b)| b.len()) {
        eprintln!("largest: {} ({} bytes)", largest.0, largest.1.len());
        parse_and_tokenize(c, "esi-largest", &[largest]);
    }
}

criterion_group! {
    name = benches;
    config = Criterion::default().with_measurement(Clock::from_env());
    targets = bench
}
criterion_main!(benches);
