//! SDO block transfer against python-canopen, on every string or DOMAIN object of the devices
//! of `odc_tests_interop::devices` (the devices without one are listed as such).
//!
//! - `our_block_server_their_client`: odc's `sdo::Server` (sub-blocks of 4 segments, so a
//!   value over 28 bytes takes several) serves the generated slave; `python/block_master.py`
//!   block-uploads every readable such object with `SdoClient.open(..., block_transfer=True)`
//!   and compares nothing itself: the Rust side checks each value against its own dictionary,
//!   then each writable one is block-downloaded (a value as long as the object takes) and
//!   block-uploaded back.
//! - `block_upload_through_the_node`: the same uploads and downloads served by
//!   `odc::node::Node` (the SDO server inside the node, sub-blocks of 127 as python-canopen
//!   asks), which must send a whole sub-block in answer to one request.
//! - `our_block_client_their_server`: odc's `Client::upload_block` against python-canopen's
//!   `LocalNode`, which has no block transfer: it answers with the normal upload protocol (as
//!   CiA 301 lets a server) and odc's client carries on; `download_block` gets its abort
//!   0x05040001 (tests/interop/README.md, differences).
#![allow(clippy::unwrap_used, clippy::expect_used, clippy::panic)]

use odc::node::Node;
use odc::sdo::{Bus, Client, SdoError, Server};
use odc::slave::{ObjectDictionary, Row};
use odc::{DataType, SdoAbort};
use odc_tests_interop::{Device, Peer, devices, last_json, python};
use serde_json::Value;
use std::time::{Duration, Instant};

/// A device of this crate's own (`eds/block-device.eds`): the eds/ devices have no string
/// object that odc's slave can take a value into (read-only, or no default and so no
/// capacity), so block download is tested on its 200-byte and 3-byte strings.
mod block_device {
    odc_macros::include_device!("eds/block-device.eds");
}

/// The devices of the other interop tests, and the one above.
fn all_devices() -> Vec<Device> {
    let mut v = devices();
    v.push(Device {
        name: "block_device",
        path: std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("eds/block-device.eds"),
        entries: block_device::slave::TABLE.rows(),
        slave: |n| Box::new(block_device::slave::Dictionary::new(n)),
        plan: |n| block_device::master::plan(n).to_vec(),
        device_type: &block_device::od::DEVICE_TYPE,
    });
    v
}

const NODE: odc::cob::NodeId = odc::node_id!(5);
const BUF: usize = 1024;
const SESSION: Duration = Duration::from_secs(120);

fn is_block_kind(r: &Row) -> bool {
    matches!(
        r.data_type(),
        DataType::VisibleString
            | DataType::OctetString
            | DataType::UnicodeString
            | DataType::Domain
    )
}

fn addr(r: &Row) -> String {
    format!("{:04X}:{:02X}", r.addr().index, r.addr().sub)
}

fn hex(b: &[u8]) -> String {
    b.iter().map(|b| format!("{b:02x}")).collect()
}

/// The longest value the dictionary takes at `r` (up to 200 bytes), found by writing, and a
/// test value of that length that differs from the current one.
fn test_value(od: &mut dyn ObjectDictionary, r: &Row) -> Option<Vec<u8>> {
    let (i, s) = (r.addr().index, r.addr().sub);
    let mut cur = [0u8; BUF];
    let had = od.read(i, s, &mut cur).ok().map(|n| cur[..n].to_vec());
    let text: Vec<u8> = (0..200u8).map(|k| b'A' + k % 26).collect();
    let n = (1..=200).rev().find(|&n| od.write(i, s, &text[..n]).is_ok())?;
    if let Some(old) = had {
        od.write(i, s, &old).unwrap();
    }
    Some(text[..n].to_vec())
}

/// What serves the SDO requests.
enum Slave {
    /// `sdo::Server` alone, sub-blocks of 4.
    Server(Box<Server<BUF>>),
    /// The node runtime, its server at its defaults.
    Node(Box<Node<BUF>>),
}

/// Counts of one session: values block-uploaded and block-downloaded, and the most frames
/// sent in answer to one received frame (a whole sub-block).
struct Served {
    read: usize,
    written: usize,
    burst: usize,
    /// Bytes of the longest value uploaded.
    longest: usize,
    failures: Vec<String>,
}

/// Serves `dev` to `block_master.py` with `sdo::Server` or, with `through_node`, with
/// `node::Node`.
fn serve(py: &std::path::Path, dev: &Device, through_node: bool) -> Served {
    let mut od = (dev.slave)(NODE);
    let rows: Vec<&Row> = dev.entries.iter().filter(|r| is_block_kind(r)).collect();
    let reads: Vec<String> =
        rows.iter().filter(|r| r.access().readable()).map(|r| addr(r)).collect();
    let mut writes = Vec::new();
    for r in rows.iter().filter(|r| r.access().writable()) {
        if let Some(v) = test_value(od.as_mut(), r) {
            writes.push((**r, v));
        }
    }
    let write_arg: Vec<String> =
        writes.iter().map(|(r, v)| format!("{}={}", addr(r), hex(v))).collect();
    let mut want = std::collections::BTreeMap::new();
    for r in rows.iter().filter(|r| r.access().readable()) {
        let mut b = [0u8; BUF];
        let n = od.read(r.addr().index, r.addr().sub, &mut b).unwrap();
        want.insert(addr(r), hex(&b[..n]));
    }
    let (read_arg, write_arg) = (reads.join(","), write_arg.join(","));
    let mut peer = Peer::start(
        py,
        "block_master.py",
        &["--node", "5", "--read", &read_arg, "--write", &write_arg],
    );
    let mut slave = if through_node {
        let mut node = Box::new(Node::<BUF>::new(NODE));
        let mut boot = Vec::new();
        node.start(od.as_mut(), peer.bus.now(), &mut |f| boot.push(f));
        for f in boot {
            peer.bus.send(&f).unwrap();
        }
        Slave::Node(node)
    } else {
        Slave::Server(Box::new(Server::<BUF>::new(NODE).with_blksize(4)))
    };
    let mut burst = 0;
    let end = Instant::now() + SESSION;
    loop {
        assert!(Instant::now() < end, "{}: session over {SESSION:?}", dev.name);
        let now = peer.bus.now();
        let mut out = Vec::new();
        let received = peer.bus.recv(now + odc::time::Duration::from_millis(20));
        let now = peer.bus.now();
        if let Ok(Some(frame)) = &received {
            match &mut slave {
                Slave::Server(s) => s.handle_into(od.as_mut(), frame, now, &mut |f| out.push(f)),
                Slave::Node(n) => {
                    n.handle(od.as_mut(), frame, now, &mut |f| out.push(f));
                }
            }
            burst = burst.max(out.len());
        }
        match &mut slave {
            Slave::Server(s) => out.extend(s.poll(now)),
            Slave::Node(n) => {
                n.poll(od.as_mut(), now, &mut |f| out.push(f));
            }
        }
        for f in out {
            peer.bus.send(&f).unwrap();
        }
        match received {
            Ok(Some(_)) => {}
            Ok(None) => {
                if peer.exited() {
                    break;
                }
            }
            Err(e) if e.kind() == std::io::ErrorKind::UnexpectedEof => break,
            Err(e) => panic!("{}: {e}", dev.name),
        }
    }
    let (out, _err) = peer.finish(Duration::from_secs(30));
    let report = last_json(&out);
    let mut failures = Vec::new();
    for (a, w) in &want {
        let got = &report["read"][a];
        if got["hex"].as_str() != Some(w.as_str()) {
            failures.push(format!("block upload {a}: got {got}, want {w}"));
        }
    }
    for (r, v) in &writes {
        let a = addr(r);
        if report["written"][&a]["ok"] != Value::Bool(true) {
            failures.push(format!("block download {a}: {}", report["written"][&a]));
            continue;
        }
        let mut b = [0u8; BUF];
        let n = od.read(r.addr().index, r.addr().sub, &mut b).unwrap();
        if &b[..n] != v.as_slice() {
            failures.push(format!(
                "{a} holds {} after the block download of {}",
                hex(&b[..n]),
                hex(v)
            ));
        }
        // Write-only objects cannot be read back; the others must give what was written.
        if r.access().readable() && report["read_back"][&a]["hex"].as_str() != Some(hex(v).as_str())
        {
            failures.push(format!("block upload back {a}: {}", report["read_back"][&a]));
        }
    }
    let longest = want.values().map(|h| h.len() / 2).max().unwrap_or(0);
    Served { read: want.len(), written: writes.len(), burst, longest, failures }
}

#[test]
#[cfg_attr(
    odc_interop_no_python,
    ignore = "needs python3 with canopen and python-can: set ODC_INTEROP_PYTHON (tests/interop/README.md)"
)]
fn our_block_server_their_client() {
    let py = python();
    println!("block transfer: odc sdo::Server, python-canopen SdoClient block_transfer=True");
    println!("{:<22} {:>8} {:>9}", "device", "uploaded", "downloaded");
    let mut failures = Vec::new();
    let mut tested = 0;
    for dev in all_devices() {
        if !dev.entries.iter().any(is_block_kind) {
            println!("{:<22} no string or DOMAIN object", dev.name);
            continue;
        }
        let Served { read, written, failures: f, .. } = serve(&py, &dev, false);
        println!("{:<22} {read:>8} {written:>9}", dev.name);
        tested += usize::from(read + written > 0);
        failures.extend(f.into_iter().map(|f| format!("{}: {f}", dev.name)));
    }
    // lexium_mdrive, servoone, lenze_e94aycca and block_device have string objects.
    assert!(tested >= 4, "string objects tested on {tested} devices");
    assert!(failures.is_empty(), "disagreements with python-canopen:\n{}", failures.join("\n"));
}

#[test]
#[cfg_attr(
    odc_interop_no_python,
    ignore = "needs python3 with canopen and python-can: set ODC_INTEROP_PYTHON (tests/interop/README.md)"
)]
fn block_upload_through_the_node() {
    let py = python();
    println!("block transfer: odc node::Node, python-canopen SdoClient block_transfer=True");
    println!(
        "{:<22} {:>8} {:>9} {:>8} {:>14}",
        "device", "uploaded", "downloaded", "longest", "frames/request"
    );
    let mut failures = Vec::new();
    let mut tested = 0;
    for dev in all_devices() {
        if !dev.entries.iter().any(is_block_kind) {
            println!("{:<22} no string or DOMAIN object", dev.name);
            continue;
        }
        let Served { read, written, burst, longest, failures: f } = serve(&py, &dev, true);
        println!("{:<22} {read:>8} {written:>9} {longest:>8} {burst:>14}", dev.name);
        tested += usize::from(read + written > 0);
        // A value of over 7 bytes takes several segments: all of them go out on
        // python-canopen's one "start upload" (sub-blocks of 127), ceil(n / 7) frames.
        if burst < longest.div_ceil(7) {
            failures.push(format!("{}: {burst} frames per request for {longest} bytes", dev.name));
        }
        failures.extend(f.into_iter().map(|f| format!("{}: {f}", dev.name)));
    }
    assert!(tested >= 4, "string objects tested on {tested} devices");
    assert!(failures.is_empty(), "disagreements with python-canopen:\n{}", failures.join("\n"));
}

#[test]
#[cfg_attr(
    odc_interop_no_python,
    ignore = "needs python3 with canopen and python-can: set ODC_INTEROP_PYTHON (tests/interop/README.md)"
)]
fn our_block_client_their_server() {
    let py = python();
    println!("block transfer: odc sdo::Client, python-canopen LocalNode (no block transfer)");
    println!("{:<22} {:>8} {:>8} {:>14}", "device", "uploaded", "no-def", "dl refused");
    let mut failures = Vec::new();
    for dev in all_devices() {
        let rows: Vec<&Row> = dev.entries.iter().filter(|r| is_block_kind(r)).collect();
        if rows.is_empty() {
            println!("{:<22} no string or DOMAIN object", dev.name);
            continue;
        }
        let path = dev.path.to_str().unwrap();
        let mut peer = Peer::start(&py, "slave.py", &["--eds", path, "--node", "5"]);
        let bus = &mut peer.bus;
        let boot = bus.now() + odc::time::Duration::from_millis(30_000);
        loop {
            match bus.recv(boot).unwrap() {
                Some(f) if f.id() == NODE.error_control().raw() && f.bytes() == [0] => break,
                Some(_) => {}
                None => panic!("{}: no boot-up message from LocalNode", dev.name),
            }
        }
        let reference = (dev.slave)(NODE);
        let mut client =
            Client::<BUF>::new(NODE).with_timeout(odc::time::Duration::from_millis(2000));
        let (mut uploaded, mut no_default, mut refused) = (0, 0, 0);
        for r in rows.iter().filter(|r| r.access().readable()) {
            let (i, s) = (r.addr().index, r.addr().sub);
            let mut want = [0u8; BUF];
            let n = reference.read(i, s, &mut want).unwrap();
            match client.upload_block(bus, i, s) {
                Ok(got) if got == &want[..n] => uploaded += 1,
                // LocalNode has no value for an object without default; an empty one it
                // refuses to upload (README, differences).
                Err(SdoError::Remote(SdoAbort::NoResource)) => no_default += 1,
                Err(SdoError::Remote(SdoAbort::NoData)) if n == 0 => uploaded += 1,
                other => {
                    failures.push(format!("{}: block upload {}: {other:?}", dev.name, addr(r)))
                }
            }
        }
        for r in rows.iter().filter(|r| r.access().writable()) {
            match client.download_block(bus, r.addr().index, r.addr().sub, b"odc block") {
                Err(SdoError::Remote(SdoAbort::InvalidCommand)) => refused += 1,
                other => {
                    failures.push(format!("{}: block download {}: {other:?}", dev.name, addr(r)))
                }
            }
        }
        peer.finish(Duration::from_secs(30));
        println!("{:<22} {uploaded:>8} {no_default:>8} {refused:>14}", dev.name);
    }
    assert!(failures.is_empty(), "disagreements with python-canopen:\n{}", failures.join("\n"));
}
