//! `#[derive(Pdo)]` pack/unpack on arbitrary bytes and arbitrary field values.
//!
//! For each of a few derived layouts (sub-byte fields, sign extension, gaps, absolute offsets,
//! 64-bit and float fields, enums with and without a catch-all, odd-width integers):
//! - `unpack` of any input never panics; when it succeeds, `pack` gives back the input's first
//!   `LEN` bytes with the gap bits cleared (except where a `bool` is mapped on more than one
//!   bit: any non-zero pattern reads as `true` and packs as 1), and `pack_into` leaves the bytes after `LEN` alone;
//! - `pack` of any value never panics: either `OutOfRange` (and then some field really does not
//!   fit its mapped width) or bytes that `unpack` turns back into the same value.
#![no_main]

use arbitrary::{Arbitrary, Unstructured};
use libfuzzer_sys::fuzz_target;
use odc::{Pdo, PdoValue, UnpackError};

#[derive(Debug, Clone, Copy, PartialEq, Eq, odc::PdoValue)]
#[repr(u8)]
#[pdo(bits = 4)]
enum Nibble {
    Zero = 0,
    Nine = 9,
    #[pdo(other)]
    Other(u8),
}

#[derive(Debug, Clone, Copy, PartialEq, Eq, odc::PdoValue)]
#[repr(i8)]
enum Strict {
    Minus = -2,
    One = 1,
    Big = 100,
}

fn nibble(u: &mut Unstructured<'_>) -> Nibble {
    match u.int_in_range(0..=2u8).unwrap_or(0) {
        0 => Nibble::Zero,
        1 => Nibble::Nine,
        _ => Nibble::Other(u8::arbitrary(u).unwrap_or(0)),
    }
}

fn strict(u: &mut Unstructured<'_>) -> Strict {
    match u.int_in_range(0..=2u8).unwrap_or(0) {
        0 => Strict::Minus,
        1 => Strict::One,
        _ => Strict::Big,
    }
}

fn arb<T: for<'a> Arbitrary<'a> + Default>(u: &mut Unstructured<'_>) -> T {
    T::arbitrary(u).unwrap_or_default()
}

fn mask(bits: u32) -> u64 {
    if bits >= 64 { u64::MAX } else { (1 << bits) - 1 }
}

/// The bits of the image that belong to a field (not gaps, not padding).
fn field_mask<P: Pdo>() -> Vec<u8> {
    let mut m = vec![0u8; P::LEN];
    let mut off = 0usize;
    for e in P::MAPPING {
        for i in 0..usize::from(e.bits) {
            if !e.is_dummy() {
                m[(off + i) / 8] |= 1 << ((off + i) % 8);
            }
        }
        off += usize::from(e.bits);
    }
    m
}

macro_rules! layout {
    ($name:ident, [$(#[$sm:meta])*], { $($(#[$fm:meta])* $f:ident : $t:ty = $make:expr),* $(,)? }) => {
        #[derive(Debug, Clone, PartialEq, odc::Pdo)]
        $(#[$sm])*
        struct $name {
            $( $(#[$fm])* $f: $t, )*
        }

        impl $name {
            /// Field values as raw bits (floats by bit pattern, so NaN compares equal).
            fn raws(&self) -> Vec<u64> {
                vec![$( self.$f.to_raw() ),*]
            }

            /// Whether each field sign-extends.
            fn signed() -> Vec<bool> {
                vec![$( <$t as PdoValue>::SIGNED ),*]
            }

            fn arbitrary(u: &mut Unstructured<'_>) -> Self {
                #[allow(clippy::redundant_closure_call)]
                Self { $( $f: ($make)(&mut *u), )* }
            }
        }
    };
}

layout!(Narrow, [], {
    #[pdo(index = 0x2000, sub = 1, bits = 3)] a: u8 = arb::<u8>,
    #[pdo(index = 0x2000, sub = 2, bits = 11)] b: i16 = arb::<i16>,
    #[pdo(index = 0x2000, sub = 3)] c: bool = arb::<bool>,
    #[pdo(index = 0x2000, sub = 4, bits = 29, pad_bits = 2)] d: u32 = arb::<u32>,
    #[pdo(index = 0x2000, sub = 5, bits = 7)] e: i8 = arb::<i8>,
    #[pdo(index = 0x2000, sub = 6, bits = 4)] f: Nibble = nibble,
});

layout!(Wide, [#[pdo(max_bits = 512, bytes = 40)]], {
    #[pdo(index = 0x3000, sub = 1, bits = 5)] a: u8 = arb::<u8>,
    #[pdo(index = 0x3000, sub = 2)] b: i64 = arb::<i64>,
    #[pdo(index = 0x3000, sub = 3)] c: f64 = |u: &mut Unstructured<'_>| f64::from_bits(arb(u)),
    #[pdo(index = 0x3000, sub = 4, bits = 17, pad_bits = 9)] d: i32 = arb::<i32>,
    #[pdo(index = 0x3000, sub = 5)] e: u64 = arb::<u64>,
    #[pdo(index = 0x3000, sub = 6)] f: f32 = |u: &mut Unstructured<'_>| f32::from_bits(arb(u)),
    #[pdo(index = 0x3000, sub = 7, bits = 24, offset = 264)] g: odc::U24 =
        |u: &mut Unstructured<'_>| odc::U24::new(arb::<u32>(u) & 0xFF_FFFF).expect("masked to 24 bits"),
});

layout!(Odd, [#[pdo(bytes = 8)]], {
    #[pdo(index = 0x4000, sub = 1, bits = 8)] flag: bool = arb::<bool>,
    #[pdo(index = 0x4000, sub = 2, bits = 8)] mode: Strict = strict,
    #[pdo(index = 0x4000, sub = 3, bits = 24)] pos: odc::I24 =
        |u: &mut Unstructured<'_>| odc::I24::new(arb::<i32>(u) >> 8).expect("shifted to 24 bits"),
    #[pdo(index = 0x4000, sub = 4, bits = 1, pad_bits = 7)] bit: u16 = arb::<u16>,
    #[pdo(index = 0x4000, sub = 5, bits = 6)] small: i64 = arb::<i64>,
});

fn check<P: Pdo + PartialEq + std::fmt::Debug>(
    data: &[u8],
    value: P,
    raws: impl Fn(&P) -> Vec<u64>,
    signed: &[bool],
    exact: bool,
) {
    // Unpack any bytes.
    match P::unpack(data) {
        Ok(v) => {
            assert!(data.len() >= P::LEN);
            let packed = v.pack().expect("an unpacked value packs");
            let fm = field_mask::<P>();
            let expect: Vec<u8> = data[..P::LEN].iter().zip(&fm).map(|(b, m)| b & m).collect();
            if exact {
                assert_eq!(packed.as_ref(), expect.as_slice(), "{v:?}");
            }
            let back = P::unpack(packed.as_ref()).expect("packed bytes unpack");
            assert_eq!(raws(&back), raws(&v));
            let mut buf = data.to_vec();
            buf.push(0xA5);
            v.pack_into(&mut buf).expect("buffer long enough");
            assert_eq!(&buf[..P::LEN], packed.as_ref());
            assert_eq!(&buf[P::LEN..data.len()], &data[P::LEN..]);
            assert_eq!(buf.last(), Some(&0xA5));
            assert!(v.pack_into(&mut buf[..P::LEN - 1]).is_err());
        }
        Err(UnpackError::BufferTooSmall { needed, got }) => {
            assert_eq!((needed, got), (P::LEN, data.len()));
            assert!(data.len() < P::LEN);
        }
        Err(UnpackError::InvalidValue { .. }) => assert!(data.len() >= P::LEN),
        Err(e) => panic!("unexpected {e:?}"),
    }
    // Pack any value.
    match value.pack() {
        Ok(bytes) => {
            let back = P::unpack(bytes.as_ref()).expect("packed bytes unpack");
            assert_eq!(raws(&back), raws(&value), "{value:?} -> {bytes:?} -> {back:?}");
        }
        Err(odc::PackError::OutOfRange { .. }) => {
            // Some field must really be too wide for its mapping.
            let entries = P::MAPPING.iter().filter(|e| !e.is_dummy());
            let fits = entries.zip(raws(&value)).zip(signed).all(|((e, raw), &signed)| {
                let bits = u32::from(e.bits);
                if signed {
                    let high = raw >> (bits - 1);
                    high == 0 || high == u64::MAX >> (bits - 1)
                } else {
                    raw & !mask(bits) == 0
                }
            });
            assert!(!fits, "{value:?} rejected but every field fits");
        }
        Err(e) => panic!("unexpected {e:?}"),
    }
}

fuzz_target!(|data: &[u8]| {
    let Some((&which, rest)) = data.split_first() else { return };
    let mut u = Unstructured::new(rest);
    match which % 3 {
        0 => check(rest, Narrow::arbitrary(&mut u), Narrow::raws, &Narrow::signed(), true),
        1 => check(rest, Wide::arbitrary(&mut u), Wide::raws, &Wide::signed(), true),
        _ => check(rest, Odd::arbitrary(&mut u), Odd::raws, &Odd::signed(), false),
    }
});
