//! Pack/unpack of two real PDOs of `eds/lxm23a.eds` (RPDO2: controlword + target position;
//! TPDO2: statusword + position actual value; 6 bytes each), four ways in one run:
//! odc's generated code, hand-written shifts and masks, `deku` and `packed_struct`.
//! Each pass packs (or unpacks) 1024 values into (from) 1024 CAN frames of 8 data bytes, the
//! PDO's length known only at run time, as a driver hands frames over; unpack stores every
//! field. `compare.sh` builds this with every loop aligned to 64 bytes (see there).
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
        v.iter().map(|&(a, b)| Rpdo2 { controlword: a.into(), target_position: b }).collect();
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
        assert_eq!((u16::from(t.statusword), t.position_actual_value), want);
        assert_eq!((dk.statusword, dk.position_actual_value), want);
        assert_eq!((p.statusword, p.position_actual_value), want);
    }

    // Into CAN frames as a driver sends them: 8 data bytes, of which the PDO's length is
    // known only at run time (a fixed-size array would let each check be decided at compile
    // time).
    let len = black_box(6usize);
    let mut out = vec![[0u8; 8]; N];
    let mut g = c.benchmark_group("pack_rpdo2_x1024");
    g.bench_function("odc", |bn| {
        bn.iter(|| {
            for (x, o) in black_box(&odc_r).iter().zip(out.iter_mut()) {
                let _ = x.pack_into(&mut o[..len]);
            }
            black_box(&out);
        })
    });
    g.bench_function("hand", |bn| {
        bn.iter(|| {
            for (x, o) in black_box(&hand_r).iter().zip(out.iter_mut()) {
                let _ = x.pack_into(&mut o[..len]);
            }
            black_box(&out);
        })
    });
    g.bench_function("deku", |bn| {
        bn.iter(|| {
            for (x, o) in black_box(&deku_r).iter().zip(out.iter_mut()) {
                let _ = x.to_slice(&mut o[..len]);
            }
            black_box(&out);
        })
    });
    g.bench_function("packed_struct", |bn| {
        bn.iter(|| {
            for (x, o) in black_box(&ps_r).iter().zip(out.iter_mut()) {
                let _ = x.pack_to_slice(&mut o[..len]);
            }
            black_box(&out);
        })
    });
    g.finish();

    // Every field of every frame is unpacked and stored, as pack stores every byte: a pass
    // that used only one field let the optimiser drop the other field's reads and checks
    // (and sum the rest with vector loads), so all four timed the same loop. The frames are
    // what a CAN driver hands over: 8 data bytes and a length known only at run time.
    let can: Vec<([u8; 8], usize)> = frames
        .iter()
        .map(|f| {
            let mut d = [0u8; 8];
            d[..6].copy_from_slice(f);
            (d, len)
        })
        .collect();
    let mut fields = vec![(0u16, 0i32); N];
    let mut g = c.benchmark_group("unpack_tpdo2_x1024");
    g.bench_function("odc", |bn| {
        bn.iter(|| {
            for ((d, n), o) in black_box(&can).iter().zip(fields.iter_mut()) {
                if let Ok(t) = Tpdo2::unpack(&d[..*n]) {
                    *o = (u16::from(t.statusword), t.position_actual_value);
                }
            }
            black_box(&fields);
        })
    });
    g.bench_function("hand", |bn| {
        bn.iter(|| {
            for ((d, n), o) in black_box(&can).iter().zip(fields.iter_mut()) {
                if let Some(t) = HandTpdo2::unpack(&d[..*n]) {
                    *o = (t.statusword, t.position_actual_value);
                }
            }
            black_box(&fields);
        })
    });
    g.bench_function("deku", |bn| {
        bn.iter(|| {
            for ((d, n), o) in black_box(&can).iter().zip(fields.iter_mut()) {
                if let Ok((_, t)) = DekuTpdo2::from_bytes((&d[..*n], 0)) {
                    *o = (t.statusword, t.position_actual_value);
                }
            }
            black_box(&fields);
        })
    });
    g.bench_function("packed_struct", |bn| {
        bn.iter(|| {
            for ((d, n), o) in black_box(&can).iter().zip(fields.iter_mut()) {
                if let Ok(t) = PsTpdo2::unpack_from_slice(&d[..*n]) {
                    *o = (t.statusword, t.position_actual_value);
                }
            }
            black_box(&fields);
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
