//! `odc simulate --tcp` as a process, with python-canopen as the master over the virtual bus
//! (tests/interop/python/master.py through socketbus.py): it resets the node and sees the
//! boot-up, uploads every readable object and compares it with the file's default, downloads
//! to every writable one and reads it back, checks limits, read-only, write-only and missing
//! objects, and saves PDO mappings, all over SDO; and with tests/interop/python/node.py, the
//! node's services (NMT, heartbeat, PDOs, EMCY, guarding).
#![allow(clippy::unwrap_used, clippy::expect_used, clippy::panic)]

use std::io::{BufRead, BufReader};
use std::path::{Path, PathBuf};
use std::process::{Command, Stdio};

fn repo(path: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../..").join(path)
}

/// Runs master.py against `odc simulate FILE --node-id 5 --tcp 127.0.0.1:0`; returns the
/// script's JSON report.
fn session(python: &Path, file: &str) -> serde_json::Value {
    run(python, file, "master.py", &["--boot-up", "--max-seconds", "200"])
}

/// Runs a python script of tests/interop as a client of `odc simulate FILE --node-id 5 --tcp
/// 127.0.0.1:0`; returns the last JSON line it prints.
fn run(python: &Path, file: &str, script: &str, args: &[&str]) -> serde_json::Value {
    let eds = repo(file);
    let mut sim = Command::new(env!("CARGO_BIN_EXE_odc"))
        .args(["simulate", eds.to_str().unwrap(), "--node-id", "5", "--tcp", "127.0.0.1:0"])
        .arg("--stop-on-eof")
        .stdin(Stdio::piped())
        .stdout(Stdio::piped())
        .stderr(Stdio::inherit())
        .spawn()
        .unwrap();
    let mut first = String::new();
    BufReader::new(sim.stdout.take().unwrap()).read_line(&mut first).unwrap();
    let addr = first.trim().strip_prefix("listening on ").unwrap_or_else(|| panic!("{first:?}"));
    let master = Command::new(python)
        .arg(repo(&format!("tests/interop/python/{script}")))
        .args(["--connect", addr, "--eds", eds.to_str().unwrap(), "--node", "5"])
        .args(args)
        .env("PYTHONDONTWRITEBYTECODE", "1")
        .output()
        .unwrap();
    // The end of standard input stops the simulation.
    drop(sim.stdin.take());
    let status = sim.wait().unwrap();
    let out = String::from_utf8_lossy(&master.stdout);
    assert!(
        master.status.success(),
        "{file}: {script} failed:\n{}\n{out}",
        String::from_utf8_lossy(&master.stderr)
    );
    assert!(status.success(), "{file}: odc simulate exited with {status}");
    odc_tests_interop::last_json(&out)
}

fn python_canopen_masters_the_simulated_device() {
    let python = PathBuf::from(std::env::var_os("ODC_INTEROP_PYTHON").unwrap_or("python3".into()));
    for file in ["eds/lxm23a.eds", "eds/lexium-mdrive.eds", "eds/linmot-e1200.eds"] {
        let r = session(&python, file);
        let n = |k: &str| r[k].as_u64().unwrap_or(0);
        println!(
            "{file}: boot-up {}, read {}, written {}, aborts {} {}, PDO maps compared {}, saved {}",
            r["boot_up"],
            n("read"),
            n("written"),
            n("aborts"),
            r["abort_codes"],
            n("pdo_compared"),
            r["saved"].as_array().map_or(0, Vec::len)
        );
        assert_eq!(r["boot_up"], true, "{file}: no boot-up after NMT reset node");
        assert!(n("read") > 50 && n("written") > 20, "{file}: {r}");
        // A running drive sets its statusword: after the boot-up it is "switch on disabled"
        // (0x40 under mask 0x6F, CiA 402), not the file's default. Nothing else may differ.
        for d in r["disagreements"].as_array().unwrap() {
            let is_statusword =
                d["addr"] == "0x6041:00" && d["kind"] == "read differs from default";
            assert!(is_statusword, "{file}: {d}");
            let got = u16::from_str_radix(d["got"].as_str().unwrap(), 16).unwrap().swap_bytes();
            assert_eq!(got & 0x6F, 0x40, "{file}: statusword {got:#06x}");
        }
    }
}

/// The node test of tests/interop (NMT, heartbeat, TPDO types 1/5/254, a remap, an RPDO,
/// EMCY 0x8210, node guarding) through the CLI: python-canopen's checks of what it sees on the
/// bus, as `tests/interop/tests/it/node.rs` makes them of a node it runs itself.
fn python_canopen_drives_the_simulated_node() {
    use odc_tests_interop::node_report::{check, int};
    let python = PathBuf::from(std::env::var_os("ODC_INTEROP_PYTHON").unwrap_or("python3".into()));
    let mut failures = Vec::new();
    for file in ["eds/lxm23a.eds", "eds/lexium-mdrive.eds", "eds/servoone.eds"] {
        let r = run(&python, file, "node.py", &[]);
        println!(
            "{file}: boot-ups {}, heartbeats {} at {} ms, type 1 {}/10 SYNCs, type 5 {}/20, \
             type 254 {}/s, remap {}, EMCY {:04X}, guarding {}",
            r["bootups"],
            r["heartbeat_preop"],
            r["heartbeat_period_ms"],
            r["type1_per_10_syncs"],
            r["type5_per_20_syncs"],
            r["type254_50ms_per_second"],
            r["remap_lengths"],
            int(&r["emcy"]["code"]),
            r["guarding_answers"],
        );
        let bad = check(&r, None);
        if !bad.is_empty() {
            failures.push(format!("{file}: {}", bad.join("; ")));
        }
    }
    assert!(failures.is_empty(), "{}", failures.join("\n"));
}

/// `--can IFACE` on a machine without that interface (no `vcan0` here) is a usage error that
/// names it; where `vcan0` exists, the device runs on it until the end of standard input
/// (`--stop-on-eof`).
fn can_on_a_missing_interface_is_a_clear_error() {
    let out = Command::new(env!("CARGO_BIN_EXE_odc"))
        .args(["simulate", repo("eds/lxm23a.eds").to_str().unwrap(), "--node-id", "5"])
        .args(["--can", "vcan0", "--stop-on-eof"])
        .stdin(Stdio::null())
        .output()
        .unwrap();
    let err = String::from_utf8_lossy(&out.stderr);
    if Path::new("/sys/class/net/vcan0").exists() {
        assert_eq!(out.status.code(), Some(0), "{err}");
        assert!(err.contains("on vcan0"), "{err}");
    } else {
        assert_eq!(out.status.code(), Some(2), "{err}");
        assert!(
            err.contains("--can vcan0: cannot open") || err.contains("without SocketCAN"),
            "{err}"
        );
    }
}

fn node_id_must_be_1_to_127() {
    let out = Command::new(env!("CARGO_BIN_EXE_odc"))
        .args(["simulate", repo("eds/lxm23a.eds").to_str().unwrap(), "--node-id", "128"])
        .args(["--tcp", "127.0.0.1:0"])
        .stdin(Stdio::null())
        .output()
        .unwrap();
    assert_eq!(out.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&out.stderr).contains("128"));
}

/// `odc simulate` is a server: with standard input /dev/null (nohup, systemd, CI) it keeps
/// serving until SIGTERM, and a closed standard output and error (`… 2>&1 | head`) do not end
/// it with a panic (exit 101): it answers SDO after both are closed and after client events
/// it logs, and exits 0 at SIGTERM.
fn simulate_serves_until_sigterm_without_stdin_or_output() {
    use std::time::{Duration, Instant};
    let eds = repo("eds/lxm23a.eds");
    let mut sim = Command::new(env!("CARGO_BIN_EXE_odc"))
        .args(["simulate", eds.to_str().unwrap(), "--node-id", "5", "--tcp", "127.0.0.1:0"])
        .stdin(Stdio::null())
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    let mut out = BufReader::new(sim.stdout.take().unwrap());
    let mut first = String::new();
    out.read_line(&mut first).unwrap();
    let addr = first.trim().strip_prefix("listening on ").unwrap_or_else(|| panic!("{first:?}"));
    // Both of its output pipes closed, as `head` closes them when it has its lines.
    drop(out);
    drop(sim.stderr.take());
    std::thread::sleep(Duration::from_millis(300));
    assert!(sim.try_wait().unwrap().is_none(), "odc simulate stopped with stdin /dev/null");
    let node = format!("5={}", eds.display());
    for _ in 0..3 {
        // Each client connects and leaves: events the simulation logs to its closed stderr.
        let read = Command::new(env!("CARGO_BIN_EXE_odc"))
            .args(["sdo", "read", "--node", &node, "--tcp", addr, "0x1000"])
            .output()
            .unwrap();
        assert_eq!(
            String::from_utf8_lossy(&read.stdout),
            "0x1000:00 Device type = 67240338 (0x4020192)\n",
            "{}",
            String::from_utf8_lossy(&read.stderr)
        );
    }
    assert!(sim.try_wait().unwrap().is_none(), "odc simulate stopped before SIGTERM");
    let kill = Command::new("kill").args(["-TERM", &sim.id().to_string()]).status().unwrap();
    assert!(kill.success());
    let deadline = Instant::now() + Duration::from_secs(10);
    let status = loop {
        if let Some(status) = sim.try_wait().unwrap() {
            break status;
        }
        if Instant::now() > deadline {
            let _ = sim.kill();
            panic!("odc simulate did not stop within 10 s of SIGTERM");
        }
        std::thread::sleep(Duration::from_millis(20));
    };
    assert_eq!(status.code(), Some(0), "odc simulate at SIGTERM: {status}");
}

/// `--interface` on an interface that is down says so and how to bring it up, not
/// "Unexpected poll event". Needs a veth pair (root, iproute2); skipped visibly without.
fn interface_down_is_a_clear_error() {
    let name = format!("odcd{}", std::process::id() % 100_000);
    let peer = format!("{name}p");
    let made = Command::new("ip")
        .args(["link", "add", &name, "type", "veth", "peer", "name", &peer])
        .stderr(Stdio::null())
        .status()
        .is_ok_and(|s| s.success());
    if !made {
        println!("skipped: cannot make a veth pair here (needs root and iproute2)");
        return;
    }
    let out = Command::new(env!("CARGO_BIN_EXE_odc"))
        .args(["simulate", repo("esi/servoone.xml").to_str().unwrap(), "--interface", &name])
        .stdin(Stdio::null())
        .output()
        .unwrap();
    let _ = Command::new("ip").args(["link", "del", &name]).status();
    let err = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(2), "{err}");
    assert!(err.contains(&format!("--interface {name}: the interface is down")), "{err}");
    assert!(err.contains(&format!("ip link set {name} up")), "{err}");
}

/// Starts `odc simulate ARGS --stop-on-eof` and reads its `listening on HOST:PORT` line.
fn spawn_simulate(args: &[&str]) -> (std::process::Child, String) {
    let mut sim = Command::new(env!("CARGO_BIN_EXE_odc"))
        .arg("simulate")
        .args(args)
        .arg("--stop-on-eof")
        .stdin(Stdio::piped())
        .stdout(Stdio::piped())
        .stderr(Stdio::inherit())
        .spawn()
        .unwrap();
    let mut first = String::new();
    BufReader::new(sim.stdout.take().unwrap()).read_line(&mut first).unwrap();
    let addr = first.trim().strip_prefix("listening on ").unwrap_or_else(|| panic!("{first:?}"));
    (sim, addr.to_owned())
}

/// Ends a simulation started by [`spawn_simulate`] (end of its standard input) and checks
/// that it exits 0.
fn stop_simulate(mut sim: std::process::Child) {
    drop(sim.stdin.take());
    let status = sim.wait().unwrap();
    assert!(status.success(), "odc simulate exited with {status}");
}

/// Three drives of different shipped files on one bus (`FILE@ID`), driven by python-canopen
/// (tests/interop/python/multinode.py) over the records wire (`--tcp`, socketbus.py) and over
/// python-can's own `socketcand` interface (`--socketcand`): NMT to all and every boot-up,
/// SDO to each against its file, heartbeats of all three in operational and stopped, and a
/// TPDO of each after one SYNC against an SDO upload of the mapped object.
fn python_canopen_drives_three_nodes_on_one_bus() {
    let python = odc_tests_support::python();
    let nodes = [(5, "eds/lxm23a.eds"), (9, "eds/lexium-mdrive.eds"), (12, "eds/servoone.eds")];
    let files: Vec<String> =
        nodes.iter().map(|(id, f)| format!("{}@{id}", repo(f).display())).collect();
    for wire in ["tcp", "socketcand"] {
        let mut args: Vec<&str> = files.iter().map(String::as_str).collect();
        let flag = format!("--{wire}");
        args.extend([flag.as_str(), "127.0.0.1:0"]);
        let (sim, addr) = spawn_simulate(&args);
        let mut master = Command::new(&python);
        master
            .arg(repo("tests/interop/python/multinode.py"))
            .args(["--connect", &addr, "--bus", wire])
            .env("PYTHONDONTWRITEBYTECODE", "1");
        for (id, f) in nodes {
            master.args(["--node", &format!("{id}={}", repo(f).display())]);
        }
        let out = master.output().unwrap();
        stop_simulate(sim);
        let stdout = String::from_utf8_lossy(&out.stdout);
        assert!(
            out.status.success(),
            "{wire}: multinode.py failed:\n{}\n{stdout}",
            String::from_utf8_lossy(&out.stderr)
        );
        let r = odc_tests_interop::last_json(&stdout);
        assert_eq!(r["errors"], serde_json::json!([]), "{wire}: {r}");
        for (id, file) in nodes {
            let n = &r["nodes"][id.to_string()];
            println!(
                "{wire}: node {id} ({file}): boot-up {}, heartbeats in 1.05 s operational {}, \
                 TPDO {} of {} (SDO {}), stopped {}",
                n["boot_up"],
                n["heartbeats_operational"],
                n["tpdo"],
                n["tpdo_object"],
                n["tpdo_sdo"],
                n["stopped"]
            );
            assert_eq!(n["boot_up"], true, "{wire} node {id}: {n}");
            assert_eq!(n["device_type"], n["device_type_in_file"], "{wire} node {id}: {n}");
            assert_eq!(n["vendor_id"], n["vendor_id_in_file"], "{wire} node {id}: {n}");
            assert_eq!(n["heartbeat_ms"], 100, "{wire} node {id}: {n}");
            // 100 ms heartbeats for 1.05 s: 10 or 11 (one at the change to operational), a
            // little more or less where the machine is busy and the window runs long or short.
            let beats = n["heartbeats_operational"].as_u64().unwrap();
            assert!((9..=13).contains(&beats), "{wire} node {id}: {beats} heartbeats");
            assert!(n["tpdo"].is_string(), "{wire} node {id}: no TPDO after SYNC: {n}");
            assert_eq!(n["tpdo"], n["tpdo_sdo"], "{wire} node {id}: {n}");
            assert_eq!(n["stopped"], true, "{wire} node {id}: {n}");
        }
    }
}

/// `odc sdo --socketcand` reads the devices of `odc simulate --socketcand` (bus `can0` by
/// default, or named: `/CHANNEL`); a bus the server does not serve is a clear error.
fn sdo_reads_over_socketcand() {
    let lxm = repo("eds/lxm23a.eds");
    let lenze = repo("eds/lenze-e94aycca.eds");
    let args = [lxm.to_str().unwrap(), "--node-id", "5", lenze.to_str().unwrap(), "--node-id", "9"];
    let (sim, addr) = spawn_simulate(&[&args[..], &["--socketcand", "127.0.0.1:0/vcan3"]].concat());
    let sdo = |node: &str, bus: &str| {
        Command::new(env!("CARGO_BIN_EXE_odc"))
            .args(["sdo", "read", "--node", node, "--socketcand", bus, "0x1000"])
            .output()
            .unwrap()
    };
    let read = sdo(&format!("5={}", lxm.display()), &format!("{addr}/vcan3"));
    assert_eq!(
        String::from_utf8_lossy(&read.stdout),
        "0x1000:00 Device type = 67240338 (0x4020192)\n",
        "{}",
        String::from_utf8_lossy(&read.stderr)
    );
    let read = sdo(&format!("9={}", lenze.display()), &format!("{addr}/vcan3"));
    // 0x1000 of eds/lenze-e94aycca.eds: 0 (the file's DefaultValue).
    assert_eq!(
        String::from_utf8_lossy(&read.stdout),
        "0x1000:00 Device type = 0 (0x0)\n",
        "{}",
        String::from_utf8_lossy(&read.stderr)
    );
    // No channel: can0, which this server does not serve.
    let refused = sdo(&format!("5={}", lxm.display()), &addr);
    let err = String::from_utf8_lossy(&refused.stderr);
    assert_ne!(refused.status.code(), Some(0), "{err}");
    assert!(err.contains("cannot open bus can0"), "{err}");
    assert!(err.contains("< error could not open bus >"), "{err}");
    stop_simulate(sim);
}

/// Two files on one node-ID, and a file without a node-ID, are usage errors that name them.
fn node_ids_of_several_files() {
    let lxm = repo("eds/lxm23a.eds");
    let lenze = repo("eds/lenze-e94aycca.eds");
    let run = |args: &[&str]| {
        let out = Command::new(env!("CARGO_BIN_EXE_odc"))
            .arg("simulate")
            .args(args)
            .args(["--tcp", "127.0.0.1:0"])
            .stdin(Stdio::null())
            .output()
            .unwrap();
        (out.status.code(), String::from_utf8_lossy(&out.stderr).into_owned())
    };
    let a = format!("{}@7", lxm.display());
    let (code, err) = run(&[&a, lenze.to_str().unwrap(), "--node-id", "7"]);
    assert_eq!(code, Some(2), "{err}");
    assert!(err.contains("node-ID 7 is given to both"), "{err}");
    let (code, err) = run(&[lxm.to_str().unwrap(), "--node-id", "7", lenze.to_str().unwrap()]);
    assert_eq!(code, Some(2), "{err}");
    assert!(err.contains("lenze-e94aycca.eds: no node-ID"), "{err}");
}

/// A PDO entry whose object the ESI's dictionary lacks is named when the file is loaded,
/// with the AL status code the device will answer at SAFE-OP (#31). The interface does not
/// exist: the load comes first, then the usage error.
fn a_mapped_object_missing_from_the_dictionary_is_named_at_load() {
    let esi = std::fs::read_to_string(repo("esi/servoone.xml")).unwrap();
    let pdo = "<Name>TxPDO 1 (factory mapping empty)</Name>";
    assert!(esi.contains(pdo));
    let entry = "<Entry><Index>#x5FFF</Index><SubIndex>0</SubIndex><BitLen>16</BitLen>\
                 <Name>Missing</Name><DataType>UINT</DataType></Entry>";
    let path = std::env::temp_dir().join(format!("odc-unmapped-{}.xml", std::process::id()));
    std::fs::write(&path, esi.replacen(pdo, &format!("{pdo}{entry}"), 1)).unwrap();
    let out = Command::new(env!("CARGO_BIN_EXE_odc"))
        .args(["simulate", path.to_str().unwrap(), "--interface", "odc-no-such0"])
        .stdin(Stdio::null())
        .output()
        .unwrap();
    let _ = std::fs::remove_file(&path);
    let err = String::from_utf8_lossy(&out.stderr);
    assert_ne!(out.status.code(), Some(0), "{err}");
    assert!(
        err.contains(
            "PDO 0x1A00 maps 0x5FFF:00, which the dictionary does not have: SAFE-OP is refused \
             with AL status 0x0024 (invalid input mapping) while it is assigned"
        ),
        "{err}"
    );
}

/// The tests, with what each needs of the machine (odc_tests_support: ignored with the reason
/// where a need is missing).
fn main() -> std::process::ExitCode {
    #[allow(unused_imports)]
    use odc_tests_support::{Need, Test};
    odc_tests_support::main(&[
        Test {
            name: "python_canopen_masters_the_simulated_device",
            run: python_canopen_masters_the_simulated_device,
            needs: &[Need::Python(&["canopen", "can"])],
        },
        Test {
            name: "python_canopen_drives_the_simulated_node",
            run: python_canopen_drives_the_simulated_node,
            needs: &[Need::Python(&["canopen", "can"])],
        },
        Test {
            name: "can_on_a_missing_interface_is_a_clear_error",
            run: can_on_a_missing_interface_is_a_clear_error,
            needs: &[],
        },
        Test { name: "node_id_must_be_1_to_127", run: node_id_must_be_1_to_127, needs: &[] },
        Test {
            name: "python_canopen_drives_three_nodes_on_one_bus",
            run: python_canopen_drives_three_nodes_on_one_bus,
            needs: &[Need::Python(&["canopen", "can"])],
        },
        Test { name: "sdo_reads_over_socketcand", run: sdo_reads_over_socketcand, needs: &[] },
        Test { name: "node_ids_of_several_files", run: node_ids_of_several_files, needs: &[] },
        Test {
            name: "simulate_serves_until_sigterm_without_stdin_or_output",
            run: simulate_serves_until_sigterm_without_stdin_or_output,
            needs: &[],
        },
        Test {
            name: "a_mapped_object_missing_from_the_dictionary_is_named_at_load",
            run: a_mapped_object_missing_from_the_dictionary_is_named_at_load,
            needs: &[],
        },
        Test {
            name: "interface_down_is_a_clear_error",
            run: interface_down_is_a_clear_error,
            needs: &[Need::Netdevs],
        },
    ])
}
