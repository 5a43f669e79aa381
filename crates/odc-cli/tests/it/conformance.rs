//! `odc conformance` as a process against `odc simulate --tcp` as a process: the summary, the
//! JSON and HTML reports, and the exit codes.
#![allow(clippy::unwrap_used, clippy::expect_used, clippy::panic)]

use std::io::{BufRead, BufReader};
use std::path::{Path, PathBuf};
use std::process::{Child, Command, Output, Stdio};

fn repo(path: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../..").join(path)
}

/// `odc simulate FILE --node-id 5 --tcp 127.0.0.1:0` and the address it listens on.
fn simulate(file: &str) -> (Child, String) {
    let mut sim = Command::new(env!("CARGO_BIN_EXE_odc"))
        .args(["simulate", repo(file).to_str().unwrap(), "--node-id", "5", "--tcp", "127.0.0.1:0"])
        .arg("--stop-on-eof")
        .stdin(Stdio::piped())
        .stdout(Stdio::piped())
        .stderr(Stdio::null())
        .spawn()
        .unwrap();
    let mut first = String::new();
    BufReader::new(sim.stdout.take().unwrap()).read_line(&mut first).unwrap();
    let addr = first.trim().strip_prefix("listening on ").unwrap().to_string();
    (sim, addr)
}

fn odc(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_odc")).args(args).output().unwrap()
}

fn tempdir() -> PathBuf {
    let dir = std::env::temp_dir().join(format!("odc-conformance-cli-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

#[test]
fn reports_and_exit_code_follow_the_checks() {
    let (mut sim, addr) = simulate("eds/lexium-mdrive.eds");
    let dir = tempdir();
    let json = dir.join("report.json");
    let html = dir.join("report.html");
    let eds = repo("eds/lexium-mdrive.eds");
    let run = |report: &Path, groups: &[&str]| {
        let mut args = vec!["conformance", eds.to_str().unwrap(), "--node-id", "5", "--tcp", &addr];
        args.extend(["--report", report.to_str().unwrap()]);
        for g in groups {
            args.extend(["--group", g]);
        }
        odc(&args)
    };
    let out = run(&json, &[]);
    let html_out = run(&html, &["identity", "sdo"]);
    drop(sim.stdin.take());
    sim.wait().unwrap();

    let text = String::from_utf8(out.stdout).unwrap();
    let report: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(&json).unwrap()).unwrap();
    let checks = report["checks"].as_array().unwrap();
    assert!(checks.len() >= 25, "{text}");
    let failed: Vec<&str> = checks
        .iter()
        .filter(|c| c["result"] == "fail")
        .map(|c| c["id"].as_str().unwrap())
        .collect();
    // The summary has a line per check, FAIL for exactly the failed ones.
    for c in checks {
        let id = c["id"].as_str().unwrap();
        let tag = match c["result"].as_str().unwrap() {
            "pass" => "pass",
            "fail" => "FAIL",
            _ => "n/a ",
        };
        assert!(text.lines().any(|l| l.starts_with(&format!("{tag}  {id} "))), "{id}\n{text}");
        assert!(c["clause"].as_str().unwrap().starts_with("CiA "), "{c}");
    }
    // The mandatory identity passes against the simulation of its own file.
    assert_eq!(report["checks"][0]["id"], "identity.device-type");
    assert_eq!(report["checks"][0]["result"], "pass");
    let want = if failed.is_empty() { 0 } else { 1 };
    assert_eq!(out.status.code(), Some(want), "{text}");
    assert_eq!(report["counts"]["fail"].as_u64(), Some(failed.len() as u64));

    let page = std::fs::read_to_string(&html).unwrap();
    assert!(page.starts_with("<!doctype html>") && page.contains("identity.identity-object"));
    assert!(!page.contains("entries.exist"), "only the groups asked for");
    assert!(html_out.status.code().is_some());
}

#[test]
fn usage_and_load_errors_exit_2() {
    let eds = repo("eds/lxm23a.eds");
    let eds = eds.to_str().unwrap();
    // A file its checks refuse (an error-level diagnostic) is a load error, not a failed check.
    let bad = repo("crates/odc-cli/tests/fixtures/bad-value.eds");
    for args in [
        vec!["conformance", bad.to_str().unwrap(), "--node-id", "5", "--tcp", "127.0.0.1:1"],
        vec!["conformance", eds, "--node-id", "0", "--tcp", "127.0.0.1:1"],
        vec!["conformance", eds, "--node-id", "5"],
        vec!["conformance", eds, "--node-id", "5", "--tcp", "127.0.0.1:1", "--group", "nope"],
        vec!["conformance", eds, "--node-id", "5", "--tcp", "127.0.0.1:1", "--report", "r.txt"],
        // Nobody listens on port 1.
        vec!["conformance", eds, "--node-id", "5", "--tcp", "127.0.0.1:1"],
        vec!["conformance", "no-such.eds", "--node-id", "5", "--tcp", "127.0.0.1:1"],
    ] {
        let out = odc(&args);
        assert_eq!(
            out.status.code(),
            Some(2),
            "{args:?}: {}",
            String::from_utf8_lossy(&out.stderr)
        );
    }
}
