//! Parse speed over the corpus ESI files (`$ODC_CORPUS/MANIFEST.tsv`, kind `esi`), with a bare
//! quick-xml tokenize pass over the same text as the ceiling.
#![allow(missing_docs, clippy::unwrap_used, clippy::expect_used, clippy::panic)]

use std::hint::black_box;
use std::path::PathBuf;

use criterion::{Criterion, Throughput, criterion_group, criterion_main};
use quick_xml::Reader;
use quick_xml::events::Event;

fn corpus() -> Vec<(String, Vec<u8>)> {
    let dir = std::env::var_os("ODC_CORPUS").map(PathBuf::from).unwrap_or_else(|| {
        PathBuf::from(concat!(env!("CARGO_MANIFEST_DIR"), "/../../../shared/corpus"))
    });
    let Ok(manifest) = std::fs::read_to_string(dir.join("MANIFEST.tsv")) else {
        eprintln!("corpus not found at {}; nothing to bench", dir.display());
        return Vec::new();
    };
    manifest
        .lines()
        .skip(1)
        .filter_map(|l| {
            let mut cols = l.split('\t');
            let file = cols.next()?;
            (cols.next()? == "esi").then(|| file.to_string())
        })
        .filter_map(|f| Some((f.clone(), std::fs::read(dir.join(&f)).ok()?)))
        .collect()
}

fn bench(c: &mut Criterion) {
    let files = corpus();
    if files.is_empty() {
        return;
    }
    let total: u64 = files.iter().map(|(_, b)| b.len() as u64).sum();
    // The tokenizer works on text; decode once, outside the measurement.
    let texts: Vec<String> =
        files.iter().map(|(_, b)| String::from_utf8_lossy(b).into_owned()).collect();
    let mut group = c.benchmark_group("esi-corpus");
    group.throughput(Throughput::Bytes(total));
    group.sample_size(10);
    group.bench_function("odc_esi::parse", |b| {
        b.iter(|| {
            let mut sources = odc_model::Sources::new();
            let mut devices = 0;
            for (name, bytes) in &files {
                devices += odc_esi::parse(&mut sources, name, black_box(bytes)).devices.len();
            }
            devices
        })
    });
    group.bench_function("quick-xml tokenize (ceiling)", |b| {
        b.iter(|| {
            let mut events = 0usize;
            for text in &texts {
                let mut reader = Reader::from_str(black_box(text));
                loop {
                    match reader.read_event() {
                        Ok(Event::Eof) | Err(_) => break,
                        Ok(_) => events += 1,
                    }
                }
            }
            events
        })
    });
    group.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
