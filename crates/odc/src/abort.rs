//! SDO abort codes (CiA 301 table 22): vocabulary that generated dictionaries, the SDO server
//! and client, and applications share, apart from the protocol machinery of [`crate::sdo`].

use core::fmt;

macro_rules! aborts {
    ($($v:ident = $code:literal, $text:literal;)*) => {
        /// SDO abort code, as sent in an abort frame (CiA 301 table 22).
        ///
        /// Unknown codes (manufacturer or newer spec versions) survive as `Other`, so a master
        /// can report exactly what the device said.
        #[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
        #[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
        #[cfg_attr(feature = "defmt", derive(defmt::Format))]
        pub enum SdoAbort {
            $(#[doc = $text] $v,)*
            /// A code not in CiA 301 table 22.
            Other(u32),
        }

        /// The variants' positions in the table: a match from a variant to its position is
        /// the identity on the discriminant, so `to_u32` is one load from [`CODES`], not a
        /// jump table with an arm per code (a firmware image pays for each arm).
        #[derive(Clone, Copy)]
        #[repr(u8)]
        enum Position {
            $($v,)*
        }

        /// The wire codes, in the order of the variants.
        const CODES: &[u32] = &[$($code),*];
        /// The positions, one byte each, for `from_u32` (`SdoAbort::ALL` is 8 bytes an entry).
        const POSITIONS: &[Position] = &[$(Position::$v),*];

        impl SdoAbort {
            /// Every code of the table (without `Other`).
            pub const ALL: &'static [SdoAbort] = &[$(Self::$v),*];

            /// The abort for a wire code; never fails, unknown codes become `Other`. A linear
            /// search: aborts are rare, and it keeps no second table.
            pub const fn from_u32(code: u32) -> Self {
                let mut i = 0;
                while i < CODES.len() && i < POSITIONS.len() {
                    if CODES[i] == code {
                        return match POSITIONS[i] {
                            $(Position::$v => Self::$v,)*
                        };
                    }
                    i += 1;
                }
                Self::Other(code)
            }

            /// The wire code.
            pub const fn to_u32(self) -> u32 {
                let i = match self {
                    $(Self::$v => Position::$v as usize,)*
                    Self::Other(c) => return c,
                };
                // One code per variant: `i` is in range; 0 cannot happen.
                if i < CODES.len() { CODES[i] } else { 0 }
            }

            /// The description from CiA 301, or `None` for `Other`.
            pub const fn description(self) -> Option<&'static str> {
                match self {
                    $(Self::$v => Some($text),)*
                    Self::Other(_) => None,
                }
            }
        }
    };
}

aborts! {
    ToggleBit = 0x0503_0000, "Toggle bit not alternated";
    Timeout = 0x0504_0000, "SDO protocol timed out";
    InvalidCommand = 0x0504_0001, "Client/server command specifier not valid or unknown";
    InvalidBlockSize = 0x0504_0002, "Invalid block size (block mode only)";
    InvalidSequence = 0x0504_0003, "Invalid sequence number (block mode only)";
    CrcError = 0x0504_0004, "CRC error (block mode only)";
    OutOfMemory = 0x0504_0005, "Out of memory";
    UnsupportedAccess = 0x0601_0000, "Unsupported access to an object";
    ReadOfWriteOnly = 0x0601_0001, "Attempt to read a write only object";
    WriteOfReadOnly = 0x0601_0002, "Attempt to write a read only object";
    NoSuchObject = 0x0602_0000, "Object does not exist in the object dictionary";
    NotMappable = 0x0604_0041, "Object cannot be mapped to the PDO";
    PdoLengthExceeded = 0x0604_0042, "The number and length of the objects to be mapped would exceed PDO length";
    ParameterIncompatible = 0x0604_0043, "General parameter incompatibility reason";
    InternalIncompatible = 0x0604_0047, "General internal incompatibility in the device";
    HardwareError = 0x0606_0000, "Access failed due to a hardware error";
    LengthMismatch = 0x0607_0010, "Data type does not match, length of service parameter does not match";
    TooLong = 0x0607_0012, "Data type does not match, length of service parameter too high";
    TooShort = 0x0607_0013, "Data type does not match, length of service parameter too low";
    NoSuchSub = 0x0609_0011, "Sub-index does not exist";
    InvalidValue = 0x0609_0030, "Invalid value for parameter (download only)";
    ValueTooHigh = 0x0609_0031, "Value of parameter written too high (download only)";
    ValueTooLow = 0x0609_0032, "Value of parameter written too low (download only)";
    MaxLessThanMin = 0x0609_0036, "Maximum value is less than minimum value";
    NoResource = 0x060A_0023, "Resource not available: SDO connection";
    General = 0x0800_0000, "General error";
    DataTransfer = 0x0800_0020, "Data cannot be transferred or stored to the application";
    LocalControl = 0x0800_0021, "Data cannot be transferred or stored to the application because of local control";
    DeviceState = 0x0800_0022, "Data cannot be transferred or stored to the application because of the present device state";
    NoObjectDictionary = 0x0800_0023, "Object dictionary dynamic generation fails or no object dictionary is present";
    NoData = 0x0800_0024, "No data available";
}

impl SdoAbort {
    /// CiA 301 gives one code for "data type does not match" and "length does not match".
    pub const TYPE_MISMATCH: Self = Self::LengthMismatch;
}

impl From<u32> for SdoAbort {
    fn from(code: u32) -> Self {
        Self::from_u32(code)
    }
}

impl From<SdoAbort> for u32 {
    fn from(a: SdoAbort) -> u32 {
        a.to_u32()
    }
}

impl fmt::Display for SdoAbort {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self.description() {
            Some(d) => write!(f, "SDO abort 0x{:08X}: {d}", self.to_u32()),
            None => write!(f, "SDO abort 0x{:08X}", self.to_u32()),
        }
    }
}

impl core::error::Error for SdoAbort {}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn codes_round_trip() {
        assert_eq!(SdoAbort::ALL.len(), 31);
        for &a in SdoAbort::ALL {
            assert_eq!(SdoAbort::from_u32(a.to_u32()), a);
            assert!(a.description().is_some());
        }
        assert_eq!(SdoAbort::from_u32(0x0609_0011), SdoAbort::NoSuchSub);
        assert_eq!(SdoAbort::from_u32(0x1234_5678), SdoAbort::Other(0x1234_5678));
        assert_eq!(SdoAbort::Other(7).to_u32(), 7);
        assert_eq!(SdoAbort::TYPE_MISMATCH.to_u32(), 0x0607_0010);
        assert_eq!(u32::from(SdoAbort::DeviceState), 0x0800_0022);
    }

    #[test]
    fn display() {
        use core::fmt::Write;
        let mut s = crate::types::tests::Buf::default();
        write!(s, "{}", SdoAbort::WriteOfReadOnly).unwrap();
        assert_eq!(s.as_str(), "SDO abort 0x06010002: Attempt to write a read only object");
    }
}
