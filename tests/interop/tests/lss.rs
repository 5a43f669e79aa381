//! LSS against python-canopen's `LssMaster`, for every device of `odc_tests_interop::devices`:
//! odc's `LssSlave` with the device's LSS address (0x1018 sub 1–4 of the generated slave, at
//! its defaults) and no node-ID, driven by `python/lss_master.py`.
//!
//! The node runtime is not used here: a small loop stands for it (LSS frames to the slave and
//! its answers back; the store answered "stored"; after the slave's own reset on leaving
//! configuration without node-ID, and after an NMT reset communication, a boot-up message at
//! the node-ID the slave then has). Checked: fastscan finds the node and its address, inquire
//! address and node-ID, configure node-ID and bit timing (index 5 refused), store, activate,
//! identify (non-configured, remote), switch state selective, and the boot-ups at the new
//! node-IDs; a fastscan finds nobody once the node has one.
#![allow(clippy::unwrap_used, clippy::expect_used, clippy::panic)]

use odc::can::CanFrame;
use odc::lss::{Identity, LssEvent, LssSlave, StoreResult};
use odc::sdo::Bus;
use odc_tests_interop::{Device, Peer, devices, python};
use serde_json::{Value, json};
use std::time::{Duration, Instant};

const NEW_NODE: u8 = 0x21;
const SECOND_NODE: u8 = 0x22;
/// CiA 301 table index 2: 500 kbit/s.
const BIT_TIMING: u8 = 2;
const SESSION: Duration = Duration::from_secs(120);

fn identity(dev: &Device) -> Identity {
    let od = (dev.slave)(1);
    let sub = |s| {
        let mut b = [0u8; 4];
        od.read(0x1018, s, &mut b).map_or(0, |_| u32::from_le_bytes(b))
    };
    Identity::new(sub(1), sub(2), sub(3), sub(4))
}

/// What the node loop saw.
#[derive(Default)]
struct Node {
    stores: Vec<(Option<u8>, u8)>,
    activations: Vec<u16>,
    bootups: Vec<u8>,
}

/// The stand-in for the node runtime: LSS frames to the slave, NMT reset communication and the
/// slave's own reset give a boot-up at the node-ID it then has.
fn run(py: &std::path::Path, dev: &Device) -> (Node, Value) {
    let mut lss = LssSlave::new(identity(dev), None, 0).with_storage();
    let mut node = Node::default();
    let new = NEW_NODE.to_string();
    let second = SECOND_NODE.to_string();
    let bt = BIT_TIMING.to_string();
    let mut peer = Peer::start(
        py,
        "lss_master.py",
        &["--new-node", &new, "--second-node", &second, "--bit-timing", &bt],
    );
    let end = Instant::now() + SESSION;
    loop {
        assert!(Instant::now() < end, "{}: session over {SESSION:?}", dev.name);
        let now = peer.bus.now_ms();
        let frame = match peer.bus.recv(now + 20) {
            Ok(Some(f)) => f,
            Ok(None) if peer.exited() => break,
            Ok(None) => continue,
            Err(e) if e.kind() == std::io::ErrorKind::UnexpectedEof => break,
            Err(e) => panic!("{}: {e}", dev.name),
        };
        let mut reset = false;
        if frame.id == 0 && frame.bytes().len() == 2 {
            // NMT: reset node or reset communication, to this node or all.
            let [cs, to] = [frame.data[0], frame.data[1]];
            reset = matches!(cs, 0x81 | 0x82) && (to == 0 || Some(to) == lss.node_id());
        }
        let (answer, event) = lss.handle(&frame);
        if let Some(a) = answer {
            peer.bus.send(&a).unwrap();
        }
        match event {
            Some(LssEvent::Store { node_id, bit_timing }) => {
                node.stores.push((node_id, bit_timing));
                peer.bus.send(&lss.store_response(StoreResult::Stored)).unwrap();
            }
            Some(LssEvent::ActivateBitTiming { delay_ms }) => node.activations.push(delay_ms),
            Some(LssEvent::ResetCommunication) => reset = true,
            _ => {}
        }
        if reset && let Some(id) = lss.reset_communication() {
            node.bootups.push(id);
            peer.bus.send(&CanFrame::from_slice(0x700 + u32::from(id), &[0]).unwrap()).unwrap();
        }
    }
    let (out, _err) = peer.finish(Duration::from_secs(30));
    let line = out
        .lines()
        .rev()
        .find(|l| l.starts_with('{'))
        .unwrap_or_else(|| panic!("no JSON in:\n{out}"));
    (node, serde_json::from_str(line).unwrap())
}

#[test]
#[cfg_attr(
    odc_interop_no_python,
    ignore = "needs python3 with canopen and python-can: set ODC_INTEROP_PYTHON (tests/interop/README.md)"
)]
fn their_lss_master_our_slave() {
    let py = python();
    println!("LSS: odc LssSlave, python-canopen LssMaster");
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
