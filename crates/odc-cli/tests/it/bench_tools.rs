//! `odc sdo`, `odc nmt` and `odc lss` against `odc simulate eds/lxm23a.eds --tcp` on a
//! loopback port: values by name and by index, typed by the file; an abort with its CiA 301
//! meaning (exit 1); a name the file lacks (exit 2, with near matches); NMT; no LSS answer
//! (its file says `LSS_Supported=0`). Then `eds/lexium-mdrive.eds` (`LSS_Supported=1`): LSS
//! inquire and a new node-ID after reset communication. Expected values are the file's defaults (0x1000
//! 0x04020192, 0x1018:01 0x1DD) and CiA 301's abort code 0x06010002.
#![allow(clippy::unwrap_used, clippy::expect_used, clippy::panic)]

use std::io::{BufRead, BufReader};
use std::path::{Path, PathBuf};
use std::process::{Child, Command, Output, Stdio};

fn repo(path: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../..").join(path)
}

fn odc(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_odc")).args(args).output().expect("odc runs")
}

/// `odc simulate FILE --node-id 5 --tcp 127.0.0.1:0`; its address.
fn simulate(file: &str) -> (Child, String) {
    simulate_as(file, "5")
}

/// `odc simulate FILE --node-id ID --tcp 127.0.0.1:0` (255: without node-ID); its address.
fn simulate_as(file: &str, node_id: &str) -> (Child, String) {
    let mut sim = Command::new(env!("CARGO_BIN_EXE_odc"))
        .args(["simulate", repo(file).to_str().unwrap(), "--node-id", node_id])
        .args(["--tcp", "127.0.0.1:0", "--stop-on-eof"])
        .stdin(Stdio::piped())
        .stdout(Stdio::piped())
        .stderr(Stdio::null())
        .spawn()
        .unwrap();
    let mut first = String::new();
    BufReader::new(sim.stdout.take().unwrap()).read_line(&mut first).unwrap();
    let addr = first.trim().strip_prefix("listening on ").unwrap().to_owned();
    (sim, addr)
}

fn text(b: &[u8]) -> String {
    String::from_utf8_lossy(b).into_owned()
}

#[test]
fn sdo_nmt_lss_against_the_simulated_drive() {
    let (mut sim, addr) = simulate("eds/lxm23a.eds");
    let file = repo("eds/lxm23a.eds");
    let node = format!("5={}", file.display());
    let sdo = |op: &str, args: &[&str]| {
        let mut all = vec!["sdo", op, "--node", &node, "--tcp", &addr];
        all.extend_from_slice(args);
        odc(&all)
    };
    let out = sdo("read", &["0x1000"]);
    assert_eq!(out.status.code(), Some(0), "{}", text(&out.stderr));
    assert_eq!(text(&out.stdout), "0x1000:00 Device type = 67240338 (0x4020192)\n");
    let out = sdo("read", &["0x1018:01"]);
    assert_eq!(text(&out.stdout), "0x1018:01 Identity object/Vendor ID = 477 (0x1DD)\n");
    // By name, written and read back; the same object by index.
    let out = sdo("write", &["Profile velocity", "12345"]);
    assert_eq!(out.status.code(), Some(0), "{}", text(&out.stderr));
    assert_eq!(
        text(&sdo("read", &["6081"]).stdout),
        "0x6081:00 Profile velocity = 12345 (0x3039)\n"
    );
    // A value the type cannot hold is refused before anything is sent (UNSIGNED32).
    let out = sdo("write", &["0x6081", "-1"]);
    assert_eq!(out.status.code(), Some(2), "{}", text(&out.stderr));
    // The drive's abort, with its meaning: exit 1.
    let out = sdo("write", &["0x1000", "5"]);
    assert_eq!(out.status.code(), Some(1));
    let err = text(&out.stderr);
    assert!(err.contains("0x06010002") && err.contains("read only"), "{err}");
    // A name the file lacks: a usage error naming the near ones.
    let out = sdo("read", &["profile"]);
    assert_eq!(out.status.code(), Some(2));
    assert!(text(&out.stderr).contains("0x6081 Profile velocity"), "{}", text(&out.stderr));

    // NMT start: the drive leaves pre-operational; SDO still answers.
    let out = odc(&["nmt", "start", "5", "--tcp", &addr]);
    assert_eq!(text(&out.stdout), "000  01 05  NMT Start to node 5\n");
    assert_eq!(sdo("read", &["Statusword"]).status.code(), Some(0));

    // LSS: the LXM23A's file says `LSS_Supported=0`, so the simulated drive does not answer
    // (CiA 306); the Lexium MDrive's says 1.
    let lss = |addr: &str, args: &[&str]| {
        let mut all = vec!["lss"];
        all.extend_from_slice(args);
        all.extend_from_slice(&["--tcp", addr]);
        odc(&all)
    };
    assert_eq!(lss(&addr, &["all"]).status.code(), Some(0));
    let out = lss(&addr, &["inquire"]);
    assert_ne!(out.status.code(), Some(0));
    assert!(text(&out.stderr).contains("no answer"), "{}", text(&out.stderr));
    drop(sim.stdin.take());
    assert!(sim.wait().unwrap().success());

    // Every device into configuration state, who it is (the file's 0x1018 defaults: vendor
    // 0x21B, product 0, revision 0x507, no serial), a new node-ID from the next reset
    // communication.
    let (mut sim, addr) = simulate("eds/lexium-mdrive.eds");
    let file = repo("eds/lexium-mdrive.eds");
    let node = format!("5={}", file.display());
    assert_eq!(lss(&addr, &["all"]).status.code(), Some(0));
    assert_eq!(
        text(&lss(&addr, &["inquire"]).stdout),
        "0x0000021B:0x00000000:0x00000507:0x00000000 node-ID 5\n"
    );
    assert_eq!(lss(&addr, &["set-id", "7"]).status.code(), Some(0));
    assert_eq!(lss(&addr, &["done"]).status.code(), Some(0));
    assert_eq!(odc(&["nmt", "reset-comm", "--tcp", &addr]).status.code(), Some(0));
    std::thread::sleep(std::time::Duration::from_millis(300));
    let at7 = format!("7={}", file.display());
    let out = odc(&["sdo", "read", "--node", &at7, "0x1000", "--tcp", &addr]);
    assert_eq!(out.status.code(), Some(0), "{}", text(&out.stderr));
    // Node 5 is gone: the client's timeout, exit 1, saying that nothing came from node 5.
    let out = odc(&["sdo", "read", "--node", &node, "0x1000", "--tcp", &addr, "--timeout", "200"]);
    assert_eq!(out.status.code(), Some(1));
    let stderr = text(&out.stderr);
    assert!(stderr.contains("nothing at all from node 5 within 200 ms"), "{stderr}");

    drop(sim.stdin.take());
    assert!(sim.wait().unwrap().success());
}

#[test]
fn monitor_reads_a_candump_log_and_a_live_bus() {
    let log = repo("tests/devices/logs/lxm23a.log");
    let node = format!("1={}", repo("eds/lxm23a.eds").display());
    let out = odc(&["monitor", "--log", log.to_str().unwrap(), "--node", &node]);
    assert_eq!(out.status.code(), Some(0), "{}", text(&out.stderr));
    let human = text(&out.stdout);
    // The 92 frames of tests/devices/logs/lxm23a.log: the 94 counted in tests/devices/README.md's
    // LXM23A table less Fig. 33's two heartbeats, whose data byte the print does not give.
    assert_eq!(human.lines().count(), 92);
    assert!(human.contains("Profile acceleration = 2000 (0x7D0)"), "{human}");
    // JSON: one object per frame, with the fields.
    let out =
        odc(&["monitor", "--log", log.to_str().unwrap(), "--node", &node, "--format", "json"]);
    let records: Vec<serde_json::Value> =
        text(&out.stdout).lines().map(|l| serde_json::from_str(l).unwrap()).collect();
    assert_eq!(records.len(), 92);
    // 6.4.1.1's relative move: RPDO2 with the target position, as fields.
    let mv = records
        .iter()
        .find(|r| r["kind"] == "RPDO2" && r["fields"][1]["value"] == "30000")
        .expect("the move's RPDO2");
    assert_eq!(mv["fields"][1]["name"], "Target position");
    assert_eq!(mv["node"], 1);
    // A line that is no candump line: its number, exit 1, the others still decoded.
    let dir = std::env::temp_dir().join(format!("odc-monitor-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let bad = dir.join("bad.log");
    std::fs::write(&bad, "(1.0) can0 701#00\n(2.0) can0 701#0\n(3.0) can0 701#05\n").unwrap();
    let out = odc(&["monitor", "--log", bad.to_str().unwrap()]);
    assert_eq!(out.status.code(), Some(1));
    assert!(text(&out.stderr).contains("bad.log:2: error"), "{}", text(&out.stderr));
    assert_eq!(text(&out.stdout).lines().count(), 2);
    let _ = std::fs::remove_dir_all(&dir);

    // Live, on the simulated drive's bus: an SDO read by another client, decoded.
    let (mut sim, addr) = simulate("eds/lxm23a.eds");
    let at5 = format!("5={}", repo("eds/lxm23a.eds").display());
    let mut monitor = Command::new(env!("CARGO_BIN_EXE_odc"))
        .args(["monitor", "--tcp", &addr, "--node", &at5])
        .stdout(Stdio::piped())
        .stderr(Stdio::null())
        .spawn()
        .unwrap();
    std::thread::sleep(std::time::Duration::from_millis(300));
    let out = odc(&["sdo", "read", "--node", &at5, "0x1000", "--tcp", &addr]);
    assert_eq!(out.status.code(), Some(0));
    std::thread::sleep(std::time::Duration::from_millis(300));
    monitor.kill().unwrap();
    let seen = std::io::read_to_string(monitor.stdout.take().unwrap()).unwrap();
    let _ = monitor.wait();
    assert!(seen.contains("SDO request node 5: read 0x1000:00 Device type"), "{seen}");
    assert!(seen.contains("Device type = 67240338 (0x4020192)"), "{seen}");
    drop(sim.stdin.take());
    let _ = sim.wait();
}

/// `odc sdo` as a user types it: `--tcp localhost:PORT`; a typo answered with the names within
/// a small edit distance; a record's exact name reads each of its sub-objects; an object the
/// node's file lacks read by index, raw (the simulated LXM23A has 0x606B, the Lexium MDrive's
/// file does not).
#[test]
fn sdo_takes_hosts_typos_records_and_unknown_indexes() {
    let (mut sim, addr) = simulate("eds/lxm23a.eds");
    let port = addr.rsplit_once(':').unwrap().1;
    let local = format!("localhost:{port}");
    let node = format!("5={}", repo("eds/lxm23a.eds").display());
    let sdo = |node: &str, object: &str| {
        odc(&["sdo", "read", "--node", node, "--tcp", &local, object, "--timeout", "2000"])
    };
    let out = sdo(&node, "0x1000");
    assert_eq!(out.status.code(), Some(0), "{}", text(&out.stderr));
    assert_eq!(text(&out.stdout), "0x1000:00 Device type = 67240338 (0x4020192)\n");

    let out = sdo(&node, "Profle velocty");
    assert_eq!(out.status.code(), Some(2));
    assert!(
        text(&out.stderr).contains("did you mean one of:\n  0x6081 Profile velocity"),
        "{}",
        text(&out.stderr)
    );

    let out = sdo(&node, "Identity object");
    assert_eq!(out.status.code(), Some(0), "{}", text(&out.stderr));
    let lines = text(&out.stdout);
    assert!(lines.starts_with("0x1018:00 Identity object/"), "{lines}");
    assert!(lines.contains("0x1018:01 Identity object/Vendor ID = 477 (0x1DD)\n"), "{lines}");

    let other = format!("5={}", repo("eds/lexium-mdrive.eds").display());
    let out = sdo(&other, "0x606B");
    assert_eq!(out.status.code(), Some(0), "{}", text(&out.stderr));
    assert!(
        text(&out.stdout).starts_with("0x606B:00 (not in the device file) = ")
            && text(&out.stdout).ends_with(" (raw)\n"),
        "{}",
        text(&out.stdout)
    );

    drop(sim.stdin.take());
    assert!(sim.wait().unwrap().success());
}

/// `odc simulate --node-id 255`: a device without node-ID (CiA 305), as the Lexium MDrive
/// comes. It stays silent (no boot-up); odc's LSS master finds it by fastscan with the
/// identity of its file's 0x1018, gives it node-ID 9, and after reset communication it boots
/// as node 9 and answers SDO there.
#[test]
fn simulate_without_node_id_is_found_by_lss_fastscan() {
    use odc::lss::Identity;
    use odc::master::Master;
    use odc::nmt::NmtCommand;
    let (mut sim, addr) = simulate_as("eds/lxm23a.eds", "255");
    let bus = odc::transport::tcp::TcpCan::connect(addr.as_str()).unwrap();
    let mut m = Master::new(bus).with_timeout(odc::time::Duration::from_millis(1000));
    let mut lss = m.lss().with_timeout(odc::time::Duration::from_millis(50));
    assert!(lss.any_unconfigured().unwrap());
    // eds/lxm23a.eds: vendor 0x1DD, product 0x6000, revision 0x02000001, no serial number.
    let found = lss.fastscan().unwrap();
    assert_eq!(
        found,
        Some(Identity { vendor: 0x1DD, product: 0x6000, revision: 0x0200_0001, serial: 0 })
    );
    assert_eq!(lss.inquire_node_id().unwrap(), None);
    let nine = odc::node_id!(9);
    lss.configure_node_id(Some(nine)).unwrap();
    lss.switch_global(false).unwrap();
    m.nmt_all(NmtCommand::ResetCommunication).unwrap();
    m.wait_boot_up(nine).unwrap();
    assert_eq!(m.upload(nine, 0x1000, 0).unwrap(), 0x0402_0192u32.to_le_bytes());
    drop(m);
    drop(sim.stdin.take());
    assert!(sim.wait().unwrap().success());
}

/// The bench commands on a socketcand server (`odc simulate --socketcand`): NMT, LSS,
/// monitor and conformance (the identity checks) connect with `--socketcand HOST:PORT` as
/// they do with `--tcp`.
#[test]
fn bench_tools_over_socketcand() {
    let file = repo("eds/lexium-mdrive.eds");
    let mut sim = Command::new(env!("CARGO_BIN_EXE_odc"))
        .args(["simulate", &format!("{}@5", file.display())])
        .args(["--socketcand", "127.0.0.1:0", "--stop-on-eof"])
        .stdin(Stdio::piped())
        .stdout(Stdio::piped())
        .stderr(Stdio::null())
        .spawn()
        .unwrap();
    let mut first = String::new();
    BufReader::new(sim.stdout.take().unwrap()).read_line(&mut first).unwrap();
    let addr = first.trim().strip_prefix("listening on ").unwrap().to_owned();
    let node = format!("5={}", file.display());
    let mut monitor = Command::new(env!("CARGO_BIN_EXE_odc"))
        .args(["monitor", "--socketcand", &addr, "--node", &node])
        .stdout(Stdio::piped())
        .stderr(Stdio::null())
        .spawn()
        .unwrap();
    std::thread::sleep(std::time::Duration::from_millis(300));
    let out = odc(&["nmt", "start", "5", "--socketcand", &addr]);
    assert_eq!(text(&out.stdout), "000  01 05  NMT Start to node 5\n", "{}", text(&out.stderr));
    // The Lexium MDrive's file says LSS_Supported=1: the file's 0x1018 defaults.
    assert_eq!(odc(&["lss", "all", "--socketcand", &addr]).status.code(), Some(0));
    let out = odc(&["lss", "inquire", "--socketcand", &addr]);
    assert_eq!(text(&out.stdout), "0x0000021B:0x00000000:0x00000507:0x00000000 node-ID 5\n");
    assert_eq!(odc(&["lss", "done", "--socketcand", &addr]).status.code(), Some(0));
    let eds = file.to_str().unwrap();
    let out =
        odc(&["conformance", eds, "--node-id", "5", "--socketcand", &addr, "--group", "identity"]);
    let summary = text(&out.stdout);
    assert!(summary.lines().any(|l| l.starts_with("pass  identity.device-type ")), "{summary}");
    assert!(!summary.contains("FAIL"), "{summary}");
    std::thread::sleep(std::time::Duration::from_millis(300));
    monitor.kill().unwrap();
    let seen = std::io::read_to_string(monitor.stdout.take().unwrap()).unwrap();
    let _ = monitor.wait();
    assert!(seen.contains("NMT node 5: Start"), "{seen}");
    assert!(seen.contains("SDO request node 5: read 0x1000:00 Device type"), "{seen}");
    drop(sim.stdin.take());
    assert!(sim.wait().unwrap().success());
}
