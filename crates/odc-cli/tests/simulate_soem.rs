//! SOEM (PyPI `pysoem`), the most used open EtherCAT master, against `odc simulate FILE.xml
//! --interface IFACE` over a veth pair whose master end is in a network namespace the test
//! makes (and removes): tests/interop/python/soem_master.py finds the devices, maps the
//! process data, reaches OP, reads, writes and aborts over CoE and exchanges process data;
//! this test decides on what it reports. Expected values are the ESI's and CiA 402's.
#![allow(clippy::unwrap_used, clippy::expect_used, clippy::panic)]

use std::io::{BufRead, BufReader, Write};
use std::path::{Path, PathBuf};
use std::process::{Command, Stdio};
use std::time::{Duration, Instant};

use serde_json::{Value, json};

fn repo(path: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../..").join(path)
}

fn ip(args: &[&str]) {
    let out = Command::new("ip").args(args).output().expect("ip (iproute2) runs");
    assert!(out.status.success(), "ip {args:?}: {}", String::from_utf8_lossy(&out.stderr));
}

/// A network namespace with one end of a veth pair in it (the master's), the other end
/// (the devices') in this namespace; both removed on drop.
struct Wire {
    netns: String,
    devices: String,
    master: String,
}

impl Wire {
    fn new() -> Wire {
        let id = std::process::id() % 100_000;
        let wire = Wire {
            netns: format!("odcsoem{id}"),
            devices: format!("odcs{id}d"),
            master: format!("odcs{id}m"),
        };
        ip(&["netns", "add", &wire.netns]);
        ip(&["link", "add", &wire.devices, "type", "veth", "peer", "name", &wire.master]);
        ip(&["link", "set", &wire.master, "netns", &wire.netns]);
        ip(&["link", "set", &wire.devices, "up"]);
        ip(&["netns", "exec", &wire.netns, "ip", "link", "set", &wire.master, "up"]);
        wire
    }
}

impl Drop for Wire {
    fn drop(&mut self) {
        let _ = Command::new("ip").args(["link", "del", &self.devices]).status();
        let _ = Command::new("ip").args(["netns", "del", &self.netns]).status();
    }
}

/// `program` under SCHED_FIFO where the machine allows it (`chrt`, root): SOEM gives a datagram
/// 2 ms to come back (EC_TIMEOUTRET), as a real device answers in microseconds; a simulated
/// device that a loaded machine does not schedule in time would make SOEM give up on it.
fn realtime(program: &str) -> Command {
    let allowed =
        Command::new("chrt").args(["-f", "10", "true"]).status().is_ok_and(|s| s.success());
    if allowed {
        let mut c = Command::new("chrt");
        c.args(["-f", "10", program]);
        c
    } else {
        Command::new(program)
    }
}

/// A PDO mapping value (ETG.1000.6: index << 16 | sub << 8 | bits), as SDO download data.
fn entry(index: u16, sub: u8, bits: u8) -> String {
    let v = u32::from(index) << 16 | u32::from(sub) << 8 | u32::from(bits);
    hex(&v.to_le_bytes())
}

fn hex(bytes: &[u8]) -> String {
    bytes.iter().map(|b| format!("{b:02x}")).collect()
}

/// The SDO writes of a configuration tool that maps `entries` into the PDO `pdo` and
/// assigns it alone to the sync manager's assignment object `assign` (ETG.1020 order:
/// clear, fill, count).
fn map(assign: u16, pdo: u16, entries: &[(u16, u8, u8)]) -> Vec<Value> {
    let mut w = vec![json!([assign, 0, "00"]), json!([pdo, 0, "00"])];
    for (k, &(index, sub, bits)) in entries.iter().enumerate() {
        w.push(json!([pdo, k + 1, entry(index, sub, bits)]));
    }
    w.push(json!([pdo, 0, hex(&[entries.len() as u8])]));
    w.push(json!([assign, 1, hex(&pdo.to_le_bytes())]));
    w.push(json!([assign, 0, "01"]));
    w
}

#[test]
#[cfg_attr(
    odc_cli_no_soem,
    ignore = "needs pysoem (ODC_INTEROP_PYTHON), root and iproute2 for a veth pair in a network namespace (ODC_NET_REQUIRED)"
)]
fn soem_finds_maps_and_runs_the_servoone() {
    let python = PathBuf::from(std::env::var_os("ODC_INTEROP_PYTHON").unwrap_or("python3".into()));
    let wire = Wire::new();
    let esi = repo("esi/servoone.xml");
    let mut sim = realtime(env!("CARGO_BIN_EXE_odc"))
        .args(["simulate", esi.to_str().unwrap(), "--interface", &wire.devices])
        .stdin(Stdio::piped())
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    let mut first = String::new();
    BufReader::new(sim.stdout.take().unwrap()).read_line(&mut first).unwrap();
    assert_eq!(first.trim(), format!("serving 1 devices on {}", wire.devices));

    // The ServoOne assigns no PDO (manual 8.3): SOEM's configuration callback maps cyclic
    // synchronous position, controlword + target position out, statusword + position in.
    let mut writes = map(0x1C12, 0x1600, &[(0x6040, 0, 16), (0x607A, 0, 32)]);
    writes.extend(map(0x1C13, 0x1A00, &[(0x6041, 0, 16), (0x6064, 0, 32)]));
    let plan = json!({
        "iface": wire.master,
        "cycles": 1000,
        "devices": [{
            "preop_writes": writes,
            "reads": [[0x1000, 0], [0x1018, 1], [0x6502, 0]],
            "writes": [[0x6060, 0, "08"], [0x607A, 0, hex(&1000i32.to_le_bytes())]],
            "aborts": [[0x1234, 0, null], [0x1000, 0, "00000000"], [0x1018, 9, null]],
            // Controlword 0x0006, shutdown; target position 1000.
            "outputs": hex(&[0x06, 0x00, 0xE8, 0x03, 0x00, 0x00]),
        }],
    });
    let mut master = Command::new("ip")
        .args(["netns", "exec", &wire.netns])
        .arg(&python)
        .arg(repo("tests/interop/python/soem_master.py"))
        .stdin(Stdio::piped())
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    master.stdin.take().unwrap().write_all(plan.to_string().as_bytes()).unwrap();
    // A watchdog: SOEM's own timeouts are seconds; two minutes is a hang.
    let deadline = Instant::now() + Duration::from_secs(120);
    while master.try_wait().unwrap().is_none() {
        if Instant::now() > deadline {
            let _ = master.kill();
            let _ = sim.kill();
            panic!("soem_master.py did not finish in 120 s");
        }
        std::thread::sleep(Duration::from_millis(50));
    }
    let out = master.wait_with_output().unwrap();
    drop(sim.stdin.take());
    let sim_out = sim.wait_with_output().unwrap();
    let sim_err = String::from_utf8_lossy(&sim_out.stderr);
    let stdout = String::from_utf8_lossy(&out.stdout);
    let report: Value =
        stdout.lines().last().and_then(|l| serde_json::from_str(l).ok()).unwrap_or_else(|| {
            panic!("no report: {stdout}\n{}\n{sim_err}", String::from_utf8_lossy(&out.stderr))
        });
    println!("SOEM: {report}\nodc simulate: {sim_err}");
    assert_eq!(report["errors"], json!([]), "{report}");
    assert_eq!(report["found"], 1);
    let dev = &report["devices"][0];
    // The ESI's identity (esi/servoone.xml: vendor, product and revision 0, as the manual
    // gives none) and name, read by SOEM from the SII.
    assert_eq!(
        (&dev["vendor"], &dev["product"], &dev["revision"]),
        (&json!(0), &json!(0), &json!(0))
    );
    assert_eq!(dev["name"], "ServoOne");
    // config_map: 6 bytes each way (INTEGER16/UNSIGNED16 + INTEGER32, CiA 402).
    assert_eq!((&dev["outputs_len"], &dev["inputs_len"]), (&json!(6), &json!(6)));
    assert_eq!(report["io_map_size"], 12);
    assert_eq!((&report["safe_op"], &report["op"]), (&json!(true), &json!(true)));
    // 0x1000 = 0x00020192 (the ESI's default), 0x1018:1 = 0, 0x6502 supported modes.
    let reads = &dev["reads"];
    assert_eq!(reads[0], json!([0x1000, 0, "92010200"]));
    assert_eq!(reads[1], json!([0x1018, 1, "00000000"]));
    assert_eq!(reads[2][2].as_str().unwrap().len(), 8, "0x6502 is UNSIGNED32");
    assert_eq!(dev["written"], json!([[0x6060, 0, "08"], [0x607A, 0, "e8030000"]]));
    // CiA 301 / ETG.1000.6 abort codes: no object, read-only, no sub-index.
    assert_eq!(
        dev["aborts"],
        json!([
            [0x1234, 0, 0x0602_0000u32],
            [0x1000, 0, 0x0601_0002u32],
            [0x1018, 9, 0x0609_0011u32]
        ])
    );
    // 1,000 cycles whose frame came back, each with the working counter SOEM expects (LRW:
    // 3 for one device with outputs and inputs); frames that did not come back within 20 ms
    // (a loaded machine) are repeated and reported.
    assert_eq!(report["expected_wkc"], 3);
    assert_eq!(report["cycles_with_expected_wkc"], 1000);
    assert_eq!(report["cycles_with_other_wkc"], json!([]));
    println!("frames lost: {}", report["frames_lost"]);
    // After "shutdown" the drive is "ready to switch on": statusword xxxx xxxx x01x 0001
    // (CiA 402 Table 30), and the position input is there.
    let inputs = hex_bytes(dev["inputs"].as_str().unwrap());
    let statusword = u16::from_le_bytes([inputs[0], inputs[1]]);
    assert_eq!(statusword & 0x6F, 0x21, "statusword {statusword:#06x}");
    assert!(sim_err.contains("frames"), "{sim_err}");
}

fn hex_bytes(s: &str) -> Vec<u8> {
    (0..s.len()).step_by(2).map(|i| u8::from_str_radix(&s[i..i + 2], 16).unwrap()).collect()
}
