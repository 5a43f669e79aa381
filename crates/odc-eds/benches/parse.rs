//! Parse throughput over every EDS/DCF file of the corpus (decode + scan + lower, including
//! `Sources::add`), and a floor (count the lines of the same bytes) to compare it with.
//!
//! Times are the CPU time of the benchmarking thread (`/proc/thread-self/schedstat`), not wall
//! time: the machines this runs on are shared (two cores, several builds at once), and wall
//! time there measures the neighbours as much as the parser. `ODC_BENCH_WALL=1` measures wall
//! time instead (where that file does not exist, wall time is used too).
#![allow(missing_docs)]

use std::hint::black_box;

mod corpus;
mod cpu_clock;
use cpu_clock::Clock;
use criterion::{Criterion, Throughput, criterion_group, criterion_main};

fn bench(c: &mut Criterion<Clock>) {
    let files = corpus::corpus(&["eds", "dcf"]);
    if files.is_empty() {
        eprintln!("corpus not found (set ODC_CORPUS); nothing to measure");
        return;
    }
    let bytes: u64 = files.iter().map(|(_, b)| b.len() as u64).sum();
    eprintln!(
        "{} EDS/DCF files, {bytes} bytes; timing {}",
        files.len(),
        if Clock::from_env().cpu { "thread CPU time" } else { "wall time" }
    );
    let mut g = c.benchmark_group("eds");
    g.throughput(Throughput::BytesDecimal(bytes));
    g.sample_size(20);
    g.bench_function("parse_corpus", |b| {
        b.iter(|| {
            for (name, data) in &files {
                let mut sources = odc_model::Sources::new();
                black_box(odc_eds::parse(&mut sources, name, data));
            }
        })
    });
    // The floor: read every byte once and count the lines; `parse_corpus / floor` is the cost
    // of parsing relative to merely touching the input.
    g.bench_function("floor", |b| {
        b.iter(|| {
            let mut lines = 0usize;
            for (_, data) in &files {
                lines += memchr::memchr_iter(b'\n', black_box(data)).count();
            }
            black_box(lines)
        })
    });
    g.finish();
}

criterion_group! {
    name = benches;
    config = Criterion::default().with_measurement(Clock::from_env());
    targets = bench
}
criterion_main!(benches);
