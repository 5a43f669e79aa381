//! `odc convert` as a user runs it: the output of every shipped device file passes `odc check`
//! as the input did, and a DCF's values are never left out without a word. (Every corpus file:
//! `tests/corpus/tests/it/convert.rs`.)
#![allow(clippy::unwrap_used, clippy::expect_used)] // test helpers: a failure is the test failing

use std::collections::BTreeSet;
use std::path::{Path, PathBuf};
use std::process::{Command, Output};

fn odc(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_odc")).args(args).output().expect("odc runs")
}

fn stderr(out: &Output) -> String {
    String::from_utf8_lossy(&out.stderr).into_owned()
}

/// A fresh directory under cargo's directory for test files.
fn tempdir(name: &str) -> PathBuf {
    let dir = Path::new(env!("CARGO_TARGET_TMPDIR")).join(format!("convert-{name}"));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

/// `odc check --format short` of `path` (with `config` as its overlay): exit code and the codes
/// of its diagnostics, by severity.
fn check(path: &Path, config: Option<&Path>) -> (i32, BTreeSet<String>, BTreeSet<String>) {
    let p = path.display().to_string();
    let mut args = vec!["check", "--format", "short", &p];
    let c = config.map(|c| c.display().to_string());
    if let Some(c) = &c {
        args.extend(["--config", c]);
    }
    let out = odc(&args);
    let text = stderr(&out);
    let codes = |severity: &str| -> BTreeSet<String> {
        text.lines()
            .filter_map(|l| l.split_once(&format!(": {severity}["))?.1.split_once(']'))
            .map(|(code, _)| code.to_owned())
            .collect()
    };
    (out.status.code().unwrap(), codes("error"), codes("warning"))
}

/// The device files the repository ships, with their overlays.
fn shipped() -> Vec<(PathBuf, Option<PathBuf>)> {
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("../..");
    let mut files = Vec::new();
    for dir in ["eds", "esi"] {
        for e in std::fs::read_dir(root.join(dir)).unwrap() {
            let path = e.unwrap().path();
            let name = path.file_name().unwrap().to_string_lossy().into_owned();
            if name.ends_with(".odc.toml") {
                continue;
            }
            let stem = path.file_stem().unwrap().to_string_lossy().into_owned();
            let overlay = path.with_file_name(format!("{stem}.odc.toml"));
            files.push((path, overlay.is_file().then_some(overlay)));
        }
    }
    files.sort();
    files
}

/// Every shipped EDS and ESI, converted to EDS and to DCF, passes `odc check` with the input's
/// overlay, and adds no warning the input did not have but those of CiA 301 rules that do not
/// apply to an EtherCAT device (C406, C407: the output is a CANopen file). Before the writer
/// wrote SubNumber for ESI objects, `esi/servoone.xml` gave 34 × C115.
#[test]
fn shipped_files_convert_to_files_that_pass_check() {
    let dir = tempdir("shipped");
    let files = shipped();
    assert!(files.len() >= 6, "{files:?}");
    for (path, overlay) in &files {
        let (code, errors, warnings) = check(path, overlay.as_deref());
        assert_eq!((code, &errors), (0, &BTreeSet::new()), "{} must pass check", path.display());
        let esi = path.extension().is_some_and(|e| e == "xml");
        for ext in ["eds", "dcf"] {
            let name = format!("{}.{ext}", path.file_name().unwrap().to_string_lossy());
            let out_path = dir.join(name);
            let out = odc(&[
                "convert",
                &path.display().to_string(),
                "-o",
                &out_path.display().to_string(),
            ]);
            assert!(out.status.success(), "{}: {}", path.display(), stderr(&out));
            assert_eq!(stderr(&out), "", "{}: nothing to warn about", path.display());
            let (code, out_errors, out_warnings) = check(&out_path, overlay.as_deref());
            assert_eq!((code, &out_errors), (0, &BTreeSet::new()), "{}", out_path.display());
            let new: Vec<&String> = out_warnings
                .difference(&warnings)
                .filter(|c| !(esi && ["C406", "C407"].contains(&c.as_str())))
                .collect();
            assert!(new.is_empty(), "{}: new warnings {new:?}", out_path.display());
        }
    }
}

/// A DCF: commissioning, two ParameterValue (one of them in a compact `[xxxxValue]` section), a
/// Denotation.
const DCF: &str = "\
[DeviceInfo]
VendorName=odc
ProductName=configured

[DeviceComissioning]
NodeID=5
NodeName=drive
Baudrate=500

[MandatoryObjects]
SupportedObjects=1
1=0x1000

[OptionalObjects]
SupportedObjects=1
1=0x1016

[1000]
ParameterName=Device type
ObjectType=0x7
DataType=0x0007
AccessType=ro
DefaultValue=0x20192
ParameterValue=0x20192
Denotation=axis 1
PDOMapping=0

[1016]
ParameterName=Consumer heartbeat time
ObjectType=0x8
DataType=0x0007
AccessType=rw
DefaultValue=0
PDOMapping=0
CompactSubObj=2

[1016Value]
NrOfEntries=1
2=0x000A03E8
";

/// A file with DCF values stays a DCF unless `--to eds` asks for an EDS; either way the user is
/// told, and nothing is left out without a warning that counts it.
#[test]
fn dcf_values_are_kept_or_counted_in_a_warning() {
    let dir = tempdir("dcf");
    let input = dir.join("configured.dcf");
    std::fs::write(&input, DCF).unwrap();
    let input = input.display().to_string();
    let eds = dir.join("out.eds").display().to_string();
    let dcf = dir.join("out.dcf").display().to_string();
    let kept =
        ["NodeID=5", "ParameterValue=0x20192", "Denotation=axis 1", "[1016Value]", "2=0xA03E8"];
    // `--to eds`: left out, and the warning says how many and how to keep them.
    // The checker's findings on this small file (no 0x1018, no controlword) are not the
    // subject: its groups are allowed, so the gate lets the file through.
    let allow = ["-A", "cia301", "-A", "cia402"];
    let out = odc(&[&["convert", &input, "--to", "eds", "-o", &eds][..], &allow].concat());
    assert!(out.status.success(), "{}", stderr(&out));
    assert_eq!(
        stderr(&out),
        "warning: 6 DCF value(s) not written to the EDS (2 ParameterValue, 1 Denotation, \
         3 [DeviceComissioning] keys); to keep them, write a DCF (leave out --to eds, or --to \
         dcf)\n"
    );
    let text = std::fs::read_to_string(&eds).unwrap();
    for k in kept {
        assert!(!text.contains(k), "{k} in:\n{text}");
    }
    // `-o out.eds` without --to: kept, written as DCF, and said so.
    let out = odc(&[&["convert", &input, "-o", &eds][..], &allow].concat());
    assert!(out.status.success(), "{}", stderr(&out));
    assert_eq!(
        stderr(&out),
        "note: the input holds 6 DCF value(s) (2 ParameterValue, 1 Denotation, \
         3 [DeviceComissioning] keys); written as DCF to keep them (--to eds leaves them out)\n"
    );
    let text = std::fs::read_to_string(&eds).unwrap();
    for k in kept {
        assert!(text.contains(k), "{k} in:\n{text}");
    }
    // To a DCF: kept, nothing to say.
    for args in [vec!["-o", &dcf], vec!["--to", "dcf"]] {
        let mut all = vec!["convert", &input];
        all.extend(args);
        all.extend(allow);
        let out = odc(&all);
        assert!(out.status.success(), "{}", stderr(&out));
        assert_eq!(stderr(&out), "");
    }
    assert_eq!(std::fs::read_to_string(&dcf).unwrap(), text);
}

/// An EtherCAT device whose PDO is longer than a CAN frame's 64 bits is no CANopen device:
/// `convert` to EDS refuses it (exit 1, nothing written) and names the rule; allowed by the
/// rule, it is written, and `check` with the same allowance passes the output.
#[test]
fn esi_device_that_is_no_canopen_device_is_refused_unless_allowed() {
    let dir = tempdir("not-canopen");
    let entry = |sub: u8| {
        format!(
            "<Entry><Index>#x6000</Index><SubIndex>{sub}</SubIndex><BitLen>32</BitLen>\
             <Name>In {sub}</Name><DataType>UDINT</DataType></Entry>"
        )
    };
    let entries: String = (1..=3).map(entry).collect();
    let esi = format!(
        r##"<?xml version="1.0" ?>
<EtherCATInfo>
  <Vendor><Id>2</Id><Name>Wide IO</Name></Vendor>
  <Descriptions><Devices><Device Physics="YY">
    <Type ProductCode="#x1" RevisionNo="#x1">WIDE</Type>
    <Name>Three 32-bit inputs in one PDO</Name>
    <Sm ControlByte="#x00" Enable="1" StartAddress="#x1000">Inputs</Sm>
    <TxPdo Fixed="1" Sm="0"><Index>#x1a00</Index><Name>Inputs</Name>{entries}</TxPdo>
  </Device></Devices></Descriptions>
</EtherCATInfo>"##
    );
    let input = dir.join("wide.xml");
    std::fs::write(&input, esi).unwrap();
    let (input, output) = (input.display().to_string(), dir.join("wide.eds"));
    let out_name = output.display().to_string();

    let refused = odc(&["convert", &input, "-o", &out_name]);
    assert_eq!(refused.status.code(), Some(1), "{}", stderr(&refused));
    let text = stderr(&refused);
    assert!(text.contains("error[C304]: TPDO 0x1A00 maps 96 bits"), "{text}");
    assert!(text.contains("refused: 1 error (C304)") && text.contains("`-A C304`"), "{text}");
    assert!(!output.exists(), "nothing written");

    let allowed = odc(&["convert", &input, "-A", "C304", "-o", &out_name]);
    assert!(allowed.status.success(), "{}", stderr(&allowed));
    let checked = odc(&["check", "-A", "C304", &out_name]);
    assert_eq!(checked.status.code(), Some(0), "{}", stderr(&checked));
    let unallowed = odc(&["check", &out_name]);
    assert!(stderr(&unallowed).contains("error[C304]"), "{}", stderr(&unallowed));
}

/// Every shipped EDS converted to XDD and that XDD back to EDS: both pass `odc check` with the
/// input's overlay with no error and no warning the input did not have (an XDD has no object
/// lists, so C102 is not expected and C101 cannot fire), and what the XDD cannot hold is named
/// in warnings, never dropped without a word.
#[test]
fn shipped_eds_convert_to_xdd_and_back() {
    let dir = tempdir("xdd");
    for (path, overlay) in
        shipped().iter().filter(|(p, _)| p.extension().is_some_and(|e| e == "eds"))
    {
        let (_, _, warnings) = check(path, overlay.as_deref());
        let name = path.file_stem().unwrap().to_string_lossy().into_owned();
        let xdd = dir.join(format!("{name}.xdd"));
        let eds = dir.join(format!("{name}.back.eds"));
        let out = odc(&["convert", &path.display().to_string(), "-o", &xdd.display().to_string()]);
        assert!(out.status.success(), "{}: {}", path.display(), stderr(&out));
        // EDSVersion and the object lists are in every shipped EDS: their loss is said.
        assert!(stderr(&out).contains("EDSVersion"), "{}", stderr(&out));
        let out = odc(&["convert", &xdd.display().to_string(), "-o", &eds.display().to_string()]);
        assert!(out.status.success(), "{}: {}", xdd.display(), stderr(&out));
        for file in [&xdd, &eds] {
            let (code, errors, out_warnings) = check(file, overlay.as_deref());
            assert_eq!((code, &errors), (0, &BTreeSet::new()), "{}", file.display());
            let new: Vec<&String> = out_warnings.difference(&warnings).collect();
            assert!(new.is_empty(), "{}: new warnings {new:?}", file.display());
        }
    }
}
