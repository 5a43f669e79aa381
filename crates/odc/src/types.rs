//! Addresses, CiA 301 data types and access rights.

use core::fmt;

/// Address of an object-dictionary entry: 16-bit index and 8-bit sub-index.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct ObjectAddr {
    /// Object index.
    pub index: u16,
    /// Sub-index (0 for simple variables).
    pub sub: u8,
}

impl ObjectAddr {
    /// The address `index:sub`.
    pub const fn new(index: u16, sub: u8) -> Self {
        Self { index, sub }
    }

    /// The `index << 16 | sub << 8` form used in PDO mapping values and SDO frames.
    pub const fn to_mapping_prefix(self) -> u32 {
        ((self.index as u32) << 16) | ((self.sub as u32) << 8)
    }
}

impl fmt::Display for ObjectAddr {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "0x{:04X}:{:02X}", self.index, self.sub)
    }
}

macro_rules! data_types {
    ($($(#[$m:meta])* $v:ident = $code:literal, $name:literal, $bits:expr;)*) => {
        /// CiA 301 static and complex data types (object indices 0x0001–0x0023).
        #[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord)]
        #[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
        #[cfg_attr(feature = "defmt", derive(defmt::Format))]
        #[non_exhaustive]
        #[repr(u16)]
        pub enum DataType {
            $($(#[$m])* $v = $code,)*
        }

        impl DataType {
            /// Every known type, in code order.
            pub const ALL: &'static [DataType] = &[$(DataType::$v),*];

            /// The type for a CiA 301 code (the `DataType` key of an EDS).
            pub const fn from_u16(code: u16) -> Option<Self> {
                match code {
                    $($code => Some(Self::$v),)*
                    _ => None,
                }
            }

            /// The CiA 301 code.
            pub const fn to_u16(self) -> u16 {
                self as u16
            }

            /// The spec's name, as written in CiA 301 (`UNSIGNED16`).
            pub const fn name(self) -> &'static str {
                match self {
                    $(Self::$v => $name,)*
                }
            }

            /// Width in bits for fixed-size types; `None` for strings, DOMAIN and records.
            pub const fn bits(self) -> Option<u32> {
                match self {
                    $(Self::$v => $bits,)*
                }
            }
        }
    };
}

data_types! {
    /// BOOLEAN (1 bit when mapped).
    Boolean = 0x01, "BOOLEAN", Some(1);
    /// INTEGER8.
    Integer8 = 0x02, "INTEGER8", Some(8);
    /// INTEGER16.
    Integer16 = 0x03, "INTEGER16", Some(16);
    /// INTEGER32.
    Integer32 = 0x04, "INTEGER32", Some(32);
    /// UNSIGNED8.
    Unsigned8 = 0x05, "UNSIGNED8", Some(8);
    /// UNSIGNED16.
    Unsigned16 = 0x06, "UNSIGNED16", Some(16);
    /// UNSIGNED32.
    Unsigned32 = 0x07, "UNSIGNED32", Some(32);
    /// REAL32 (IEEE 754 single).
    Real32 = 0x08, "REAL32", Some(32);
    /// VISIBLE_STRING (variable length).
    VisibleString = 0x09, "VISIBLE_STRING", None;
    /// OCTET_STRING (variable length).
    OctetString = 0x0A, "OCTET_STRING", None;
    /// UNICODE_STRING (variable length, UTF-16 code units).
    UnicodeString = 0x0B, "UNICODE_STRING", None;
    /// TIME_OF_DAY (28-bit ms after midnight + 16-bit days since 1984-01-01).
    TimeOfDay = 0x0C, "TIME_OF_DAY", Some(48);
    /// TIME_DIFFERENCE (same layout as TIME_OF_DAY).
    TimeDifference = 0x0D, "TIME_DIFFERENCE", Some(48);
    /// DOMAIN (arbitrary data block).
    Domain = 0x0F, "DOMAIN", None;
    /// INTEGER24.
    Integer24 = 0x10, "INTEGER24", Some(24);
    /// REAL64 (IEEE 754 double).
    Real64 = 0x11, "REAL64", Some(64);
    /// INTEGER40.
    Integer40 = 0x12, "INTEGER40", Some(40);
    /// INTEGER48.
    Integer48 = 0x13, "INTEGER48", Some(48);
    /// INTEGER56.
    Integer56 = 0x14, "INTEGER56", Some(56);
    /// INTEGER64.
    Integer64 = 0x15, "INTEGER64", Some(64);
    /// UNSIGNED24.
    Unsigned24 = 0x16, "UNSIGNED24", Some(24);
    /// UNSIGNED40.
    Unsigned40 = 0x18, "UNSIGNED40", Some(40);
    /// UNSIGNED48.
    Unsigned48 = 0x19, "UNSIGNED48", Some(48);
    /// UNSIGNED56.
    Unsigned56 = 0x1A, "UNSIGNED56", Some(56);
    /// UNSIGNED64.
    Unsigned64 = 0x1B, "UNSIGNED64", Some(64);
    /// PDO_COMMUNICATION_PARAMETER record.
    PdoCommPar = 0x20, "PDO_COMMUNICATION_PARAMETER", None;
    /// PDO_MAPPING record.
    PdoMapping = 0x21, "PDO_MAPPING", None;
    /// SDO_PARAMETER record.
    SdoParameter = 0x22, "SDO_PARAMETER", None;
    /// IDENTITY record.
    Identity = 0x23, "IDENTITY", None;
}

impl DataType {
    /// Width in whole bytes for fixed-size types (BOOLEAN takes one byte in SDO transfers).
    pub const fn bytes(self) -> Option<u32> {
        match self.bits() {
            Some(b) => Some(b.div_ceil(8)),
            None => None,
        }
    }

    /// Whether the type is a signed integer.
    pub const fn is_signed_integer(self) -> bool {
        matches!(
            self,
            Self::Integer8
                | Self::Integer16
                | Self::Integer24
                | Self::Integer32
                | Self::Integer40
                | Self::Integer48
                | Self::Integer56
                | Self::Integer64
        )
    }

    /// Whether the type is an unsigned integer.
    pub const fn is_unsigned_integer(self) -> bool {
        matches!(
            self,
            Self::Unsigned8
                | Self::Unsigned16
                | Self::Unsigned24
                | Self::Unsigned32
                | Self::Unsigned40
                | Self::Unsigned48
                | Self::Unsigned56
                | Self::Unsigned64
        )
    }
}

impl fmt::Display for DataType {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.name())
    }
}

/// Access right of an entry (CiA 306 `AccessType`). `Rwr`/`Rww` are kept apart from `Rw`
/// because they say which PDO direction the entry belongs to.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum Access {
    /// Read only.
    Ro,
    /// Write only.
    Wo,
    /// Read and write.
    Rw,
    /// Read and write; process input, mappable to a TPDO.
    Rwr,
    /// Read and write; process output, mappable to an RPDO.
    Rww,
    /// Read only and constant.
    Const,
}

impl Access {
    /// Whether an SDO upload may read the entry.
    pub const fn readable(self) -> bool {
        !matches!(self, Self::Wo)
    }

    /// Whether an SDO download may write the entry.
    pub const fn writable(self) -> bool {
        matches!(self, Self::Wo | Self::Rw | Self::Rwr | Self::Rww)
    }

    /// Whether the access right allows mapping into a TPDO (device → bus).
    pub const fn tpdo_allowed(self) -> bool {
        matches!(self, Self::Ro | Self::Rw | Self::Rwr | Self::Const)
    }

    /// Whether the access right allows mapping into an RPDO (bus → device).
    pub const fn rpdo_allowed(self) -> bool {
        matches!(self, Self::Wo | Self::Rw | Self::Rww)
    }

    /// Parse the CiA 306 spelling (`ro`, `wo`, `rw`, `rwr`, `rww`, `const`), any case.
    pub fn from_eds(s: &str) -> Option<Self> {
        let s = s.trim();
        [
            ("ro", Self::Ro),
            ("wo", Self::Wo),
            ("rw", Self::Rw),
            ("rwr", Self::Rwr),
            ("rww", Self::Rww),
            ("const", Self::Const),
        ]
        .into_iter()
        .find(|(k, _)| k.eq_ignore_ascii_case(s))
        .map(|(_, v)| v)
    }

    /// The CiA 306 spelling.
    pub const fn as_eds(self) -> &'static str {
        match self {
            Self::Ro => "ro",
            Self::Wo => "wo",
            Self::Rw => "rw",
            Self::Rwr => "rwr",
            Self::Rww => "rww",
            Self::Const => "const",
        }
    }
}

impl fmt::Display for Access {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.as_eds())
    }
}

#[cfg(test)]
pub(crate) mod tests {
    use super::*;

    #[test]
    fn data_type_codes_round_trip() {
        for &t in DataType::ALL {
            assert_eq!(DataType::from_u16(t.to_u16()), Some(t));
        }
        assert_eq!(DataType::ALL.len(), 29);
        assert_eq!(DataType::from_u16(0x0E), None);
        assert_eq!(DataType::from_u16(0x17), None);
        assert_eq!(DataType::Integer24.bits(), Some(24));
        assert_eq!(DataType::Unsigned56.to_u16(), 0x1A);
        assert_eq!(DataType::TimeOfDay.bytes(), Some(6));
        assert_eq!(DataType::Boolean.bytes(), Some(1));
        assert_eq!(DataType::Domain.bits(), None);
        assert!(DataType::Integer40.is_signed_integer());
        assert!(!DataType::Real32.is_signed_integer());
        assert!(DataType::Unsigned24.is_unsigned_integer());
        assert_eq!(DataType::Unsigned16.name(), "UNSIGNED16");
    }

    #[test]
    fn access_rules() {
        assert!(Access::Ro.readable() && !Access::Ro.writable());
        assert!(!Access::Wo.readable() && Access::Wo.writable());
        assert!(Access::Const.tpdo_allowed() && !Access::Const.rpdo_allowed());
        assert!(Access::Rwr.tpdo_allowed() && !Access::Rwr.rpdo_allowed());
        assert!(Access::Rww.rpdo_allowed() && !Access::Rww.tpdo_allowed());
        assert_eq!(Access::from_eds(" RWW "), Some(Access::Rww));
        assert_eq!(Access::from_eds("Const"), Some(Access::Const));
        assert_eq!(Access::from_eds("rx"), None);
    }

    #[test]
    fn addr_display() {
        assert_eq!(ObjectAddr::new(0x6040, 0).to_mapping_prefix(), 0x6040_0000);
        let mut s = Buf::default();
        core::fmt::write(&mut s, format_args!("{}", ObjectAddr::new(0x1A00, 3))).unwrap();
        assert_eq!(s.as_str(), "0x1A00:03");
    }

    /// Tiny fixed buffer so tests can format without alloc.
    pub(crate) struct Buf {
        b: [u8; 128],
        n: usize,
    }
    impl Default for Buf {
        fn default() -> Self {
            Self { b: [0; 128], n: 0 }
        }
    }
    impl Buf {
        pub(crate) fn as_str(&self) -> &str {
            core::str::from_utf8(&self.b[..self.n]).unwrap()
        }
    }
    impl core::fmt::Write for Buf {
        fn write_str(&mut self, s: &str) -> core::fmt::Result {
            let end = self.n + s.len();
            self.b.get_mut(self.n..end).ok_or(core::fmt::Error)?.copy_from_slice(s.as_bytes());
            self.n = end;
            Ok(())
        }
    }
}
