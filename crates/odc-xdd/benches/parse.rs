//! Parse throughput over every XDD/XDC file of the corpus (`$ODC_CORPUS/MANIFEST.tsv`, kind
//! `xdd`), next to a bare quick-xml tokenize pass over the same text measured in the same run:
//! the ceiling for any XML parser built on quick-xml (as the ESI bench does for `odc-esi`).
//!
//! `odc_xdd::parse` is timed whole: decoding (a copy into the source text), the element tree,
//! lowering and dropping the device. The tokenize pass reads pre-decoded text and builds
//! nothing. Times are the benchmarking thread's CPU time (see the ESI bench's `cpu_clock`);
//! `ODC_BENCH_WALL=1` measures wall time.
#![allow(missing_docs, clippy::unwrap_used, clippy::expect_used, clippy::panic)]

use std::hint::black_box;

#[path = "../../odc-eds/benches/corpus/mod.rs"]
mod corpus;
#[path = "../../odc-eds/benches/cpu_clock/mod.rs"]
mod cpu_clock;
#[path = "../../odc-esi/benches/tokenize/mod.rs"]
mod tokenize;
use cpu_clock::Clock;
use criterion::{Criterion, Throughput, criterion_group, criterion_main};
use tokenize::tokenize;

fn bench(c: &mut Criterion<Clock>) {
    let files = corpus::corpus(&["xdd"]);
    if files.is_empty() {
        eprintln!("corpus not found (set ODC_CORPUS); nothing to measure");
        return;
    }
    let bytes: u64 = files.iter().map(|(_, b)| b.len() as u64).sum();
    eprintln!("{} XDD files, {bytes} bytes", files.len());
    let texts: Vec<String> =
        files.iter().map(|(_, b)| String::from_utf8_lossy(b).into_owned()).collect();
    let mut g = c.benchmark_group("xdd-corpus");
    g.throughput(Throughput::BytesDecimal(bytes));
    g.sample_size(10);
    g.bench_function("odc_xdd::parse", |b| {
        b.iter(|| {
            let mut objects = 0;
            for (name, data) in &files {
                let mut sources = odc_model::Sources::new();
                let p = odc_xdd::parse(&mut sources, name, black_box(data));
                objects += p.device.map_or(0, |d| d.objects.len());
            }
            objects
        })
    });
    g.bench_function("quick-xml tokenize", |b| {
        b.iter(|| texts.iter().map(|t| tokenize(black_box(t))).sum::<usize>())
    });
    g.finish();
}

criterion_group! {
    name = benches;
    config = Criterion::default().with_measurement(Clock::from_env());
    targets = bench
}
criterion_main!(benches);
