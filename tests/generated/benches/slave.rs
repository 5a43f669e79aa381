//! Lookup by (index, sub-index) in generated slave dictionaries: the 500-object dictionary of
//! `build.rs` (900 entries) and `eds/lenze-e94aycca.eds`, the largest device of `eds/`.
//!
//! Each iteration visits 1,024 addresses of the dictionary in a pseudo-random order (so that
//! the branch predictor cannot learn the search path); the throughput line gives lookups per
//! second, and 1,000 / (Melem/s) is the time of one lookup in ns. The goal is ≤ 20 ns per
//! lookup in a 500-object dictionary.
//!
//! - `read`: a whole SDO upload (`Dictionary::read`: the binary search of the table's rows,
//!   access check, copy into a buffer);
//! - `read_missing`: uploads of addresses that do not exist (the abort path).
//!
//! Measured 21 November 2026 (x86-64, rustc 1.95, 2 shared cores at load 3–4;
//! `cargo bench -p odc-tests-generated --bench slave`): `find` 7.5 ns, `read` 7.3 ns,
//! `read_missing` 7.6 ns per lookup in the 500-object dictionary; 7.9, 11.4 and 8.5 ns in
//! lenze's 787 entries. The generator before the `KEYS` table (binary search of `ENTRIES`,
//! 24-byte entries) took 30 and 33 ns. Since then the dictionary is a table of 24-byte rows
//! (`odc::slave::Table`) searched directly, and `find` over `KEYS` is gone; not measured again.
#![allow(clippy::unwrap_used, clippy::expect_used, clippy::panic)] // bench code: a panic is a failure report
#![allow(missing_docs)] // criterion's macros generate undocumented items

use criterion::{Criterion, Throughput, criterion_group, criterion_main};
use std::hint::black_box;

/// The made-up 500-object device of `build.rs`, slave side. (The bench uses only its
/// dictionary, not every descriptor and PDO.)
#[allow(dead_code)]
mod bench500 {
    odc::include_od!("bench500");
}

/// Lenze E94AYCCA (`eds/lenze-e94aycca.eds`), slave side.
#[allow(dead_code)]
mod lenze_e94aycca {
    odc::include_od!("lenze_e94aycca");
}

const N: usize = 1024;

/// `N` addresses of `table`, in a fixed pseudo-random order.
fn addresses(table: &[odc::slave::Row]) -> Vec<(u16, u8)> {
    let mut x: u64 = 0x9E37_79B9_7F4A_7C15;
    (0..N)
        .map(|_| {
            x ^= x << 13;
            x ^= x >> 7;
            x ^= x << 17;
            let e = &table[(x % table.len() as u64) as usize];
            (e.addr().index, e.addr().sub)
        })
        .collect()
}

macro_rules! dictionary_benches {
    ($c:expr, $name:literal, $m:ident) => {{
        let table = $m::slave::TABLE.rows();
        let addrs = addresses(table);
        // Misses: sub-indexes past the end of existing objects, and indexes nobody uses.
        let missing: Vec<(u16, u8)> = addrs
            .iter()
            .enumerate()
            .map(|(n, &(i, _))| if n % 2 == 0 { (i, 0xFE) } else { (0x5F00 + n as u16, 0) })
            .collect();
        let dict = $m::slave::Dictionary::new(odc::node_id!(5));
        // Every address is found.
        let mut buf = [0u8; 256];
        for &(i, s) in &addrs {
            assert!(!matches!(
                dict.read(i, s, &mut buf),
                Err(odc::SdoAbort::NoSuchObject | odc::SdoAbort::NoSuchSub)
            ));
        }
        let mut g = $c.benchmark_group(concat!("slave_", $name, "_x1024"));
        g.throughput(Throughput::Elements(N as u64));
        g.bench_function("read", |b| {
            let mut buf = [0u8; 256];
            b.iter(|| {
                let mut acc = 0usize;
                for &(i, s) in black_box(&addrs) {
                    acc = acc.wrapping_add(dict.read(i, s, &mut buf).unwrap_or(0));
                }
                black_box(acc)
            })
        });
        g.bench_function("read_missing", |b| {
            let mut buf = [0u8; 256];
            b.iter(|| {
                let mut acc = 0u32;
                for &(i, s) in black_box(&missing) {
                    if let Err(e) = dict.read(i, s, &mut buf) {
                        acc = acc.wrapping_add(e.to_u32());
                    }
                }
                black_box(acc)
            })
        });
        g.finish();
    }};
}

fn bench(c: &mut Criterion) {
    assert_eq!(bench500::slave::TABLE.len(), 900);
    dictionary_benches!(c, "bench500", bench500);
    dictionary_benches!(c, "lenze_e94aycca", lenze_e94aycca);
}

criterion_group!(benches, bench);
criterion_main!(benches);
