//! `--slcan`: the simulated device behind an slcan adapter (`odc simulate --slcan pty`),
//! driven by python-can's own `slcan` interface with python-canopen (SDO, NMT, PDO: the
//! scripts of tests/interop/python with `--connect slcan:PATH`), and read by `odc sdo
//! --slcan` (odc on both ends); and `--slcan DEVICE` on a pseudo-terminal the test makes,
//! with the test as the host on the other end.
//!
//! Design: `odc simulate --slcan pty` makes the pseudo-terminal and prints its path, as
//! `--tcp 127.0.0.1:0` prints its address, and keeps that end open itself, so hosts come and
//! go (each `odc sdo` opens and closes the path). No relay, no socat.
#![allow(clippy::unwrap_used, clippy::expect_used, clippy::panic)]

use std::io::{BufRead, BufReader, Read, Write};
use std::path::{Path, PathBuf};
use std::process::{Child, Command, Stdio};
use std::time::Duration;

fn repo(path: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../..").join(path)
}

fn python() -> PathBuf {
    PathBuf::from(std::env::var_os("ODC_INTEROP_PYTHON").unwrap_or("python3".into()))
}

/// `odc simulate FILE --node-id 5 --slcan SPEC --stop-on-eof`, and the first line it prints.
fn simulate(file: &str, spec: &str) -> (Child, String) {
    let mut sim = Command::new(env!("CARGO_BIN_EXE_odc"))
        .args(["simulate", repo(file).to_str().unwrap(), "--node-id", "5", "--slcan", spec])
        .arg("--stop-on-eof")
        .stdin(Stdio::piped())
        .stdout(Stdio::piped())
        .stderr(Stdio::inherit())
        .spawn()
        .unwrap();
    let mut first = String::new();
    if spec == "pty" {
        BufReader::new(sim.stdout.take().unwrap()).read_line(&mut first).unwrap();
    }
    (sim, first)
}

/// Stops a simulation by closing its standard input; it must exit 0.
fn stop(mut sim: Child) {
    drop(sim.stdin.take());
    let status = sim.wait().unwrap();
    assert!(status.success(), "odc simulate exited with {status}");
}

/// The path `odc simulate --slcan pty` printed.
fn pty_path(first: &str) -> &str {
    first.trim().strip_prefix("listening on ").unwrap_or_else(|| panic!("{first:?}"))
}

/// A script of tests/interop/python against the simulated device, through python-can's
/// `slcan` interface; its last JSON line.
fn python_session(file: &str, script: &str, args: &[&str]) -> serde_json::Value {
    let (sim, first) = simulate(file, "pty");
    let path = pty_path(&first);
    let eds = repo(file);
    let out = Command::new(python())
        .arg(repo(&format!("tests/interop/python/{script}")))
        .args(["--connect", &format!("slcan:{path}"), "--eds", eds.to_str().unwrap()])
        .args(["--node", "5"])
        .args(args)
        .env("PYTHONDONTWRITEBYTECODE", "1")
        .output()
        .unwrap();
    stop(sim);
    let stdout = String::from_utf8_lossy(&out.stdout);
    assert!(
        out.status.success(),
        "{file}: {script} over slcan failed:\n{}\n{stdout}",
        String::from_utf8_lossy(&out.stderr)
    );
    odc_tests_interop::last_json(&stdout)
}

fn python_can_slcan_masters_the_simulated_device() {
    let file = "eds/lxm23a.eds";
    let r = python_session(file, "master.py", &["--boot-up", "--max-seconds", "200"]);
    let n = |k: &str| r[k].as_u64().unwrap_or(0);
    println!(
        "{file} over slcan: boot-up {}, read {}, written {}, aborts {}, PDO maps compared {}",
        r["boot_up"],
        n("read"),
        n("written"),
        n("aborts"),
        n("pdo_compared")
    );
    assert_eq!(r["boot_up"], true, "no boot-up after NMT reset node over slcan");
    assert!(n("read") > 50 && n("written") > 20 && n("pdo_compared") > 0, "{r}");
    // As over --tcp (tests/simulate.rs): only the running drive's statusword differs from
    // the file's default.
    for d in r["disagreements"].as_array().unwrap() {
        assert!(d["addr"] == "0x6041:00" && d["kind"] == "read differs from default", "{d}");
    }
}

fn python_can_slcan_drives_the_simulated_node() {
    use odc_tests_interop::node_report::check;
    let file = "eds/lxm23a.eds";
    let r = python_session(file, "node.py", &[]);
    println!(
        "{file} over slcan: boot-ups {}, heartbeats {} at {} ms, type 1 {}/10 SYNCs, \
         remap {}, guarding {}",
        r["bootups"],
        r["heartbeat_preop"],
        r["heartbeat_period_ms"],
        r["type1_per_10_syncs"],
        r["remap_lengths"],
        r["guarding_answers"],
    );
    let bad = check(&r, None);
    assert!(bad.is_empty(), "{file} over slcan: {}", bad.join("; "));
}

fn odc_sdo_and_nmt_over_slcan() {
    let file = "eds/lxm23a.eds";
    let (sim, first) = simulate(file, "pty");
    let path = pty_path(&first);
    let node = format!("5={}", repo(file).display());
    let odc = |args: &[&str]| Command::new(env!("CARGO_BIN_EXE_odc")).args(args).output().unwrap();
    // Hosts come and go on the same path; with and without a bit rate.
    for spec in [format!("{path}@500k"), path.to_owned(), format!("{path}@125000")] {
        let read = odc(&["sdo", "read", "--node", &node, "--slcan", &spec, "0x1000"]);
        assert_eq!(
            String::from_utf8_lossy(&read.stdout),
            "0x1000:00 Device type = 67240338 (0x4020192)\n",
            "{spec}: {}",
            String::from_utf8_lossy(&read.stderr)
        );
    }
    let write = odc(&["sdo", "write", "--node", &node, "--slcan", path, "0x6060", "1"]);
    assert!(write.status.success(), "{}", String::from_utf8_lossy(&write.stderr));
    let read = odc(&["sdo", "read", "--node", &node, "--slcan", path, "0x6060"]);
    assert!(String::from_utf8_lossy(&read.stdout).trim_end().ends_with("= 1"), "{read:?}");
    let nmt = odc(&["nmt", "--slcan", path, "start", "5"]);
    assert!(nmt.status.success(), "{}", String::from_utf8_lossy(&nmt.stderr));
    // A bit rate slcan has no Sn for is an error before the port is touched.
    let bad = odc(&["sdo", "read", "--node", &node, "--slcan", &format!("{path}@83300"), "0x1000"]);
    assert_eq!(bad.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&bad.stderr).contains("no slcan bit rate"), "{bad:?}");
    stop(sim);
}

/// `--slcan DEVICE`: the adapter on a pseudo-terminal end the test made; the test is the
/// host on the other end and writes the protocol's bytes itself.
fn simulate_is_the_adapter_on_a_given_port() {
    use serialport::{SerialPort, TTYPort};
    let (mut host, device_end) = TTYPort::pair().unwrap();
    let path = device_end.name().unwrap();
    // odc opens the path itself; the test keeps its handle (never read) so that the host end
    // has a peer from the start (a pty's master cannot be written with no slave open).
    let (sim, _) = simulate("eds/lxm23a.eds", &path);
    host.set_timeout(Duration::from_millis(200)).unwrap();
    let mut seen = Vec::new();
    let read_until = |host: &mut TTYPort, want: &[u8], seen: &mut Vec<u8>| {
        let deadline = std::time::Instant::now() + Duration::from_secs(10);
        while !seen.windows(want.len()).any(|w| w == want) {
            assert!(std::time::Instant::now() < deadline, "no {want:?} in {seen:?}");
            let mut buf = [0u8; 256];
            if let Ok(n) = host.read(&mut buf) {
                seen.extend_from_slice(&buf[..n]);
            }
        }
    };
    // Version, then open at 500 kbit/s; then an SDO upload of 0x1000 (CiA 301 7.2.4.3.3):
    // the device type 0x04020192 comes back as an expedited 4-byte answer on 0x585.
    host.write_all(b"V\rS6\rO\r").unwrap();
    read_until(&mut host, b"V1010\r\r\r", &mut seen);
    host.write_all(b"t60584000100000000000\r").unwrap();
    read_until(&mut host, b"t58584300100092010204\r", &mut seen);
    // The transmit was acknowledged (`z`) before the answer came.
    let text = String::from_utf8_lossy(&seen);
    assert!(text.contains("z\r"), "{text:?}");
    host.write_all(b"C\r").unwrap();
    stop(sim);
    drop(device_end);
}

fn main() -> std::process::ExitCode {
    use odc_tests_support::{Need, Test};
    odc_tests_support::main(&[
        Test {
            name: "python_can_slcan_masters_the_simulated_device",
            run: python_can_slcan_masters_the_simulated_device,
            needs: &[Need::Python(&["canopen", "can", "serial"])],
        },
        Test {
            name: "python_can_slcan_drives_the_simulated_node",
            run: python_can_slcan_drives_the_simulated_node,
            needs: &[Need::Python(&["canopen", "can", "serial"])],
        },
        Test { name: "odc_sdo_and_nmt_over_slcan", run: odc_sdo_and_nmt_over_slcan, needs: &[] },
        Test {
            name: "simulate_is_the_adapter_on_a_given_port",
            run: simulate_is_the_adapter_on_a_given_port,
            needs: &[],
        },
    ])
}
