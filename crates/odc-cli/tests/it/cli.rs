//! The `odc` binary as a user runs it: exit codes, diagnostic positions, atomic output.
#![allow(clippy::unwrap_used, clippy::expect_used)] // test helpers: a failure is the test failing

use std::path::{Path, PathBuf};
use std::process::{Command, Output};

fn odc(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_odc")).args(args).output().expect("odc runs")
}

fn fixture(name: &str) -> String {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/fixtures").join(name).display().to_string()
}

fn repo_file(path: &str) -> String {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../..").join(path).display().to_string()
}

fn stderr(out: &Output) -> String {
    String::from_utf8_lossy(&out.stderr).into_owned()
}

#[test]
fn check_points_at_the_line_and_column_of_a_bad_value() {
    let path = fixture("bad-value.eds");
    let out = odc(&["check", "--format", "short", &path]);
    let text = stderr(&out);
    // `DefaultValue=0x1FF` is line 32; the value starts at column 14. 0x1FF does not fit UNSIGNED8.
    assert!(text.contains(&format!("{path}:32:14: error[F108]")), "{text}");
    assert_eq!(out.status.code(), Some(1), "{text}");
}

#[test]
fn check_human_output_underlines_the_value() {
    let out = odc(&["check", "--color", "never", &fixture("bad-value.eds")]);
    let text = stderr(&out);
    assert!(text.contains("DefaultValue=0x1FF"), "{text}");
    assert!(text.contains("^^^^^"), "{text}");
}

#[test]
fn check_json_is_an_array_with_positions() {
    let out = odc(&["check", "--format", "json", &fixture("bad-value.eds")]);
    let v: serde_json::Value = serde_json::from_slice(&out.stdout).expect("JSON on stdout");
    let bad_value = v.as_array().unwrap().iter().find(|d| d["code"] == "F108").unwrap();
    assert_eq!(bad_value["severity"], "error");
    assert_eq!(bad_value["labels"][0]["line"], 32);
    assert_eq!(bad_value["labels"][0]["column"], 14);
}

#[test]
fn missing_file_is_exit_code_2() {
    let out = odc(&["check", "/nonexistent/odc/file.eds"]);
    assert_eq!(out.status.code(), Some(2));
    assert!(stderr(&out).contains("cannot read"), "{}", stderr(&out));
}

#[test]
fn usage_error_is_exit_code_2() {
    assert_eq!(odc(&["check"]).status.code(), Some(2));
    assert_eq!(odc(&["no-such-command"]).status.code(), Some(2));
}

/// The six device files of the manuals check clean, warnings included: a quirk of a manual is
/// allowed in the `<stem>.odc.toml` beside its file, never by a rule turned off for all.
#[test]
fn shipped_device_files_check_clean_with_their_allowances() {
    let files = [
        "eds/lxm23a.eds",
        "eds/lexium-mdrive.eds",
        "eds/servoone.eds",
        "esi/servoone.xml",
        "eds/lenze-e94aycca.eds",
        "eds/linmot-e1200.eds",
    ];
    for file in files {
        let out = odc(&["check", "--strict", "--format", "short", &repo_file(file)]);
        assert_eq!(out.status.code(), Some(0), "{file}: {}", stderr(&out));
        assert!(!stderr(&out).contains("warning["), "{file}: {}", stderr(&out));
    }
}

#[test]
fn convert_to_dcf_and_back_keeps_the_dictionary() {
    let dir = tempdir();
    let dcf = dir.join("lxm23a.dcf");
    let eds = dir.join("lxm23a.eds");
    let out = odc(&["convert", &repo_file("eds/lxm23a.eds"), "-o", &dcf.display().to_string()]);
    assert!(out.status.success(), "{}", stderr(&out));
    let out = odc(&["convert", &dcf.display().to_string(), "-o", &eds.display().to_string()]);
    assert!(out.status.success(), "{}", stderr(&out));
    let a = odc(&["dump", "--format", "json", &repo_file("eds/lxm23a.eds")]);
    let b = odc(&["dump", "--format", "json", &eds.display().to_string()]);
    let mut a: serde_json::Value = serde_json::from_slice(&a.stdout).unwrap();
    let mut b: serde_json::Value = serde_json::from_slice(&b.stdout).unwrap();
    // Spans and the format differ by construction; the dictionary must not.
    for v in [&mut a, &mut b] {
        strip(v);
    }
    assert_eq!(a["objects"], b["objects"]);
    assert_eq!(a["device_info"], b["device_info"]);
}

#[test]
fn failed_convert_leaves_the_previous_output_untouched() {
    let dir = tempdir();
    let out_path = dir.join("out.eds");
    std::fs::write(&out_path, "previous content").unwrap();
    let garbage = dir.join("garbage.eds");
    std::fs::write(&garbage, "[1000]\nDataType=0x0007\nDefaultValue=not a number\n").unwrap();
    let out =
        odc(&["convert", &garbage.display().to_string(), "-o", &out_path.display().to_string()]);
    assert_ne!(out.status.code(), Some(0));
    assert_eq!(std::fs::read_to_string(&out_path).unwrap(), "previous content");
    let leftovers: Vec<_> =
        std::fs::read_dir(&dir).unwrap().filter_map(|e| e.ok()).map(|e| e.file_name()).collect();
    assert_eq!(leftovers.len(), 2, "no temporary file left behind: {leftovers:?}");
}

#[test]
fn explain_prints_a_rule() {
    let out = odc(&["lints"]);
    assert!(out.status.success());
    let listing = String::from_utf8(out.stdout).unwrap();
    let code = listing.split_whitespace().next().expect("at least one rule");
    let out = odc(&["explain", code]);
    assert!(out.status.success());
    assert!(String::from_utf8(out.stdout).unwrap().starts_with(code));
    assert_eq!(odc(&["explain", "Z999"]).status.code(), Some(2));
}

fn strip(v: &mut serde_json::Value) {
    match v {
        serde_json::Value::Object(map) => {
            map.remove("span");
            map.values_mut().for_each(strip);
        }
        serde_json::Value::Array(items) => items.iter_mut().for_each(strip),
        _ => {}
    }
}

fn tempdir() -> PathBuf {
    use std::sync::atomic::{AtomicU32, Ordering};
    static N: AtomicU32 = AtomicU32::new(0);
    let dir = std::env::temp_dir().join(format!(
        "odc-cli-test-{}-{}",
        std::process::id(),
        N.fetch_add(1, Ordering::Relaxed)
    ));
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

#[test]
fn generate_writes_a_module_with_the_generated_header() {
    let dir = tempdir();
    let out_path = dir.join("lxm23a.rs");
    let out =
        odc(&["generate", &repo_file("eds/lxm23a.eds"), "-o", &out_path.display().to_string()]);
    assert!(out.status.success(), "{}", stderr(&out));
    let text = std::fs::read_to_string(&out_path).unwrap();
    assert!(text.starts_with("// @generated by odc"), "{}", &text[..80]);
    assert!(text.contains("pub mod od"));
    assert!(text.contains("pub mod pdo"));
}

#[test]
fn devices_of_a_many_device_file_are_listed_and_selected() {
    let dir = tempdir();
    let esi = dir.join("two.xml");
    let device = |code: &str, rev: &str, name: &str| {
        format!(
            "<Device><Type ProductCode=\"{code}\" RevisionNo=\"{rev}\">{name}</Type><Name LcId=\"1033\">{name}</Name></Device>"
        )
    };
    std::fs::write(
        &esi,
        format!(
            "<?xml version=\"1.0\"?><EtherCATInfo><Vendor><Id>2</Id><Name>V</Name></Vendor><Descriptions><Devices>{}{}{}</Devices></Descriptions></EtherCATInfo>",
            device("#x10", "#x1", "Alpha"),
            device("#x10", "#x2", "Alpha"),
            device("#x20", "#x1", "Beta")
        ),
    )
    .unwrap();
    let esi = esi.display().to_string();
    let listing = String::from_utf8(odc(&["info", &esi]).stdout).unwrap();
    assert!(listing.starts_with("3 devices:"), "{listing}");
    assert!(listing.contains("0x00000010:0x00000002  Alpha"), "{listing}");
    // Without --device a command that needs one device says which ones there are.
    let out = odc(&["generate", &esi]);
    assert_eq!(out.status.code(), Some(2));
    assert!(stderr(&out).contains("0x00000020:0x00000001  Beta"), "{}", stderr(&out));
    // PRODUCT alone takes the highest revision; PRODUCT:REVISION and names select exactly.
    let info =
        |spec: &str| String::from_utf8(odc(&["info", &esi, "--device", spec]).stdout).unwrap();
    assert!(info("0x10").contains("revision 0x00000002"), "{}", info("0x10"));
    assert!(info("#x10:1").contains("revision 0x00000001"), "{}", info("#x10:1"));
    assert!(info("beta").contains("product 0x00000020"), "{}", info("beta"));
    assert_eq!(odc(&["info", &esi, "--device", "0x30"]).status.code(), Some(2));
}

#[cfg(unix)]
#[test]
fn output_to_a_device_writes_into_it_instead_of_replacing_it() {
    use std::os::unix::fs::FileTypeExt;
    let out = odc(&["generate", &repo_file("eds/lxm23a.eds"), "-o", "/dev/null"]);
    assert!(out.status.success(), "{}", stderr(&out));
    let kind = std::fs::metadata("/dev/null").unwrap().file_type();
    assert!(kind.is_char_device(), "/dev/null was replaced by a {kind:?}");
}

#[cfg(unix)]
#[test]
fn output_through_a_symlink_replaces_the_target_and_keeps_the_link() {
    let dir = tempdir();
    let target = dir.join("real.rs");
    let link = dir.join("link.rs");
    std::fs::write(&target, "old").unwrap();
    std::os::unix::fs::symlink(&target, &link).unwrap();
    let out = odc(&["generate", &repo_file("eds/lxm23a.eds"), "-o", &link.display().to_string()]);
    assert!(out.status.success(), "{}", stderr(&out));
    assert!(std::fs::symlink_metadata(&link).unwrap().file_type().is_symlink());
    assert!(std::fs::read_to_string(&target).unwrap().starts_with("// @generated by odc"));
}

/// The JSON form is an interface: its shape is pinned here (file names as given on the command
/// line, so the test runs in the fixture directory with a relative path).
#[test]
fn check_json_form_is_stable() {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/fixtures");
    let out = Command::new(env!("CARGO_BIN_EXE_odc"))
        .current_dir(&dir)
        .args(["check", "--format", "json", "bad-value.eds"])
        .output()
        .expect("odc runs");
    assert_eq!(out.status.code(), Some(1), "{}", stderr(&out));
    insta::assert_snapshot!(String::from_utf8(out.stdout).unwrap());
}

// ----- exit codes: 0 clean, 1 error-level diagnostics, 2 usage or I/O error -------------------

/// A file whose only problem is a warning (`AccessType=r`) once the CiA 301 rules are allowed.
fn warnings_only(dir: &Path) -> String {
    let path = dir.join("warn.eds");
    std::fs::write(&path, "[1000]\nParameterName=x\nDataType=0x0007\nAccessType=r\n").unwrap();
    path.display().to_string()
}

#[test]
fn exit_0_with_warnings_only() {
    let dir = tempdir();
    let out = odc(&["check", "--format", "short", "-A", "cia301", &warnings_only(&dir)]);
    assert!(stderr(&out).contains("warning[F114]"), "{}", stderr(&out));
    assert_eq!(out.status.code(), Some(0));
    // --strict makes the same warning an error.
    let out = odc(&["check", "--strict", "-A", "cia301", &warnings_only(&dir)]);
    assert_eq!(out.status.code(), Some(1), "{}", stderr(&out));
}

#[test]
fn exit_1_when_a_command_needs_a_model_and_the_file_has_errors() {
    let bad = fixture("bad-value.eds");
    let dir = tempdir();
    let target = dir.join("out.eds").display().to_string();
    for args in [
        vec!["dump", &bad],
        vec!["info", &bad],
        vec!["convert", &bad, "-o", &target],
        vec!["generate", &bad, "-o", &target],
    ] {
        let out = odc(&args);
        assert_eq!(out.status.code(), Some(1), "{args:?}: {}", stderr(&out));
        assert!(stderr(&out).contains("error[F108]"), "{args:?}: {}", stderr(&out));
        assert!(out.stdout.is_empty(), "{args:?}");
    }
    assert!(!dir.join("out.eds").exists());
}

#[test]
fn exit_0_for_commands_on_a_clean_file() {
    let lxm = repo_file("eds/lxm23a.eds");
    for args in [vec!["dump", "--format", "json", &lxm], vec!["info", &lxm], vec!["lints"]] {
        let out = odc(&args);
        assert_eq!(out.status.code(), Some(0), "{args:?}: {}", stderr(&out));
        assert!(!out.stdout.is_empty(), "{args:?}");
    }
}

#[test]
fn exit_2_for_usage_errors() {
    let lxm = repo_file("eds/lxm23a.eds");
    for args in [
        vec!["check", "--no-such-flag", &lxm],
        vec!["check", "--deny", "no-such-rule", &lxm],
        vec!["generate", &lxm, "--role", "neither"],
        vec!["convert", &lxm, "--to", "xml"], // xdd and xdc are targets since issue 20
        vec!["explain"],
    ] {
        let out = odc(&args);
        assert_eq!(out.status.code(), Some(2), "{args:?}: {}", stderr(&out));
        assert!(!stderr(&out).is_empty(), "{args:?}: says why");
    }
}

#[test]
fn exit_2_for_io_errors_and_nothing_written() {
    let dir = tempdir();
    let lxm = repo_file("eds/lxm23a.eds");
    // Output into a directory that does not exist.
    let target = dir.join("no/such/dir/out.dcf").display().to_string();
    let out = odc(&["convert", &lxm, "-o", &target]);
    assert_eq!(out.status.code(), Some(2), "{}", stderr(&out));
    assert!(stderr(&out).contains("cannot write"), "{}", stderr(&out));
    // A directory as input.
    let out = odc(&["check", &dir.display().to_string()]);
    assert_eq!(out.status.code(), Some(2), "{}", stderr(&out));
    assert!(stderr(&out).contains("cannot read"), "{}", stderr(&out));
    assert_eq!(std::fs::read_dir(&dir).unwrap().count(), 0, "nothing written");
}

#[test]
fn help_documents_the_exit_codes() {
    let out = odc(&["--help"]);
    assert_eq!(out.status.code(), Some(0));
    let text = String::from_utf8(out.stdout).unwrap();
    for line in
        ["Exit status:", "  0  no diagnostic at error level", "  1  at least one", "  2  usage"]
    {
        assert!(text.contains(line), "{line}\n{text}");
    }
}

#[test]
fn failed_generate_leaves_the_previous_output_untouched() {
    let dir = tempdir();
    let out_path = dir.join("out.rs");
    std::fs::write(&out_path, "previous module").unwrap();
    let out = odc(&["generate", &fixture("bad-value.eds"), "-o", &out_path.display().to_string()]);
    assert_eq!(out.status.code(), Some(1), "{}", stderr(&out));
    assert_eq!(std::fs::read_to_string(&out_path).unwrap(), "previous module");
    assert_eq!(std::fs::read_dir(&dir).unwrap().count(), 1, "no temporary file left behind");
}

/// Every command that loads a device file takes the rule levels its refusal names (`-A CODE`):
/// the fixture's two errors (C205, F108) allowed, each gets past the gate; without them it
/// is refused (exit 1) with the `-A` advice. Commands that talk to a bus print the file's
/// warnings as one count with the command that shows them, not the warning itself (C407).
#[test]
fn every_loading_command_takes_the_rule_levels() {
    let eds = fixture("bad-value.eds");
    let node = format!("5={eds}");
    let dir = tempdir();
    let dir_s = dir.display().to_string();
    let out_eds = dir.join("out.eds").display().to_string();
    // Port 1 on loopback refuses connections and 192.0.2.1 (TEST-NET-1) is no local address:
    // each bus command fails after loading, with exit 2.
    let commands: Vec<(Vec<&str>, Option<i32>, bool)> = vec![
        (vec!["check", &eds], Some(0), false),
        (vec!["dump", &eds], Some(0), false),
        (vec!["info", &eds], Some(0), false),
        (vec!["doc", &eds, "-o", &dir_s], Some(0), false),
        (vec!["convert", &eds, "-o", &out_eds], Some(0), false),
        (vec!["diff", &eds, &eds], Some(0), false),
        (vec!["monitor", "--node", &node, "--log", "/dev/null"], Some(0), true),
        (vec!["sdo", "read", "--node", &node, "--tcp", "127.0.0.1:1", "0x1000"], Some(2), true),
        (vec!["simulate", &eds, "--node-id", "5", "--tcp", "192.0.2.1:0"], Some(2), true),
    ];
    for (args, code, bus) in commands {
        let mut with = args.clone();
        with.extend(["-A", "C205", "-A", "F108"]);
        let out = odc(&with);
        let err = stderr(&out);
        assert_eq!(out.status.code(), code, "odc {}: {err}", with.join(" "));
        assert!(!err.contains("error["), "odc {}: {err}", with.join(" "));
        if bus {
            let count = format!("1 warning (`odc check {eds}` shows them)");
            assert!(err.contains(&count), "odc {}: {err}", with.join(" "));
            assert!(!err.contains("C407"), "odc {}: {err}", with.join(" "));
        }
        if args[0] == "diff" {
            // diff allows the CiA rules itself: only the format rule is left to refuse.
            continue;
        }
        let out = odc(&args);
        let err = stderr(&out);
        assert_eq!(out.status.code(), Some(1), "odc {}: {err}", args.join(" "));
        // `check` reports; the others refuse and say how to go on.
        let advice = args[0] == "check" || err.contains("`-A C205`");
        assert!(advice, "odc {}: {err}", args.join(" "));
    }
    let out = odc(&["diff", &eds, &eds]);
    assert!(stderr(&out).contains("`-A F108`"), "{}", stderr(&out));
}

/// An I/O error prints its cause once, not `(os error 2): … (os error 2)`.
#[test]
fn io_error_cause_printed_once() {
    let out = odc(&["info", "/nonexistent/odc/file.eds"]);
    let err = stderr(&out);
    assert_eq!(out.status.code(), Some(2));
    assert_eq!(err.matches("(os error 2)").count(), 1, "{err}");
}

/// Standard input as a device file: `-`, and `/dev/stdin` read once (through a pipe, which
/// cannot be read twice).
#[test]
fn info_reads_standard_input_once() {
    use std::io::Write;
    use std::process::Stdio;
    let eds = std::fs::read(repo_file("eds/lxm23a.eds")).unwrap();
    for file in ["-", "/dev/stdin"] {
        let mut child = Command::new(env!("CARGO_BIN_EXE_odc"))
            .args(["info", file])
            .stdin(Stdio::piped())
            .stdout(Stdio::piped())
            .stderr(Stdio::piped())
            .spawn()
            .unwrap();
        child.stdin.take().unwrap().write_all(&eds).unwrap();
        let out = child.wait_with_output().unwrap();
        let text = String::from_utf8_lossy(&out.stdout);
        assert_eq!(out.status.code(), Some(0), "{file}: {}", stderr(&out));
        assert!(text.starts_with("LXM23A ("), "{file}: {text}");
        assert!(text.contains("98 objects"), "{file}: {text}");
    }
}

/// A file that is not well-formed XML is refused without advice to allow the rule that says
/// so (`-A F202` would only hide what was lost).
#[test]
fn malformed_xml_is_not_advised_around() {
    let dir = tempdir();
    let path = dir.join("broken.xml");
    std::fs::write(&path, "<EtherCATInfo><Vendor>").unwrap();
    let out = odc(&["dump", &path.display().to_string()]);
    let err = stderr(&out);
    assert_eq!(out.status.code(), Some(1), "{err}");
    assert!(err.contains("F202"), "{err}");
    assert!(!err.contains("-A F202") && !err.contains("allow"), "{err}");
    assert!(err.contains("cannot be read as a device description"), "{err}");
}

/// `--color auto` follows the conventions: `CLICOLOR_FORCE` colours output that is no
/// terminal, and `NO_COLOR` wins over it.
#[test]
fn no_color_is_honoured() {
    let run = |vars: &[(&str, &str)]| {
        let mut cmd = Command::new(env!("CARGO_BIN_EXE_odc"));
        cmd.args(["check", &fixture("bad-value.eds")]);
        for k in ["NO_COLOR", "CLICOLOR", "CLICOLOR_FORCE"] {
            cmd.env_remove(k);
        }
        for (k, v) in vars {
            cmd.env(k, v);
        }
        stderr(&cmd.output().unwrap())
    };
    assert!(run(&[("CLICOLOR_FORCE", "1")]).contains("\x1b["));
    assert!(!run(&[("CLICOLOR_FORCE", "1"), ("NO_COLOR", "1")]).contains("\x1b["));
    assert!(!run(&[]).contains("\x1b["), "a pipe is no terminal");
}

/// Shell completions and a manual page, from the command's own definition.
#[test]
fn completions_and_man_page() {
    let out = odc(&["completions", "bash"]);
    assert_eq!(out.status.code(), Some(0));
    let bash = String::from_utf8_lossy(&out.stdout);
    assert!(bash.contains("_odc()") && bash.contains("simulate") && bash.contains("--stop-on-eof"));
    let out = odc(&["completions", "zsh"]);
    assert!(String::from_utf8_lossy(&out.stdout).starts_with("#compdef odc"));
    let out = odc(&["man"]);
    assert_eq!(out.status.code(), Some(0));
    let page = String::from_utf8_lossy(&out.stdout);
    assert!(page.contains(".TH odc 1"), "{page}");
    assert!(page.contains("simulate"), "{page}");
}

/// The monitor without a device file shows an SDO answer's address once, and with one names
/// the CiA 402 modes of operation (0x6060/0x6061) as it names controlword and statusword.
#[test]
fn monitor_addresses_once_and_names_modes() {
    let dir = tempdir();
    let log = dir.join("sdo.log");
    std::fs::write(
        &log,
        "(1.0) can0 605#4000100000000000\n(1.1) can0 585#4300100092010400\n\
         (1.2) can0 605#2F60600001000000\n(1.3) can0 585#6060600000000000\n",
    )
    .unwrap();
    let out = odc(&["monitor", "--log", &log.display().to_string()]);
    let text = String::from_utf8_lossy(&out.stdout).into_owned();
    let answer = text.lines().nth(1).unwrap();
    assert!(answer.ends_with("read answer 0x1000:00 = 92 01 04 00"), "{answer}");
    let node = format!("5={}", repo_file("eds/lxm23a.eds"));
    let out = odc(&["monitor", "--log", &log.display().to_string(), "--node", &node]);
    let text = String::from_utf8_lossy(&out.stdout).into_owned();
    assert!(
        text.contains(
            "write confirmed 0x6060:00 Modes of operation = 1 (Profile position mode (pp))"
        ),
        "{text}"
    );
}

/// README's first command writes where git ignores it (`target/`), so trying it leaves no
/// untracked file in the repository.
#[test]
fn readme_first_command_writes_under_target() {
    let readme = std::fs::read_to_string(repo_file("README.md")).unwrap();
    let first = readme
        .lines()
        .find(|l| l.starts_with("cargo run -p odc-cli -- "))
        .expect("README starts with a cargo run line");
    let output = first
        .split_whitespace()
        .skip_while(|w| *w != "-o")
        .nth(1)
        .unwrap_or_else(|| panic!("no -o in {first}"));
    let ignore = std::fs::read_to_string(repo_file(".gitignore")).unwrap();
    assert!(ignore.lines().any(|l| l == "/target"), "target/ is no longer ignored");
    assert!(output.starts_with("target/"), "README's first command writes {output}");
}
