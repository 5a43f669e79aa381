//! Properties of PDO packing: pack → unpack is identity, and pack agrees with a naive
//! bit-by-bit reference writer that walks the `MAPPING` table.
#![allow(clippy::unwrap_used, clippy::expect_used, clippy::panic)] // test code: a panic is a failure report

use odc::bits::{read_bits, write_bits};
use odc::{Pdo, PdoValue};
use proptest::prelude::*;

/// Reference: set bit `offset + i` of a LSB0 little-endian image to bit `i` of `value`.
fn ref_write(buf: &mut [u8], offset: usize, len: u32, value: u64) {
    for i in 0..len as usize {
        let bit = (value >> i) & 1;
        let pos = offset + i;
        if bit == 1 {
            buf[pos / 8] |= 1 << (pos % 8);
        } else {
            buf[pos / 8] &= !(1 << (pos % 8));
        }
    }
}

fn ref_read(buf: &[u8], offset: usize, len: u32) -> u64 {
    (0..len as usize).fold(0, |acc, i| {
        let pos = offset + i;
        acc | (u64::from((buf[pos / 8] >> (pos % 8)) & 1) << i)
    })
}

/// Pack `raws` (one per non-dummy mapping entry) as the mapping table says, bit by bit.
fn ref_pack<P: Pdo>(raws: &[u64]) -> Vec<u8> {
    let mut buf = vec![0u8; P::LEN];
    let mut off = 0usize;
    let mut raws = raws.iter();
    for e in P::MAPPING {
        if !e.is_dummy() {
            let raw = *raws.next().unwrap();
            ref_write(&mut buf, off, u32::from(e.bits), raw);
        }
        off += usize::from(e.bits);
    }
    assert!(raws.next().is_none(), "every field mapped");
    assert_eq!(off, P::BITS);
    buf
}

fn mask(bits: u32) -> u64 {
    if bits >= 64 { u64::MAX } else { (1 << bits) - 1 }
}

/// A value of a signed type that fits `bits` bits.
fn signed_in(bits: u32) -> impl Strategy<Value = i64> {
    let lo = -(1i128 << (bits - 1));
    let hi = (1i128 << (bits - 1)) - 1;
    (lo as i64)..=(hi as i64)
}

#[derive(Debug, Clone, Copy, PartialEq, Eq, odc::PdoValue)]
#[repr(u8)]
#[pdo(bits = 4)]
enum Nibble {
    Zero = 0,
    Nine = 9,
    #[pdo(other)]
    Other(u8),
}

#[derive(Debug, Clone, PartialEq, odc::Pdo)]
struct Narrow {
    #[pdo(index = 0x2000, sub = 1, bits = 3)]
    a: u8,
    #[pdo(index = 0x2000, sub = 2, bits = 11)]
    b: i16,
    #[pdo(index = 0x2000, sub = 3)]
    c: bool,
    #[pdo(index = 0x2000, sub = 4, bits = 29, pad_bits = 2)]
    d: u32,
    #[pdo(index = 0x2000, sub = 5, bits = 7)]
    e: i8,
    #[pdo(index = 0x2000, sub = 6, bits = 4)]
    f: Nibble,
}

impl Narrow {
    fn raws(&self) -> Vec<u64> {
        vec![
            self.a.to_raw(),
            self.b.to_raw(),
            self.c.to_raw(),
            self.d.to_raw(),
            self.e.to_raw(),
            self.f.to_raw(),
        ]
    }
}

#[derive(Debug, Clone, PartialEq, odc::Pdo)]
#[pdo(max_bits = 512, bytes = 40)]
struct Wide {
    #[pdo(index = 0x3000, sub = 1, bits = 5)]
    a: u8,
    #[pdo(index = 0x3000, sub = 2)]
    b: i64,
    #[pdo(index = 0x3000, sub = 3)]
    c: f64,
    #[pdo(index = 0x3000, sub = 4, bits = 17, pad_bits = 9)]
    d: i32,
    #[pdo(index = 0x3000, sub = 5)]
    e: u64,
    #[pdo(index = 0x3000, sub = 6)]
    f: f32,
    #[pdo(index = 0x3000, sub = 7, bits = 24, offset = 264)]
    g: odc::U24,
}

impl Wide {
    fn raws(&self) -> Vec<u64> {
        vec![
            self.a.to_raw(),
            self.b.to_raw(),
            self.c.to_raw(),
            self.d.to_raw(),
            self.e.to_raw(),
            self.f.to_raw(),
            self.g.to_raw(),
        ]
    }
}

/// Byte-aligned fields in a 6-byte image: the one-move-per-field path.
#[derive(Debug, Clone, Copy, PartialEq, odc::Pdo)]
struct Aligned6 {
    #[pdo(index = 0x6041)]
    statusword: u16,
    #[pdo(index = 0x6064)]
    position: i32,
}

/// Byte-aligned fields over 8 bytes with a padding byte and 24-bit fields: still one move per
/// field, the gap cleared.
#[derive(Debug, Clone, Copy, PartialEq, odc::Pdo)]
#[pdo(max_bits = 128)]
struct Aligned14 {
    #[pdo(index = 0x2100, sub = 1)]
    a: u8,
    #[pdo(index = 0x2100, sub = 2, bits = 24, pad_bits = 8)]
    b: odc::I24,
    #[pdo(index = 0x2100, sub = 3)]
    c: i64,
    #[pdo(index = 0x2100, sub = 4, bits = 8)]
    d: i16,
}

/// Byte-aligned fields filling exactly 8 bytes (a CiA 402 TPDO: statusword, position,
/// torque): one move per field too, not one word assembled from pieces.
#[derive(Debug, Clone, Copy, PartialEq, odc::Pdo)]
struct Aligned8 {
    #[pdo(index = 0x6041)]
    statusword: u16,
    #[pdo(index = 0x6064)]
    position: i32,
    #[pdo(index = 0x6077)]
    torque: i16,
}

/// 8 bytes with a gap byte: the gap is cleared, the fields moved one by one.
#[derive(Debug, Clone, Copy, PartialEq, odc::Pdo)]
struct Aligned8Gap {
    #[pdo(index = 0x6061)]
    mode: i8,
    #[pdo(index = 0x606C, pad_bits = 8)]
    velocity: i32,
    #[pdo(index = 0x6077)]
    torque: i16,
}

fn narrow() -> impl Strategy<Value = Narrow> {
    (0u8..8, signed_in(11), any::<bool>(), 0u32..(1 << 29), signed_in(7), 0u8..16).prop_map(
        |(a, b, c, d, e, f)| Narrow {
            a,
            b: b as i16,
            c,
            d,
            e: e as i8,
            f: Nibble::from_raw(u64::from(f), 4).unwrap(),
        },
    )
}

fn wide() -> impl Strategy<Value = Wide> {
    (
        0u8..32,
        any::<i64>(),
        any::<u64>(),
        signed_in(17),
        any::<u64>(),
        any::<u32>(),
        0u32..(1 << 24),
    )
        .prop_map(|(a, b, c, d, e, f, g)| Wide {
            a,
            b,
            c: f64::from_bits(c),
            d: d as i32,
            e,
            f: f32::from_bits(f),
            g: odc::U24::new(g).unwrap(),
        })
}

/// Float fields compare by bits so NaN payloads count as equal.
fn same_wide(x: &Wide, y: &Wide) -> bool {
    x.raws() == y.raws()
}

proptest! {
    #[test]
    fn helpers_match_reference(fields in prop::collection::vec((1u32..=64, any::<u64>()), 1..12), start in 0usize..13) {
        let total: usize = start + fields.iter().map(|f| f.0 as usize).sum::<usize>();
        let len = total.div_ceil(8) + 1;
        let mut fast = vec![0xA5u8; len];
        let mut slow = fast.clone();
        let mut off = start;
        for &(bits, v) in &fields {
            write_bits(&mut fast, off, bits, v);
            ref_write(&mut slow, off, bits, v & mask(bits));
            prop_assert_eq!(&fast, &slow);
            prop_assert_eq!(read_bits(&fast, off, bits), v & mask(bits));
            prop_assert_eq!(ref_read(&fast, off, bits), v & mask(bits));
            off += bits as usize;
        }
    }

    #[test]
    fn narrow_round_trip_and_reference(v in narrow()) {
        let packed = v.pack().unwrap();
        let reference = ref_pack::<Narrow>(&v.raws());
        prop_assert_eq!(packed.as_slice(), reference.as_slice());
        prop_assert_eq!(Narrow::unpack(&packed).unwrap(), v);
    }

    #[test]
    fn wide_round_trip_and_reference(v in wide()) {
        let packed = v.pack().unwrap();
        let reference = ref_pack::<Wide>(&v.raws());
        prop_assert_eq!(packed.as_slice(), reference.as_slice());
        let back = Wide::unpack(&packed).unwrap();
        prop_assert!(same_wide(&back, &v));
    }

    #[test]
    fn aligned_round_trip_and_reference(statusword: u16, position: i32) {
        let v = Aligned6 { statusword, position };
        let packed = v.pack().unwrap();
        let reference = ref_pack::<Aligned6>(&[v.statusword.to_raw(), v.position.to_raw()]);
        prop_assert_eq!(packed.as_slice(), reference.as_slice());
        prop_assert_eq!(Aligned6::unpack(&packed).unwrap(), v);
        prop_assert_eq!(Aligned6::unpack(&reference).unwrap(), v);
    }

    #[test]
    fn aligned_with_gap_round_trip_and_reference(a: u8, b in signed_in(24), c: i64, d in signed_in(8)) {
        let v = Aligned14 { a, b: odc::I24::new(b as i32).unwrap(), c, d: d as i16 };
        // Garbage in the buffer must not survive in the gap.
        let mut packed = [0xA5u8; 14];
        v.pack_into(&mut packed).unwrap();
        let reference = ref_pack::<Aligned14>(&[v.a.to_raw(), v.b.to_raw(), v.c.to_raw(), v.d.to_raw()]);
        prop_assert_eq!(packed.as_slice(), reference.as_slice());
        prop_assert_eq!(Aligned14::unpack(&packed).unwrap(), v);
    }

    #[test]
    fn aligned8_round_trip_and_reference(statusword: u16, position: i32, torque: i16) {
        let v = Aligned8 { statusword, position, torque };
        // Bytes past the PDO stay as they were.
        let mut packed = [0xA5u8; 10];
        v.pack_into(&mut packed).unwrap();
        let reference = ref_pack::<Aligned8>(&[v.statusword.to_raw(), v.position.to_raw(), v.torque.to_raw()]);
        prop_assert_eq!(&packed[..8], reference.as_slice());
        prop_assert_eq!(&packed[8..], &[0xA5, 0xA5]);
        prop_assert_eq!(Aligned8::unpack(&packed).unwrap(), v);
        prop_assert_eq!(Aligned8::unpack(&reference).unwrap(), v);
    }

    #[test]
    fn aligned8_with_gap_round_trip_and_reference(mode: i8, velocity: i32, torque: i16) {
        let v = Aligned8Gap { mode, velocity, torque };
        // Garbage in the buffer must not survive in the gap.
        let mut packed = [0xA5u8; 8];
        v.pack_into(&mut packed).unwrap();
        let reference = ref_pack::<Aligned8Gap>(&[v.mode.to_raw(), v.velocity.to_raw(), v.torque.to_raw()]);
        prop_assert_eq!(packed.as_slice(), reference.as_slice());
        prop_assert_eq!(packed[1], 0);
        prop_assert_eq!(Aligned8Gap::unpack(&packed).unwrap(), v);
    }

    /// Any byte pattern unpacks (no enum without catch-all here) and re-packs to itself with
    /// the gap and tail bits cleared.
    #[test]
    fn narrow_unpack_then_pack(bytes in prop::array::uniform8(any::<u8>())) {
        let v = Narrow::unpack(&bytes).unwrap();
        let again = v.pack().unwrap();
        let mut expect = bytes;
        ref_write(&mut expect, 15, 2, 0); // the pad_bits = 2 gap
        ref_write(&mut expect, 57, 7, 0); // bits past the last field
        prop_assert_eq!(again, expect);
    }
}

#[test]
fn layouts_are_what_the_mapping_says() {
    assert_eq!(Narrow::BITS, 3 + 11 + 1 + 2 + 29 + 7 + 4);
    assert_eq!(Narrow::LEN, 8);
    assert_eq!(Wide::BITS, 320);
    assert_eq!(Wide::MAPPING.iter().map(|e| usize::from(e.bits)).sum::<usize>(), Wide::BITS);
    assert_eq!((Aligned6::BITS, Aligned6::LEN), (48, 6));
    assert_eq!((Aligned8::BITS, Aligned8::LEN), (64, 8));
    assert_eq!((Aligned8Gap::BITS, Aligned8Gap::LEN), (64, 8));
    assert_eq!((Aligned14::BITS, Aligned14::LEN), (112, 14));
    // An i16 mapped into 8 bits refuses values it cannot carry.
    let too_big = Aligned14 { a: 0, b: odc::I24::ZERO, c: 0, d: 200 };
    assert!(too_big.pack().is_err());
}

/// One derived struct per generated case, and a property over its values: raw bits drawn at
/// random, built into field values with `from_raw`, must come back bit-exact from `pack`, at
/// the offsets the reference writer computes from `MAPPING`, and `unpack` must invert `pack`.
macro_rules! layout_case {
    ($name:ident, $test:ident, $(#[$m:meta])? [$($f:ident : $t:ty = $bits:literal, pad $pad:literal),*]) => {
        #[derive(Debug, Clone, PartialEq, odc::Pdo)]
        $(#[$m])?
        struct $name {
            $(
                #[pdo(index = 0x4000, bits = $bits, pad_bits = $pad)]
                $f: $t,
            )*
        }

        proptest! {
            #[test]
            fn $test(raws in prop::collection::vec(any::<u64>(), 12)) {
                let mut it = raws.iter().copied();
                let v = $name {
                    $( $f: <$t as PdoValue>::from_raw(it.next().unwrap() & mask($bits), $bits).unwrap(), )*
                };
                let got_raws = vec![$( v.$f.to_raw() & mask($bits) ),*];
                let drawn: Vec<u64> = [$($bits),*].iter().zip(&raws).map(|(b, r)| r & mask(*b)).collect();
                prop_assert_eq!(&got_raws, &drawn);
                let packed = v.pack().unwrap();
                let reference = ref_pack::<$name>(&got_raws);
                prop_assert_eq!(packed.as_slice(), reference.as_slice());
                prop_assert_eq!($name::unpack(&packed).unwrap(), v);
            }
        }
    };
}

#[rustfmt::skip]
#[path = "../gen/layout_cases.rs"]
mod layout_cases;
