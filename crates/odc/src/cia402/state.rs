//! The states of the CiA 402 power state machine, their statuswords, and the transitions a
//! controlword commands.

use core::fmt;

use super::{Command, Controlword, Statusword};

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
