//! LSS against python-canopen's `LssMaster`, for every device of `odc_tests_interop::devices`:
//! odc's `node::Node` over the device's generated slave, with an LSS slave whose address is
//! the dictionary's 0x1018 sub 1–4 and no node-ID (0xFF: initialising, no boot-up), driven by
//! `python/lss_master.py`.
//!
//! The application's part is what a firmware's would be: the store answered "stored"
//! (`Node::lss_store_response`), the dictionary set back to its defaults for
//! `Node::next_node_id` at each reset. Checked: fastscan finds the node and its address,
//! inquire address and node-ID, configure node-ID and bit timing (index 5 refused), store,
//! activate, identify (non-configured, remote), switch state selective, the node's boot-up at
//! the new node-ID when it leaves configuration (its own reset communication) and at the
//! second node-ID after NMT reset communication; a fastscan finds nobody once the node has one.
#![allow(clippy::unwrap_used, clippy::expect_used, clippy::panic)]

use odc::lss::{Identity, LssEvent, StoreResult};
use odc::node::Node;
use odc::sdo::Bus;
use odc_tests_interop::{Device, Peer, devices, last_json, python};
use serde_json::{Value, json};
use std::time::{Duration, Instant};

const NEW_NODE: u8 = 0x21;
const SECOND_NODE: u8 = 0x22;
/// CiA 301 table index 2: 500 kbit/s.
const BIT_TIMING: u8 = 2;
const SESSION: Duration = Duration::from_secs(120);
const BUF: usize = 1024;

fn identity(dev: &Device) -> Identity {
    let od = (dev.slave)(odc::node_id!(1));
    let sub = |s| {
        let mut b = [0u8; 4];
        od.read(0x1018, s, &mut b).map_or(0, |_| u32::from_le_bytes(b))
    };
    Identity::new(sub(1), sub(2), sub(3), sub(4))
}

/// What the application saw.
#[derive(Default)]
struct Seen {
    stores: Vec<(Option<u8>, u8)>,
    activations: Vec<u16>,
    /// Node-IDs of the boot-up messages the node sent.
    bootups: Vec<u32>,
    /// The node-ID at the end.
    node_id: u8,
}

/// The node, started without node-ID, until the python master is done.
fn run(py: &std::path::Path, dev: &Device) -> (Seen, Value) {
    // A dictionary for node-ID 1 until the node has one: no frame of it is sent before.
    let mut od = (dev.slave)(odc::node_id!(1));
    let mut node: Node<BUF> = Node::unconfigured().with_lss(None, 0).with_lss_storage();
    let mut seen = Seen::default();
    let new = NEW_NODE.to_string();
    let second = SECOND_NODE.to_string();
    let bt = BIT_TIMING.to_string();
    let mut peer = Peer::start(
        py,
        "lss_master.py",
        &["--new-node", &new, "--second-node", &second, "--bit-timing", &bt],
    );
    let mut out = Vec::new();
    node.start(od.as_mut(), peer.bus.now(), &mut |f| out.push(f));
    let end = Instant::now() + SESSION;
    'run: loop {
        assert!(Instant::now() < end, "{}: session over {SESSION:?}", dev.name);
        let now = peer.bus.now();
        let frame = match peer.bus.recv(now + odc::time::Duration::from_millis(1)) {
            Ok(f) => f,
            Err(e) if e.kind() == std::io::ErrorKind::UnexpectedEof => break,
            Err(e) => panic!("{}: {e}", dev.name),
        };
        let now = peer.bus.now();
        let mut events = node.poll(od.as_mut(), now, &mut |f| out.push(f));
        if let Some(f) = &frame {
            events.absorb(node.handle(od.as_mut(), f, now, &mut |f| out.push(f)));
        }
        match events.lss {
            Some(LssEvent::Store { node_id, bit_timing }) => {
                seen.stores.push((node_id.map(odc::cob::NodeId::get), bit_timing));
                node.lss_store_response(StoreResult::Stored, &mut |f| out.push(f));
            }
            Some(LssEvent::ActivateBitTiming { delay_ms }) => seen.activations.push(delay_ms),
            _ => {}
        }
        if events.reset.is_some() {
            od = (dev.slave)(node.next_node_id().unwrap_or(odc::node_id!(1)));
        }
        for f in out.drain(..) {
            if (0x701..=0x77F).contains(&f.id()) && f.bytes() == [0] {
                seen.bootups.push(f.id() - 0x700);
            }
            if peer.bus.send(&f).is_err() {
                break 'run;
            }
        }
        if frame.is_none() && peer.exited() {
            break;
        }
    }
    seen.node_id = odc::cob::NodeId::to_lss(node.node_id());
    let (stdout, _err) = peer.finish(Duration::from_secs(30));
    (seen, last_json(&stdout))
}

#[test]
#[cfg_attr(
    odc_interop_no_python,
    ignore = "needs python3 with canopen and python-can: set ODC_INTEROP_PYTHON (tests/interop/README.md)"
)]
fn their_lss_master_our_slave() {
    let py = python();
    println!("LSS: odc node::Node with LssSlave, python-canopen LssMaster");
    println!(
        "{:<22} {:>8} {:>8} {:>6} {:>8}  address found",
        "device", "checks", "failed", "stores", "bootups"
    );
    let mut failures = Vec::new();
    for dev in devices() {
        let id = identity(&dev);
        let (node, r) = run(&py, &dev);
        let ok = |v: Value| json!({ "ok": v });
        let address = json!([id.vendor, id.product, id.revision, id.serial]);
        let boot = |n: u8| json!([n, "00"]);
        let checks: Vec<(&str, Value, Value)> = vec![
            ("identify non-configured (0x50)", r["non_configured"].clone(), json!(0x50)),
            ("fastscan", r["fastscan"].clone(), json!([true, address])),
            ("inquire node-ID (unconfigured)", r["node_id_before"].clone(), ok(json!(0xFF))),
            (
                "inquire address",
                r["inquire"].clone(),
                json!([
                    ok(json!(id.vendor)),
                    ok(json!(id.product)),
                    ok(json!(id.revision)),
                    ok(json!(id.serial))
                ]),
            ),
            ("configure node-ID", r["configure_node_id"].clone(), ok(json!(true))),
            ("configure bit timing", r["configure_bit_timing"].clone(), ok(json!(true))),
            (
                "bit timing 5 refused",
                r["configure_bit_timing_5"].clone(),
                json!({ "error": "LSS Error: 1" }),
            ),
            ("store", r["store"].clone(), ok(json!(true))),
            (
                "boot-up on leaving configuration",
                r["bootups_after_waiting"].clone(),
                json!([boot(NEW_NODE)]),
            ),
            ("identify remote slave (0x4F)", r["identify_remote"].clone(), json!(0x4F)),
            ("switch state selective", r["selective"].clone(), ok(json!(true))),
            ("inquire node-ID (new)", r["node_id_now"].clone(), ok(json!(NEW_NODE))),
            ("configure second node-ID", r["configure_second"].clone(), ok(json!(true))),
            ("store second", r["store_second"].clone(), ok(json!(true))),
            ("pending until reset", r["bootups_before_reset"].clone(), json!([boot(NEW_NODE)])),
            (
                "boot-up after reset communication",
                r["bootups"].clone(),
                json!([boot(NEW_NODE), boot(SECOND_NODE)]),
            ),
            ("fastscan finds nobody configured", r["fastscan_configured"].clone(), json!(false)),
        ];
        let failed: Vec<String> = checks
            .iter()
            .filter(|(_, got, want)| got != want)
            .map(|(what, got, want)| format!("{}: {what}: got {got}, want {want}", dev.name))
            .collect();
        // The node's own boot-ups: the new node-ID on leaving configuration, the second
        // after NMT reset communication; none while it had no node-ID.
        let boots = [u32::from(NEW_NODE), u32::from(SECOND_NODE)];
        if node.bootups != boots || node.node_id != SECOND_NODE {
            failures.push(format!(
                "{}: node boot-ups {:02X?}, node-ID {:#04X} at the end",
                dev.name, node.bootups, node.node_id
            ));
        }
        if node.stores != [(Some(NEW_NODE), BIT_TIMING), (Some(SECOND_NODE), BIT_TIMING)] {
            failures.push(format!("{}: stores {:?}", dev.name, node.stores));
        }
        if node.activations != [10] {
            failures.push(format!("{}: activations {:?}", dev.name, node.activations));
        }
        println!(
            "{:<22} {:>8} {:>8} {:>6} {:>8}  {:08X} {:08X} {:08X} {:08X}",
            dev.name,
            checks.len(),
            failed.len(),
            node.stores.len(),
            node.bootups.len(),
            id.vendor,
            id.product,
            id.revision,
            id.serial
        );
        failures.extend(failed);
    }
    assert!(failures.is_empty(), "disagreements with python-canopen:\n{}", failures.join("\n"));
}
