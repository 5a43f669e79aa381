//! COB-IDs: the CiA 301 predefined connection set and the COB-ID entry format.

//!
//! Every CAN-ID the runtime derives from a node-ID is computed here ([`NodeId`]'s methods and
//! [`Function::can_id`]), so the node, the SDO client and server and the master agree.

use core::fmt;

use crate::can::StdId;

/// A CANopen node-ID, 1–127 (CiA 301 §7.3.2). A node without one (CiA 305's unconfigured
/// 0xFF, while an LSS master has not given it one) is `Option<NodeId>::None` where LSS needs
/// it.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
#[cfg_attr(feature = "serde", serde(try_from = "u8", into = "u8"))]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct NodeId(u8);

/// The node-ID byte of a node that has none (CiA 305: "invalid node-ID", 0xFF).
pub const UNCONFIGURED: u8 = 0xFF;

impl NodeId {
    /// The lowest node-ID.
    pub const MIN: Self = Self(1);
    /// The highest node-ID.
    pub const MAX: Self = Self(127);

    /// The node id, or `None` outside 1–127.
    pub const fn new(id: u8) -> Option<Self> {
        if id >= 1 && id <= 127 { Some(Self(id)) } else { None }
    }

    /// The raw id.
    pub const fn get(self) -> u8 {
        self.0
    }

    /// A node-ID as LSS (CiA 305) carries it: `Some(None)` for the unconfigured 0xFF,
    /// `Some(Some(id))` for 1–127, `None` for any other byte.
    pub const fn from_lss(byte: u8) -> Option<Option<Self>> {
        match Self::new(byte) {
            Some(id) => Some(Some(id)),
            None if byte == UNCONFIGURED => Some(None),
            None => None,
        }
    }

    /// The byte LSS carries for `id`: its value, or 0xFF for none.
    pub const fn to_lss(id: Option<Self>) -> u8 {
        match id {
            Some(n) => n.0,
            None => UNCONFIGURED,
        }
    }

    const fn plus(self, base: u16) -> StdId {
        // base ≤ 0x700 and the id ≤ 127: at most 0x77F, always an 11-bit identifier.
        StdId::masked(base as u32 + self.0 as u32)
    }

    /// EMCY CAN-ID (0x080 + id).
    pub const fn emcy(self) -> StdId {
        self.plus(0x080)
    }

    /// SDO server → client CAN-ID (0x580 + id).
    pub const fn sdo_response(self) -> StdId {
        self.plus(0x580)
    }

    /// SDO client → server CAN-ID (0x600 + id).
    pub const fn sdo_request(self) -> StdId {
        self.plus(0x600)
    }

    /// NMT error control CAN-ID: boot-up, heartbeat, guarding (0x700 + id).
    pub const fn error_control(self) -> StdId {
        self.plus(0x700)
    }

    /// The node whose error-control frame (boot-up, heartbeat) has CAN-ID `id`.
    pub const fn of_error_control(id: u32) -> Option<Self> {
        if id >= 0x701 && id <= 0x77F { Self::new((id - 0x700) as u8) } else { None }
    }

    /// The node whose EMCY has CAN-ID `id` (0x081–0x0FF).
    pub const fn of_emcy(id: u32) -> Option<Self> {
        if id >= 0x081 && id <= 0x0FF { Self::new((id - 0x080) as u8) } else { None }
    }
}

impl TryFrom<u8> for NodeId {
    type Error = InvalidNodeId;

    fn try_from(id: u8) -> Result<Self, InvalidNodeId> {
        Self::new(id).ok_or(InvalidNodeId(id))
    }
}

impl From<NodeId> for u8 {
    fn from(id: NodeId) -> u8 {
        id.0
    }
}

impl fmt::Display for NodeId {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        fmt::Display::fmt(&self.0, f)
    }
}

/// A byte that is no node-ID (0 or above 127).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct InvalidNodeId(pub u8);

impl fmt::Display for InvalidNodeId {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "node-ID {} outside 1..=127", self.0)
    }
}

impl core::error::Error for InvalidNodeId {}

/// A [`NodeId`] from a constant, checked at compile time: `odc::node_id!(5)`.
///
/// ```
/// const NODE: odc::cob::NodeId = odc::node_id!(5);
/// assert_eq!(NODE.get(), 5);
/// ```
///
/// ```compile_fail
/// let _ = odc::node_id!(0);
/// ```
#[macro_export]
macro_rules! node_id {
    ($id:expr) => {
        const {
            match $crate::cob::NodeId::new($id) {
                Some(n) => n,
                None => panic!("a node-ID is 1..=127"),
            }
        }
    };
}

/// Function of a frame in the predefined connection set.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum Function {
    /// NMT module control (0x000).
    Nmt,
    /// SYNC (0x080).
    Sync,
    /// EMCY (0x080 + node).
    Emcy,
    /// TIME (0x100).
    Time,
    /// TPDO 1–4 (0x180/0x280/0x380/0x480 + node).
    Tpdo(u8),
    /// RPDO 1–4 (0x200/0x300/0x400/0x500 + node).
    Rpdo(u8),
    /// SDO server → client (0x580 + node).
    SdoTx,
    /// SDO client → server (0x600 + node).
    SdoRx,
    /// NMT error control: heartbeat, boot-up (0x700 + node).
    Heartbeat,
}

/// NMT CAN-ID.
pub const NMT: u16 = 0x000;
/// SYNC CAN-ID.
pub const SYNC: u16 = 0x080;
/// TIME CAN-ID.
pub const TIME: u16 = 0x100;

impl Function {
    /// The function-code base of the CAN-ID; `None` for PDO numbers outside 1–4.
    pub const fn base(self) -> Option<u16> {
        match self {
            Self::Nmt => Some(NMT),
            Self::Sync | Self::Emcy => Some(SYNC),
            Self::Time => Some(TIME),
            Self::Tpdo(n @ 1..=4) => Some(0x080 + 0x100 * n as u16),
            Self::Rpdo(n @ 1..=4) => Some(0x100 + 0x100 * n as u16),
            Self::Tpdo(_) | Self::Rpdo(_) => None,
            Self::SdoTx => Some(0x580),
            Self::SdoRx => Some(0x600),
            Self::Heartbeat => Some(0x700),
        }
    }

    /// Whether the CAN-ID includes the node id.
    pub const fn per_node(self) -> bool {
        !matches!(self, Self::Nmt | Self::Sync | Self::Time)
    }

    /// The predefined CAN-ID of this function for `node`.
    pub const fn can_id(self, node: NodeId) -> Option<u16> {
        match self.base() {
            Some(b) if self.per_node() => Some(node.plus(b).get()),
            Some(b) => Some(b),
            None => None,
        }
    }
}

/// Classify an 11-bit CAN-ID by the predefined connection set.
pub const fn classify(can_id: u16) -> Option<(Function, Option<NodeId>)> {
    let node = NodeId::new((can_id & 0x7F) as u8);
    let f = match can_id & 0x780 {
        0x000 if can_id == NMT => return Some((Function::Nmt, None)),
        0x080 if can_id == SYNC => return Some((Function::Sync, None)),
        0x080 => Function::Emcy,
        0x100 if can_id == TIME => return Some((Function::Time, None)),
        0x180 => Function::Tpdo(1),
        0x200 => Function::Rpdo(1),
        0x280 => Function::Tpdo(2),
        0x300 => Function::Rpdo(2),
        0x380 => Function::Tpdo(3),
        0x400 => Function::Rpdo(3),
        0x480 => Function::Tpdo(4),
        0x500 => Function::Rpdo(4),
        0x580 => Function::SdoTx,
        0x600 => Function::SdoRx,
        0x700 => Function::Heartbeat,
        _ => return None,
    };
    match node {
        Some(n) => Some((f, Some(n))),
        None => None,
    }
}

/// CAN-IDs that CiA 301 §7.3.5 reserves and that must not be configured for PDOs, EMCY, etc.
pub const fn is_restricted(can_id: u16) -> bool {
    matches!(can_id, 0x000 | 0x001..=0x07F | 0x101..=0x180 | 0x581..=0x5FF | 0x601..=0x67F | 0x6E0..=0x6FF
        | 0x701..=0x77F | 0x780..=0x7FF)
}

/// A COB-ID entry value (0x1014, 0x1400 sub 1, 0x1800 sub 1, …).
///
/// Bit 31 set means the object is **not** valid (disabled), bit 30 set means no RTR allowed
/// (PDOs), bit 29 set means a 29-bit CAN-ID.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct CobId(pub u32);

impl CobId {
    /// Bit 31: not valid.
    pub const NOT_VALID: u32 = 1 << 31;
    /// Bit 30: no RTR allowed.
    pub const NO_RTR: u32 = 1 << 30;
    /// Bit 29: 29-bit identifier.
    pub const FRAME_29BIT: u32 = 1 << 29;

    /// A valid COB-ID with an 11-bit CAN-ID.
    pub const fn new(can_id: u16) -> Self {
        Self((can_id & 0x7FF) as u32)
    }

    /// Whether the object is enabled (bit 31 clear).
    pub const fn is_valid(self) -> bool {
        self.0 & Self::NOT_VALID == 0
    }

    /// Whether remote frames are allowed (bit 30 clear).
    pub const fn rtr_allowed(self) -> bool {
        self.0 & Self::NO_RTR == 0
    }

    /// Whether the id is 29-bit (bit 29 set).
    pub const fn is_extended(self) -> bool {
        self.0 & Self::FRAME_29BIT != 0
    }

    /// The CAN-ID: 11 or 29 bits depending on bit 29.
    pub const fn can_id(self) -> u32 {
        if self.is_extended() { self.0 & 0x1FFF_FFFF } else { self.0 & 0x7FF }
    }

    /// The same COB-ID enabled or disabled; the CiA 301 PDO re-mapping sequence disables
    /// first, changes, then enables.
    pub const fn with_valid(self, valid: bool) -> Self {
        if valid { Self(self.0 & !Self::NOT_VALID) } else { Self(self.0 | Self::NOT_VALID) }
    }

    /// The same COB-ID with RTR allowed or not.
    pub const fn with_rtr(self, allowed: bool) -> Self {
        if allowed { Self(self.0 & !Self::NO_RTR) } else { Self(self.0 | Self::NO_RTR) }
    }

    /// Whether an 11-bit CAN-ID is in the restricted set.
    pub const fn is_restricted(self) -> bool {
        !self.is_extended() && is_restricted(self.can_id() as u16)
    }

    /// Whether `frame` is a data frame on this COB-ID: the same identifier in the same
    /// format (an 11-bit 0x181 is not the 29-bit 0x181), not a remote frame.
    pub const fn matches(self, frame: &crate::can::CanFrame) -> bool {
        !frame.is_remote()
            && frame.is_extended() == self.is_extended()
            && frame.id() == self.can_id()
    }

    /// A data frame with `data` on this COB-ID, in its format; `None` for more than 8 bytes.
    pub fn frame(self, data: &[u8]) -> Option<crate::can::CanFrame> {
        if self.is_extended() {
            crate::can::CanFrame::extended(self.can_id(), data)
        } else {
            crate::can::CanFrame::from_slice(self.can_id(), data)
        }
    }

    /// The COB-ID of a received data frame (valid, its format's bit 29).
    pub const fn of_frame(frame: &crate::can::CanFrame) -> Self {
        if frame.is_extended() { Self(frame.id() | Self::FRAME_29BIT) } else { Self(frame.id()) }
    }
}

impl fmt::Display for CobId {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "0x{:08X}", self.0)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn predefined_set() {
        let n = NodeId::new(5).unwrap();
        assert_eq!(Function::Emcy.can_id(n), Some(0x85));
        assert_eq!(Function::Tpdo(1).can_id(n), Some(0x185));
        assert_eq!(Function::Tpdo(4).can_id(n), Some(0x485));
        assert_eq!(Function::Rpdo(1).can_id(n), Some(0x205));
        assert_eq!(Function::Rpdo(4).can_id(n), Some(0x505));
        assert_eq!(Function::SdoTx.can_id(n), Some(0x585));
        assert_eq!(Function::SdoRx.can_id(n), Some(0x605));
        assert_eq!(Function::Heartbeat.can_id(n), Some(0x705));
        assert_eq!(Function::Sync.can_id(n), Some(0x080));
        assert_eq!(Function::Nmt.can_id(n), Some(0));
        assert_eq!(Function::Tpdo(5).can_id(n), None);
        assert!(NodeId::new(0).is_none() && NodeId::new(128).is_none());
        assert_eq!(n.emcy().get(), 0x85);
        assert_eq!(n.sdo_response().get(), 0x585);
        assert_eq!(n.sdo_request().get(), 0x605);
        assert_eq!(n.error_control().get(), 0x705);
        assert_eq!(NodeId::MAX.error_control().get(), 0x77F);
        assert_eq!(NodeId::of_error_control(0x705), Some(n));
        assert_eq!(NodeId::of_error_control(0x700), None);
        assert_eq!(NodeId::of_error_control(0x780), None);
        assert_eq!(NodeId::of_emcy(0x85), Some(n));
        assert_eq!(NodeId::of_emcy(0x80), None);
        assert_eq!(NodeId::try_from(128), Err(InvalidNodeId(128)));
        assert_eq!(crate::node_id!(5), n);
    }

    #[test]
    fn lss_node_ids() {
        assert_eq!(NodeId::from_lss(0xFF), Some(None));
        assert_eq!(NodeId::from_lss(0), None);
        assert_eq!(NodeId::from_lss(128), None);
        assert_eq!(NodeId::from_lss(127), Some(NodeId::new(127)));
        assert_eq!(NodeId::to_lss(None), 0xFF);
        assert_eq!(NodeId::to_lss(NodeId::new(9)), 9);
    }

    #[test]
    fn classify_round_trip() {
        let fs = [
            Function::Emcy,
            Function::Tpdo(1),
            Function::Tpdo(2),
            Function::Tpdo(3),
            Function::Tpdo(4),
            Function::Rpdo(1),
            Function::Rpdo(2),
            Function::Rpdo(3),
            Function::Rpdo(4),
            Function::SdoTx,
            Function::SdoRx,
            Function::Heartbeat,
        ];
        for id in 1..=127 {
            let n = NodeId::new(id).unwrap();
            for f in fs {
                assert_eq!(classify(f.can_id(n).unwrap()), Some((f, Some(n))));
            }
        }
        assert_eq!(classify(0), Some((Function::Nmt, None)));
        assert_eq!(classify(0x80), Some((Function::Sync, None)));
        assert_eq!(classify(0x100), Some((Function::Time, None)));
        assert_eq!(classify(0x7E5), None);
        assert_eq!(classify(0x180), None);
    }

    #[test]
    fn restricted_and_bits() {
        for id in [
            0x000, 0x001, 0x07F, 0x101, 0x180, 0x581, 0x5FF, 0x601, 0x67F, 0x6E0, 0x6FF, 0x701,
            0x7FF,
        ] {
            assert!(is_restricted(id), "{id:#x}");
        }
        for id in [0x080, 0x100, 0x181, 0x1FF, 0x580, 0x600, 0x680, 0x6DF, 0x700] {
            assert!(!is_restricted(id), "{id:#x}");
        }
        let c = CobId(0x8000_0185);
        assert!(!c.is_valid() && c.rtr_allowed() && !c.is_extended());
        assert_eq!(c.can_id(), 0x185);
        assert_eq!(c.with_valid(true), CobId(0x185));
        assert_eq!(CobId::new(0x185).with_rtr(false).0, 0x4000_0185);
        let x = CobId(0x2000_0000 | 0x1234_5678);
        assert!(x.is_extended() && !x.is_restricted());
        assert_eq!(x.can_id(), 0x1234_5678);
        assert!(CobId::new(0x5FF).is_restricted());
    }

    #[test]
    fn eleven_and_twenty_nine_bit_ids_stay_apart() {
        use crate::can::CanFrame;
        let std = CobId(0x8000_0181); // not valid: flags do not change the identifier
        let ext = CobId(CobId::FRAME_29BIT | 0x181);
        let f11 = CanFrame::from_slice(0x181, &[1]).unwrap();
        let f29 = CanFrame::extended(0x181, &[1]).unwrap();
        assert!(std.matches(&f11) && !std.matches(&f29));
        assert!(ext.matches(&f29) && !ext.matches(&f11));
        assert!(!std.matches(&CanFrame::remote(0x181, 1).unwrap()));
        assert_eq!(std.frame(&[1]), Some(f11));
        assert_eq!(ext.frame(&[1]), Some(f29));
        assert_eq!(std.frame(&[0; 9]), None);
        assert_eq!(CobId::of_frame(&f29), ext);
        assert_eq!(CobId::of_frame(&f11), CobId::new(0x181));
    }
}
