//! The controlword (0x6040) and statusword (0x6041): the commands a master sends and the
//! state and flags a drive reports.

use super::State;

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
