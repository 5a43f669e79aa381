//! Modes of operation (0x6060, display 0x6061) and supported drive modes (0x6502).

/// Mode of operation (0x6060 / display 0x6061), an `i8` on the wire.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum ModeOfOperation {
    /// 0: no mode assigned.
    NoMode,
    /// 1: profile position (pp).
    ProfilePosition,
    /// 2: velocity (vl).
    Velocity,
    /// 3: profile velocity (pv).
    ProfileVelocity,
    /// 4: profile torque (tq).
    ProfileTorque,
    /// 6: homing (hm).
    Homing,
    /// 7: interpolated position (ip).
    InterpolatedPosition,
    /// 8: cyclic synchronous position (csp).
    CyclicSyncPosition,
    /// 9: cyclic synchronous velocity (csv).
    CyclicSyncVelocity,
    /// 10: cyclic synchronous torque (cst).
    CyclicSyncTorque,
    /// Anything else: negative values are manufacturer modes, others reserved.
    Other(i8),
}

impl ModeOfOperation {
    /// The mode for a wire value.
    pub const fn from_i8(v: i8) -> Self {
        match v {
            0 => Self::NoMode,
            1 => Self::ProfilePosition,
            2 => Self::Velocity,
            3 => Self::ProfileVelocity,
            4 => Self::ProfileTorque,
            6 => Self::Homing,
            7 => Self::InterpolatedPosition,
            8 => Self::CyclicSyncPosition,
            9 => Self::CyclicSyncVelocity,
            10 => Self::CyclicSyncTorque,
            other => Self::Other(other),
        }
    }

    /// The wire value.
    pub const fn to_i8(self) -> i8 {
        match self {
            Self::NoMode => 0,
            Self::ProfilePosition => 1,
            Self::Velocity => 2,
            Self::ProfileVelocity => 3,
            Self::ProfileTorque => 4,
            Self::Homing => 6,
            Self::InterpolatedPosition => 7,
            Self::CyclicSyncPosition => 8,
            Self::CyclicSyncVelocity => 9,
            Self::CyclicSyncTorque => 10,
            Self::Other(v) => v,
        }
    }

    /// Whether the value is in the manufacturer range (negative).
    pub const fn is_manufacturer_specific(self) -> bool {
        self.to_i8() < 0
    }

    /// The bit of 0x6502 that announces this mode, if the profile defines one.
    pub const fn supported_bit(self) -> Option<u32> {
        match self {
            Self::ProfilePosition => Some(0),
            Self::Velocity => Some(1),
            Self::ProfileVelocity => Some(2),
            Self::ProfileTorque => Some(3),
            Self::Homing => Some(5),
            Self::InterpolatedPosition => Some(6),
            Self::CyclicSyncPosition => Some(7),
            Self::CyclicSyncVelocity => Some(8),
            Self::CyclicSyncTorque => Some(9),
            Self::NoMode | Self::Other(_) => None,
        }
    }
}

impl From<i8> for ModeOfOperation {
    fn from(v: i8) -> Self {
        Self::from_i8(v)
    }
}

impl From<ModeOfOperation> for i8 {
    fn from(m: ModeOfOperation) -> i8 {
        m.to_i8()
    }
}

/// Supported drive modes (0x6502), a bit set.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct SupportedModes(pub u32);

impl SupportedModes {
    /// Whether the drive announces `mode`; manufacturer modes and `NoMode` are never announced
    /// through a profile bit.
    pub const fn supports(self, mode: ModeOfOperation) -> bool {
        match mode.supported_bit() {
            Some(b) => self.0 & (1 << b) != 0,
            None => false,
        }
    }

    /// Bits 16–31: manufacturer-specific modes.
    pub const fn manufacturer_bits(self) -> u16 {
        (self.0 >> 16) as u16
    }

    /// The announced profile modes, in bit order.
    pub fn iter(self) -> impl Iterator<Item = ModeOfOperation> {
        [1i8, 2, 3, 4, 6, 7, 8, 9, 10]
            .into_iter()
            .map(ModeOfOperation::from_i8)
            .filter(move |m| self.supports(*m))
    }
}
