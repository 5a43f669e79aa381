//! The CANopen node (`odc::node::Node`, with its LSS slave) over the generated dictionary of
//! `eds/lxm23a.eds`, fed arbitrary frame sequences at arbitrary time steps (NMT, SYNC, SDO,
//! heartbeats, guarding RTRs, LSS, PDOs, anything), with the application's part done as the
//! node's documentation says (a reset restores the dictionary's defaults). After every call:
//! - every frame sent is a data frame of at most 8 bytes, bytes past the length zero, an
//!   11-bit identifier (29-bit only for a PDO configured so);
//! - the NMT state follows CiA 301's state machine (fig. 48) as a model here drives it from
//!   the NMT commands addressed to the node; a reset sends the boot-up (0x700 + node, one
//!   byte 0) at the next call and enters pre-operational, and no boot-up comes otherwise;
//! - heartbeats carry the node's state; guarding answers carry it with a toggle bit that
//!   starts at 0 after each boot-up and alternates;
//! - nothing goes out on a restricted CAN-ID (CiA 301: NMT, SDO, error control, LSS
//!   ranges) but the node's own error control, SDO responses and LSS answers;
//! - services per state (CiA 301 table 80): in stopped, only NMT error control (0x700 +
//!   node) and LSS (0x7E4) frames go out and no SDO is answered; PDOs only in operational;
//! - the SDO server, in pre-operational and operational, follows CiA 301's protocol
//!   (`common/sdo_model.rs`: every request answered or aborted, exactly once where the
//!   protocol says so, on 0x580 + node, 8 bytes; timeouts abort).
#![no_main]

#[path = "common/sdo_model.rs"]
mod sdo_model;

mod lxm23a {
    odc_macros::include_device!("../eds/lxm23a.eds", role = "slave");
}

use arbitrary::{Arbitrary, Unstructured};
use libfuzzer_sys::fuzz_target;
use odc::can::CanFrame;
use odc::cob::NodeId;
use odc::nmt::NmtState;
use odc::node::{Events, Node};
use odc::time::Instant;
use sdo_model::Model;

type Dict = lxm23a::slave::Dictionary;
type TheNode = Node<64, 4, 4>;

// The calls into the node, in one place: only these functions know its time type
// (`odc::time::Instant`, µs), node-ID type (`NodeId`, `None` without one) and frame
// constructors. The harness counts in µs and names a node without node-ID 0xFF (CiA 305).
fn node_new(id: u8, lss: bool) -> TheNode {
    let n = match NodeId::new(id) {
        Some(id) => TheNode::new(id),
        None => TheNode::unconfigured(),
    };
    if lss { n.with_lss(None, 0) } else { n }
}
fn node_start(n: &mut TheNode, d: &mut Dict, now_us: u64, out: &mut Vec<CanFrame>) {
    n.start(d, Instant::from_micros(now_us), &mut |f| out.push(f));
}
fn node_handle(
    n: &mut TheNode,
    d: &mut Dict,
    f: &CanFrame,
    now_us: u64,
    out: &mut Vec<CanFrame>,
) -> Events {
    n.handle(d, f, Instant::from_micros(now_us), &mut |f| out.push(f))
}
fn node_poll(n: &mut TheNode, d: &mut Dict, now_us: u64, out: &mut Vec<CanFrame>) -> Events {
    n.poll(d, Instant::from_micros(now_us), &mut |f| out.push(f))
}
fn node_id(n: &TheNode) -> u8 {
    NodeId::to_lss(n.node_id())
}
fn next_node_id(n: &TheNode) -> Option<NodeId> {
    n.next_node_id()
}
fn dict_new(id: u8) -> Dict {
    Dict::new(NodeId::new(id))
}
fn frame(id: u32, b: &[u8]) -> CanFrame {
    CanFrame::from_slice(id, b).expect("11 bits and at most 8 bytes, by construction")
}
fn remote(id: u32, len: u8) -> CanFrame {
    CanFrame::remote(id, len).expect("11 bits and at most 8 bytes, by construction")
}

/// `ODC_FUZZ_TRACE=1 target/.../node INPUT` prints every call, to read a failing input.
fn trace() -> bool {
    static ON: std::sync::OnceLock<bool> = std::sync::OnceLock::new();
    *ON.get_or_init(|| std::env::var_os("ODC_FUZZ_TRACE").is_some())
}

struct Harness {
    node: TheNode,
    dict: Dict,
    now_us: u64,
    /// The NMT state by CiA 301; `None` while initialising or with a reset pending.
    state: Option<NmtState>,
    /// A reset was reported: the next call boots.
    reset_pending: bool,
    /// The toggle bit the next guarding answer carries.
    toggle: bool,
    sdo: Model,
}

/// CiA 301's restricted CAN-IDs, which no configurable communication object may use (as
/// CANopenNode's `CO_IS_RESTRICTED_CAN_ID`).
fn restricted(id: u32) -> bool {
    matches!(id, 0x000..=0x07F | 0x101..=0x180 | 0x581..=0x5FF | 0x601..=0x67F | 0x6E0..=0x6FF | 0x701..=0x7FF)
}

fn check_frame(f: &CanFrame) {
    assert!(!f.is_remote(), "the node sent a remote frame: {f:?}");
    assert!(f.len() <= 8, "{f:?}");
    assert!(
        f.data()[usize::from(f.len())..].iter().all(|&b| b == 0),
        "bytes past the length: {f:?}"
    );
    let max = if f.is_extended() { 0x1FFF_FFFF } else { 0x7FF };
    assert!(f.id() <= max, "identifier out of range: {f:?}");
}

impl Harness {
    /// Checks one call's frames and events against the model; `input`: the frame handled.
    fn after(
        &mut self,
        before: Option<NmtState>,
        id: u8,
        ev: &Events,
        out: &[CanFrame],
        input: Option<&CanFrame>,
    ) {
        for f in out {
            check_frame(f);
            // CiA 301: the restricted CAN-IDs carry only the services they are for;
            // what this node may send on them is its error control, SDO responses and LSS.
            let own = [0x700 + u32::from(id), 0x580 + u32::from(id), 0x7E4];
            assert!(
                f.is_extended() || !restricted(f.id()) || own.contains(&f.id()),
                "{f:02X?} on a restricted CAN-ID"
            );
        }
        let booted = self.reset_pending;
        let ec = 0x700 + u32::from(id);
        let bootups = out.iter().filter(|f| f.is_data(ec) && f.bytes() == [0]).count();
        if booted {
            self.reset_pending = false;
            self.toggle = false;
            self.sdo = Model::new(odc::sdo::DEFAULT_TIMEOUT);
            let valid = (1..=127).contains(&id);
            assert_eq!(bootups, usize::from(valid), "boot-up after a reset: {out:02X?}");
            if valid {
                let first = out.iter().find(|f| f.is_data(ec));
                assert_eq!(
                    first.map(CanFrame::bytes),
                    Some(&[0u8][..]),
                    "boot-up not first: {out:02X?}"
                );
            }
            self.state = valid.then_some(NmtState::PreOperational);
        } else {
            assert_eq!(bootups, 0, "a boot-up without a reset: {out:02X?}");
        }
        // The state the rest of the call ran in.
        let running = if booted { self.state } else { before };
        if let Some(f) = input
            && f.is_data(0)
            && f.len() >= 2
            && running.is_some()
            && (f.data()[1] == 0 || f.data()[1] == id)
        {
            match f.data()[0] {
                0x01 => self.state = Some(NmtState::Operational),
                0x02 => self.state = Some(NmtState::Stopped),
                0x80 => self.state = Some(NmtState::PreOperational),
                0x81 | 0x82 => {
                    self.state = None;
                    self.reset_pending = true;
                    assert!(ev.reset.is_some(), "reset command without the reset event");
                }
                _ => {}
            }
        }
        if ev.lss == Some(odc::lss::LssEvent::ResetCommunication) {
            self.state = None;
            self.reset_pending = true;
        }
        assert_eq!(ev.reset.is_some(), self.reset_pending, "reset event: {ev:?}");
        let now = self.node.state();
        assert_eq!(now, self.state.unwrap_or(NmtState::BootUp), "NMT state after {input:02X?}");
        if self.state != running && self.state.is_some() {
            assert_eq!(ev.state, self.state, "state change not reported");
        }
        // Error control: heartbeats carry the state; a guarding answer the toggle bit.
        let guarding = input.is_some_and(|f| {
            f.is_remote() && !f.is_extended() && f.id() == ec && running.is_some()
        });
        for f in out.iter().filter(|f| f.is_data(ec) && f.bytes() != [0]) {
            assert_eq!(f.len(), 1, "error control frame of {} bytes", f.len());
            let s = running.expect("error control only from a started node");
            if guarding {
                assert_eq!(
                    f.data()[0],
                    s.to_u8() | if self.toggle { 0x80 } else { 0 },
                    "guarding answer"
                );
                self.toggle = !self.toggle;
            } else {
                assert_eq!(f.data()[0], s.to_u8(), "heartbeat");
            }
        }
        if guarding {
            let answers = out.iter().filter(|f| f.is_data(ec)).count() - bootups;
            assert_eq!(answers, 1, "guarding answered {out:02X?}");
        }
        // Services per state (CiA 301 table 80), for a call that stayed in one state.
        if running == self.state {
            match running {
                Some(NmtState::Stopped) | None => {
                    for f in out {
                        assert!(
                            f.is_data(ec) || f.is_data(0x7E4),
                            "{f:02X?} sent while {running:?}"
                        );
                    }
                    assert!(
                        ev.rpdo == 0 && ev.tpdo == 0 && !ev.sdo_written,
                        "{ev:?} while {running:?}"
                    );
                }
                Some(NmtState::PreOperational) => {
                    assert!(ev.rpdo == 0 && ev.tpdo == 0, "PDO in pre-operational: {ev:?}");
                }
                _ => {}
            }
        }
        // SDO.
        let (req, resp) = (0x600 + u32::from(id), 0x580 + u32::from(id));
        let sdo_out: Vec<CanFrame> = out.iter().filter(|f| f.is_data(resp)).copied().collect();
        let sdo_on = matches!(running, Some(NmtState::PreOperational | NmtState::Operational));
        let now = Instant::from_micros(self.now_us);
        match input {
            Some(f) if f.is_data(req) && sdo_on => {
                for o in &sdo_out {
                    sdo_model::check_frame(o, resp);
                }
                self.sdo.request(f.bytes(), &sdo_out, None, now, &|_| None);
            }
            None if sdo_on => self.sdo.poll(&sdo_out, now),
            _ => assert!(
                sdo_out.is_empty(),
                "SDO frames {sdo_out:02X?} for {input:02X?} while {running:?}"
            ),
        }
        if self.reset_pending {
            self.sdo = Model::new(odc::sdo::DEFAULT_TIMEOUT);
        }
    }

    fn handle(&mut self, f: &CanFrame) {
        let (before, id) = (self.state, node_id(&self.node));
        let mut out = Vec::new();
        let ev = node_handle(&mut self.node, &mut self.dict, f, self.now_us, &mut out);
        if trace() {
            eprintln!("{} us: {f:02X?} -> {out:02X?}", self.now_us);
        }
        // A reset performed in this call may have given the node another node-ID (LSS).
        let id = if self.reset_pending { node_id(&self.node) } else { id };
        self.after(before, id, &ev, &out, Some(f));
        self.app(&ev);
    }

    fn poll(&mut self) {
        let (before, id) = (self.state, node_id(&self.node));
        let mut out = Vec::new();
        let ev = node_poll(&mut self.node, &mut self.dict, self.now_us, &mut out);
        if trace() {
            eprintln!("{} us: poll -> {out:02X?}", self.now_us);
        }
        let id = if self.reset_pending { node_id(&self.node) } else { id };
        self.after(before, id, &ev, &out, None);
        self.app(&ev);
    }

    /// The application's part: a reset restores the dictionary's defaults.
    fn app(&mut self, ev: &Events) {
        if ev.reset.is_some() {
            self.dict = Dict::new(next_node_id(&self.node));
        }
    }
}

/// COB-IDs worth aiming at for node `id`.
fn cob(u: &mut Unstructured<'_>, id: u32) -> arbitrary::Result<u32> {
    Ok(match u.int_in_range(0..=12u8)? {
        0 | 1 => 0x000,
        2 => 0x080,
        3..=5 => 0x600 + id,
        6 => 0x700 + u32::from(u.int_in_range(1..=127u8)?),
        7 => 0x7E5,
        8 => *u.choose(&[0x200, 0x300, 0x400, 0x500])? + id,
        9 => 0x580 + id,
        10 => 0x700 + id,
        _ => u.int_in_range(0..=0x7FF)?,
    })
}

fn run(u: &mut Unstructured<'_>) -> arbitrary::Result<()> {
    let id = if u.ratio(1, 8)? { 0xFF } else { u.int_in_range(1..=127)? };
    let lss = id == 0xFF || bool::arbitrary(u)?;
    let mut h = Harness {
        node: node_new(id, lss),
        dict: dict_new(id),
        now_us: 0,
        state: None,
        reset_pending: false,
        toggle: false,
        sdo: Model::new(odc::sdo::DEFAULT_TIMEOUT),
    };
    let mut out = Vec::new();
    node_start(&mut h.node, &mut h.dict, 0, &mut out);
    let valid = (1..=127).contains(&id);
    assert_eq!(out, if valid { vec![frame(0x700 + u32::from(id), &[0])] } else { vec![] }, "start");
    h.state = valid.then_some(NmtState::PreOperational);
    while !u.is_empty() {
        let me = u32::from(node_id(&h.node) & 0x7F);
        match u.int_in_range(0..=9u8)? {
            0..=5 => {
                let id = cob(u, me)?;
                let len = u.int_in_range(0..=8usize)?;
                let mut b = [0u8; 8];
                u.fill_buffer(&mut b[..len])?;
                if id == 0 && len >= 2 {
                    b[0] = *u.choose(&[0x01, 0x02, 0x80, 0x81, 0x82, b[0]])?;
                    b[1] = *u.choose(&[0, me as u8, b[1]])?;
                }
                if id == 0x600 + me && len >= 4 && u.ratio(3, 4)? {
                    b[0] = *u.choose(&[
                        0x23, 0x2B, 0x2F, 0x22, 0x21, 0x40, 0x60, 0x00, 0x01, 0xA0, 0xA3, 0xA2,
                        0xC6, 0xC1, 0x80,
                    ])?;
                    let (i, s) = *u.choose(&[
                        (0x1017u16, 0u8),
                        (0x1016, 1),
                        (0x1016, 0),
                        (0x100C, 0),
                        (0x100D, 0),
                        (0x1005, 0),
                        (0x1006, 0),
                        (0x1019, 0),
                        (0x1400, 1),
                        (0x1800, 1),
                        (0x1800, 2),
                        (0x1800, 3),
                        (0x1800, 5),
                        (0x1A00, 0),
                        (0x1A00, 1),
                        (0x1600, 0),
                        (0x1003, 0),
                        (0x1001, 0),
                        (0x1015, 0),
                        (0x1008, 0),
                        (0x1018, 1),
                    ])?;
                    b[1..3].copy_from_slice(&i.to_le_bytes());
                    b[3] = s;
                }
                let f = match u.int_in_range(0..=9u8)? {
                    0 => remote(id, len as u8),
                    1 => CanFrame::extended(id, &b[..len]).expect("at most 8 bytes"),
                    _ => frame(id, &b[..len]),
                };
                h.handle(&f);
            }
            6 => h.handle(&remote(0x700 + me, 1)),
            _ => {
                let dt = match u.int_in_range(0..=3u8)? {
                    0 => u64::from(u.int_in_range(0..=2000u16)?),
                    1 => u64::from(u16::arbitrary(u)?) * 100,
                    2 => u64::from(u32::arbitrary(u)?),
                    _ => u64::arbitrary(u)? >> u.int_in_range(0..=63)?,
                };
                h.now_us = h.now_us.saturating_add(dt);
                h.poll();
            }
        }
    }
    Ok(())
}

fuzz_target!(|data: &[u8]| {
    let _ = run(&mut Unstructured::new(data));
});
