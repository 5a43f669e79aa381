//! The node's LSS slave (CiA 305): built at the first start with the device's LSS address,
//! fed the frames of 0x7E5 in every NMT state and while a node without node-ID initialises;
//! the node-ID it configures becomes the node's at the next reset.

use super::params::get_u32;
use super::{Events, Node, Reset};
use crate::can::CanFrame;
use crate::cob::NodeId;
use crate::lss::{Identity, LssEvent, LssSlave, StoreResult};
use crate::slave::ObjectDictionary;

/// How the node builds its LSS slave at the first start.
#[derive(Clone, Copy, Debug)]
pub(super) struct LssSetup {
    /// `None`: 0x1018 sub 1–4 of the dictionary.
    identity: Option<Identity>,
    bit_timing: u8,
    /// `None`: the LSS slave's default set.
    bit_timings: Option<u16>,
    storage: bool,
}

impl LssSetup {
    pub(super) fn slave<D: ObjectDictionary + ?Sized>(
        &self,
        dict: &D,
        node_id: Option<NodeId>,
    ) -> LssSlave {
        // A part 0x1018 lacks is 0, as CiA 301 has the sub-indexes 2–4 optional.
        let part = |sub| get_u32(dict, 0x1018, sub).unwrap_or(0);
        let identity =
            self.identity.unwrap_or_else(|| Identity::new(part(1), part(2), part(3), part(4)));
        let mut slave = LssSlave::new(identity, node_id, self.bit_timing);
        if let Some(mask) = self.bit_timings {
            slave = slave.with_bit_timings(mask);
        }
        if self.storage { slave.with_storage() } else { slave }
    }
}

impl<const N: usize, const R: usize, const T: usize> Node<N, R, T> {
    /// The same node with an LSS slave: LSS address `identity` (`None`: 0x1018 sub 1–4 of the
    /// dictionary, read at the first [`Node::start`]), running at bit timing `bit_timing`
    /// (index of CiA 301's table: 0 = 1000 kbit/s … 4 = 125 kbit/s). It answers "store not
    /// supported" until [`Node::with_lss_storage`].
    pub fn with_lss(mut self, identity: Option<Identity>, bit_timing: u8) -> Self {
        self.lss_setup = Some(LssSetup { identity, bit_timing, bit_timings: None, storage: false });
        self.lss = None;
        self
    }

    /// The LSS slave passes "store configuration" to the application ([`LssEvent::Store`] in
    /// [`Events::lss`]), which answers with [`Node::lss_store_response`].
    pub fn with_lss_storage(mut self) -> Self {
        if let Some(s) = self.lss_setup.as_mut() {
            s.storage = true;
        }
        self
    }

    /// The LSS slave accepts the bit timings whose table index is set in `mask` (bit n =
    /// index n; 0–4 and 6–8 otherwise).
    pub fn with_lss_bit_timings(mut self, mask: u16) -> Self {
        if let Some(s) = self.lss_setup.as_mut() {
            s.bit_timings = Some(mask);
        }
        self
    }

    /// The LSS slave, once started: its state, pending node-ID and bit timing.
    pub fn lss(&self) -> Option<&LssSlave> {
        self.lss.as_ref()
    }

    /// The node-ID the next start (reset node or communication) takes: the one an LSS master
    /// configured, or [`Node::set_node_id`]'s; `None` when the node will have none. The
    /// application restores its dictionary's defaults for this node-ID at [`Events::reset`].
    pub fn next_node_id(&self) -> Option<NodeId> {
        match &self.lss {
            Some(l) => l.pending_node_id(),
            None => self.next_node_id.or(self.node_id),
        }
    }

    /// Sends the answer to [`LssEvent::Store`] once the application has stored the
    /// configuration (or failed to). `false` when the node has no LSS slave.
    pub fn lss_store_response<S: super::Sent>(
        &mut self,
        result: StoreResult,
        out: &mut impl FnMut(CanFrame) -> S,
    ) -> bool {
        let Some(answer) = self.lss.as_ref().map(|l| l.store_response(result)) else {
            return false;
        };
        self.with_tx(out, |_, o| o(answer));
        true
    }

    /// A request on 0x7E5.
    pub(super) fn lss_in(
        &mut self,
        frame: &CanFrame,
        out: &mut impl FnMut(CanFrame),
        ev: &mut Events,
    ) {
        let Some(lss) = self.lss.as_mut() else { return };
        let (answer, event) = lss.handle(frame);
        if let Some(a) = answer {
            out(a);
        }
        ev.lss = event;
        if event == Some(LssEvent::ResetCommunication) {
            // A node without node-ID got one (CiA 305): it resets its communication, which
            // makes the node-ID active and sends the boot-up.
            self.state = None;
            self.pending_reset = Some(Reset::Communication);
            ev.reset = Some(Reset::Communication);
        }
    }
}
