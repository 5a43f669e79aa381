//! odc's `node::Node` over each device's generated `slave::Dictionary`, driven by
//! python-canopen as NMT master (`python/node.py`), for every device of
//! `odc_tests_interop::devices`: NMT (reset node and reset communication give a boot-up;
//! stopped silences SDO; pre-operational has no PDOs), the heartbeat written over SDO to
//! 0x1017 (period and state), TPDO 1 configured with `pdo.save()` as type 1, type 5 and type
//! 254 with a 50 ms event timer, a remap (length and content on the wire), RPDO 1 from
//! python-canopen into the dictionary, EMCY 0x8210 (an RPDO one byte short) decoded by
//! python-canopen's EMCY consumer, node guarding with python-canopen's guarding, and the
//! life-guarding loss when it stops.
//!
//! Ignored, with the reason in `cargo test`'s output, when the build found no python with
//! `canopen` (see `python.rs`). One line of counts per device (`--nocapture`).
//!
//! `socketcan_vcan0`: the node and odc's SDO client on a SocketCAN `vcan0`, shown ignored
//! where the machine has none.
#![allow(clippy::unwrap_used, clippy::expect_used, clippy::panic)]

use odc::node::{Node, Reset};
use odc::sdo::Bus;
use odc_tests_interop::node_report::{Seen, check, int};
use odc_tests_interop::{Device, Peer, devices, last_json, python};
use serde_json::Value;
use std::time::{Duration, Instant};

const NODE: odc::cob::NodeId = odc::node_id!(5);
/// SDO buffer: larger than any value of the device files under test.
const BUF: usize = 1024;
/// A bound on one device's session (about 8 s of python's steps).
const SESSION: Duration = Duration::from_secs(120);

/// Runs `dev` as a node on the loopback bus until the python master is done.
fn session(py: &std::path::Path, dev: &Device) -> (Value, Seen) {
    let path = dev.path.to_str().unwrap();
    let mut peer =
        Peer::start(py, "node.py", &["--eds", path, "--node", "5", "--device", dev.name]);
    let mut od = (dev.slave)(NODE);
    let mut node: Node<BUF> = Node::new(NODE);
    let start = Instant::now();
    let now_us = || u64::try_from(start.elapsed().as_micros()).unwrap();
    let mut out = Vec::new();
    let mut seen = Seen::default();
    node.start(od.as_mut(), odc::time::Instant::from_micros(now_us()), &mut |f| out.push(f));
    let end = Instant::now() + SESSION;
    'run: loop {
        assert!(Instant::now() < end, "{}: session over {SESSION:?}", dev.name);
        let now = peer.bus.now();
        let frame = match peer.bus.recv(now + odc::time::Duration::from_millis(1)) {
            Ok(f) => f,
            Err(e) if e.kind() == std::io::ErrorKind::UnexpectedEof => break,
            Err(e) => panic!("{}: {e}", dev.name),
        };
        if let Some(f) = frame {
            let ev =
                node.handle(od.as_mut(), &f, odc::time::Instant::from_micros(now_us()), &mut |f| {
                    out.push(f)
                });
            seen.note(&ev);
            // The application's part of a reset: the dictionary back to its defaults (both
            // kinds here: a generated dictionary has no separate communication defaults).
            if matches!(ev.reset, Some(Reset::Node | Reset::Communication)) {
                od = (dev.slave)(NODE);
            }
        }
        let ev =
            node.poll(od.as_mut(), odc::time::Instant::from_micros(now_us()), &mut |f| out.push(f));
        seen.note(&ev);
        for f in out.drain(..) {
            if peer.bus.send(&f).is_err() {
                break 'run;
            }
        }
        if frame.is_none() && peer.exited() {
            break;
        }
    }
    let (stdout, _err) = peer.finish(Duration::from_secs(30));
    (last_json(&stdout), seen)
}

#[test]
#[cfg_attr(
    odc_interop_no_python,
    ignore = "needs python3 with canopen and python-can: set ODC_INTEROP_PYTHON (tests/interop/README.md)"
)]
fn our_node_their_nmt_master() {
    let py = python();
    println!(
        "our node, their master (odc node::Node + generated slave, python-canopen RemoteNode)"
    );
    println!(
        "{:<16} {:>4} {:>3} {:>6} {:>3} {:>3} {:>5} {:>6} {:>5} {:>6} {:>5}  notes",
        "device", "boot", "hb", "hb-ms", "t1", "t5", "t254", "remap", "rpdo", "emcy", "guard"
    );
    let mut failures = Vec::new();
    for dev in devices() {
        let (r, seen) = session(&py, &dev);
        if std::env::var_os("ODC_INTEROP_DEBUG").is_some() {
            eprintln!("{r:#}\n{seen:?}");
        }
        let lengths: Vec<String> =
            r["remap_lengths"].as_array().into_iter().flatten().map(|v| v.to_string()).collect();
        let mut notes = Vec::new();
        if r["tpdo_configured_by"] == serde_json::json!(["sdo"]) {
            notes.push("COB-ID read-only: configured by SDO, not pdo.save()");
        }
        if r["tpdo_mappable_in_eds"] == false {
            notes.push(
                "no object flagged PDOMapping=1: mapping refused (0x06040041), no PDO tested",
            );
        }
        if r["event_timer"] == false {
            notes.push("no 0x1800:05");
        }
        if r["life_guarding"] == false {
            notes.push("no 0x100C/0x100D");
        }
        println!(
            "{:<16} {:>4} {:>3} {:>6} {:>3} {:>3} {:>5} {:>6} {:>5} {:>6} {:>5}  {}",
            dev.name,
            r["bootups"],
            r["heartbeat_preop"],
            r["heartbeat_period_ms"],
            r["type1_per_10_syncs"],
            r["type5_per_20_syncs"],
            if r["event_timer"] == false {
                "none".into()
            } else {
                r["type254_50ms_per_second"].to_string()
            },
            lengths.join("→"),
            seen.rpdos,
            format!("{:04X}", int(&r["emcy"]["code"])),
            format!("{}/{}", r["guarding_answers"], seen.life_guarding_lost),
            notes.join("; "),
        );
        let bad = check(&r, Some(&seen));
        if !bad.is_empty() {
            failures.push(format!("{}: {}", dev.name, bad.join("; ")));
        }
    }
    assert!(failures.is_empty(), "{}", failures.join("\n"));
}

/// The node and odc's SDO client on a SocketCAN `vcan0`: boot-up, an SDO upload of the device
/// type, NMT start and a heartbeat written over SDO.
#[test]
#[cfg(target_os = "linux")]
#[cfg_attr(
    not(odc_vcan0),
    ignore = "needs a SocketCAN vcan0 interface (ip link add dev vcan0 type vcan && ip link set up vcan0)"
)]
fn socketcan_vcan0() {
    use odc::transport::socketcan::SocketCan;
    let dev = devices().into_iter().next().unwrap();
    let mut master = SocketCan::open("vcan0").unwrap();
    let mut wire = SocketCan::open("vcan0").unwrap();
    let stop = std::sync::Arc::new(std::sync::atomic::AtomicBool::new(false));
    let stop_node = stop.clone();
    let slave = dev.slave;
    let runner = std::thread::spawn(move || {
        let mut od = slave(NODE);
        let mut node: Node<BUF> = Node::new(NODE);
        let start = Instant::now();
        let now_us = || u64::try_from(start.elapsed().as_micros()).unwrap();
        let mut out = Vec::new();
        std::thread::sleep(Duration::from_millis(50));
        node.start(od.as_mut(), odc::time::Instant::from_micros(now_us()), &mut |f| out.push(f));
        while !stop_node.load(std::sync::atomic::Ordering::Relaxed) {
            let now = wire.now();
            if let Some(f) = wire.recv(now + odc::time::Duration::from_millis(1)).unwrap() {
                node.handle(od.as_mut(), &f, odc::time::Instant::from_micros(now_us()), &mut |f| {
                    out.push(f)
                });
            }
            node.poll(od.as_mut(), odc::time::Instant::from_micros(now_us()), &mut |f| out.push(f));
            for f in out.drain(..) {
                wire.send(&f).unwrap();
            }
        }
    });
    let deadline = master.now() + odc::time::Duration::from_millis(2000);
    let boot = loop {
        match master.recv(deadline).unwrap() {
            Some(f) if f.id() == 0x705 => break Some(f),
            Some(_) => {}
            None => break None,
        }
    };
    assert_eq!(boot.map(|f| f.bytes().to_vec()), Some(vec![0]));
    let mut sdo = odc::sdo::Client::<64>::new(NODE);
    let device_type: u32 = sdo.read(&mut master, dev.device_type).unwrap();
    assert_eq!(Some(device_type), dev.device_type.default.and_then(|d| d.resolve(NODE)));
    sdo.download(&mut master, 0x1017, 0, &50u16.to_le_bytes()).unwrap();
    master.send(&odc::can::CanFrame::from_slice(0, &[0x01, NODE.get()]).unwrap()).unwrap();
    let end = master.now() + odc::time::Duration::from_millis(520);
    let mut beats = Vec::new();
    while master.now() < end {
        if let Some(f) = master.recv(end).unwrap()
            && f.id() == 0x705
        {
            beats.push(f.data()[0]);
        }
    }
    stop.store(true, std::sync::atomic::Ordering::Relaxed);
    runner.join().unwrap();
    assert!((9..=11).contains(&beats.len()), "{beats:?}");
    assert!(beats.iter().skip(1).all(|&b| b == 0x05), "{beats:?}");
}

/// The node in a thread on `odc::transport::mem`, odc's SDO client on another port, a third
/// port listening: the boot-up reaches both, the client reads the device type and configures
/// the heartbeat, NMT start gives operational heartbeats. What `odc simulate` and a test of a
/// master do without a CAN interface.
#[test]
fn node_and_sdo_client_on_the_in_memory_bus() {
    use odc::transport::mem::MemBus;
    let bus = MemBus::new();
    let (mut wire, mut master, mut sniffer) = (bus.port(), bus.port(), bus.port());
    let dev = devices().into_iter().next().unwrap();
    let slave = dev.slave;
    let stop = std::sync::Arc::new(std::sync::atomic::AtomicBool::new(false));
    let stop_node = stop.clone();
    let runner = std::thread::spawn(move || {
        let mut od = slave(NODE);
        let mut node: Node<BUF> = Node::new(NODE);
        let mut out = Vec::new();
        let now = wire.now();
        node.start(od.as_mut(), now, &mut |f| out.push(f));
        while !stop_node.load(std::sync::atomic::Ordering::Relaxed) {
            let now = wire.now();
            if let Some(f) = wire.recv(now + odc::time::Duration::from_millis(1)).unwrap() {
                let now = wire.now();
                node.handle(od.as_mut(), &f, now, &mut |f| out.push(f));
            }
            let now = wire.now();
            node.poll(od.as_mut(), now, &mut |f| out.push(f));
            for f in out.drain(..) {
                wire.send(&f).unwrap();
            }
        }
    });
    let boot = |p: &mut odc::transport::mem::MemPort| {
        let deadline = p.now() + odc::time::Duration::from_millis(2000);
        loop {
            match p.recv(deadline).unwrap() {
                Some(f) if f.id() == 0x705 => break Some(f.bytes().to_vec()),
                Some(_) => {}
                None => break None,
            }
        }
    };
    assert_eq!(boot(&mut master), Some(vec![0]));
    assert_eq!(boot(&mut sniffer), Some(vec![0]));
    let mut sdo = odc::sdo::Client::<64>::new(NODE);
    let device_type: u32 = sdo.read(&mut master, dev.device_type).unwrap();
    assert_eq!(Some(device_type), dev.device_type.default.and_then(|d| d.resolve(NODE)));
    sdo.download(&mut master, 0x1017, 0, &20u16.to_le_bytes()).unwrap();
    master.send(&odc::can::CanFrame::from_slice(0, &[0x01, NODE.get()]).unwrap()).unwrap();
    let end = sniffer.now() + odc::time::Duration::from_millis(210);
    let mut beats = Vec::new();
    let mut requests = 0;
    while sniffer.now() < end {
        match sniffer.recv(end).unwrap() {
            Some(f) if f.id() == 0x705 => beats.push(f.data()[0]),
            Some(f) if f.id() == 0x605 => requests += 1,
            _ => {}
        }
    }
    stop.store(true, std::sync::atomic::Ordering::Relaxed);
    runner.join().unwrap();
    // The sniffer gets the master's frames too: the two expedited SDO requests.
    assert_eq!(requests, 2);
    let operational = beats.iter().filter(|&&b| b == 0x05).count();
    assert!((9..=11).contains(&operational), "{beats:?}");
}
