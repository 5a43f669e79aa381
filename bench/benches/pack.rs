//! Pack/unpack of two real PDOs of `eds/lxm23a.eds` (RPDO2: controlword + target position;
//! TPDO2: statusword + position actual value; 6 bytes each), four ways in one run:
//! odc's generated code, hand-written shifts and masks, `deku` and `packed_struct`.
//! Each pass packs (or unpacks) 1024 values into (from) 1024 buffers.
#![allow(missing_docs, clippy::unwrap_used, clippy::expect_used)]

use criterion::{Criterion, criterion_group, criterion_main};
use deku::{DekuContainerRead, DekuContainerWrite, DekuRead, DekuWrite};
use odc::Pdo;
use odc_bench::lxm23a::pdo::{Rpdo2, Tpdo2};
use packed_struct::prelude::*;
use std::hint::black_box;

/// RPDO2 by hand: the bytes are little-endian fields in mapping order.
#[derive(Clone, Copy, Debug, PartialEq)]
struct HandRpdo2 {
    controlword: u16,
    target_position: i32,
}

impl HandRpdo2 {
    #[inline]
    fn pack_into(&self, buf: &mut [u8]) -> Option<()> {
        let buf = buf.get_mut(..6)?;
        buf[..2].copy_from_slice(&self.controlword.to_le_bytes());
        buf[2..6].copy_from_slice(&self.target_position.to_le_bytes());
        Some(())
    }
    #[inline]
    fn unpack(buf: &[u8]) -> Option<Self> {
        let b: &[u8; 6] = buf.get(..6)?.try_into().ok()?;
        Some(Self {
            controlword: u16::from_le_bytes([b[0], b[1]]),
            target_position: i32::from_le_bytes([b[2], b[3], b[4], b[5]]),
        })
    }
}

/// TPDO2 by hand.
#[derive(Clone, Copy, Debug, PartialEq)]
struct HandTpdo2 {
    statusword: u16,
    position_actual_value: i32,
}

impl HandTpdo2 {
    #[inline]
    fn unpack(buf: &[u8]) -> Option<Self> {
        let b: &[u8; 6] = buf.get(..6)?.try_into().ok()?;
        Some(Self {
            statusword: u16::from_le_bytes([b[0], b[1]]),
            position_actual_value: i32::from_le_bytes([b[2], b[3], b[4], b[5]]),
        })
    }
}

#[derive(Clone, Copy, Debug, PartialEq, DekuRead, DekuWrite)]
#[deku(endian = "little")]
struct DekuRpdo2 {
    controlword: u16,
    target_position: i32,
}

#[derive(Clone, Copy, Debug, PartialEq, DekuRead, DekuWrite)]
#[deku(endian = "little")]
struct DekuTpdo2 {
    statusword: u16,
    position_actual_value: i32,
}

#[derive(Clone, Copy, Debug, PartialEq, PackedStruct)]
#[packed_struct(endian = "lsb", bit_numbering = "msb0")]
struct PsRpdo2 {
    #[packed_field(bytes = "0..=1")]
    controlword: u16,
    #[packed_field(bytes = "2..=5")]
    target_position: i32,
}

#[derive(Clone, Copy, Debug, PartialEq, PackedStruct)]
#[packed_struct(endian = "lsb", bit_numbering = "msb0")]
struct PsTpdo2 {
    #[packed_field(bytes = "0..=1")]
    statusword: u16,
    #[packed_field(bytes = "2..=5")]
    position_actual_value: i32,
}

const N: usize = 1024;

fn values() -> Vec<(u16, i32)> {
    let mut x: u64 = 0x9E37_79B9_7F4A_7C15;
    (0..N)
        .map(|_| {
            x ^= x << 13;
            x ^= x >> 7;
            x ^= x << 17;
            (x as u16, (x >> 16) as i32)
        })
        .collect()
}

fn bench(c: &mut Criterion) {
    let v = values();
    let odc_r: Vec<Rpdo2> =
        v.iter().map(|&(a, b)| Rpdo2 { controlword: a, target_position: b }).collect();
    let hand_r: Vec<HandRpdo2> =
        v.iter().map(|&(a, b)| HandRpdo2 { controlword: a, target_position: b }).collect();
    let deku_r: Vec<DekuRpdo2> =
        v.iter().map(|&(a, b)| DekuRpdo2 { controlword: a, target_position: b }).collect();
    let ps_r: Vec<PsRpdo2> =
        v.iter().map(|&(a, b)| PsRpdo2 { controlword: a, target_position: b }).collect();
    let frames: Vec<[u8; 6]> = hand_r
        .iter()
        .map(|h| {
            let mut f = [0u8; 6];
            h.pack_into(&mut f).unwrap();
            f
        })
        .collect();

    // All four agree on every byte and value, or the timings compare different work.
    for i in 0..N {
        let mut a = [0u8; 6];
        odc_r[i].pack_into(&mut a).unwrap();
        let mut d = [0u8; 6];
        assert_eq!(deku_r[i].to_slice(&mut d).unwrap(), 6);
        assert_eq!(
            (a, d, PackedStruct::pack(&ps_r[i]).unwrap()),
            (frames[i], frames[i], frames[i])
        );
        // The hand-written reference itself reads back what it wrote.
        assert_eq!(HandRpdo2::unpack(&frames[i]), Some(hand_r[i]));
        let t = Tpdo2::unpack(&frames[i]).unwrap();
        let h = HandTpdo2::unpack(&frames[i]).unwrap();
        let (_, dk) = DekuTpdo2::from_bytes((&frames[i], 0)).unwrap();
        let p = <PsTpdo2 as PackedStruct>::unpack(&frames[i]).unwrap();
        let want = (h.statusword, h.position_actual_value);
        assert_eq!((t.statusword, t.position_actual_value), want);
        assert_eq!((dk.statusword, dk.position_actual_value), want);
        assert_eq!((p.statusword, p.position_actual_value), want);
    }

    let mut out = vec![[0u8; 6]; N];
    let mut g = c.benchmark_group("pack_rpdo2_x1024");
    g.bench_function("odc", |bn| {
        bn.iter(|| {
            for (x, o) in black_box(&odc_r).iter().zip(out.iter_mut()) {
                let _ = x.pack_into(o);
            }
            black_box(&out);
        })
    });
    g.bench_function("hand", |bn| {
        bn.iter(|| {
            for (x, o) in black_box(&hand_r).iter().zip(out.iter_mut()) {
                let _ = x.pack_into(o);
            }
            black_box(&out);
        })
    });
    g.bench_function("deku", |bn| {
        bn.iter(|| {
            for (x, o) in black_box(&deku_r).iter().zip(out.iter_mut()) {
                let _ = x.to_slice(o);
            }
            black_box(&out);
        })
    });
    g.bench_function("packed_struct", |bn| {
        bn.iter(|| {
            for (x, o) in black_box(&ps_r).iter().zip(out.iter_mut()) {
                if let Ok(b) = PackedStruct::pack(x) {
                    *o = b;
                }
            }
            black_box(&out);
        })
    });
    g.finish();

    let mut g = c.benchmark_group("unpack_tpdo2_x1024");
    g.bench_function("odc", |bn| {
        bn.iter(|| {
            black_box(&frames)
                .iter()
                .filter_map(|f| Tpdo2::unpack(f).ok())
                .fold(0i64, |a, t| a + i64::from(t.position_actual_value))
        })
    });
    g.bench_function("hand", |bn| {
        bn.iter(|| {
            black_box(&frames)
                .iter()
                .filter_map(|f| HandTpdo2::unpack(f))
                .fold(0i64, |a, t| a + i64::from(t.position_actual_value))
        })
    });
    g.bench_function("deku", |bn| {
        bn.iter(|| {
            black_box(&frames)
                .iter()
                .filter_map(|f| DekuTpdo2::from_bytes((f, 0)).ok())
                .fold(0i64, |a, (_, t)| a + i64::from(t.position_actual_value))
        })
    });
    g.bench_function("packed_struct", |bn| {
        bn.iter(|| {
            black_box(&frames)
                .iter()
                .filter_map(|f| <PsTpdo2 as PackedStruct>::unpack(f).ok())
                .fold(0i64, |a, t| a + i64::from(t.position_actual_value))
        })
    });
    g.finish();
}

criterion_group! {
    name = benches;
    config = Criterion::default().sample_size(20).warm_up_time(std::time::Duration::from_millis(500)).measurement_time(std::time::Duration::from_secs(2));
    targets = bench
}
criterion_main!(benches);
