//! Emergency (EMCY) messages: error codes (CiA 301 table 21, common CiA 402 codes), the error
//! register (0x1001) and the 8-byte frame.

use core::fmt;

/// An EMCY error code. A newtype, not an enum: devices use many manufacturer and profile
/// codes, and the class is in the high bits anyway.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct EmcyCode(pub u16);

macro_rules! codes {
    ($($name:ident = $code:literal, $text:literal;)*) => {
        impl EmcyCode {
            $(#[doc = $text] pub const $name: Self = Self($code);)*

            /// The description of a code listed here, or `None`.
            pub const fn description(self) -> Option<&'static str> {
                match self.0 {
                    $($code => Some($text),)*
                    _ => None,
                }
            }
        }
    };
}

codes! {
    NO_ERROR = 0x0000, "Error reset or no error";
    GENERIC = 0x1000, "Generic error";
    CURRENT = 0x2000, "Current";
    CURRENT_INPUT = 0x2100, "Current, device input side";
    CURRENT_INSIDE = 0x2200, "Current inside the device";
    CURRENT_OUTPUT = 0x2300, "Current, device output side";
    CONTINUOUS_OVER_CURRENT = 0x2310, "Continuous over current (CiA 402)";
    SHORT_CIRCUIT = 0x2320, "Short circuit/earth leakage (CiA 402)";
    VOLTAGE = 0x3000, "Voltage";
    MAINS_VOLTAGE = 0x3100, "Mains voltage";
    VOLTAGE_INSIDE = 0x3200, "Voltage inside the device";
    DC_LINK_OVER_VOLTAGE = 0x3210, "DC link over-voltage (CiA 402)";
    DC_LINK_UNDER_VOLTAGE = 0x3220, "DC link under-voltage (CiA 402)";
    OUTPUT_VOLTAGE = 0x3300, "Output voltage";
    TEMPERATURE = 0x4000, "Temperature";
    AMBIENT_TEMPERATURE = 0x4100, "Ambient temperature";
    DEVICE_TEMPERATURE = 0x4200, "Device temperature";
    EXCESS_TEMPERATURE_DEVICE = 0x4210, "Excess temperature device (CiA 402)";
    EXCESS_TEMPERATURE_DRIVE = 0x4310, "Excess temperature drive (CiA 402)";
    HARDWARE = 0x5000, "Device hardware";
    SOFTWARE = 0x6000, "Device software";
    INTERNAL_SOFTWARE = 0x6100, "Internal software";
    USER_SOFTWARE = 0x6200, "User software";
    DATA_SET = 0x6300, "Data set";
    PARAMETER_ERROR = 0x6320, "Parameter error (CiA 402)";
    ADDITIONAL_MODULES = 0x7000, "Additional modules";
    MOTOR_BLOCKED = 0x7121, "Motor blocked (CiA 402)";
    SENSOR = 0x7300, "Sensor (CiA 402)";
    INCREMENTAL_SENSOR_1 = 0x7305, "Incremental sensor 1 fault (CiA 402)";
    MONITORING = 0x8000, "Monitoring";
    COMMUNICATION = 0x8100, "Communication";
    CAN_OVERRUN = 0x8110, "CAN overrun (objects lost)";
    CAN_ERROR_PASSIVE = 0x8120, "CAN in error passive mode";
    HEARTBEAT = 0x8130, "Life guard error or heartbeat error";
    BUS_OFF_RECOVERED = 0x8140, "Recovered from bus off";
    CAN_ID_COLLISION = 0x8150, "CAN-ID collision";
    PROTOCOL = 0x8200, "Protocol error";
    PDO_LENGTH = 0x8210, "PDO not processed due to length error";
    PDO_LENGTH_EXCEEDED = 0x8220, "PDO length exceeded";
    DAM_MPDO = 0x8230, "DAM MPDO not processed, destination object not available";
    SYNC_LENGTH = 0x8240, "Unexpected SYNC data length";
    RPDO_TIMEOUT = 0x8250, "RPDO timeout";
    FOLLOWING_ERROR = 0x8611, "Following error (CiA 402)";
    REFERENCE_LIMIT = 0x8612, "Reference limit (CiA 402)";
    EXTERNAL = 0x9000, "External error";
    ADDITIONAL_FUNCTIONS = 0xF000, "Additional functions";
    DEVICE_SPECIFIC = 0xFF00, "Device specific";
}

/// The class of an EMCY code, from its high bits (CiA 301 table 21).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum ErrorClass {
    /// 0x00xx: error reset or no error.
    NoError,
    /// 0x10xx.
    Generic,
    /// 0x2xxx.
    Current,
    /// 0x3xxx.
    Voltage,
    /// 0x4xxx.
    Temperature,
    /// 0x50xx.
    Hardware,
    /// 0x6xxx.
    Software,
    /// 0x70xx and other 0x7xxx (CiA 402 uses 0x71xx–0x75xx).
    AdditionalModules,
    /// 0x8xxx.
    Monitoring,
    /// 0x90xx.
    External,
    /// 0xF0xx.
    AdditionalFunctions,
    /// 0xFFxx.
    DeviceSpecific,
    /// Anything else (0x01xx–0x0Fxx, 0xA000–0xEFFF, …).
    Reserved,
}

impl EmcyCode {
    /// The class of this code.
    pub const fn class(self) -> ErrorClass {
        match self.0 >> 8 {
            0x00 => ErrorClass::NoError,
            0x10..=0x1F => ErrorClass::Generic,
            0x20..=0x2F => ErrorClass::Current,
            0x30..=0x3F => ErrorClass::Voltage,
            0x40..=0x4F => ErrorClass::Temperature,
            0x50..=0x5F => ErrorClass::Hardware,
            0x60..=0x6F => ErrorClass::Software,
            0x70..=0x7F => ErrorClass::AdditionalModules,
            0x80..=0x8F => ErrorClass::Monitoring,
            0x90..=0x9F => ErrorClass::External,
            0xFF => ErrorClass::DeviceSpecific,
            0xF0..=0xFE => ErrorClass::AdditionalFunctions,
            _ => ErrorClass::Reserved,
        }
    }

    /// The error-register bit a device should set along with this code (CiA 301 7.5.2.2).
    pub const fn register_bit(self) -> ErrorRegister {
        match self.class() {
            ErrorClass::NoError => ErrorRegister::NONE,
            ErrorClass::Current => ErrorRegister::CURRENT,
            ErrorClass::Voltage => ErrorRegister::VOLTAGE,
            ErrorClass::Temperature => ErrorRegister::TEMPERATURE,
            ErrorClass::Monitoring if matches!((self.0 >> 8) & 0xF, 1 | 2) => {
                ErrorRegister::COMMUNICATION
            }
            ErrorClass::DeviceSpecific => ErrorRegister::MANUFACTURER,
            _ => ErrorRegister::GENERIC,
        }
    }
}

impl fmt::Display for EmcyCode {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self.description() {
            Some(d) => write!(f, "0x{:04X} ({d})", self.0),
            None => write!(f, "0x{:04X}", self.0),
        }
    }
}

/// Error register (object 0x1001), a bit set.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct ErrorRegister(pub u8);

impl ErrorRegister {
    /// No bit set.
    pub const NONE: Self = Self(0);
    /// Bit 0: generic error (set whenever any other is).
    pub const GENERIC: Self = Self(1 << 0);
    /// Bit 1: current.
    pub const CURRENT: Self = Self(1 << 1);
    /// Bit 2: voltage.
    pub const VOLTAGE: Self = Self(1 << 2);
    /// Bit 3: temperature.
    pub const TEMPERATURE: Self = Self(1 << 3);
    /// Bit 4: communication error (overrun, error state).
    pub const COMMUNICATION: Self = Self(1 << 4);
    /// Bit 5: device profile specific.
    pub const PROFILE: Self = Self(1 << 5);
    /// Bit 7: manufacturer specific.
    pub const MANUFACTURER: Self = Self(1 << 7);

    /// Whether every bit of `other` is set.
    pub const fn contains(self, other: Self) -> bool {
        self.0 & other.0 == other.0
    }

    /// Union of both sets.
    pub const fn union(self, other: Self) -> Self {
        Self(self.0 | other.0)
    }

    /// With `flag` set, and the generic bit that CiA 301 requires along with any error.
    pub const fn with_error(self, flag: Self) -> Self {
        if flag.0 == 0 { self } else { Self(self.0 | flag.0 | Self::GENERIC.0) }
    }

    /// Whether no error is flagged.
    pub const fn is_empty(self) -> bool {
        self.0 == 0
    }
}

impl core::ops::BitOr for ErrorRegister {
    type Output = Self;
    fn bitor(self, rhs: Self) -> Self {
        self.union(rhs)
    }
}

/// An EMCY frame payload: code (LE u16), error register, 5 manufacturer bytes.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct EmcyFrame {
    /// Error code.
    pub code: EmcyCode,
    /// Error register at the time of the error.
    pub register: ErrorRegister,
    /// Manufacturer-specific bytes.
    pub manufacturer: [u8; 5],
}

/// The EMCY payload was not 8 bytes.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct BadEmcyLength(pub usize);

impl fmt::Display for BadEmcyLength {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "EMCY payload has {} bytes, expected 8", self.0)
    }
}

impl core::error::Error for BadEmcyLength {}

impl EmcyFrame {
    /// A frame with zero manufacturer bytes.
    pub const fn new(code: EmcyCode, register: ErrorRegister) -> Self {
        Self { code, register, manufacturer: [0; 5] }
    }

    /// The 8-byte payload.
    pub const fn encode(&self) -> [u8; 8] {
        let c = self.code.0.to_le_bytes();
        let m = self.manufacturer;
        [c[0], c[1], self.register.0, m[0], m[1], m[2], m[3], m[4]]
    }

    /// Decode a payload, which must be exactly 8 bytes.
    pub fn decode(buf: &[u8]) -> Result<Self, BadEmcyLength> {
        let b: [u8; 8] = buf.try_into().map_err(|_| BadEmcyLength(buf.len()))?;
        Ok(Self {
            code: EmcyCode(u16::from_le_bytes([b[0], b[1]])),
            register: ErrorRegister(b[2]),
            manufacturer: [b[3], b[4], b[5], b[6], b[7]],
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn frame_round_trip() {
        let f = EmcyFrame {
            code: EmcyCode::FOLLOWING_ERROR,
            register: ErrorRegister::NONE.with_error(ErrorRegister::PROFILE),
            manufacturer: [1, 2, 3, 4, 5],
        };
        let b = f.encode();
        assert_eq!(b, [0x11, 0x86, 0x21, 1, 2, 3, 4, 5]);
        assert_eq!(EmcyFrame::decode(&b), Ok(f));
        assert_eq!(EmcyFrame::decode(&b[..7]), Err(BadEmcyLength(7)));
    }

    #[test]
    fn classes() {
        assert_eq!(EmcyCode(0x2310).class(), ErrorClass::Current);
        assert_eq!(EmcyCode(0x8611).class(), ErrorClass::Monitoring);
        assert_eq!(EmcyCode(0xFF42).class(), ErrorClass::DeviceSpecific);
        assert_eq!(EmcyCode(0xF001).class(), ErrorClass::AdditionalFunctions);
        assert_eq!(EmcyCode(0xA000).class(), ErrorClass::Reserved);
        assert_eq!(EmcyCode::CAN_OVERRUN.register_bit(), ErrorRegister::COMMUNICATION);
        assert_eq!(EmcyCode::FOLLOWING_ERROR.register_bit(), ErrorRegister::GENERIC);
        assert_eq!(EmcyCode(0x3210).register_bit(), ErrorRegister::VOLTAGE);
        assert_eq!(EmcyCode::HEARTBEAT.description(), Some("Life guard error or heartbeat error"));
        assert_eq!(EmcyCode(0x1234).description(), None);
    }

    #[test]
    fn register_flags() {
        let r = ErrorRegister::CURRENT | ErrorRegister::VOLTAGE;
        assert!(r.contains(ErrorRegister::CURRENT));
        assert!(!r.contains(ErrorRegister::GENERIC));
        assert!(ErrorRegister::NONE.is_empty());
        assert_eq!(ErrorRegister::NONE.with_error(ErrorRegister::NONE), ErrorRegister::NONE);
    }
}
