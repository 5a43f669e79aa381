//! The LSS slave (CiA 305): waiting and configuration state, node-ID and bit timing
//! configuration, identification and fastscan.
//!
//! Shaped as CANopenNode's LSS slave: the slave keeps a pending node-ID and bit timing and
//! answers the master; what touches the device (applying the node-ID at reset communication,
//! switching the CAN controller, writing non-volatile memory) is the node's, told by
//! [`LssEvent`]. Storing is answered by the application ([`LssSlave::store_response`]), as
//! CANopenNode's store callback returns its result.

use super::frame::Part;
#[cfg_attr(not(feature = "lss-slave"), allow(unused_imports))]
use super::{REQUEST_ID, RESPONSE_ID};
#[cfg_attr(not(feature = "lss-slave"), allow(unused_imports))]
use crate::can::CanFrame;
use crate::cob::NodeId;

/// The LSS address: 0x1018 sub 1–4.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, Default)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct Identity {
    /// Vendor-ID (0x1018:01).
    pub vendor: u32,
    /// Product code (0x1018:02).
    pub product: u32,
    /// Revision number (0x1018:03).
    pub revision: u32,
    /// Serial number (0x1018:04).
    pub serial: u32,
}

impl Identity {
    /// The address of these four numbers.
    pub const fn new(vendor: u32, product: u32, revision: u32, serial: u32) -> Self {
        Self { vendor, product, revision, serial }
    }

    /// One of the four numbers.
    pub const fn part(&self, p: Part) -> u32 {
        self.nth(p as u8)
    }

    /// Number `i` (0 vendor, 1 product, 2 revision, 3 and above serial), as the command
    /// specifiers of CiA 305 count them from their first.
    const fn nth(&self, i: u8) -> u32 {
        match i {
            0 => self.vendor,
            1 => self.product,
            2 => self.revision,
            _ => self.serial,
        }
    }
}

/// The slave's LSS state.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum LssState {
    /// Only switch, identify and fastscan requests are served.
    Waiting,
    /// The node-ID and bit timing may be configured, inquired and stored.
    Configuration,
}

/// What the node must do after a request.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum LssEvent {
    /// The LSS state changed.
    State(LssState),
    /// A new node-ID is pending (`None`: unconfigured); it takes effect at the next NMT reset
    /// communication ([`LssSlave::reset_communication`]).
    NodeIdConfigured(Option<NodeId>),
    /// A new bit timing (index of CiA 301's table) is pending; [`LssEvent::ActivateBitTiming`]
    /// or a power cycle makes it active.
    BitTimingConfigured(u8),
    /// Switch the CAN controller to [`LssSlave::bit_timing`] after `delay_ms`, then send
    /// nothing for another `delay_ms` (CiA 305 activate bit timing).
    ActivateBitTiming {
        /// The switch delay in milliseconds.
        delay_ms: u16,
    },
    /// Store the pending node-ID and bit timing in non-volatile memory, then answer with
    /// [`LssSlave::store_response`].
    Store {
        /// The node-ID to store (`None`: unconfigured).
        node_id: Option<NodeId>,
        /// The bit timing table index to store.
        bit_timing: u8,
    },
    /// A slave without node-ID got one and was switched back to waiting state: CiA 305 has it
    /// perform an NMT reset communication, which makes the node-ID active.
    ResetCommunication,
}

/// The application's answer to [`LssEvent::Store`] (CiA 305 error codes).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum StoreResult {
    /// Stored (error code 0).
    Stored,
    /// The device cannot store (1).
    NotSupported,
    /// The storage could not be accessed (2).
    AccessError,
    /// A manufacturer-specific error (0xFF and this code).
    Specific(u8),
}

impl StoreResult {
    #[cfg(feature = "lss-slave")]
    const fn codes(self) -> (u8, u8) {
        match self {
            Self::Stored => (0, 0),
            Self::NotSupported => (1, 0),
            Self::AccessError => (2, 0),
            Self::Specific(e) => (0xFF, e),
        }
    }
}

/// The table indexes of CiA 301's bit timing table a slave takes by default: 0–4 (1000–125
/// kbit/s) and 6–8 (50, 20, 10 kbit/s). Index 5 (100 kbit/s in some older tables, such as the
/// Lexium MDrive manual's; reserved in CANopenNode's) and 9 (automatic detection) only when
/// the device says so ([`LssSlave::with_bit_timings`]).
#[cfg(feature = "lss-slave")]
pub const DEFAULT_BIT_TIMINGS: u16 = 0b1_1101_1111;

/// An LSS slave: one per node, fed the frames of CAN-ID 0x7E5.
///
/// ```
/// use odc::can::CanFrame;
/// use odc::cob::NodeId;
/// use odc::lss::{Identity, LssEvent, LssSlave};
///
/// let mut lss = LssSlave::new(Identity::new(0x5A, 1, 2, 3), None, 0);
/// let req = |b| CanFrame::new(0x7E5, b).unwrap();
/// // Switch state global, configuration; configure node-ID 0x42: answered "success".
/// assert_eq!(lss.handle(&req([0x04, 1, 0, 0, 0, 0, 0, 0])).0, None);
/// let (answer, event) = lss.handle(&req([0x11, 0x42, 0, 0, 0, 0, 0, 0]));
/// assert_eq!(answer, Some(CanFrame::new(0x7E4, [0x11, 0, 0, 0, 0, 0, 0, 0]).unwrap()));
/// assert_eq!(event, Some(LssEvent::NodeIdConfigured(NodeId::new(0x42))));
/// // Pending until reset communication.
/// assert_eq!((lss.node_id(), lss.pending_node_id()), (None, NodeId::new(0x42)));
/// assert_eq!(lss.reset_communication(), NodeId::new(0x42));
/// ```
#[cfg(feature = "lss-slave")]
#[derive(Clone, Debug)]
pub struct LssSlave {
    identity: Identity,
    state: LssState,
    active: Option<NodeId>,
    pending: Option<NodeId>,
    bit_timing: u8,
    pending_bit_timing: u8,
    bit_timings: u16,
    storage: bool,
    /// Parts of a switch state selective matched in order (0–4).
    selective: u8,
    /// Steps of an identify remote slave matched in order (0–6).
    remote: u8,
    /// The part fastscan compares next (0–3).
    fastscan: u8,
}

#[cfg(feature = "lss-slave")]
impl LssSlave {
    /// A slave with LSS address `identity`, node-ID `node_id` (`None`: unconfigured, 0xFF)
    /// and the bit timing of table index `bit_timing`, in waiting state. It answers "store
    /// not supported" until [`LssSlave::with_storage`].
    pub const fn new(identity: Identity, node_id: Option<NodeId>, bit_timing: u8) -> Self {
        let id = node_id;
        Self {
            identity,
            state: LssState::Waiting,
            active: id,
            pending: id,
            bit_timing,
            pending_bit_timing: bit_timing,
            bit_timings: DEFAULT_BIT_TIMINGS,
            storage: false,
            selective: 0,
            remote: 0,
            fastscan: 0,
        }
    }

    /// The same slave accepting the bit timings whose table index is set in `mask` (bit n =
    /// index n).
    pub const fn with_bit_timings(mut self, mask: u16) -> Self {
        self.bit_timings = mask;
        self
    }

    /// The same slave passing store configuration to the application ([`LssEvent::Store`]).
    pub const fn with_storage(mut self) -> Self {
        self.storage = true;
        self
    }

    /// The LSS state.
    pub const fn state(&self) -> LssState {
        self.state
    }

    /// The active node-ID; `None` when unconfigured.
    pub const fn node_id(&self) -> Option<NodeId> {
        self.active
    }

    /// The node-ID that the next reset communication makes active.
    pub const fn pending_node_id(&self) -> Option<NodeId> {
        self.pending
    }

    /// The active bit timing (table index).
    pub const fn bit_timing(&self) -> u8 {
        self.bit_timing
    }

    /// The configured bit timing that activation or a power cycle makes active.
    pub const fn pending_bit_timing(&self) -> u8 {
        self.pending_bit_timing
    }

    /// NMT reset communication (or reset node): the pending node-ID becomes active; the
    /// node-ID the node now has.
    pub const fn reset_communication(&mut self) -> Option<NodeId> {
        self.active = self.pending;
        self.node_id()
    }

    /// The answer to [`LssEvent::Store`], once the application has stored (or not).
    pub const fn store_response(&self, result: StoreResult) -> CanFrame {
        let (error, specific) = result.codes();
        CanFrame::standard(RESPONSE_ID, [0x17, error, specific, 0, 0, 0, 0, 0])
    }

    fn enter(&mut self, state: LssState) -> Option<LssEvent> {
        let changed = self.state != state;
        self.state = state;
        self.selective = 0;
        self.remote = 0;
        changed.then_some(LssEvent::State(state))
    }

    /// Handles one received frame: the answer to send on 0x7E4, if any, and what the node
    /// must do. Frames of other CAN-IDs, remote and extended frames, frames shorter than 8
    /// bytes or with an unknown command are ignored (CiA 305: a slave does not answer what it
    /// does not serve).
    pub fn handle(&mut self, frame: &CanFrame) -> (Option<CanFrame>, Option<LssEvent>) {
        // Remote and extended frames on 0x7E5 are no LSS requests.
        if !frame.is_data(REQUEST_ID.raw()) {
            return (None, None);
        }
        let Ok(bytes) = <[u8; 8]>::try_from(frame.bytes()) else { return (None, None) };
        let (answer, event) = self.serve(bytes);
        (answer.map(|a| CanFrame::standard(RESPONSE_ID, a)), event)
    }

    /// One request's answer (its 8 bytes) and event. The request is read from its bytes as
    /// the table in [`frame`](super::frame) lays them out, without decoding it into a
    /// [`Request`](super::frame::Request) first: the decode, the match over its variants
    /// and the encoding of a `Response` took the slave 1,558 B of Thumb code
    /// (`tests/slave-size`).
    fn serve(&mut self, b: [u8; 8]) -> (Option<[u8; 8]>, Option<LssEvent>) {
        let [cs, b1, b2, _, _, bit_checked, sub, next] = b;
        let n = u32::from_le_bytes([b[1], b[2], b[3], b[4]]);
        let short = |cs: u8, b1: u8| Some([cs, b1, 0, 0, 0, 0, 0, 0]);
        let configuring = self.state == LssState::Configuration;
        match cs {
            // Switch state global: mode 1 configuration, 0 waiting.
            0x04 if b1 == 1 => (None, self.enter(LssState::Configuration)),
            0x04 if b1 == 0 => {
                let apply = configuring && self.active.is_none() && self.pending.is_some();
                let event = self.enter(LssState::Waiting);
                (None, if apply { Some(LssEvent::ResetCommunication) } else { event })
            }
            0x40..=0x43 => self.selective(cs - 0x40, n),
            0x46..=0x4B => (self.identify(cs - 0x46, n), None),
            0x4C => {
                let unconfigured = self.active.is_none() && self.pending.is_none();
                (if unconfigured { short(0x50, 0) } else { None }, None)
            }
            0x51 => self.fastscan(n, bit_checked, sub, next),
            // The rest is served in configuration state only.
            _ if !configuring => (None, None),
            0x11 => match NodeId::from_lss(b1) {
                Some(id) => {
                    self.pending = id;
                    (short(0x11, 0), Some(LssEvent::NodeIdConfigured(id)))
                }
                None => (short(0x11, 1), None),
            },
            // Configure bit timing: table selector 0 (CiA 301's table), table index.
            0x13 if b1 == 0 && b2 < 16 && self.bit_timings & (1 << b2) != 0 => {
                self.pending_bit_timing = b2;
                (short(0x13, 0), Some(LssEvent::BitTimingConfigured(b2)))
            }
            0x13 => (short(0x13, 1), None),
            0x15 => {
                self.bit_timing = self.pending_bit_timing;
                let delay_ms = u16::from_le_bytes([b1, b2]);
                (None, Some(LssEvent::ActivateBitTiming { delay_ms }))
            }
            0x17 if self.storage => {
                let event = LssEvent::Store {
                    node_id: self.pending_node_id(),
                    bit_timing: self.pending_bit_timing,
                };
                (None, Some(event))
            }
            0x17 => (short(0x17, StoreResult::NotSupported.codes().0), None),
            0x5A..=0x5D => {
                let v = self.identity.nth(cs - 0x5A).to_le_bytes();
                (Some([cs, v[0], v[1], v[2], v[3], 0, 0, 0]), None)
            }
            0x5E => (short(0x5E, NodeId::to_lss(self.active)), None),
            _ => (None, None),
        }
    }

    /// Switch state selective: the four parts (`step` 0–3) in order, the last one answered
    /// and the slave in configuration state if all matched. Served in waiting state.
    fn selective(&mut self, step: u8, n: u32) -> (Option<[u8; 8]>, Option<LssEvent>) {
        if self.state != LssState::Waiting {
            return (None, None);
        }
        let matched = self.identity.nth(step) == n;
        self.selective = match (step, matched) {
            (0, true) => 1,
            (s, true) if s == self.selective => s + 1,
            _ => 0,
        };
        if self.selective < 4 {
            return (None, None);
        }
        let event = self.enter(LssState::Configuration);
        (Some(SELECTIVE_DONE), event)
    }

    /// Identify remote slave: vendor, product, revision low and high, serial low and high in
    /// order (`step` 0–5); answered after the last if the address is inside.
    fn identify(&mut self, step: u8, n: u32) -> Option<[u8; 8]> {
        // Steps 0 and 1 compare exactly, 2 and 4 are low bounds, 3 and 5 high bounds.
        let v = self.identity.nth(match step {
            0 | 1 => step,
            2 | 3 => 2,
            _ => 3,
        });
        let ok = match step {
            0 | 1 => v == n,
            2 | 4 => v >= n,
            _ => v <= n,
        };
        self.remote = match (step, ok) {
            (0, true) => 1,
            (s, true) if s == self.remote => s + 1,
            _ => 0,
        };
        if self.remote < 6 {
            return None;
        }
        self.remote = 0;
        Some(IDENTIFY_SLAVE)
    }

    /// Fastscan, for a slave without node-ID in waiting state: BitChecked 0x80 restarts; else
    /// the part under test answers if its bits from `bit_checked` up equal `id_number`'s, and
    /// a complete match (BitChecked 0) moves to part `next`; a `next` below `sub` ends the
    /// scan with this slave in configuration state.
    fn fastscan(
        &mut self,
        id_number: u32,
        bit_checked: u8,
        sub: u8,
        next: u8,
    ) -> (Option<[u8; 8]>, Option<LssEvent>) {
        let candidate =
            self.state == LssState::Waiting && self.active.is_none() && self.pending.is_none();
        if !candidate {
            return (None, None);
        }
        if bit_checked == 0x80 {
            self.fastscan = 0;
            return (Some(IDENTIFY_SLAVE), None);
        }
        if sub > 3 || bit_checked > 31 || next > 3 || self.fastscan != sub {
            return (None, None);
        }
        let mask = u32::MAX << bit_checked;
        if (self.identity.nth(sub) ^ id_number) & mask != 0 {
            return (None, None);
        }
        let mut event = None;
        if bit_checked == 0 {
            if next < sub {
                self.fastscan = 0;
                event = self.enter(LssState::Configuration);
            } else {
                self.fastscan = next;
            }
        }
        (Some(IDENTIFY_SLAVE), event)
    }
}

/// The answer "identify slave" (0x4F), to identify remote slave and fastscan.
#[cfg(feature = "lss-slave")]
const IDENTIFY_SLAVE: [u8; 8] = [0x4F, 0, 0, 0, 0, 0, 0, 0];
/// The answer to a switch state selective (0x44).
#[cfg(feature = "lss-slave")]
const SELECTIVE_DONE: [u8; 8] = [0x44, 0, 0, 0, 0, 0, 0, 0];

#[cfg(all(test, feature = "lss-slave"))]
mod tests {
    use super::*;

    const ID: Identity = Identity::new(0x0800_005A, 0x0000_0000, 0x0000_0507, 0x1454_523E);

    fn req(b: [u8; 8]) -> CanFrame {
        CanFrame::standard(REQUEST_ID, b)
    }

    fn ans(b: [u8; 8]) -> Option<CanFrame> {
        Some(CanFrame::standard(RESPONSE_ID, b))
    }

    fn number(cs: u8, n: u32) -> [u8; 8] {
        let n = n.to_le_bytes();
        [cs, n[0], n[1], n[2], n[3], 0, 0, 0]
    }

    /// CiA 305: LSS requests are 11-bit data frames; a remote or extended frame on 0x7E5 is
    /// another message and gets no answer.
    #[test]
    fn remote_and_extended_frames_are_not_lss() {
        let mut s = LssSlave::new(ID, NodeId::new(5), 0);
        let inquire_vendor = [0x5A, 0, 0, 0, 0, 0, 0, 0];
        let global = [0x04, 0x01, 0, 0, 0, 0, 0, 0];
        for b in [global, inquire_vendor] {
            assert_eq!(s.handle(&CanFrame::extended(0x7E5, &b).unwrap()), (None, None));
        }
        assert_eq!(s.handle(&CanFrame::remote(0x7E5, 8).unwrap()), (None, None));
        assert_eq!(s.state(), LssState::Waiting);
        // The same requests as data frames are served.
        assert_eq!(s.handle(&req(global)), (None, Some(LssEvent::State(LssState::Configuration))));
        assert_eq!(s.handle(&req(inquire_vendor)).0, ans(number(0x5A, ID.vendor)));
    }

    #[test]
    fn global_configure_store_inquire() {
        let mut s = LssSlave::new(ID, NodeId::new(5), 0).with_storage();
        // Waiting state: configuration services are ignored.
        assert_eq!(s.handle(&req([0x11, 0x42, 0, 0, 0, 0, 0, 0])), (None, None));
        assert_eq!(s.handle(&req([0x5E, 0, 0, 0, 0, 0, 0, 0])), (None, None));
        assert_eq!(
            s.handle(&req([0x04, 0x01, 0, 0, 0, 0, 0, 0])),
            (None, Some(LssEvent::State(LssState::Configuration)))
        );
        // Node-ID 0 and 128 are out of range (error 1); 0x42 and 0xFF are taken.
        for bad in [0u8, 128, 0xFE] {
            assert_eq!(
                s.handle(&req([0x11, bad, 0, 0, 0, 0, 0, 0])).0,
                ans([0x11, 1, 0, 0, 0, 0, 0, 0])
            );
        }
        assert_eq!(
            s.handle(&req([0x11, 0x42, 0, 0, 0, 0, 0, 0])),
            (ans([0x11, 0, 0, 0, 0, 0, 0, 0]), Some(LssEvent::NodeIdConfigured(NodeId::new(0x42))))
        );
        // Inquire node-ID answers the active one, still 5.
        assert_eq!(s.handle(&req([0x5E, 0, 0, 0, 0, 0, 0, 0])).0, ans([0x5E, 5, 0, 0, 0, 0, 0, 0]));
        // Bit timing: index 6 (50 kbit/s) taken; index 5 (reserved) and table 1 refused.
        assert_eq!(
            s.handle(&req([0x13, 0, 6, 0, 0, 0, 0, 0])),
            (ans([0x13, 0, 0, 0, 0, 0, 0, 0]), Some(LssEvent::BitTimingConfigured(6)))
        );
        assert_eq!(s.handle(&req([0x13, 0, 5, 0, 0, 0, 0, 0])).0, ans([0x13, 1, 0, 0, 0, 0, 0, 0]));
        assert_eq!(s.handle(&req([0x13, 1, 0, 0, 0, 0, 0, 0])).0, ans([0x13, 1, 0, 0, 0, 0, 0, 0]));
        assert_eq!((s.bit_timing(), s.pending_bit_timing()), (0, 6));
        // Store: the application's result is the answer.
        assert_eq!(
            s.handle(&req([0x17, 0, 0, 0, 0, 0, 0, 0])),
            (None, Some(LssEvent::Store { node_id: NodeId::new(0x42), bit_timing: 6 }))
        );
        assert_eq!(Some(s.store_response(StoreResult::Stored)), ans([0x17, 0, 0, 0, 0, 0, 0, 0]));
        assert_eq!(
            Some(s.store_response(StoreResult::Specific(7))),
            ans([0x17, 0xFF, 7, 0, 0, 0, 0, 0])
        );
        // Without storage the slave answers "not supported" (1) itself.
        let mut plain = LssSlave::new(ID, NodeId::new(5), 0);
        plain.handle(&req([0x04, 0x01, 0, 0, 0, 0, 0, 0]));
        assert_eq!(
            plain.handle(&req([0x17, 0, 0, 0, 0, 0, 0, 0])),
            (ans([0x17, 1, 0, 0, 0, 0, 0, 0]), None)
        );
        // Inquire the address: cs 0x5A-0x5D, the number LE.
        for (cs, n) in
            [(0x5A, ID.vendor), (0x5B, ID.product), (0x5C, ID.revision), (0x5D, ID.serial)]
        {
            assert_eq!(s.handle(&req([cs, 0, 0, 0, 0, 0, 0, 0])).0, ans(number(cs, n)));
        }
        // Activate bit timing: no answer, the delay to the node.
        assert_eq!(
            s.handle(&req([0x15, 0xF4, 0x01, 0, 0, 0, 0, 0])),
            (None, Some(LssEvent::ActivateBitTiming { delay_ms: 500 }))
        );
        assert_eq!(s.bit_timing(), 6);
        // Back to waiting: the node had a node-ID, so nothing to reset; the pending one waits
        // for the node's reset communication.
        assert_eq!(
            s.handle(&req([0x04, 0x00, 0, 0, 0, 0, 0, 0])),
            (None, Some(LssEvent::State(LssState::Waiting)))
        );
        assert_eq!((s.node_id(), s.pending_node_id()), (NodeId::new(5), NodeId::new(0x42)));
        assert_eq!(s.reset_communication(), NodeId::new(0x42));
        // Other CAN-IDs and short frames are not LSS requests.
        assert_eq!(
            s.handle(&CanFrame::new(0x7E4, [0x04, 1, 0, 0, 0, 0, 0, 0]).unwrap()),
            (None, None)
        );
        assert_eq!(s.handle(&CanFrame::from_slice(0x7E5, &[0x04, 1]).unwrap()), (None, None));
    }

    #[test]
    fn unconfigured_slave_resets_itself_on_waiting() {
        let mut s = LssSlave::new(ID, None, 0);
        assert_eq!(s.node_id(), None);
        s.handle(&req([0x04, 0x01, 0, 0, 0, 0, 0, 0]));
        s.handle(&req([0x11, 0x20, 0, 0, 0, 0, 0, 0]));
        assert_eq!(
            s.handle(&req([0x04, 0x00, 0, 0, 0, 0, 0, 0])),
            (None, Some(LssEvent::ResetCommunication))
        );
        assert_eq!(s.reset_communication(), NodeId::new(0x20));
        // 0xFF given to new() is unconfigured too, as is anything outside 1-127.
        assert_eq!(LssSlave::new(ID, None, 0).node_id(), None);
    }

    #[test]
    fn selective_and_identify() {
        let mut s = LssSlave::new(ID, NodeId::new(5), 0);
        let sel = |s: &mut LssSlave, serial| {
            let mut last = (None, None);
            for (cs, n) in
                [(0x40, ID.vendor), (0x41, ID.product), (0x42, ID.revision), (0x43, serial)]
            {
                last = s.handle(&req(number(cs, n)));
            }
            last
        };
        // Another serial: silence, still waiting.
        assert_eq!(sel(&mut s, ID.serial + 1), (None, None));
        assert_eq!(s.state(), LssState::Waiting);
        // Out of order (serial alone) does nothing either.
        assert_eq!(s.handle(&req(number(0x43, ID.serial))), (None, None));
        assert_eq!(
            sel(&mut s, ID.serial),
            (ans([0x44, 0, 0, 0, 0, 0, 0, 0]), Some(LssEvent::State(LssState::Configuration)))
        );
        // Identify remote slave: ranges around revision and serial.
        let ident = |s: &mut LssSlave, rev: (u32, u32), ser: (u32, u32)| {
            let steps = [
                (0x46, ID.vendor),
                (0x47, ID.product),
                (0x48, rev.0),
                (0x49, rev.1),
                (0x4A, ser.0),
                (0x4B, ser.1),
            ];
            steps.iter().map(|&(cs, n)| s.handle(&req(number(cs, n))).0).last().flatten()
        };
        assert_eq!(
            ident(&mut s, (0, 0x507), (ID.serial, u32::MAX)),
            ans([0x4F, 0, 0, 0, 0, 0, 0, 0])
        );
        assert_eq!(ident(&mut s, (0x508, 0x600), (0, u32::MAX)), None);
        assert_eq!(ident(&mut s, (0, 0x600), (0, ID.serial - 1)), None);
        // Non-configured: only a slave without node-ID (active and pending) answers 0x50.
        assert_eq!(s.handle(&req([0x4C, 0, 0, 0, 0, 0, 0, 0])).0, None);
        let mut u = LssSlave::new(ID, None, 0);
        assert_eq!(u.handle(&req([0x4C, 0, 0, 0, 0, 0, 0, 0])).0, ans([0x50, 0, 0, 0, 0, 0, 0, 0]));
    }

    /// CiA 305's fastscan, as a master runs it: for each part, from bit 31 down, a request
    /// with the bit clear; silence means the slave's bit is set.
    fn fastscan(s: &mut LssSlave) -> Option<[u32; 4]> {
        let mut ask = |n: u32, bit: u8, sub: u8, next: u8| {
            let b = n.to_le_bytes();
            s.handle(&req([0x51, b[0], b[1], b[2], b[3], bit, sub, next])).0.is_some()
        };
        if !ask(0, 0x80, 0, 0) {
            return None;
        }
        let mut id = [0u32; 4];
        for sub in 0..4u8 {
            for bit in (0..32u8).rev() {
                if !ask(id[usize::from(sub)], bit, sub, sub) {
                    id[usize::from(sub)] |= 1 << bit;
                }
            }
            if !ask(id[usize::from(sub)], 0, sub, (sub + 1) & 3) {
                return None;
            }
        }
        Some(id)
    }

    #[test]
    fn fastscan_finds_the_unconfigured_slave() {
        let mut s = LssSlave::new(ID, None, 0);
        assert_eq!(fastscan(&mut s), Some([ID.vendor, ID.product, ID.revision, ID.serial]));
        assert_eq!(s.state(), LssState::Configuration);
        // Now in configuration state it takes a node-ID.
        assert_eq!(
            s.handle(&req([0x11, 0x10, 0, 0, 0, 0, 0, 0])).0,
            ans([0x11, 0, 0, 0, 0, 0, 0, 0])
        );
        // A slave with a node-ID stays silent.
        assert_eq!(fastscan(&mut LssSlave::new(ID, NodeId::new(3), 0)), None);
        // A request for a part not under test is ignored: BitChecked 0 of the serial first.
        let mut s = LssSlave::new(ID, None, 0);
        let b = ID.serial.to_le_bytes();
        assert_eq!(s.handle(&req([0x51, b[0], b[1], b[2], b[3], 0, 3, 0])).0, None);
        assert_eq!(s.state(), LssState::Waiting);
    }
}
