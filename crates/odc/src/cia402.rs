//! CiA 402 drive profile: controlword (0x6040), statusword (0x6041), the state machine, modes of
//! operation (0x6060/0x6061) and supported modes (0x6502).
//!
//! A master walks a drive to "operation enabled" by reading the state from the statusword and
//! sending the controlword that leads on; [`State::after`] is the drive's side of the same
//! state machine (what a simulated or slave-side drive does with a controlword):
//!
//! ```
//! use odc::cia402::{Controlword, ModeOfOperation, State, Statusword, SupportedModes};
//!
//! let mut drive = State::SwitchOnDisabled;
//! let mut sent = Vec::new();
//! // Master: from the statusword, the next controlword, until the drive is enabled.
//! while drive.statusword().state() != Some(State::OperationEnabled) {
//!     let state = drive.statusword().state().ok_or("not a state")?;
//!     let cw = state.next_command_towards_enabled().ok_or("wait for the drive")?;
//!     sent.push(cw);
//!     drive = drive.after(cw, false); // the drive's transition
//! }
//! assert_eq!(drive, State::OperationEnabled);
//! use Controlword as Cw;
//! assert_eq!(sent, [Cw::SHUTDOWN, Cw::SWITCH_ON, Cw::ENABLE_OPERATION]);
//!
//! // A profile-position set-point: enable operation with "new set-point".
//! let cw = Controlword::ENABLE_OPERATION.with_new_setpoint(true);
//! assert_eq!(cw.bits(), 0x001F);
//! let sw = Statusword(0x1637); // as read from 0x6041
//! assert_eq!(sw.state(), Some(State::OperationEnabled));
//! assert!(sw.target_reached() && sw.setpoint_ack());
//!
//! // 0x6502: which modes the drive supports.
//! let modes = SupportedModes(0x0000_0025); // pp, pv, hm
//! assert!(modes.supports(ModeOfOperation::ProfilePosition));
//! assert!(!modes.supports(ModeOfOperation::CyclicSyncPosition));
//! assert_eq!(ModeOfOperation::from_i8(8), ModeOfOperation::CyclicSyncPosition);
//! # Ok::<(), &str>(())
//! ```

use crate::{DataType, ObjValue, PdoValue, ValueError};
use core::fmt;

/// Controlword (0x6040). Commands are associated consts; mode-specific bits are set builder-style:
/// `Controlword::ENABLE_OPERATION.with_new_setpoint(true)`.
///
/// The value type of a generated `od::CONTROLWORD` (`odc::Entry<Controlword>`) and of the PDO
/// fields that map 0x6040; it converts from and into the `u16` on the wire. It orders by that
/// raw value, as the limits of a device file compare it.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, PartialOrd, Ord, Hash)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct Controlword(pub u16);

impl Controlword {
    /// Disable voltage (transitions 7, 9, 10, 12).
    pub const DISABLE_VOLTAGE: Self = Self(0x0000);
    /// Quick stop (transitions 7, 10, 11).
    pub const QUICK_STOP: Self = Self(0x0002);
    /// Shutdown (transitions 2, 6, 8).
    pub const SHUTDOWN: Self = Self(0x0006);
    /// Switch on (transition 3).
    pub const SWITCH_ON: Self = Self(0x0007);
    /// Disable operation (transition 5); the same bits as switch on.
    pub const DISABLE_OPERATION: Self = Self(0x0007);
    /// Enable operation (transitions 4, 16).
    pub const ENABLE_OPERATION: Self = Self(0x000F);
    /// Fault reset (transition 15). Acts on the rising edge of bit 7: send a controlword with
    /// bit 7 clear first, then this one.
    pub const FAULT_RESET: Self = Self(0x0080);

    const NEW_SETPOINT: u16 = 1 << 4;
    const CHANGE_SET_IMMEDIATELY: u16 = 1 << 5;
    const RELATIVE: u16 = 1 << 6;
    const FAULT_RESET_BIT: u16 = 1 << 7;
    const HALT: u16 = 1 << 8;
    const CHANGE_ON_SETPOINT: u16 = 1 << 9;

    /// The raw value.
    pub const fn bits(self) -> u16 {
        self.0
    }

    const fn with(self, bit: u16, on: bool) -> Self {
        if on { Self(self.0 | bit) } else { Self(self.0 & !bit) }
    }

    /// Bit 4, profile position: new set-point.
    pub const fn with_new_setpoint(self, on: bool) -> Self {
        self.with(Self::NEW_SETPOINT, on)
    }

    /// Bit 4, homing: start homing.
    pub const fn with_homing_start(self, on: bool) -> Self {
        self.with(Self::NEW_SETPOINT, on)
    }

    /// Bit 5, profile position: change set immediately.
    pub const fn with_change_set_immediately(self, on: bool) -> Self {
        self.with(Self::CHANGE_SET_IMMEDIATELY, on)
    }

    /// Bit 6, profile position: target is relative (clear: absolute).
    pub const fn with_relative(self, on: bool) -> Self {
        self.with(Self::RELATIVE, on)
    }

    /// Bit 7: fault reset.
    pub const fn with_fault_reset(self, on: bool) -> Self {
        self.with(Self::FAULT_RESET_BIT, on)
    }

    /// Bit 8: halt.
    pub const fn with_halt(self, on: bool) -> Self {
        self.with(Self::HALT, on)
    }

    /// Bit 9, profile position: change on set-point.
    pub const fn with_change_on_setpoint(self, on: bool) -> Self {
        self.with(Self::CHANGE_ON_SETPOINT, on)
    }

    /// Whether bit `n` is set.
    pub const fn bit(self, n: u32) -> bool {
        n < 16 && self.0 & (1 << n) != 0
    }
}

/// Statusword (0x6041).
///
/// The value type of a generated `od::STATUSWORD` (`odc::Entry<Statusword>`) and of the PDO
/// fields that map 0x6041; it converts from and into the `u16` on the wire, and orders by it.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, PartialOrd, Ord, Hash)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct Statusword(pub u16);

/// Power state of a CiA 402 drive.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum State {
    /// Initialising; the drive leaves it on its own.
    NotReadyToSwitchOn,
    /// Power stage off, drive reachable.
    SwitchOnDisabled,
    /// After shutdown.
    ReadyToSwitchOn,
    /// Power stage on, no torque.
    SwitchedOn,
    /// Following commands.
    OperationEnabled,
    /// Quick stop in progress or done.
    QuickStopActive,
    /// Reacting to a fault; the drive leaves it on its own.
    FaultReactionActive,
    /// Fault; needs a fault reset.
    Fault,
}

impl Statusword {
    /// The raw value.
    pub const fn bits(self) -> u16 {
        self.0
    }

    /// Decode the state (CiA 402 masks 0x4F and 0x6F); `None` for patterns the profile
    /// does not define.
    pub const fn state(self) -> Option<State> {
        let s = self.0;
        if s & 0x4F == 0x00 {
            return Some(State::NotReadyToSwitchOn);
        }
        if s & 0x4F == 0x40 {
            return Some(State::SwitchOnDisabled);
        }
        if s & 0x4F == 0x0F {
            return Some(State::FaultReactionActive);
        }
        if s & 0x4F == 0x08 {
            return Some(State::Fault);
        }
        match s & 0x6F {
            0x21 => Some(State::ReadyToSwitchOn),
            0x23 => Some(State::SwitchedOn),
            0x27 => Some(State::OperationEnabled),
            0x07 => Some(State::QuickStopActive),
            _ => None,
        }
    }

    const fn bit(self, n: u32) -> bool {
        self.0 & (1 << n) != 0
    }

    /// Bit 3: fault.
    pub const fn fault(self) -> bool {
        self.bit(3)
    }
    /// Bit 4: voltage enabled.
    pub const fn voltage_enabled(self) -> bool {
        self.bit(4)
    }
    /// Bit 5: quick stop; active low (clear while a quick stop is running).
    pub const fn quick_stop(self) -> bool {
        self.bit(5)
    }
    /// Bit 7: warning.
    pub const fn warning(self) -> bool {
        self.bit(7)
    }
    /// Bit 9: remote (controlword is processed).
    pub const fn remote(self) -> bool {
        self.bit(9)
    }
    /// Bit 10: target reached.
    pub const fn target_reached(self) -> bool {
        self.bit(10)
    }
    /// Bit 11: internal limit active.
    pub const fn internal_limit(self) -> bool {
        self.bit(11)
    }
    /// Bit 12 in profile position: set-point acknowledge.
    pub const fn setpoint_ack(self) -> bool {
        self.bit(12)
    }
    /// Bit 12 in homing: homing attained.
    pub const fn homing_attained(self) -> bool {
        self.bit(12)
    }
    /// Bit 13 in profile/cyclic position: following error.
    pub const fn following_error(self) -> bool {
        self.bit(13)
    }
    /// Bit 13 in homing: homing error.
    pub const fn homing_error(self) -> bool {
        self.bit(13)
    }

    /// The same statusword with bit `n` (0–15) set or cleared; the state bits are better set
    /// with [`State::statusword`] and [`Statusword::with_state`].
    pub const fn with_bit(self, n: u32, on: bool) -> Self {
        if n >= 16 {
            return self;
        }
        let bit = 1 << n;
        if on { Self(self.0 | bit) } else { Self(self.0 & !bit) }
    }

    /// The same statusword in `state`: bits 0–3, 5 and 6 replaced, the others kept.
    pub const fn with_state(self, state: State) -> Self {
        Self((self.0 & !State::STATE_BITS) | state.statusword().0)
    }

    /// Bit 4 set or cleared: voltage enabled.
    pub const fn with_voltage_enabled(self, on: bool) -> Self {
        self.with_bit(4, on)
    }
    /// Bit 7 set or cleared: warning.
    pub const fn with_warning(self, on: bool) -> Self {
        self.with_bit(7, on)
    }
    /// Bit 9 set or cleared: remote.
    pub const fn with_remote(self, on: bool) -> Self {
        self.with_bit(9, on)
    }
    /// Bit 10 set or cleared: target reached.
    pub const fn with_target_reached(self, on: bool) -> Self {
        self.with_bit(10, on)
    }
    /// Bit 11 set or cleared: internal limit active.
    pub const fn with_internal_limit(self, on: bool) -> Self {
        self.with_bit(11, on)
    }
    /// Bit 12 set or cleared: set-point acknowledge (pp), homing attained (hm), speed zero (pv).
    pub const fn with_setpoint_ack(self, on: bool) -> Self {
        self.with_bit(12, on)
    }
    /// Bit 13 set or cleared: following error (pp, csp), homing error (hm).
    pub const fn with_following_error(self, on: bool) -> Self {
        self.with_bit(13, on)
    }
}

/// A controlword as the device reads it: the command of bits 0–3 (CiA 402 table 28), with
/// "disable voltage" winning over "quick stop" winning over the others, as the table's "x"
/// entries imply.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum Command {
    /// Bit 1 clear.
    DisableVoltage,
    /// Bit 1 set, bit 2 clear.
    QuickStop,
    /// Bits 2, 1 set, bit 0 clear.
    Shutdown,
    /// Bits 2, 1, 0 set, bit 3 clear: switch on, or disable operation.
    SwitchOn,
    /// Bits 3, 2, 1, 0 set: enable operation (from "ready to switch on", switch on too).
    EnableOperation,
}

impl Controlword {
    /// The device-control command bits 0–3 hold (bit 7, fault reset, acts on its edge and is
    /// not part of it).
    pub const fn command(self) -> Command {
        let c = self.0;
        if c & 0x02 == 0 {
            Command::DisableVoltage
        } else if c & 0x04 == 0 {
            Command::QuickStop
        } else if c & 0x01 == 0 {
            Command::Shutdown
        } else if c & 0x08 == 0 {
            Command::SwitchOn
        } else {
            Command::EnableOperation
        }
    }
}

impl State {
    /// The statusword bits that encode a state: 0–3, 5 and 6.
    pub const STATE_BITS: u16 = 0x6F;

    /// The statusword of a drive in this state, with only the state bits set (CiA 402 table
    /// 30; bit 5, "quick stop", set where the table leaves it open). A drive adds voltage
    /// enabled, remote, target reached and the mode bits with the `Statusword::with_*`
    /// methods; [`Statusword::state`] decodes the result back to `self`.
    pub const fn statusword(self) -> Statusword {
        Statusword(match self {
            Self::NotReadyToSwitchOn => 0x00,
            Self::SwitchOnDisabled => 0x40,
            Self::ReadyToSwitchOn => 0x21,
            Self::SwitchedOn => 0x23,
            Self::OperationEnabled => 0x27,
            Self::QuickStopActive => 0x07,
            Self::FaultReactionActive => 0x2F,
            Self::Fault => 0x28,
        })
    }

    /// The state a drive in this state moves to on receiving `cw`: the device-control
    /// transitions 2–12, 15 and 16 of CiA 402 (§6.2). A command with no transition from this
    /// state leaves it unchanged; "enable operation" in "ready to switch on" runs transitions
    /// 3 and 4 at once, as the profile allows. Fault reset (15) acts on the rising edge of bit
    /// 7 only, which the caller knows: `fault_reset_edge` says the previous controlword had
    /// bit 7 clear. The transitions the drive makes on its own (0, 1, 13, 14, and leaving
    /// "quick stop active" after the stop) are the drive's, not the controlword's.
    pub const fn after(self, cw: Controlword, fault_reset_edge: bool) -> State {
        use Command::*;
        match (self, cw.command()) {
            (Self::Fault, _) if fault_reset_edge && cw.bit(7) => Self::SwitchOnDisabled,
            (Self::SwitchOnDisabled, Shutdown) => Self::ReadyToSwitchOn,
            (Self::ReadyToSwitchOn, SwitchOn) => Self::SwitchedOn,
            (Self::ReadyToSwitchOn, EnableOperation) => Self::OperationEnabled,
            (Self::ReadyToSwitchOn, DisableVoltage | QuickStop) => Self::SwitchOnDisabled,
            (Self::SwitchedOn, EnableOperation) => Self::OperationEnabled,
            (Self::SwitchedOn, Shutdown) => Self::ReadyToSwitchOn,
            (Self::SwitchedOn, DisableVoltage | QuickStop) => Self::SwitchOnDisabled,
            (Self::OperationEnabled, SwitchOn) => Self::SwitchedOn,
            (Self::OperationEnabled, Shutdown) => Self::ReadyToSwitchOn,
            (Self::OperationEnabled, DisableVoltage) => Self::SwitchOnDisabled,
            (Self::OperationEnabled, QuickStop) => Self::QuickStopActive,
            (Self::QuickStopActive, DisableVoltage) => Self::SwitchOnDisabled,
            (Self::QuickStopActive, EnableOperation) => Self::OperationEnabled,
            (s, _) => s,
        }
    }

    /// The controlword that moves this state one step toward `OperationEnabled`, or holds it
    /// there. `None` while the drive changes state on its own (not ready, fault reaction).
    ///
    /// From `Fault` this is [`Controlword::FAULT_RESET`], which only acts on a rising edge.
    pub const fn next_command_towards_enabled(self) -> Option<Controlword> {
        match self {
            Self::NotReadyToSwitchOn | Self::FaultReactionActive => None,
            Self::SwitchOnDisabled => Some(Controlword::SHUTDOWN),
            Self::ReadyToSwitchOn => Some(Controlword::SWITCH_ON),
            Self::SwitchedOn | Self::OperationEnabled => Some(Controlword::ENABLE_OPERATION),
            Self::QuickStopActive => Some(Controlword::DISABLE_VOLTAGE),
            Self::Fault => Some(Controlword::FAULT_RESET),
        }
    }
}

impl fmt::Display for State {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(match self {
            Self::NotReadyToSwitchOn => "not ready to switch on",
            Self::SwitchOnDisabled => "switch on disabled",
            Self::ReadyToSwitchOn => "ready to switch on",
            Self::SwitchedOn => "switched on",
            Self::OperationEnabled => "operation enabled",
            Self::QuickStopActive => "quick stop active",
            Self::FaultReactionActive => "fault reaction active",
            Self::Fault => "fault",
        })
    }
}

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

macro_rules! word_pdo {
    ($($t:ty),*) => {$(
        impl PdoValue for $t {
            const BITS: u32 = 16;
            const SIGNED: bool = false;
            #[inline(always)]
            fn to_raw(&self) -> u64 {
                u64::from(self.0)
            }
            #[inline(always)]
            fn from_raw(raw: u64, _bits: u32) -> Option<Self> {
                u16::try_from(raw).ok().map(Self)
            }
        }
    )*};
}
word_pdo!(Controlword, Statusword);

macro_rules! word_u16 {
    ($($t:ident),*) => {$(
        impl From<u16> for $t {
            fn from(bits: u16) -> Self {
                Self(bits)
            }
        }

        impl From<$t> for u16 {
            fn from(word: $t) -> u16 {
                word.0
            }
        }
    )*};
}
word_u16!(Controlword, Statusword);

/// SDO encodings, so generated descriptors can be typed `Entry<Controlword>` and so on.
macro_rules! obj_value_via {
    ($t:ty, $inner:ty, $dt:ident, $to:expr, $from:expr) => {
        impl ObjValue for $t {
            const DATA_TYPE: DataType = DataType::$dt;
            const MAX_LEN: usize = core::mem::size_of::<$inner>();
            fn encode(&self, buf: &mut [u8]) -> Result<usize, ValueError> {
                let to: fn(&$t) -> $inner = $to;
                to(self).encode(buf)
            }
            fn decode(buf: &[u8]) -> Result<Self, ValueError> {
                let from: fn($inner) -> $t = $from;
                <$inner>::decode(buf).map(from)
            }
        }
    };
}
obj_value_via!(Controlword, u16, Unsigned16, |c| c.0, Controlword);
obj_value_via!(Statusword, u16, Unsigned16, |s| s.0, Statusword);
obj_value_via!(ModeOfOperation, i8, Integer8, |m| m.to_i8(), ModeOfOperation::from_i8);
obj_value_via!(SupportedModes, u32, Unsigned32, |m| m.0, SupportedModes);

impl PdoValue for ModeOfOperation {
    const BITS: u32 = 8;
    const SIGNED: bool = true;
    #[inline(always)]
    fn to_raw(&self) -> u64 {
        self.to_i8() as i64 as u64
    }
    #[inline(always)]
    fn from_raw(raw: u64, bits: u32) -> Option<Self> {
        i8::from_raw(raw, bits).map(Self::from_i8)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn commands_and_bits() {
        assert_eq!(Controlword::ENABLE_OPERATION.with_new_setpoint(true).bits(), 0x001F);
        assert_eq!(
            Controlword::ENABLE_OPERATION
                .with_change_set_immediately(true)
                .with_relative(true)
                .bits(),
            0x006F
        );
        assert_eq!(
            Controlword::ENABLE_OPERATION.with_halt(true).with_halt(false),
            Controlword::ENABLE_OPERATION
        );
        assert_eq!(Controlword::SHUTDOWN.with_change_on_setpoint(true).bits(), 0x0206);
        assert_eq!(Controlword::DISABLE_VOLTAGE.with_fault_reset(true), Controlword::FAULT_RESET);
        assert!(Controlword::ENABLE_OPERATION.with_homing_start(true).bit(4));
        assert!(!Controlword::SHUTDOWN.bit(16));
    }

    #[test]
    fn state_decode() {
        let cases = [
            (0x0000, State::NotReadyToSwitchOn),
            (0x0250, State::SwitchOnDisabled),
            (0x0231, State::ReadyToSwitchOn),
            (0x0233, State::SwitchedOn),
            (0x0237, State::OperationEnabled),
            (0x1637, State::OperationEnabled),
            (0x0217, State::QuickStopActive),
            (0x021F, State::FaultReactionActive),
            (0x0218, State::Fault),
        ];
        for (w, s) in cases {
            assert_eq!(Statusword(w).state(), Some(s), "{w:#06x}");
        }
        assert_eq!(Statusword(0x0001).state(), None);
        let sw = Statusword(0x3637 | 0x0880);
        assert!(sw.target_reached() && sw.setpoint_ack() && sw.following_error());
        assert!(
            sw.voltage_enabled()
                && sw.quick_stop()
                && sw.remote()
                && sw.warning()
                && sw.internal_limit()
        );
        assert!(!sw.fault());
    }

    #[test]
    fn walk_to_enabled() {
        // A toy drive that follows the CiA 402 transitions.
        fn step(s: State, c: Controlword) -> State {
            match (s, c.bits() & 0x8F) {
                (State::SwitchOnDisabled, 0x06) => State::ReadyToSwitchOn,
                (State::ReadyToSwitchOn, 0x07) => State::SwitchedOn,
                (State::SwitchedOn, 0x0F) => State::OperationEnabled,
                (State::Fault, 0x80) => State::SwitchOnDisabled,
                (State::QuickStopActive, 0x00) => State::SwitchOnDisabled,
                (s, _) => s,
            }
        }
        for start in [State::Fault, State::SwitchOnDisabled, State::QuickStopActive] {
            let mut s = start;
            for _ in 0..5 {
                s = step(s, s.next_command_towards_enabled().unwrap());
            }
            assert_eq!(s, State::OperationEnabled);
        }
        assert_eq!(State::FaultReactionActive.next_command_towards_enabled(), None);
    }

    #[test]
    fn device_side_transitions() {
        use State::*;
        let cw = Controlword;
        // Every state's statusword decodes back to it.
        for s in [
            NotReadyToSwitchOn,
            SwitchOnDisabled,
            ReadyToSwitchOn,
            SwitchedOn,
            OperationEnabled,
            QuickStopActive,
            FaultReactionActive,
            Fault,
        ] {
            assert_eq!(s.statusword().state(), Some(s), "{s}");
            assert_eq!(s.statusword().with_voltage_enabled(true).state(), Some(s), "{s}");
        }
        assert_eq!(SwitchOnDisabled.after(Controlword::SHUTDOWN, false), ReadyToSwitchOn);
        assert_eq!(ReadyToSwitchOn.after(Controlword::SWITCH_ON, false), SwitchedOn);
        assert_eq!(ReadyToSwitchOn.after(Controlword::ENABLE_OPERATION, false), OperationEnabled);
        assert_eq!(SwitchedOn.after(Controlword::ENABLE_OPERATION, false), OperationEnabled);
        // Mode bits do not change the command: 0x1F is enable operation + new set-point.
        assert_eq!(OperationEnabled.after(cw(0x1F), false), OperationEnabled);
        assert_eq!(OperationEnabled.after(Controlword::DISABLE_OPERATION, false), SwitchedOn);
        assert_eq!(OperationEnabled.after(Controlword::SHUTDOWN, false), ReadyToSwitchOn);
        assert_eq!(OperationEnabled.after(Controlword::DISABLE_VOLTAGE, false), SwitchOnDisabled);
        // 0x000B (bits 0, 1, 3; bit 2 clear) is quick stop, as the LXM23A examples send it.
        assert_eq!(OperationEnabled.after(cw(0x0B), false), QuickStopActive);
        assert_eq!(QuickStopActive.after(Controlword::ENABLE_OPERATION, false), OperationEnabled);
        assert_eq!(QuickStopActive.after(Controlword::DISABLE_VOLTAGE, false), SwitchOnDisabled);
        assert_eq!(SwitchOnDisabled.after(Controlword::ENABLE_OPERATION, false), SwitchOnDisabled);
        assert_eq!(Fault.after(Controlword::FAULT_RESET, false), Fault);
        assert_eq!(Fault.after(Controlword::FAULT_RESET, true), SwitchOnDisabled);
        assert_eq!(Fault.after(Controlword::SHUTDOWN, true), Fault);
        // The manual drive's walk reaches "operation enabled" by the host's own commands.
        let mut s = SwitchOnDisabled;
        while let Some(c) = s.next_command_towards_enabled().filter(|_| s != OperationEnabled) {
            s = s.after(c, true);
        }
        assert_eq!(s, OperationEnabled);
    }

    #[test]
    fn statusword_builders() {
        let sw = State::OperationEnabled
            .statusword()
            .with_voltage_enabled(true)
            .with_remote(true)
            .with_target_reached(true)
            .with_setpoint_ack(true)
            .with_bit(14, true);
        assert_eq!(sw.bits(), 0x5637);
        assert_eq!(sw.with_state(State::SwitchOnDisabled).bits(), 0x5650);
        assert_eq!(sw.with_bit(16, true), sw);
        assert_eq!(sw.with_following_error(true).bits(), 0x7637);
        assert!(sw.with_warning(true).warning());
        assert!(sw.with_internal_limit(true).internal_limit());
        assert_eq!(Controlword(0x0B).command(), Command::QuickStop);
        assert_eq!(Controlword(0x80).command(), Command::DisableVoltage);
        assert_eq!(Controlword(0x0E).command(), Command::Shutdown);
    }

    #[test]
    fn modes() {
        for v in i8::MIN..=i8::MAX {
            assert_eq!(ModeOfOperation::from_i8(v).to_i8(), v);
        }
        assert_eq!(ModeOfOperation::from_i8(8), ModeOfOperation::CyclicSyncPosition);
        assert!(ModeOfOperation::from_i8(-3).is_manufacturer_specific());
        assert_eq!(ModeOfOperation::from_i8(5), ModeOfOperation::Other(5));
        let s = SupportedModes(0x0001_03A1);
        let listed: [Option<ModeOfOperation>; 5] = {
            let mut it = s.iter();
            [it.next(), it.next(), it.next(), it.next(), it.next()]
        };
        assert_eq!(
            listed,
            [
                Some(ModeOfOperation::ProfilePosition),
                Some(ModeOfOperation::Homing),
                Some(ModeOfOperation::CyclicSyncPosition),
                Some(ModeOfOperation::CyclicSyncVelocity),
                Some(ModeOfOperation::CyclicSyncTorque),
            ]
        );
        assert!(!s.supports(ModeOfOperation::Other(-1)));
        assert_eq!(s.manufacturer_bits(), 1);
        assert_eq!(ModeOfOperation::from_raw(0xF8, 8), Some(ModeOfOperation::Other(-8)));
        assert_eq!(ModeOfOperation::Other(-8).to_raw() & 0xFF, 0xF8);
    }

    #[test]
    fn words_convert_and_order_by_raw_value() {
        let raw: u16 = Controlword::SHUTDOWN.into();
        assert_eq!(raw, 0x0006);
        assert_eq!(Controlword::from(0x000F), Controlword::ENABLE_OPERATION);
        assert_eq!(u16::from(Statusword(0x0237)), 0x0237);
        assert_eq!(Statusword::from(0x0250).state(), Some(State::SwitchOnDisabled));
        assert!(Controlword::SHUTDOWN < Controlword::ENABLE_OPERATION);
        assert!(Statusword(0x8000) > Statusword(0x7FFF));
    }

    #[test]
    fn sdo_encodings() {
        let mut b = [0u8; 4];
        assert_eq!(Controlword::SHUTDOWN.encode(&mut b), Ok(2));
        assert_eq!(&b[..2], &[0x06, 0x00]);
        assert_eq!(Statusword::decode(&[0x37, 0x02]), Ok(Statusword(0x0237)));
        assert_eq!(ModeOfOperation::decode(&[0xFE]), Ok(ModeOfOperation::Other(-2)));
        assert_eq!(ModeOfOperation::Homing.encode(&mut b), Ok(1));
        assert_eq!(b[0], 6);
        assert_eq!(SupportedModes::decode(&[0x81, 0, 0, 0]), Ok(SupportedModes(0x81)));
        assert_eq!(Controlword::decode(&[1]), Err(ValueError::TooShort));
        assert_eq!(<ModeOfOperation as ObjValue>::DATA_TYPE, DataType::Integer8);
    }
}
