//! A candump `-l` log of a CiA 402 session decodes as the live monitor does: `odc monitor
//! --tcp` watches `odc simulate`'s bus while tests/interop/python/record_cia402.py records
//! the same session with python-can's `can.Logger` (CanutilsLogWriter) and drives it with
//! python-canopen; then `odc monitor --log` reads the recording. Without their time columns
//! the log's lines are the live lines, in order.
#![allow(clippy::unwrap_used, clippy::expect_used, clippy::panic)]

use std::io::{BufRead, BufReader, Read};
use std::path::{Path, PathBuf};
use std::process::{Command, Stdio};

fn repo(path: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../..").join(path)
}

/// A monitor line without its time column (the first field).
fn untimed(line: &str) -> String {
    line.trim_start().split_once(' ').map_or("", |(_, rest)| rest).trim_start().to_owned()
}

fn a_recorded_cia402_session_decodes_as_the_live_monitor() {
    let python = PathBuf::from(std::env::var_os("ODC_INTEROP_PYTHON").unwrap_or("python3".into()));
    let eds = repo("eds/lxm23a.eds");
    let node = format!("5={}", eds.display());
    let mut sim = Command::new(env!("CARGO_BIN_EXE_odc"))
        .args(["simulate", eds.to_str().unwrap(), "--node-id", "5", "--tcp", "127.0.0.1:0"])
        .arg("--stop-on-eof")
        .stdin(Stdio::piped())
        .stdout(Stdio::piped())
        .stderr(Stdio::null())
        .spawn()
        .unwrap();
    let mut first = String::new();
    BufReader::new(sim.stdout.take().unwrap()).read_line(&mut first).unwrap();
    let addr = first.trim().strip_prefix("listening on ").unwrap().to_owned();
    let mut live = Command::new(env!("CARGO_BIN_EXE_odc"))
        .args(["monitor", "--tcp", &addr, "--node", &node])
        .stdout(Stdio::piped())
        .stderr(Stdio::inherit())
        .spawn()
        .unwrap();
    // The monitor is on the bus before the session starts (it prints nothing until then).
    std::thread::sleep(std::time::Duration::from_millis(300));
    let dir = std::env::temp_dir().join(format!("odc-monitor-logs-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let log = dir.join("cia402.log");
    let session = Command::new(&python)
        .arg(repo("tests/interop/python/record_cia402.py"))
        .args(["--connect", &addr, "--eds", eds.to_str().unwrap()])
        .arg("--log")
        .arg(&log)
        .env("PYTHONDONTWRITEBYTECODE", "1")
        .output()
        .unwrap();
    assert!(session.status.success(), "{}", String::from_utf8_lossy(&session.stderr));
    // The end of the simulation closes the bus; the live monitor ends with it.
    drop(sim.stdin.take());
    assert!(sim.wait().unwrap().success());
    let mut live_out = String::new();
    live.stdout.take().unwrap().read_to_string(&mut live_out).unwrap();
    assert!(live.wait().unwrap().success());
    let from_log = Command::new(env!("CARGO_BIN_EXE_odc"))
        .args(["monitor", "--node", &node, "--log"])
        .arg(&log)
        .output()
        .unwrap();
    assert!(from_log.status.success(), "{}", String::from_utf8_lossy(&from_log.stderr));
    let live_lines: Vec<String> = live_out.lines().map(untimed).collect();
    let log_lines: Vec<String> =
        String::from_utf8_lossy(&from_log.stdout).lines().map(untimed).collect();
    println!(
        "CiA 402 session: {} frames in the log, {} seen live; {} SDO, {} PDO, {} NMT lines",
        log_lines.len(),
        live_lines.len(),
        log_lines.iter().filter(|l| l.contains("SDO")).count(),
        log_lines.iter().filter(|l| l.contains("PDO")).count(),
        log_lines.iter().filter(|l| l.contains("NMT")).count(),
    );
    assert!(log_lines.len() > 20, "{log_lines:#?}");
    assert!(
        log_lines
            .iter()
            .any(|l| l.contains("Modes of operation") && l.contains("Profile position")),
        "{log_lines:#?}"
    );
    assert_eq!(log_lines, live_lines, "the log's decoding differs from the live monitor's");
    let _ = std::fs::remove_dir_all(&dir);
}

/// The format is told from the content, whatever the file's name; `--log-format` names it;
/// a file no reader knows is a usage error that says how to name the format.
fn the_log_format_is_detected_or_named() {
    let dir = std::env::temp_dir().join(format!("odc-log-format-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let asc = dir.join("session.log");
    std::fs::write(&asc, "date Tue Nov 14 22:13:20 2023\nbase hex  timestamps absolute\n   0.500000 1  185             Rx   d 2 40 06\n").unwrap();
    let odc = |args: &[&str]| Command::new(env!("CARGO_BIN_EXE_odc")).args(args).output().unwrap();
    let path = asc.to_str().unwrap();
    let out = odc(&["monitor", "--log", path]);
    assert_eq!(
        String::from_utf8_lossy(&out.stdout).split_whitespace().collect::<Vec<_>>(),
        ["0.500000", "185", "40", "06", "TPDO1", "node", "5"]
    );
    let out = odc(&["monitor", "--log", path, "--log-format", "asc"]);
    assert!(out.status.success());
    // Read as candump, the ASC lines are errors with their line numbers.
    let out = odc(&["monitor", "--log", path, "--log-format", "candump"]);
    assert_eq!(out.status.code(), Some(1));
    assert!(String::from_utf8_lossy(&out.stderr).contains("session.log:3: error:"), "{out:?}");
    let junk = dir.join("junk.bin");
    std::fs::write(&junk, [0x13u8, 0x37, 0, 1, 2]).unwrap();
    let out = odc(&["monitor", "--log", junk.to_str().unwrap()]);
    assert_eq!(out.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&out.stderr).contains("--log-format"), "{out:?}");
    let _ = std::fs::remove_dir_all(&dir);
}

fn main() -> std::process::ExitCode {
    use odc_tests_support::{Need, Test};
    odc_tests_support::main(&[
        Test {
            name: "a_recorded_cia402_session_decodes_as_the_live_monitor",
            run: a_recorded_cia402_session_decodes_as_the_live_monitor,
            needs: &[Need::Python(&["canopen", "can"])],
        },
        Test {
            name: "the_log_format_is_detected_or_named",
            run: the_log_format_is_detected_or_named,
            needs: &[],
        },
    ])
}
