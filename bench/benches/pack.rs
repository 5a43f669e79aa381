//! Pack/unpack of two real PDOs of `eds/lxm23a.eds` (RPDO2: controlword + target position;
//! TPDO2: statusword + position actual value; 6 bytes each), four ways in one run: odc's
//! generated code, hand-written `to_le_bytes`/`from_le_bytes`, `deku` and `packed_struct`.
//!
//! One pass packs (or unpacks) 1024 values into (from) 1024 CAN frames of 8 data bytes, the
//! PDO's length known only at run time, as a driver hands frames over; unpack stores every
//! field. Each pass is a function of its own that is never inlined, so the loop criterion
//! times is the very code whose instructions the count mode counts:
//!
//! - `cargo bench --bench pack`: criterion timings (`compare.sh` builds it with every loop
//!   aligned to 64 bytes and runs it several times: see there);
//! - `ODC_PACK_COUNT="pack|unpack TOOL PASSES" BENCH_BINARY`: PASSES passes of one tool and
//!   nothing else, for `valgrind --tool=callgrind --toggle-collect='*pass_pack_odc'`, an
//!   instruction count no neighbour on the machine can disturb.
//!
//! Everything lives in this bench binary, not in the library: here every function is
//! private to the program, so the optimiser inlines a tool's single-use functions into its
//! pass (deku's `from_bytes` is inlined here and called out of line from a library).
#![allow(missing_docs, clippy::unwrap_used, clippy::expect_used)]

use criterion::measurement::{Measurement, ValueFormatter, WallTime};
use criterion::{Criterion, criterion_group};
use std::hint::black_box;

use deku::{DekuContainerRead, DekuContainerWrite, DekuRead, DekuWrite};
use odc::Pdo;
use odc_bench::lxm23a::pdo::{Rpdo2, Tpdo2};
use packed_struct::prelude::*;

/// Values a pass packs or unpacks.
const N: usize = 1024;

/// RPDO2 by hand: the bytes are little-endian fields in mapping order.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
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
}

/// TPDO2 by hand.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
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

#[derive(Clone, Copy, Debug, Default, PartialEq, DekuRead, DekuWrite)]
#[deku(endian = "little")]
struct DekuRpdo2 {
    controlword: u16,
    target_position: i32,
}

#[derive(Clone, Copy, Debug, Default, PartialEq, DekuRead, DekuWrite)]
#[deku(endian = "little")]
struct DekuTpdo2 {
    statusword: u16,
    position_actual_value: i32,
}

#[derive(Clone, Copy, Debug, Default, PartialEq, PackedStruct)]
#[packed_struct(endian = "lsb", bit_numbering = "msb0")]
struct PsRpdo2 {
    #[packed_field(bytes = "0..=1")]
    controlword: u16,
    #[packed_field(bytes = "2..=5")]
    target_position: i32,
}

#[derive(Clone, Copy, Debug, Default, PartialEq, PackedStruct)]
#[packed_struct(endian = "lsb", bit_numbering = "msb0")]
struct PsTpdo2 {
    #[packed_field(bytes = "0..=1")]
    statusword: u16,
    #[packed_field(bytes = "2..=5")]
    position_actual_value: i32,
}

/// Storage that starts on a 4 KiB page. Every tool's input and the output then sit at the
/// same offset from each other modulo 4096: where a load's address matches an earlier store's
/// in its low 12 bits the CPU holds the load back (4K aliasing), and with `Vec`s wherever the
/// allocator put them odc's input happened to sit 16 bytes past the output modulo 4096 and
/// the hand-written one's 688, a difference in the data, not in the code (both passes are the
/// same instructions).
#[repr(C, align(4096))]
struct Page<T>(T);

/// `N` values on a page of their own.
type Paged<T> = Box<Page<[T; N]>>;

fn paged<T: Copy + Default>(values: impl Iterator<Item = T>) -> Paged<T> {
    let mut p = Box::new(Page([T::default(); N]));
    for (slot, v) in p.0.iter_mut().zip(values) {
        *slot = v;
    }
    p
}

/// The inputs of every pass: the same 1024 values in each tool's type, and the frames they
/// make.
struct Inputs {
    odc: Paged<Rpdo2>,
    hand: Paged<HandRpdo2>,
    deku: Paged<DekuRpdo2>,
    packed_struct: Paged<PsRpdo2>,
    /// What a CAN driver hands over: 8 data bytes and the length (6).
    can: Paged<([u8; 8], usize)>,
    /// The PDO's length, opaque to the optimiser (a constant would let it decide each
    /// check at compile time).
    len: usize,
}

/// Pseudo-random (xorshift) values, the same in every run.
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

impl Inputs {
    /// The inputs, after checking that every tool's pass gives the same bytes and values (or
    /// the timings would compare different work): the first disagreement is the error. The
    /// check runs the passes themselves, so each tool's functions have the one caller they
    /// have in a program that only packs (its pass) and are inlined or not as there.
    fn new() -> Result<Self, String> {
        let v = values();
        let len = black_box(6usize);
        let inp = Self {
            odc: paged(v.iter().map(|&(a, b)| Rpdo2 { controlword: a.into(), target_position: b })),
            hand: paged(v.iter().map(|&(a, b)| HandRpdo2 { controlword: a, target_position: b })),
            deku: paged(v.iter().map(|&(a, b)| DekuRpdo2 { controlword: a, target_position: b })),
            packed_struct: paged(
                v.iter().map(|&(a, b)| PsRpdo2 { controlword: a, target_position: b }),
            ),
            // The reference frames, written out here rather than by any of the four: the
            // fields little-endian in mapping order, then two bytes no PDO byte reaches.
            can: paged(v.iter().map(|&(a, b)| {
                let mut f = [0u8; 8];
                f[..2].copy_from_slice(&a.to_le_bytes());
                f[2..6].copy_from_slice(&b.to_le_bytes());
                (f, len)
            })),
            len,
        };
        for tool in TOOLS {
            let mut out = paged(std::iter::repeat([0xA5u8; 8]));
            pack(tool, &inp, &mut out.0);
            for (i, (o, (want, _))) in out.0.iter().zip(&inp.can.0).enumerate() {
                if o[..6] != want[..6] || o[6..] != [0xA5, 0xA5] {
                    return Err(format!("{tool} packed value {i} as {o:02X?}, want {want:02X?}"));
                }
            }
            let mut fields: Paged<(u16, i32)> = paged(std::iter::empty());
            unpack(tool, &inp, &mut fields.0);
            if let Some(i) = (0..N).find(|&i| fields.0[i] != v[i]) {
                return Err(format!(
                    "{tool} unpacked frame {i} as {:?}, want {:?}",
                    fields.0[i], v[i]
                ));
            }
        }
        Ok(inp)
    }
}

/// Pack passes: `out` gets 1024 frames.
#[inline(never)]
fn pass_pack_odc(xs: &[Rpdo2], out: &mut [[u8; 8]], len: usize) {
    for (x, o) in xs.iter().zip(out.iter_mut()) {
        let _ = x.pack_into(&mut o[..len]);
    }
}

#[inline(never)]
fn pass_pack_hand(xs: &[HandRpdo2], out: &mut [[u8; 8]], len: usize) {
    for (x, o) in xs.iter().zip(out.iter_mut()) {
        let _ = x.pack_into(&mut o[..len]);
    }
}

#[inline(never)]
fn pass_pack_deku(xs: &[DekuRpdo2], out: &mut [[u8; 8]], len: usize) {
    for (x, o) in xs.iter().zip(out.iter_mut()) {
        let _ = x.to_slice(&mut o[..len]);
    }
}

#[inline(never)]
fn pass_pack_packed_struct(xs: &[PsRpdo2], out: &mut [[u8; 8]], len: usize) {
    for (x, o) in xs.iter().zip(out.iter_mut()) {
        let _ = x.pack_to_slice(&mut o[..len]);
    }
}

/// Unpack passes: every field of every frame is stored, as pack stores every byte (a pass
/// that used one field let the optimiser drop the other field's reads and checks).
#[inline(never)]
fn pass_unpack_odc(can: &[([u8; 8], usize)], fields: &mut [(u16, i32)]) {
    for ((d, n), o) in can.iter().zip(fields.iter_mut()) {
        if let Ok(t) = Tpdo2::unpack(&d[..*n]) {
            *o = (u16::from(t.statusword), t.position_actual_value);
        }
    }
}

#[inline(never)]
fn pass_unpack_hand(can: &[([u8; 8], usize)], fields: &mut [(u16, i32)]) {
    for ((d, n), o) in can.iter().zip(fields.iter_mut()) {
        if let Some(t) = HandTpdo2::unpack(&d[..*n]) {
            *o = (t.statusword, t.position_actual_value);
        }
    }
}

#[inline(never)]
fn pass_unpack_deku(can: &[([u8; 8], usize)], fields: &mut [(u16, i32)]) {
    for ((d, n), o) in can.iter().zip(fields.iter_mut()) {
        if let Ok((_, t)) = DekuTpdo2::from_bytes((&d[..*n], 0)) {
            *o = (t.statusword, t.position_actual_value);
        }
    }
}

#[inline(never)]
fn pass_unpack_packed_struct(can: &[([u8; 8], usize)], fields: &mut [(u16, i32)]) {
    for ((d, n), o) in can.iter().zip(fields.iter_mut()) {
        if let Ok(t) = PsTpdo2::unpack_from_slice(&d[..*n]) {
            *o = (t.statusword, t.position_actual_value);
        }
    }
}

/// The tools, in the order of every table.
const TOOLS: [&str; 4] = ["odc", "hand", "deku", "packed_struct"];

/// One pack pass of `tool` (one of [`TOOLS`]); false for another name.
fn pack(tool: &str, inp: &Inputs, out: &mut [[u8; 8]]) -> bool {
    match tool {
        "odc" => pass_pack_odc(&inp.odc.0, out, inp.len),
        "hand" => pass_pack_hand(&inp.hand.0, out, inp.len),
        "deku" => pass_pack_deku(&inp.deku.0, out, inp.len),
        "packed_struct" => pass_pack_packed_struct(&inp.packed_struct.0, out, inp.len),
        _ => return false,
    }
    true
}

/// One unpack pass of `tool` (one of [`TOOLS`]); false for another name.
fn unpack(tool: &str, inp: &Inputs, fields: &mut [(u16, i32)]) -> bool {
    match tool {
        "odc" => pass_unpack_odc(&inp.can.0, fields),
        "hand" => pass_unpack_hand(&inp.can.0, fields),
        "deku" => pass_unpack_deku(&inp.can.0, fields),
        "packed_struct" => pass_unpack_packed_struct(&inp.can.0, fields),
        _ => return false,
    }
    true
}

/// Criterion's clock here: CPU time of the benchmarking thread (`CLOCK_THREAD_CPUTIME_ID`),
/// as the parse rows take, so the time neighbours on a shared machine have the core is not
/// counted (wall time moved odc's and the hand-written pass, the same instructions, apart by
/// 5% under a load of 9 on 2 cores). Values are nanoseconds, printed as criterion prints
/// wall time.
struct ThreadCpu;

/// Criterion's formatter for nanoseconds.
static NANOS: WallTime = WallTime;

impl Measurement for ThreadCpu {
    type Intermediate = u64;
    type Value = u64;
    fn start(&self) -> u64 {
        odc_bench::cpu_ns()
    }
    fn end(&self, start: u64) -> u64 {
        odc_bench::cpu_ns().saturating_sub(start)
    }
    fn add(&self, a: &u64, b: &u64) -> u64 {
        a + b
    }
    fn zero(&self) -> u64 {
        0
    }
    fn to_f64(&self, v: &u64) -> f64 {
        *v as f64
    }
    fn formatter(&self) -> &dyn ValueFormatter {
        NANOS.formatter()
    }
}

fn bench(c: &mut Criterion<ThreadCpu>) {
    let inp = Inputs::new().expect("the four tools agree");
    let mut out = paged(std::iter::empty());
    let mut g = c.benchmark_group("pack_rpdo2_x1024");
    for tool in TOOLS {
        g.bench_function(tool, |bn| {
            bn.iter(|| {
                pack(tool, black_box(&inp), &mut out.0);
                black_box(&out);
            })
        });
    }
    g.finish();

    let mut fields: Paged<(u16, i32)> = paged(std::iter::empty());
    let mut g = c.benchmark_group("unpack_tpdo2_x1024");
    for tool in TOOLS {
        g.bench_function(tool, |bn| {
            bn.iter(|| {
                unpack(tool, black_box(&inp), &mut fields.0);
                black_box(&fields);
            })
        });
    }
    g.finish();
}

criterion_group! {
    name = benches;
    config = Criterion::default().with_measurement(ThreadCpu).sample_size(20).warm_up_time(std::time::Duration::from_millis(500)).measurement_time(std::time::Duration::from_secs(2));
    targets = bench
}

/// `ODC_PACK_COUNT="OP TOOL PASSES"`: PASSES passes of one tool's pack or unpack, nothing
/// timed; an unknown operation, tool or count is an error.
fn count(spec: &str) -> Result<(), String> {
    let w: Vec<&str> = spec.split_whitespace().collect();
    let [op, tool, passes] = w[..] else {
        return Err(format!("want `OP TOOL PASSES`, got `{spec}`"));
    };
    let passes: u32 = passes.parse().map_err(|e| format!("PASSES `{passes}`: {e}"))?;
    let inp = Inputs::new()?;
    let mut out: Paged<[u8; 8]> = paged(std::iter::empty());
    let mut fields: Paged<(u16, i32)> = paged(std::iter::empty());
    for _ in 0..passes {
        let known = match op {
            "pack" => pack(tool, black_box(&inp), &mut out.0),
            "unpack" => unpack(tool, black_box(&inp), &mut fields.0),
            _ => false,
        };
        if !known {
            return Err(format!("unknown operation or tool: {op} {tool}"));
        }
        black_box((&out, &fields));
    }
    Ok(())
}

fn main() {
    if let Ok(spec) = std::env::var("ODC_PACK_COUNT") {
        if let Err(e) = count(&spec) {
            eprintln!("ODC_PACK_COUNT: {e}");
            std::process::exit(2);
        }
        return;
    }
    // What `criterion_main!(benches)` expands to.
    benches();
    Criterion::default().configure_from_args().final_summary();
}
