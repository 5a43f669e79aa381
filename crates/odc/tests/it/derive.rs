//! Behaviour of `#[derive(Pdo)]` / `#[derive(PdoValue)]` through the public `odc` paths.
#![allow(clippy::unwrap_used, clippy::expect_used, clippy::panic)] // test code: a panic is a failure report

use odc::cia402::{Controlword, ModeOfOperation};
use odc::{MappingEntry, PackError, Pdo, PdoValue, UnpackError};

#[derive(Debug, Clone, Copy, PartialEq, Eq, odc::PdoValue)]
#[repr(i8)]
enum Mode {
    ProfilePosition = 1,
    Velocity,
    CyclicSyncPosition = 8,
    #[pdo(other)]
    Other(i8),
}

#[derive(Debug, Clone, Copy, PartialEq, Eq, odc::PdoValue)]
#[repr(u8)]
#[pdo(bits = 3)]
enum Small {
    A = 0,
    B = 5,
}

#[derive(Debug, PartialEq, odc::Pdo)]
#[pdo(bytes = 8)]
struct DriveRx {
    #[pdo(index = 0x6040)]
    controlword: u16,
    #[pdo(index = 0x6060, bits = 8)]
    mode: Mode,
    #[pdo(index = 0x607A)]
    target_position: i32,
}

#[derive(Debug, PartialEq, odc::Pdo)]
struct Odd {
    #[pdo(index = 0x2000, sub = 1)]
    flag: bool,
    #[pdo(index = 0x2000, sub = 2, bits = 12)]
    twelve: u16,
    #[pdo(index = 0x2000, sub = 3, bits = 3)]
    small: Small,
    #[pdo(index = 0x2000, sub = 4, bits = 5, pad_bits = 3)]
    signed5: i8,
    #[pdo(index = 0x2000, sub = 5, offset = 32, bits = 16)]
    word: Controlword,
}

#[derive(Debug, PartialEq, odc::Pdo)]
#[pdo(max_bits = 1024)]
struct Big {
    #[pdo(index = 0x6041)]
    status: u16,
    #[pdo(index = 0x6064, pad_bits = 1)]
    position: i64,
    #[pdo(index = 0x606C)]
    velocity: f32,
    #[pdo(index = 0x6061, bits = 8)]
    mode: ModeOfOperation,
    #[pdo(index = 0x6077, bits = 24)]
    torque: i32,
}

#[test]
fn drive_rx_bytes_and_mapping() {
    let v = DriveRx { controlword: 0x000F, mode: Mode::CyclicSyncPosition, target_position: -2 };
    let b = v.pack().unwrap();
    assert_eq!(b, [0x0F, 0x00, 0x08, 0xFE, 0xFF, 0xFF, 0xFF, 0x00]);
    assert_eq!(DriveRx::unpack(&b).unwrap(), v);
    assert_eq!((DriveRx::BITS, DriveRx::LEN), (64, 8));
    assert_eq!(
        DriveRx::MAPPING,
        &[
            MappingEntry::new(0x6040, 0, 16),
            MappingEntry::new(0x6060, 0, 8),
            MappingEntry::new(0x607A, 0, 32),
            MappingEntry::new(0x0005, 0, 8),
        ]
    );
    assert_eq!(DriveRx::unpack(&b[..7]), Err(UnpackError::BufferTooSmall { needed: 8, got: 7 }));
    let mut short = [0u8; 4];
    assert_eq!(v.pack_into(&mut short), Err(PackError::BufferTooSmall { needed: 8, got: 4 }));
    let unknown = DriveRx::unpack(&[0, 0, 0xFD, 0, 0, 0, 0, 0]).unwrap();
    assert_eq!(unknown.mode, Mode::Other(-3));
    assert_eq!(Mode::from_raw(2, 8), Some(Mode::Velocity));
}

#[test]
fn odd_offsets_cross_bytes() {
    let v =
        Odd { flag: true, twelve: 0xABC, small: Small::B, signed5: -7, word: Controlword(0x1234) };
    let b = v.pack().unwrap();
    // flag bit 0, twelve bits 1..13, small bits 13..16, gap 16..19, signed5 19..24, word 32..48
    let expect: u64 =
        1 | (0xABC << 1) | (5 << 13) | (((-7i64 as u64) & 0x1F) << 19) | (0x1234 << 32);
    assert_eq!(b.as_slice(), &expect.to_le_bytes()[..6]);
    assert_eq!(Odd::unpack(&b).unwrap(), v);
    assert_eq!(Odd::LEN, 6);
    assert_eq!(
        Odd::MAPPING.iter().map(|e| e.to_u32()).collect::<Vec<_>>(),
        [
            0x2000_0101,
            0x2000_020C,
            0x2000_0303,
            0x0001_0001,
            0x0001_0001,
            0x0001_0001,
            0x2000_0405,
            0x0005_0008,
            0x2000_0510
        ]
    );
    // an enum without catch-all refuses unknown bits
    let mut bad = b;
    bad[1] &= !(0b111 << 5);
    bad[1] |= 0b011 << 5;
    assert_eq!(Odd::unpack(&bad), Err(UnpackError::InvalidValue { field: "small" }));
    // a value that does not fit its narrower mapping is refused, not truncated
    let too_big = Odd { twelve: 0x1000, ..v };
    assert_eq!(too_big.pack(), Err(PackError::OutOfRange { field: "twelve" }));
    let too_small = Odd { signed5: -17, ..v };
    assert_eq!(too_small.pack(), Err(PackError::OutOfRange { field: "signed5" }));
}

#[test]
fn wide_image_uses_bit_helpers() {
    let v = Big {
        status: 0x0237,
        position: -123_456_789_012,
        velocity: 1.25,
        mode: ModeOfOperation::CyclicSyncVelocity,
        torque: -1000,
    };
    let mut buf = [0xAAu8; 20];
    v.pack_into(&mut buf).unwrap();
    assert_eq!(Big::BITS, 16 + 1 + 64 + 32 + 8 + 24);
    assert_eq!(Big::LEN, 19);
    assert_eq!(buf[19], 0xAA, "bytes past LEN untouched");
    assert_eq!(odc::bits::read_bits(&buf, 17, 64) as i64, -123_456_789_012);
    assert_eq!(odc::bits::read_bits(&buf, 16, 1), 0, "gap zeroed");
    assert_eq!(Big::unpack(&buf).unwrap(), v);
    assert_eq!(Big::MAPPING[1], MappingEntry::new(0x0001, 0, 1));
    let too_big = Big { torque: 1 << 23, ..v };
    assert_eq!(too_big.pack_into(&mut buf), Err(PackError::OutOfRange { field: "torque" }));
}

/// A struct declared by a `macro_rules!` macro: field types arrive as `$t:ty`, wrapped in an
/// invisible group; their widths are still inferred (found by the `pdo_pack` fuzz target's
/// harness, which declares its layouts this way).
macro_rules! declare {
    ($name:ident { $($f:ident : $t:ty = $index:literal),* }) => {
        #[derive(Debug, PartialEq, odc::Pdo)]
        struct $name {
            $( #[pdo(index = $index)] $f: $t, )*
        }
    };
}

declare!(FromMacro { flag: bool = 0x2001, word: u16 = 0x2002, wide: i32 = 0x2003 });

#[test]
fn field_types_from_a_macro_infer_their_width() {
    assert_eq!(FromMacro::BITS, 1 + 16 + 32);
    let v = FromMacro { flag: true, word: 0xBEEF, wide: -2 };
    let bytes = v.pack().unwrap();
    assert_eq!(FromMacro::unpack(&bytes).unwrap(), v);
}

#[derive(Debug, Clone, Copy, PartialEq, Eq, odc::PdoValue)]
#[repr(u8)]
#[pdo(bits = 4)]
enum Nibble {
    Nine = 9,
    #[pdo(other)]
    Other(u8),
}

#[derive(Debug, PartialEq, odc::Pdo)]
struct WithNibble {
    #[pdo(index = 0x2000, bits = 4)]
    nibble: Nibble,
    #[pdo(index = 0x2001, bits = 4)]
    after: u8,
}

/// A catch-all variant holding more bits than the enum's declared width is out of range, not
/// silently truncated into the neighbouring field (found by the `pdo_pack` fuzz target).
#[test]
fn catch_all_wider_than_its_bits_is_out_of_range() {
    let v = WithNibble { nibble: Nibble::Other(173), after: 0 };
    assert_eq!(v.pack(), Err(PackError::OutOfRange { field: "nibble" }));
    let v = WithNibble { nibble: Nibble::Other(13), after: 2 };
    assert_eq!(v.pack(), Ok([0x2D]));
    assert_eq!(WithNibble::unpack(&[0x29]).unwrap().nibble, Nibble::Nine);
}
