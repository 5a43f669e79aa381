//! One error gate for every command: a file is refused when, after its overlay and the
//! command-line levels, a diagnostic is at error level; warnings never stop a command.
#![allow(clippy::unwrap_used, clippy::expect_used)] // test helpers: a failure is the test failing

use std::path::{Path, PathBuf};
use std::process::{Command, Output};

fn odc(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_odc")).args(args).output().expect("odc runs")
}

fn stderr(out: &Output) -> String {
    String::from_utf8_lossy(&out.stderr).into_owned()
}

/// A fresh directory for one test.
fn scratch(name: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("odc-gate-{name}-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

/// The Lexium MDrive's EDS with its first TPDO mapping the statusword replaced by an object
/// the file does not define: C301, an error of the checker (not of the front-end).
fn c301_file(dir: &Path) -> String {
    let repo = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../eds/lexium-mdrive.eds");
    let text = std::fs::read_to_string(repo).unwrap();
    let broken = text.replacen("DefaultValue=0x60410010", "DefaultValue=0x2FFF0010", 1);
    assert_ne!(text, broken);
    let path = dir.join("mdrive.eds");
    std::fs::write(&path, broken).unwrap();
    path.display().to_string()
}

/// Each command that reads a device file, writing its output into `dir`.
fn commands(file: &str, dir: &Path) -> Vec<Vec<String>> {
    let out = |name: &str| dir.join(name).display().to_string();
    vec![
        vec!["check".to_string(), file.to_string()],
        vec!["generate".into(), file.into(), "-o".into(), out("x.rs")],
        vec!["info".into(), file.into()],
        vec!["dump".into(), file.into()],
        vec!["convert".into(), file.into(), "-o".into(), out("x.dcf")],
        vec!["doc".into(), file.into(), "-o".into(), out("doc")],
    ]
}

fn run(cmd: &[String], extra: &[&str]) -> Output {
    let mut args: Vec<&str> = cmd.iter().map(String::as_str).collect();
    args.extend_from_slice(extra);
    odc(&args)
}

#[test]
fn a_checker_error_refuses_every_command_and_allowing_it_lets_each_go_on() {
    let dir = scratch("c301");
    let file = c301_file(&dir);
    for cmd in commands(&file, &dir) {
        let out = run(&cmd, &[]);
        let text = stderr(&out);
        assert_eq!(out.status.code(), Some(1), "{cmd:?}: {text}");
        assert!(text.contains("error[C301]"), "{cmd:?}: {text}");
        if cmd[0] != "check" {
            // The one-line way on: which code, and the two places to allow it.
            let last = text.lines().last().unwrap_or("");
            assert!(last.contains("refused: 1 error (C301)"), "{cmd:?}: {last}");
            assert!(last.contains("-A C301"), "{cmd:?}: {last}");
            assert!(last.contains("mdrive.odc.toml"), "{cmd:?}: {last}");
        }
        let out = run(&cmd, &["-A", "C301"]);
        assert_eq!(out.status.code(), Some(0), "{cmd:?} -A C301: {}", stderr(&out));
        // As a warning it is printed and does not stop the command.
        let out = run(&cmd, &["-W", "C301"]);
        assert_eq!(out.status.code(), Some(0), "{cmd:?} -W C301: {}", stderr(&out));
        assert!(stderr(&out).contains("warning[C301]"), "{cmd:?}");
    }
    assert!(dir.join("x.rs").is_file() && dir.join("x.dcf").is_file());
    assert!(dir.join("doc/mdrive.html").is_file() && dir.join("doc/mdrive.md").is_file());
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn the_overlay_beside_the_file_sets_the_levels_of_every_command() {
    let dir = scratch("overlay");
    let file = c301_file(&dir);
    std::fs::write(dir.join("mdrive.odc.toml"), "[rules]\nC301 = \"allow\"\n").unwrap();
    for cmd in commands(&file, &dir) {
        let out = run(&cmd, &[]);
        assert_eq!(out.status.code(), Some(0), "{cmd:?}: {}", stderr(&out));
        // --config replaces the overlay's checker settings.
        let empty = dir.join("empty.toml");
        std::fs::write(&empty, "").unwrap();
        let out = run(&cmd, &["--config", empty.to_str().unwrap()]);
        assert_eq!(out.status.code(), Some(1), "{cmd:?} --config: {}", stderr(&out));
        // The command line beats the overlay, and --strict turns the warning into an error.
        let out = run(&cmd, &["-W", "C301"]);
        assert_eq!(out.status.code(), Some(0), "{cmd:?} -W: {}", stderr(&out));
        let out = run(&cmd, &["-W", "C301", "--strict"]);
        let text = stderr(&out);
        assert_eq!(out.status.code(), Some(1), "{cmd:?} --strict: {text}");
    }
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn an_allowed_value_error_is_left_out_of_generated_code() {
    let file = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/fixtures/bad-value.eds");
    let file = file.to_str().unwrap();
    let dir = scratch("value");
    let rs = dir.join("bad-value.rs");
    let args = ["generate", file, "-A", "cia301", "-o", rs.to_str().unwrap()];
    let out = odc(&args);
    assert_eq!(out.status.code(), Some(1), "{}", stderr(&out));
    assert!(stderr(&out).contains("-A F108"), "{}", stderr(&out));
    let out = odc(&[&args[..], &["-W", "F108"]].concat());
    let text = stderr(&out);
    assert_eq!(out.status.code(), Some(0), "{text}");
    assert!(text.contains("warning[F108]: `0x1FF` does not fit UNSIGNED8"), "{text}");
    let code = std::fs::read_to_string(&rs).unwrap();
    // The value is named in the object's documentation (as the file spells it, the one
    // value_text), and nowhere used.
    assert!(code.contains("Default: `0x1FF` (not a value of the type; not used)"), "{code}");
    assert!(!code.contains("0x1FF,") && !code.contains("511"), "{code}");
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn generate_and_check_say_in_one_line_what_they_did() {
    let lxm = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../eds/lxm23a.eds");
    let out = odc(&["check", lxm.to_str().unwrap()]);
    let text = stderr(&out);
    assert_eq!(out.status.code(), Some(0), "{text}");
    assert_eq!(text.trim_end(), format!("{}: 0 errors, 0 warnings", lxm.display()));
    let dir = scratch("oneline");
    let rs = dir.join("lxm23a.rs");
    let out = odc(&["generate", lxm.to_str().unwrap(), "-o", rs.to_str().unwrap()]);
    assert_eq!(stderr(&out).trim_end(), format!("wrote {}: 98 objects, 8 PDOs", rs.display()));
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn a_level_for_an_unknown_rule_is_a_usage_error() {
    let lxm = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../eds/lxm23a.eds");
    let out = odc(&["generate", lxm.to_str().unwrap(), "-A", "no-such-rule"]);
    assert_eq!(out.status.code(), Some(2));
    assert!(stderr(&out).contains("unknown rule or group `no-such-rule`"), "{}", stderr(&out));
}

#[test]
fn explain_and_lints_know_every_code_of_every_stage() {
    for code in ["F108", "F201", "C301", "D502", "T601", "G604", "S701"] {
        let out = odc(&["explain", code]);
        assert_eq!(out.status.code(), Some(0), "{code}: {}", stderr(&out));
        assert!(String::from_utf8_lossy(&out.stdout).starts_with(code), "{code}");
    }
    let lints = String::from_utf8_lossy(&odc(&["lints"]).stdout).into_owned();
    for code in ["F101", "F201", "C101", "D501", "T601", "G601", "G605", "S702"] {
        assert!(lints.lines().any(|l| l.starts_with(code)), "{code} not listed");
    }
    // A front-end code's level is set like a checker rule's.
    let lxm = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../eds/lxm23a.eds");
    assert_eq!(odc(&["check", lxm.to_str().unwrap(), "-D", "F130"]).status.code(), Some(0));
}
