//! NMT module control commands and the states reported by heartbeat.

use crate::cob::NodeId;

/// NMT command specifier (first byte of the NMT frame).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
#[repr(u8)]
pub enum NmtCommand {
    /// Start remote node.
    Start = 0x01,
    /// Stop remote node.
    Stop = 0x02,
    /// Enter pre-operational.
    EnterPreOperational = 0x80,
    /// Reset node.
    ResetNode = 0x81,
    /// Reset communication.
    ResetCommunication = 0x82,
}

impl NmtCommand {
    /// The command for a command specifier.
    pub const fn from_u8(v: u8) -> Option<Self> {
        match v {
            0x01 => Some(Self::Start),
            0x02 => Some(Self::Stop),
            0x80 => Some(Self::EnterPreOperational),
            0x81 => Some(Self::ResetNode),
            0x82 => Some(Self::ResetCommunication),
            _ => None,
        }
    }

    /// The 2-byte NMT frame payload for `node`, or for every node with `None` (node-ID
    /// byte 0).
    pub const fn frame(self, node: Option<NodeId>) -> [u8; 2] {
        let target = match node {
            Some(n) => n.get(),
            None => 0,
        };
        [self as u8, target]
    }
}

/// NMT state as carried in a heartbeat (bit 7, the toggle of node guarding, is ignored).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
#[repr(u8)]
pub enum NmtState {
    /// Boot-up message.
    BootUp = 0x00,
    /// Stopped.
    Stopped = 0x04,
    /// Operational.
    Operational = 0x05,
    /// Pre-operational.
    PreOperational = 0x7F,
}

impl core::fmt::Display for NmtState {
    /// CiA 301's name: `pre-operational`, `operational`, `stopped`, `boot-up`.
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        f.write_str(match self {
            Self::BootUp => "boot-up",
            Self::Stopped => "stopped",
            Self::Operational => "operational",
            Self::PreOperational => "pre-operational",
        })
    }
}

impl NmtState {
    /// The state for a heartbeat byte.
    pub const fn from_u8(v: u8) -> Option<Self> {
        match v & 0x7F {
            0x00 => Some(Self::BootUp),
            0x04 => Some(Self::Stopped),
            0x05 => Some(Self::Operational),
            0x7F => Some(Self::PreOperational),
            _ => None,
        }
    }

    /// The heartbeat byte.
    pub const fn to_u8(self) -> u8 {
        self as u8
    }

    /// The byte of a node-guarding response: the state in bits 0–6, the toggle in bit 7 (0 in
    /// the first response after reset communication, inverted in each next one).
    pub const fn guarding_byte(self, toggle: bool) -> u8 {
        self as u8 | if toggle { 0x80 } else { 0 }
    }

    /// Whether SDO communication works in this state.
    pub const fn sdo_allowed(self) -> bool {
        matches!(self, Self::Operational | Self::PreOperational)
    }

    /// Whether PDOs are exchanged in this state.
    pub const fn pdo_allowed(self) -> bool {
        matches!(self, Self::Operational)
    }
}

/// An entry of the consumer heartbeat time array 0x1016 (CiA 301 §7.5.2.14): the producer's
/// node id in bits 16–23, its heartbeat time in ms in bits 0–15.
///
/// `time_ms` stays a bare `u16`: it is the entry's 16-bit wire field, in CiA 301's unit, not
/// an instant or a duration of the runtime's clock ([`crate::time`]).
pub const fn heartbeat_consumer_entry(node: NodeId, time_ms: u16) -> u32 {
    (node.get() as u32) << 16 | time_ms as u32
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn commands_and_states() {
        for c in [
            NmtCommand::Start,
            NmtCommand::Stop,
            NmtCommand::EnterPreOperational,
            NmtCommand::ResetNode,
            NmtCommand::ResetCommunication,
        ] {
            assert_eq!(NmtCommand::from_u8(c as u8), Some(c));
        }
        assert_eq!(NmtCommand::Start.frame(None), [1, 0]);
        assert_eq!(NmtCommand::Stop.frame(Some(crate::node_id!(9))), [2, 9]);
        assert_eq!(NmtCommand::from_u8(3), None);
        assert_eq!(NmtState::from_u8(0x85), Some(NmtState::Operational));
        assert_eq!(NmtState::from_u8(0x7F).map(NmtState::to_u8), Some(0x7F));
        assert_eq!(NmtState::from_u8(1), None);
        assert!(NmtState::PreOperational.sdo_allowed() && !NmtState::PreOperational.pdo_allowed());
        assert!(!NmtState::Stopped.sdo_allowed());
        assert_eq!(NmtState::Operational.guarding_byte(false), 0x05);
        assert_eq!(NmtState::Operational.guarding_byte(true), 0x85);
        assert_eq!(
            NmtState::from_u8(NmtState::Stopped.guarding_byte(true)),
            Some(NmtState::Stopped)
        );
        assert_eq!(heartbeat_consumer_entry(crate::node_id!(1), 15), 0x0001_000F);
    }
}
