//! Derived pack/unpack against hand-written code, in the same run:
//!
//! - `pdo_8_bytes_x1024`: the 8-byte, 4-field RPDO of the acceptance criterion (controlword
//!   u16, modes of operation i8, target position i32, a u8 of digital outputs) against
//!   shift-and-mask code on one little-endian u64. The goal is a derived/hand ratio within
//!   1.10.
//! - `pdo_6_bytes_x1024`: a 6-byte, 2-field PDO (statusword u16, position actual value i32, as
//!   `eds/lxm23a.eds` maps TPDO2) against the byte-slice code most people write
//!   (`to_le_bytes`/`from_le_bytes` per field).
//!
//! Each pass packs 1,024 values into 1,024 buffers, or unpacks 1,024 frames and sums a field.
//! Run with `cargo bench -p odc --bench pdo`.
//!
//! Measured 21 November 2026 (x86-64, rustc 1.95, 2 shared cores at load 1.9–2.1, three runs
//! of `--measurement-time 5`), derived/hand:
//!
//! - 8 bytes: pack 0.65–0.72 (454–457 ns against 635–701 ns), unpack 1.07–1.10 (640–643 ns
//!   against 583–600 ns). The two unpack loops are the same instructions (objdump of the bench
//!   binary, RIP-relative operands aside), so the difference is where the code lies: the same
//!   code measured 1.00–1.01 in the build before, and run alone each keeps its time.
//! - 6 bytes: pack 0.99–1.00 (261–267 ns against 262–273 ns), unpack 1.00 (185 ns both).
//!   Before the derive moved byte-aligned fields one by one (it assembled one word from 4 + 2
//!   bytes), 1.37 and 1.70.
#![allow(clippy::unwrap_used, clippy::expect_used, clippy::panic)] // test code: a panic is a failure report
#![allow(missing_docs)] // criterion's macros generate undocumented items

use criterion::{Criterion, criterion_group, criterion_main};
use odc::Pdo;
use std::hint::black_box;

#[derive(Debug, Clone, Copy, PartialEq, odc::Pdo)]
struct Derived8 {
    #[pdo(index = 0x6040)]
    controlword: u16,
    #[pdo(index = 0x6060)]
    mode: i8,
    #[pdo(index = 0x607A)]
    target_position: i32,
    #[pdo(index = 0x2000, sub = 1)]
    outputs: u8,
}

#[derive(Debug, Clone, Copy, PartialEq)]
struct Hand8 {
    controlword: u16,
    mode: i8,
    target_position: i32,
    outputs: u8,
}

impl Hand8 {
    #[inline]
    fn pack_into(&self, buf: &mut [u8]) -> Option<()> {
        let buf = buf.get_mut(..8)?;
        let w = u64::from(self.controlword)
            | (u64::from(self.mode as u8) << 16)
            | (u64::from(self.target_position as u32) << 24)
            | (u64::from(self.outputs) << 56);
        buf.copy_from_slice(&w.to_le_bytes());
        Some(())
    }

    #[inline]
    fn unpack(buf: &[u8]) -> Option<Self> {
        let b: [u8; 8] = buf.get(..8)?.try_into().ok()?;
        let w = u64::from_le_bytes(b);
        Some(Self {
            controlword: w as u16,
            mode: (w >> 16) as u8 as i8,
            target_position: (w >> 24) as u32 as i32,
            outputs: (w >> 56) as u8,
        })
    }
}

#[derive(Debug, Clone, Copy, PartialEq, odc::Pdo)]
struct Derived6 {
    #[pdo(index = 0x6041)]
    statusword: u16,
    #[pdo(index = 0x6064)]
    position: i32,
}

#[derive(Debug, Clone, Copy, PartialEq)]
struct Hand6 {
    statusword: u16,
    position: i32,
}

impl Hand6 {
    #[inline]
    fn pack_into(&self, buf: &mut [u8]) -> Option<()> {
        let buf = buf.get_mut(..6)?;
        buf[..2].copy_from_slice(&self.statusword.to_le_bytes());
        buf[2..6].copy_from_slice(&self.position.to_le_bytes());
        Some(())
    }

    #[inline]
    fn unpack(buf: &[u8]) -> Option<Self> {
        let b: &[u8; 6] = buf.get(..6)?.try_into().ok()?;
        Some(Self {
            statusword: u16::from_le_bytes([b[0], b[1]]),
            position: i32::from_le_bytes([b[2], b[3], b[4], b[5]]),
        })
    }
}

const N: usize = 1024;

/// `N` pseudo-random words.
fn words() -> Vec<u64> {
    let mut x: u64 = 0x9E37_79B9_7F4A_7C15;
    (0..N)
        .map(|_| {
            x ^= x << 13;
            x ^= x >> 7;
            x ^= x << 17;
            x
        })
        .collect()
}

fn bench(c: &mut Criterion) {
    let w = words();

    // 8 bytes, 4 fields.
    let d8: Vec<Derived8> = w
        .iter()
        .map(|&x| Derived8 {
            controlword: x as u16,
            mode: (x >> 16) as i8,
            target_position: (x >> 24) as i32,
            outputs: (x >> 56) as u8,
        })
        .collect();
    let h8: Vec<Hand8> = d8
        .iter()
        .map(|v| Hand8 {
            controlword: v.controlword,
            mode: v.mode,
            target_position: v.target_position,
            outputs: v.outputs,
        })
        .collect();
    let frames8: Vec<[u8; 8]> = w.iter().map(|x| x.to_le_bytes()).collect();
    // Same bytes both ways, or the comparison means nothing.
    for ((dv, hv), f) in d8.iter().zip(&h8).zip(&frames8) {
        let (mut a, mut b) = ([0u8; 8], [0u8; 8]);
        dv.pack_into(&mut a).unwrap();
        hv.pack_into(&mut b).unwrap();
        assert_eq!((a, b), (*f, *f));
        let (du, hu) = (Derived8::unpack(f).unwrap(), Hand8::unpack(f).unwrap());
        assert_eq!(
            (du.controlword, du.mode, du.target_position, du.outputs),
            (hu.controlword, hu.mode, hu.target_position, hu.outputs)
        );
    }

    let mut g = c.benchmark_group("pdo_8_bytes_x1024");
    let mut out = vec![[0u8; 8]; N];
    g.bench_function("pack/derived", |bn| {
        bn.iter(|| {
            for (v, o) in black_box(&d8).iter().zip(out.iter_mut()) {
                let _ = v.pack_into(o);
            }
            black_box(&out);
        })
    });
    g.bench_function("pack/hand", |bn| {
        bn.iter(|| {
            for (v, o) in black_box(&h8).iter().zip(out.iter_mut()) {
                let _ = v.pack_into(o);
            }
            black_box(&out);
        })
    });
    g.bench_function("unpack/derived", |bn| {
        bn.iter(|| {
            let mut acc = 0i64;
            for f in black_box(&frames8) {
                if let Ok(v) = Derived8::unpack(f) {
                    acc = acc.wrapping_add(
                        i64::from(v.target_position) ^ i64::from(v.controlword) ^ i64::from(v.mode),
                    ) ^ i64::from(v.outputs);
                }
            }
            black_box(acc)
        })
    });
    g.bench_function("unpack/hand", |bn| {
        bn.iter(|| {
            let mut acc = 0i64;
            for f in black_box(&frames8) {
                if let Some(v) = Hand8::unpack(f) {
                    acc = acc.wrapping_add(
                        i64::from(v.target_position) ^ i64::from(v.controlword) ^ i64::from(v.mode),
                    ) ^ i64::from(v.outputs);
                }
            }
            black_box(acc)
        })
    });
    g.finish();

    // 6 bytes, 2 fields.
    let d6: Vec<Derived6> =
        w.iter().map(|&x| Derived6 { statusword: x as u16, position: (x >> 16) as i32 }).collect();
    let h6: Vec<Hand6> =
        d6.iter().map(|v| Hand6 { statusword: v.statusword, position: v.position }).collect();
    let frames6: Vec<[u8; 6]> = d6.iter().map(|v| v.pack().unwrap()).collect();
    for ((dv, hv), f) in d6.iter().zip(&h6).zip(&frames6) {
        let mut b = [0u8; 6];
        hv.pack_into(&mut b).unwrap();
        assert_eq!(b, *f);
        let (du, hu) = (Derived6::unpack(f).unwrap(), Hand6::unpack(f).unwrap());
        assert_eq!((du.statusword, du.position), (hu.statusword, hu.position));
        assert_eq!(*dv, du);
    }

    let mut g = c.benchmark_group("pdo_6_bytes_x1024");
    let mut out = vec![[0u8; 6]; N];
    g.bench_function("pack/derived", |bn| {
        bn.iter(|| {
            for (v, o) in black_box(&d6).iter().zip(out.iter_mut()) {
                let _ = v.pack_into(o);
            }
            black_box(&out);
        })
    });
    g.bench_function("pack/hand", |bn| {
        bn.iter(|| {
            for (v, o) in black_box(&h6).iter().zip(out.iter_mut()) {
                let _ = v.pack_into(o);
            }
            black_box(&out);
        })
    });
    g.bench_function("unpack/derived", |bn| {
        bn.iter(|| {
            black_box(&frames6)
                .iter()
                .filter_map(|f| Derived6::unpack(f).ok())
                .fold(0i64, |a, v| a + i64::from(v.position))
        })
    });
    g.bench_function("unpack/hand", |bn| {
        bn.iter(|| {
            black_box(&frames6)
                .iter()
                .filter_map(|f| Hand6::unpack(f))
                .fold(0i64, |a, v| a + i64::from(v.position))
        })
    });
    g.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
