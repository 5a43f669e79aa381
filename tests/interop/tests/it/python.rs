//! odc against python-canopen, both ways, for every device of `odc_tests_interop::devices`.
//!
//! - `our_slave_their_master`: odc's `sdo::Server` serves the generated `slave::Dictionary`;
//!   `python/master.py` drives it with `canopen.RemoteNode` loaded from the same file.
//! - `their_slave_our_master`: `python/slave.py` serves the file with `canopen.LocalNode`;
//!   odc's `sdo::Client` reads it through the generated descriptors and executes the
//!   generated PDO-mapping plan, then reads the mapping back.
//!
//! Ignored, with the reason in `cargo test`'s output, when the build found no python with
//! `canopen`, unless `ODC_INTEROP_REQUIRED` is set (as `.ci/run` does). Each device prints one
//! line of counts; run with `--nocapture` to see them.
#![allow(clippy::unwrap_used, clippy::expect_used, clippy::panic)]

use odc::SdoAbort;
use odc::master::Error as MasterError;
use odc::sdo::{Bus, SdoError, Server};
use odc::slave::ObjectDictionary;
use odc_tests_interop::{Device, Peer, devices, last_json, python};
use serde_json::Value;
use std::collections::BTreeMap;
use std::time::{Duration, Instant};

const NODE: odc::cob::NodeId = odc::node_id!(5);
/// Transfer buffer of both sides: larger than any value of the device files under test.
const BUF: usize = 1024;
/// A bound on one device's session (the slowest takes a few seconds).
const SESSION: Duration = Duration::from_secs(240);

/// Serves `dev`'s generated slave to the python master until it disconnects; returns the
/// dictionary as the session left it and the script's report.
fn serve(py: &std::path::Path, dev: &Device) -> (Box<dyn ObjectDictionary + Send>, Value) {
    let path = dev.path.to_str().unwrap();
    let mut peer =
        Peer::start(py, "master.py", &["--eds", path, "--node", "5", "--device", dev.name]);
    let mut od = (dev.slave)(NODE);
    let mut server = Server::<BUF>::new(NODE);
    let end = Instant::now() + SESSION;
    loop {
        assert!(Instant::now() < end, "{}: session over {SESSION:?}", dev.name);
        let now = peer.bus.now();
        match peer.bus.recv(now + odc::time::Duration::from_millis(20)) {
            Ok(Some(frame)) => {
                if let Some(r) = server.handle(od.as_mut(), &frame, peer.bus.now()) {
                    peer.bus.send(&r).unwrap();
                }
            }
            Ok(None) => {
                if let Some(abort) = server.poll(peer.bus.now()) {
                    peer.bus.send(&abort).unwrap();
                }
                if peer.exited() {
                    break;
                }
            }
            Err(e) if e.kind() == std::io::ErrorKind::UnexpectedEof => break,
            Err(e) => panic!("{}: {e}", dev.name),
        }
    }
    let (out, _err) = peer.finish(Duration::from_secs(30));
    (od, last_json(&out))
}

fn read_u32(od: &dyn ObjectDictionary, index: u16, sub: u8) -> Option<u32> {
    let mut b = [0u8; 8];
    let n = od.read(index, sub, &mut b).ok()?;
    let mut w = [0u8; 4];
    w[..n.min(4)].copy_from_slice(&b[..n.min(4)]);
    Some(u32::from_le_bytes(w))
}

#[test]
#[cfg_attr(
    odc_interop_no_python,
    ignore = "needs python3 with canopen and python-can: set ODC_INTEROP_PYTHON (tests/interop/README.md)"
)]
fn our_slave_their_master() {
    let py = python();
    println!(
        "our slave, their master (odc sdo::Server + generated slave, python-canopen RemoteNode)"
    );
    println!(
        "{:<22} {:>5} {:>6} {:>7} {:>6} {:>5} {:>7} {:>5}  abort codes",
        "device", "read", "no-def", "written", "aborts", "pdos", "pdo-sdo", "saved"
    );
    let mut failures = Vec::new();
    for dev in devices() {
        let (od, report) = serve(&py, &dev);
        if std::env::var_os("ODC_INTEROP_DEBUG").is_some() {
            eprintln!("{report:#}");
        }
        let fresh = (dev.slave)(NODE);
        // pdo.save() must have changed the slave's own tables, to exactly what python read back.
        let saved = report["saved"].as_array().unwrap();
        for s in saved {
            let map = u16::try_from(s["map_index"].as_u64().unwrap()).unwrap();
            let comm = u16::try_from(s["comm_index"].as_u64().unwrap()).unwrap();
            let entries: Vec<u32> = s["entries"]
                .as_array()
                .unwrap()
                .iter()
                .map(|v| u32::try_from(v.as_u64().unwrap()).unwrap())
                .collect();
            assert_eq!(
                read_u32(od.as_ref(), map, 0),
                Some(u32::try_from(entries.len()).unwrap()),
                "{} 0x{map:04X}:00",
                dev.name
            );
            for (i, e) in entries.iter().enumerate() {
                let sub = u8::try_from(i + 1).unwrap();
                assert_eq!(
                    read_u32(od.as_ref(), map, sub),
                    Some(*e),
                    "{} 0x{map:04X}:{sub:02X}",
                    dev.name
                );
            }
            let tt = u32::try_from(s["trans_type"].as_u64().unwrap()).unwrap();
            assert_eq!(read_u32(od.as_ref(), comm, 2), Some(tt), "{} 0x{comm:04X}:02", dev.name);
            let changed = (0..=entries.len()).any(|i| {
                let sub = u8::try_from(i).unwrap();
                read_u32(od.as_ref(), map, sub) != read_u32(fresh.as_ref(), map, sub)
            }) || read_u32(od.as_ref(), comm, 2) != read_u32(fresh.as_ref(), comm, 2);
            assert!(changed, "{}: 0x{map:04X} unchanged by pdo.save()", dev.name);
            let cob = u32::try_from(s["cob_id"].as_u64().unwrap()).unwrap();
            // python-canopen keeps the 29 identifier bits in `cob_id` and bit 30 (no RTR) apart.
            assert_eq!(
                read_u32(od.as_ref(), comm, 1).map(|c| c & 0x1FFF_FFFF),
                Some(cob),
                "{} 0x{comm:04X}:01",
                dev.name
            );
            assert_eq!(
                read_u32(od.as_ref(), comm, 1).map(|c| c >> 31),
                Some(0),
                "{}: PDO left invalid",
                dev.name
            );
        }
        let n = |k: &str| report[k].as_u64().unwrap();
        println!(
            "{:<22} {:>5} {:>6} {:>7} {:>6} {:>5} {:>7} {:>5}  {}",
            dev.name,
            n("read"),
            n("read_without_default"),
            n("written"),
            n("aborts"),
            n("pdo_compared"),
            report["pdo_read_sdo_only"].as_u64().unwrap_or(0),
            saved.len(),
            report["abort_codes"]
        );
        if let Some(settled) = report["settled"].as_object() {
            for (why, at) in settled {
                println!("{:<22} settled ({}x): {why}", "", at.as_array().map_or(0, Vec::len));
            }
        }
        if report["skipped"].as_object().is_some_and(|m| !m.is_empty()) {
            println!("{:<22} skipped: {}", "", report["skipped"]);
        }
        for d in report["disagreements"].as_array().unwrap() {
            failures.push(format!("{}: {d}", dev.name));
        }
    }
    assert!(failures.is_empty(), "disagreements with python-canopen:\n{}", failures.join("\n"));
}

/// What odc's client saw from python-canopen's LocalNode for one device.
#[derive(Default)]
struct Master {
    read: usize,
    matched: usize,
    /// LocalNode answers 0x060A0023 for an object without default (it has no value to give);
    /// odc's generated slave starts those at zero.
    no_default: usize,
    written: usize,
    checked_back: usize,
    /// Remote aborts checked (code as expected).
    aborts: usize,
    failures: Vec<String>,
}

fn drive(py: &std::path::Path, dev: &Device) -> Master {
    let path = dev.path.to_str().unwrap();
    let mut peer = Peer::start(py, "slave.py", &["--eds", path, "--node", "5"]);
    let reference = (dev.slave)(NODE);
    let mut m = Master::default();
    // odc's master runtime, on the test's end of the socket. LocalNode answers SDO requests
    // only after its boot-up message, which python can take long to send.
    let mut master = odc::master::Master::new(&mut peer.bus)
        .with_timeout(odc::time::Duration::from_millis(30_000));
    if let Err(e) = master.wait_boot_up(NODE) {
        panic!("{}: no boot-up message from LocalNode: {e}", dev.name);
    }
    let mut master = master.with_timeout(odc::time::Duration::from_millis(2000));
    let remote = |e: &MasterError<std::io::Error>| match e {
        MasterError::Sdo { error: SdoError::Remote(a), .. } => Some(*a),
        _ => None,
    };

    // A typed read through a generated descriptor.
    let want = dev.device_type.default.and_then(|d| d.resolve(NODE));
    match master.read(NODE, dev.device_type) {
        Ok(v) if Some(v) == want => m.matched += 1,
        Err(e) if remote(&e) == Some(SdoAbort::NoResource) && want.is_none() => m.no_default += 1,
        other => m.failures.push(format!("DEVICE_TYPE: {other:?}, want {want:?}")),
    }
    m.read += 1;

    // Every readable entry, byte for byte against odc's own slave at its defaults.
    for e in dev.entries.iter().filter(|e| e.access().readable()) {
        let (i, s) = (e.addr().index, e.addr().sub);
        let mut want = [0u8; BUF];
        let n = reference.read(i, s, &mut want).unwrap();
        m.read += 1;
        match master.upload(NODE, i, s) {
            Ok(got) if got == want[..n] => m.matched += 1,
            Ok(got) => {
                m.failures.push(format!("{}: got {got:02X?}, want {:02X?}", e.addr(), &want[..n]))
            }
            Err(err) => match remote(&err) {
                Some(SdoAbort::NoResource) => m.no_default += 1,
                Some(SdoAbort::NoData) if n == 0 => m.matched += 1,
                _ => m.failures.push(format!("{}: {err:?}", e.addr())),
            },
        }
    }

    // Aborts from LocalNode reach odc's master as remote aborts with their codes: a write to
    // every entry the file makes read-only, a read and a write of a missing object.
    for e in dev.entries.iter().filter(|e| !e.access().writable()) {
        let mut cur = [0u8; BUF];
        let n = reference.read(e.addr().index, e.addr().sub, &mut cur).unwrap_or(4).max(1);
        match master.download(NODE, e.addr().index, e.addr().sub, &cur[..n]) {
            Err(err) if remote(&err) == Some(SdoAbort::WriteOfReadOnly) => m.aborts += 1,
            other => m.failures.push(format!("write of read-only {}: {other:?}", e.addr())),
        }
    }
    for index in [0x1FFFu16, 0x5FFF, 0x9FFF] {
        if dev.entries.iter().any(|e| e.addr().index == index) {
            continue;
        }
        match master.upload(NODE, index, 0) {
            Err(err) if remote(&err) == Some(SdoAbort::NoSuchObject) => m.aborts += 1,
            other => m.failures.push(format!("read of missing 0x{index:04X}: {other:?}")),
        }
        match master.download(NODE, index, 0, &[1]) {
            Err(err) if remote(&err) == Some(SdoAbort::NoSuchObject) => m.aborts += 1,
            other => m.failures.push(format!("write of missing 0x{index:04X}: {other:?}")),
        }
    }

    // The generated PDO-mapping plan, then every address it wrote read back.
    let plan = (dev.plan)(NODE);
    if let Err(err) = master.execute(NODE, &plan) {
        m.failures.push(format!("plan: {err:?}"));
    }
    m.written = plan.len();
    let mut last = BTreeMap::new();
    for w in &plan {
        last.insert((w.index, w.sub), *w);
    }
    for ((i, s), w) in &last {
        let (bytes, n) = w.to_le_bytes();
        match master.upload(NODE, *i, *s) {
            Ok(got) if got == bytes[..n] => m.checked_back += 1,
            other => m
                .failures
                .push(format!("read back 0x{i:04X}:{s:02X}: {other:?}, want {:02X?}", &bytes[..n])),
        }
    }
    drop(master);
    let (out, _err) = peer.finish(Duration::from_secs(30));
    // LocalNode's own store holds what the plan wrote.
    let store = &last_json(&out)["data_store"];
    for ((i, s), w) in &last {
        let (bytes, n) = w.to_le_bytes();
        let hex: String = bytes[..n].iter().map(|b| format!("{b:02x}")).collect();
        let key = format!("0x{i:04X}:{s:02X}");
        if store[&key].as_str() != Some(hex.as_str()) {
            m.failures.push(format!("LocalNode store {key} = {}, want {hex}", store[&key]));
        }
    }
    m
}

#[test]
#[cfg_attr(
    odc_interop_no_python,
    ignore = "needs python3 with canopen and python-can: set ODC_INTEROP_PYTHON (tests/interop/README.md)"
)]
fn their_slave_our_master() {
    let py = python();
    println!(
        "their slave, our master (python-canopen LocalNode, odc::master::Master + generated od/master)"
    );
    println!(
        "{:<22} {:>5} {:>7} {:>6} {:>7} {:>9} {:>6}",
        "device", "read", "matched", "no-def", "written", "read-back", "aborts"
    );
    let mut failures = Vec::new();
    for dev in devices() {
        let m = drive(&py, &dev);
        println!(
            "{:<22} {:>5} {:>7} {:>6} {:>7} {:>9} {:>6}",
            dev.name, m.read, m.matched, m.no_default, m.written, m.checked_back, m.aborts
        );
        failures.extend(m.failures.iter().map(|f| format!("{}: {f}", dev.name)));
    }
    assert!(failures.is_empty(), "disagreements with python-canopen:\n{}", failures.join("\n"));
}

/// The two corpus devices are among those tested when the corpus is there; where it is not,
/// this test shows in `cargo test`'s output that they were left out.
#[test]
#[cfg_attr(
    not(odc_interop_corpus),
    ignore = "needs the real-world corpus (ODC_CORPUS): maxon EPOS4 and Elcom e-RIO left out of the interop tests"
)]
fn corpus_devices_are_tested() {
    let names: Vec<&str> = devices().iter().map(|d| d.name).collect();
    for name in ["maxon_epos4", "elcom_erio"] {
        assert!(names.contains(&name), "{name} not among {names:?}");
    }
}
