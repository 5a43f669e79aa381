//! Typed object values and their little-endian SDO encoding.

use crate::DataType;
use crate::SdoAbort;
use core::fmt;

/// Why a value could not be encoded or decoded; each maps onto the SDO abort a server sends.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
#[non_exhaustive]
pub enum ValueError {
    /// Fewer bytes than the type needs (or the output buffer is too small).
    TooShort,
    /// More bytes than the type holds.
    TooLong,
    /// The bytes are not a valid value of the type.
    Invalid,
}

impl From<ValueError> for SdoAbort {
    fn from(e: ValueError) -> Self {
        match e {
            ValueError::TooShort => SdoAbort::TooShort,
            ValueError::TooLong => SdoAbort::TooLong,
            ValueError::Invalid => SdoAbort::InvalidValue,
        }
    }
}

impl fmt::Display for ValueError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(match self {
            Self::TooShort => "too few bytes for the value type",
            Self::TooLong => "too many bytes for the value type",
            Self::Invalid => "invalid value for the type",
        })
    }
}

impl core::error::Error for ValueError {}

/// A value that can live in an object-dictionary entry.
///
/// The type parameter of [`crate::Entry`]: it is what makes `sdo.write(od::X, v)` type-checked.
pub trait ObjValue: Copy {
    /// The CiA 301 type this Rust type stands for.
    const DATA_TYPE: DataType;
    /// Largest encoded size in bytes.
    const MAX_LEN: usize;

    /// Write the little-endian encoding into `buf`, returning the number of bytes used.
    fn encode(&self, buf: &mut [u8]) -> Result<usize, ValueError>;

    /// Read a value from exactly the bytes of one transfer.
    fn decode(buf: &[u8]) -> Result<Self, ValueError>;

    /// Build the value from an integer, for `$NODEID`-relative defaults; `None` if the type has
    /// no such meaning or the number does not fit.
    fn from_u64(v: u64) -> Option<Self> {
        let _ = v;
        None
    }
}

/// Copy `N` bytes out of `buf`, which must have exactly `N`.
#[inline]
fn exact<const N: usize>(buf: &[u8]) -> Result<[u8; N], ValueError> {
    match buf.len() {
        n if n < N => Err(ValueError::TooShort),
        n if n > N => Err(ValueError::TooLong),
        _ => <[u8; N]>::try_from(buf).map_err(|_| ValueError::Invalid),
    }
}

#[inline]
fn put(buf: &mut [u8], bytes: &[u8]) -> Result<usize, ValueError> {
    let dst = buf.get_mut(..bytes.len()).ok_or(ValueError::TooShort)?;
    // Not `copy_from_slice`: its length-mismatch panic (and the formatting it drags in, 2.7 KB
    // on a Cortex-M) stays linked where the optimiser does not see that the lengths agree.
    for (d, s) in dst.iter_mut().zip(bytes) {
        *d = *s;
    }
    Ok(bytes.len())
}

macro_rules! int_values {
    ($($t:ty => $dt:ident;)*) => {$(
        impl ObjValue for $t {
            const DATA_TYPE: DataType = DataType::$dt;
            const MAX_LEN: usize = core::mem::size_of::<$t>();
            #[inline]
            fn encode(&self, buf: &mut [u8]) -> Result<usize, ValueError> {
                put(buf, &self.to_le_bytes())
            }
            #[inline]
            fn decode(buf: &[u8]) -> Result<Self, ValueError> {
                exact(buf).map(<$t>::from_le_bytes)
            }
            fn from_u64(v: u64) -> Option<Self> {
                <$t>::try_from(v).ok()
            }
        }
    )*};
}

int_values! {
    u8 => Unsigned8; u16 => Unsigned16; u32 => Unsigned32; u64 => Unsigned64;
    i8 => Integer8; i16 => Integer16; i32 => Integer32; i64 => Integer64;
}

macro_rules! float_values {
    ($($t:ty => $dt:ident;)*) => {$(
        impl ObjValue for $t {
            const DATA_TYPE: DataType = DataType::$dt;
            const MAX_LEN: usize = core::mem::size_of::<$t>();
            #[inline]
            fn encode(&self, buf: &mut [u8]) -> Result<usize, ValueError> {
                put(buf, &self.to_le_bytes())
            }
            #[inline]
            fn decode(buf: &[u8]) -> Result<Self, ValueError> {
                exact(buf).map(<$t>::from_le_bytes)
            }
        }
    )*};
}

float_values! { f32 => Real32; f64 => Real64; }

impl ObjValue for bool {
    const DATA_TYPE: DataType = DataType::Boolean;
    const MAX_LEN: usize = 1;
    fn encode(&self, buf: &mut [u8]) -> Result<usize, ValueError> {
        put(buf, &[u8::from(*self)])
    }
    /// Only 0 and 1 are accepted: anything else is a garbled transfer, not a truthy value.
    fn decode(buf: &[u8]) -> Result<Self, ValueError> {
        match exact::<1>(buf)? {
            [0] => Ok(false),
            [1] => Ok(true),
            _ => Err(ValueError::Invalid),
        }
    }
}

macro_rules! odd_ints {
    ($($(#[$m:meta])* $name:ident($inner:ty, $bytes:literal, $signed:literal) => $dt:ident;)*) => {$(
        $(#[$m])*
        ///
        /// Stored in the next wider Rust integer; the constructor refuses values out of range.
        #[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash, PartialOrd, Ord)]
        #[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
        #[cfg_attr(feature = "defmt", derive(defmt::Format))]
        pub struct $name($inner);

        impl $name {
            /// Width in bits.
            pub const BITS: u32 = $bytes * 8;
            /// Smallest value.
            pub const MIN: $inner = if $signed { !0 << (Self::BITS - 1) } else { 0 };
            /// Largest value.
            pub const MAX: $inner = if $signed { !(!0 << (Self::BITS - 1)) } else { !(!0 << Self::BITS) };
            /// Zero, for `const` initial values.
            pub const ZERO: Self = Self(0);

            /// The value, or `None` if it does not fit in the width.
            pub const fn new(v: $inner) -> Option<Self> {
                if v >= Self::MIN && v <= Self::MAX { Some(Self(v)) } else { None }
            }

            /// The value as the wider Rust integer.
            pub const fn get(self) -> $inner {
                self.0
            }
        }

        impl From<$name> for $inner {
            fn from(v: $name) -> $inner {
                v.0
            }
        }

        impl ObjValue for $name {
            const DATA_TYPE: DataType = DataType::$dt;
            const MAX_LEN: usize = $bytes;
            fn encode(&self, buf: &mut [u8]) -> Result<usize, ValueError> {
                let b = self.0.to_le_bytes();
                put(buf, b.get(..$bytes).ok_or(ValueError::Invalid)?)
            }
            fn decode(buf: &[u8]) -> Result<Self, ValueError> {
                let b: [u8; $bytes] = exact(buf)?;
                let mut w = [0u8; 8];
                w[..$bytes].copy_from_slice(&b);
                let raw = u64::from_le_bytes(w);
                let v = if $signed { crate::bits::sign_extend(raw, $bytes * 8) as $inner } else { raw as $inner };
                Ok(Self(v))
            }
            fn from_u64(v: u64) -> Option<Self> {
                <$inner>::try_from(v).ok().and_then(Self::new)
            }
        }

        impl crate::PdoValue for $name {
            const BITS: u32 = $bytes * 8;
            const SIGNED: bool = $signed;
            #[inline(always)]
            fn to_raw(&self) -> u64 {
                self.0 as u64
            }
            #[inline(always)]
            fn from_raw(raw: u64, bits: u32) -> Option<Self> {
                let v = if $signed { crate::bits::sign_extend(raw, bits) as $inner } else { raw as $inner };
                Self::new(v)
            }
        }
    )*};
}

odd_ints! {
    /// CiA 301 INTEGER24.
    I24(i32, 3, true) => Integer24;
    /// CiA 301 INTEGER40.
    I40(i64, 5, true) => Integer40;
    /// CiA 301 INTEGER48.
    I48(i64, 6, true) => Integer48;
    /// CiA 301 INTEGER56.
    I56(i64, 7, true) => Integer56;
    /// CiA 301 UNSIGNED24.
    U24(u32, 3, false) => Unsigned24;
    /// CiA 301 UNSIGNED40.
    U40(u64, 5, false) => Unsigned40;
    /// CiA 301 UNSIGNED48.
    U48(u64, 6, false) => Unsigned48;
    /// CiA 301 UNSIGNED56.
    U56(u64, 7, false) => Unsigned56;
}

/// OCTET_STRING of a fixed length `N` (the length the device file declares).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct OctetString<const N: usize>(pub [u8; N]);

impl<const N: usize> ObjValue for OctetString<N> {
    const DATA_TYPE: DataType = DataType::OctetString;
    const MAX_LEN: usize = N;
    fn encode(&self, buf: &mut [u8]) -> Result<usize, ValueError> {
        put(buf, &self.0)
    }
    fn decode(buf: &[u8]) -> Result<Self, ValueError> {
        exact(buf).map(Self)
    }
}

/// VISIBLE_STRING of at most `N` bytes, stored inline (no heap). Ordered by its bytes, then
/// its length, as a derived order would be.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct VisibleString<const N: usize> {
    bytes: [u8; N],
    len: usize,
}

impl<const N: usize> Ord for VisibleString<N> {
    fn cmp(&self, other: &Self) -> core::cmp::Ordering {
        compare_bytes(&self.bytes, &other.bytes).then(self.len.cmp(&other.len))
    }
}

impl<const N: usize> PartialOrd for VisibleString<N> {
    fn partial_cmp(&self, other: &Self) -> Option<core::cmp::Ordering> {
        Some(self.cmp(other))
    }
}

/// `a` against `b` byte by byte: the order of `[u8]`, without the `memcmp` that the slices'
/// own order calls (a firmware whose only caller is a string limit check links it for
/// that alone: 116 B on a Cortex-M4).
fn compare_bytes(a: &[u8], b: &[u8]) -> core::cmp::Ordering {
    for (x, y) in a.iter().zip(b) {
        if x != y {
            return x.cmp(y);
        }
    }
    a.len().cmp(&b.len())
}

impl<const N: usize> VisibleString<N> {
    /// The empty string, for `const` initial values.
    pub const EMPTY: Self = Self { bytes: [0; N], len: 0 };

    /// The string, or `None` if it is longer than `N` bytes or not visible ASCII (0x20–0x7E).
    pub const fn new(s: &str) -> Option<Self> {
        let src = s.as_bytes();
        if src.len() > N {
            return None;
        }
        let mut bytes = [0u8; N];
        let mut i = 0;
        while i < src.len() {
            if src[i] < 0x20 || src[i] > 0x7E {
                return None;
            }
            bytes[i] = src[i];
            i += 1;
        }
        Some(Self { bytes, len: src.len() })
    }

    /// A device file's default, kept as written: any text of at most `N` bytes without NUL
    /// (which pads). Real files put tabs and UTF-8 ('€') in VISIBLE_STRING defaults, where
    /// CiA 301 allows visible ASCII only; the device holds the file's text rather than
    /// losing it. What a master writes is still checked by [`VisibleString::new`].
    pub const fn from_default(s: &str) -> Option<Self> {
        let src = s.as_bytes();
        if src.len() > N {
            return None;
        }
        let mut bytes = [0u8; N];
        let mut i = 0;
        while i < src.len() {
            if src[i] == 0 {
                return None;
            }
            bytes[i] = src[i];
            i += 1;
        }
        Some(Self { bytes, len: src.len() })
    }

    /// The text.
    pub fn as_str(&self) -> &str {
        // Only UTF-8 gets in (a `&str`, or checked by `decode`).
        self.bytes.get(..self.len).and_then(|b| core::str::from_utf8(b).ok()).unwrap_or("")
    }

    /// Length in bytes.
    pub const fn len(&self) -> usize {
        self.len
    }

    /// Whether the string is empty.
    pub const fn is_empty(&self) -> bool {
        self.len == 0
    }
}

impl<const N: usize> ObjValue for VisibleString<N> {
    const DATA_TYPE: DataType = DataType::VisibleString;
    const MAX_LEN: usize = N;
    fn encode(&self, buf: &mut [u8]) -> Result<usize, ValueError> {
        put(buf, self.bytes.get(..self.len).ok_or(ValueError::Invalid)?)
    }
    /// Trailing NULs are dropped: many devices pad strings to a fixed width. Longer than `N`
    /// is too long whatever the bytes; the rest must be visible ASCII, checked byte by byte
    /// (no UTF-8 validation, whose 368 B a firmware would link only for this).
    fn decode(buf: &[u8]) -> Result<Self, ValueError> {
        let end = buf.iter().rposition(|&b| b != 0).map_or(0, |p| p + 1);
        let text = buf.get(..end).unwrap_or(&[]);
        if text.len() > N {
            return Err(ValueError::TooLong);
        }
        let mut bytes = [0u8; N];
        for (d, &b) in bytes.iter_mut().zip(text) {
            if !(0x20..=0x7E).contains(&b) {
                return Err(ValueError::Invalid);
            }
            *d = b;
        }
        Ok(Self { bytes, len: text.len() })
    }
}

/// UNICODE_STRING of at most `N` bytes (`N / 2` UTF-16 code units, little-endian, as CiA 301
/// encodes it), stored inline. Trailing zero code units are padding, as a VISIBLE_STRING's
/// zeros are.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct UnicodeString<const N: usize> {
    bytes: [u8; N],
    len: usize,
}

impl<const N: usize> UnicodeString<N> {
    /// The empty string, for `const` initial values.
    pub const EMPTY: Self = Self { bytes: [0; N], len: 0 };

    /// The string of the UTF-16LE `bytes`, or `None` if they are more than `N` or an odd
    /// number. `const`, for the defaults of generated code.
    pub const fn from_le_bytes(src: &[u8]) -> Option<Self> {
        if src.len() > N || src.len() & 1 != 0 {
            return None;
        }
        let mut bytes = [0u8; N];
        let mut i = 0;
        while i < src.len() {
            bytes[i] = src[i];
            i += 1;
        }
        Some(Self { bytes, len: src.len() })
    }

    /// The UTF-16LE bytes.
    pub fn as_bytes(&self) -> &[u8] {
        self.bytes.get(..self.len).unwrap_or(&[])
    }

    /// The code units.
    pub fn units(&self) -> impl Iterator<Item = u16> + '_ {
        self.as_bytes().chunks_exact(2).map(|c| u16::from(c[0]) | u16::from(c[1]) << 8)
    }
}

impl<const N: usize> ObjValue for UnicodeString<N> {
    const DATA_TYPE: DataType = DataType::UnicodeString;
    const MAX_LEN: usize = N;
    fn encode(&self, buf: &mut [u8]) -> Result<usize, ValueError> {
        put(buf, self.as_bytes())
    }
    /// Trailing zero code units are dropped, as a padded VISIBLE_STRING's zeros are.
    fn decode(buf: &[u8]) -> Result<Self, ValueError> {
        if buf.len() & 1 != 0 {
            return Err(ValueError::Invalid);
        }
        let end = unicode_len(buf);
        if end > N {
            return Err(ValueError::TooLong);
        }
        Self::from_le_bytes(buf.get(..end).unwrap_or(&[])).ok_or(ValueError::Invalid)
    }
}

/// The length of UTF-16LE `buf` without its trailing zero code units.
pub(crate) fn unicode_len(buf: &[u8]) -> usize {
    let mut end = buf.len() & !1;
    while end >= 2 && buf.get(end - 2..end) == Some(&[0, 0]) {
        end -= 2;
    }
    end
}

/// DOMAIN: data of any length (a program image, a file). The value holds none of it: a
/// dictionary stores no DOMAIN bytes, the download goes to the application
/// ([`WriteHook::write_domain`](crate::slave::WriteHook::write_domain)), whole, at most the
/// SDO server's buffer long.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash, PartialOrd, Ord)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct Domain;

impl ObjValue for Domain {
    const DATA_TYPE: DataType = DataType::Domain;
    const MAX_LEN: usize = 0;
    fn encode(&self, _: &mut [u8]) -> Result<usize, ValueError> {
        Ok(0)
    }
    /// Any bytes: their meaning is the application's.
    fn decode(_: &[u8]) -> Result<Self, ValueError> {
        Ok(Domain)
    }
}

macro_rules! time_type {
    ($(#[$m:meta])* $name:ident => $dt:ident) => {
        $(#[$m])*
        #[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash, PartialOrd, Ord)]
        #[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
        #[cfg_attr(feature = "defmt", derive(defmt::Format))]
        pub struct $name {
            /// Milliseconds (28 bits used).
            pub ms: u32,
            /// Days.
            pub days: u16,
        }

        impl $name {
            /// Zero days, zero milliseconds, for `const` initial values.
            pub const ZERO: Self = Self { ms: 0, days: 0 };
        }

        impl ObjValue for $name {
            const DATA_TYPE: DataType = DataType::$dt;
            const MAX_LEN: usize = 6;
            fn encode(&self, buf: &mut [u8]) -> Result<usize, ValueError> {
                if self.ms >> 28 != 0 {
                    return Err(ValueError::Invalid);
                }
                let m = self.ms.to_le_bytes();
                let d = self.days.to_le_bytes();
                put(buf, &[m[0], m[1], m[2], m[3], d[0], d[1]])
            }
            /// The 4 reserved bits above the milliseconds are ignored, as CiA 301 asks.
            fn decode(buf: &[u8]) -> Result<Self, ValueError> {
                let b: [u8; 6] = exact(buf)?;
                Ok(Self {
                    ms: u32::from_le_bytes([b[0], b[1], b[2], b[3]]) & 0x0FFF_FFFF,
                    days: u16::from_le_bytes([b[4], b[5]]),
                })
            }
        }
    };
}

time_type!(
    /// TIME_OF_DAY: milliseconds after midnight and days since 1984-01-01.
    TimeOfDay => TimeOfDay
);
time_type!(
    /// TIME_DIFFERENCE: a duration in days and milliseconds.
    TimeDifference => TimeDifference
);

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn ints_round_trip_exact_length() {
        let mut b = [0u8; 8];
        assert_eq!(0x1234u16.encode(&mut b), Ok(2));
        assert_eq!(&b[..2], &[0x34, 0x12]);
        assert_eq!(u16::decode(&b[..2]), Ok(0x1234));
        assert_eq!(u16::decode(&b[..1]), Err(ValueError::TooShort));
        assert_eq!(u16::decode(&b[..3]), Err(ValueError::TooLong));
        assert_eq!((-2i32).encode(&mut b[..3]), Err(ValueError::TooShort));
        assert_eq!(i32::decode(&[0xFE, 0xFF, 0xFF, 0xFF]), Ok(-2));
        assert_eq!(f32::decode(&1.5f32.to_le_bytes()), Ok(1.5));
        assert_eq!(u8::from_u64(300), None);
        assert_eq!(u8::from_u64(0x85), Some(0x85));
        assert_eq!(bool::decode(&[2]), Err(ValueError::Invalid));
        assert_eq!(bool::decode(&[1]), Ok(true));
        assert_eq!(SdoAbort::from(ValueError::TooLong), SdoAbort::TooLong);
    }

    #[test]
    fn unicode_and_domain() {
        // "Ab" in UTF-16LE, padded with a zero code unit.
        let s = UnicodeString::<6>::decode(&[0x41, 0, 0x62, 0, 0, 0]).unwrap();
        let mut units = s.units();
        assert_eq!((units.next(), units.next(), units.next()), (Some(0x41), Some(0x62), None));
        let mut b = [0u8; 6];
        assert_eq!(s.encode(&mut b), Ok(4));
        assert_eq!(UnicodeString::<2>::decode(&[0x41, 0, 0x62, 0]), Err(ValueError::TooLong));
        assert_eq!(UnicodeString::<6>::decode(&[0x41]), Err(ValueError::Invalid));
        assert_eq!(Domain::decode(&[1, 2, 3]), Ok(Domain));
    }

    #[test]
    fn odd_widths() {
        assert_eq!(I24::MIN, -0x80_0000);
        assert_eq!(I24::MAX, 0x7F_FFFF);
        assert_eq!(U24::MAX, 0xFF_FFFF);
        assert_eq!(U56::MAX, 0x00FF_FFFF_FFFF_FFFF);
        assert!(I24::new(0x80_0000).is_none());
        let v = I24::new(-3).unwrap();
        let mut b = [0u8; 3];
        assert_eq!(v.encode(&mut b), Ok(3));
        assert_eq!(b, [0xFD, 0xFF, 0xFF]);
        assert_eq!(I24::decode(&b), Ok(v));
        assert_eq!(U40::decode(&[1, 0, 0, 0, 0x80]).map(U40::get), Ok(0x80_0000_0001));
        assert_eq!(I48::DATA_TYPE, DataType::Integer48);
    }

    #[test]
    fn strings_and_time() {
        let s = VisibleString::<8>::new("abc").unwrap();
        assert_eq!(s.as_str(), "abc");
        assert!(VisibleString::<2>::new("abc").is_none());
        assert!(VisibleString::<8>::new("a\nb").is_none());
        // A file's default is kept as written: a tab and '€' (3 bytes), not a NUL.
        let d = VisibleString::<8>::from_default("a\t\u{20AC}").unwrap();
        assert_eq!(d.as_str(), "a\t\u{20AC}");
        let mut buf = [0u8; 8];
        assert_eq!(d.encode(&mut buf), Ok(5));
        assert_eq!(buf[..5], [b'a', 0x09, 0xE2, 0x82, 0xAC]);
        assert!(VisibleString::<8>::from_default("a\0b").is_none());
        assert!(VisibleString::<4>::from_default("ab\u{20AC}").is_none());
        assert_eq!(VisibleString::<8>::decode(b"ab\0\0").map(|s| s.len()), Ok(2));
        assert_eq!(VisibleString::<2>::decode(b"abc"), Err(ValueError::TooLong));
        // Too long whatever the bytes; within the length, only visible ASCII.
        assert_eq!(VisibleString::<2>::decode(b"a\xFFc"), Err(ValueError::TooLong));
        assert_eq!(VisibleString::<8>::decode(b"a\xFFc"), Err(ValueError::Invalid));
        assert_eq!(VisibleString::<8>::decode(b"a\tc"), Err(ValueError::Invalid));
        assert_eq!(VisibleString::<8>::decode(b"a~ ").map(|s| s.as_str() == "a~ "), Ok(true));
        // Ordered by the bytes (zero-padded), then the length: as `str` orders them.
        let v = |s| VisibleString::<4>::new(s).unwrap();
        assert!(v("ab") < v("b"));
        assert!(v("a") < v("ab"));
        assert!(v("b") > v("abcd"));
        assert_eq!(v("abc").cmp(&v("abc")), core::cmp::Ordering::Equal);
        assert!(v("") < v(" "));
        let o = OctetString([1u8, 2, 3]);
        assert_eq!(OctetString::<3>::decode(&[1, 2, 3]), Ok(o));
        let t = TimeOfDay { ms: 1000, days: 2 };
        let mut b = [0u8; 6];
        assert_eq!(t.encode(&mut b), Ok(6));
        assert_eq!(TimeOfDay::decode(&b), Ok(t));
        assert_eq!(TimeOfDay { ms: 1 << 28, days: 0 }.encode(&mut b), Err(ValueError::Invalid));
    }
}
