//! `odc_monitor::log` on files other tools wrote: python-can's `can.Logger` (candump `-l`
//! through CanutilsLogWriter, ASC, BLF) and scapy (pcap, pcapng, link type 227), from
//! tests/write_logs.py; and can-utils' `log2long` (candump's screen lines) and `log2asc`
//! where can-utils is installed (`.ci/run` installs it; `candump` itself needs a CAN
//! interface and is not used). Each file must give back FRAMES: the format detected from the
//! content, every frame, and the times.
#![allow(clippy::unwrap_used, clippy::expect_used, clippy::panic)]

use std::path::{Path, PathBuf};
use std::process::{Command, Stdio};

use odc::can::CanFrame;
use odc_monitor::log::{self, FdFrame, Format, Frame};

/// The frames of write_logs.py, seconds after 1 700 000 000.
fn frames() -> Vec<(f64, Frame)> {
    let can = |id, data: &[u8]| Frame::Can(CanFrame::from_slice(id, data).unwrap());
    vec![
        (0.0, can(0x185, &[0x40, 0x06])),
        (0.1, Frame::Can(CanFrame::remote(0x701, 1).unwrap())),
        (0.2, Frame::Can(CanFrame::extended(0x1234_5678, &[1, 2]).unwrap())),
        (
            0.3,
            Frame::Fd(FdFrame {
                id: 0x123,
                extended: false,
                brs: true,
                esi: false,
                data: (0..12).collect(),
            }),
        ),
        (0.4, can(0x7FF, &[])),
        (0.5, can(0x605, &[0x40, 0x00, 0x10, 0, 0, 0, 0, 0])),
    ]
}

const T0: f64 = 1_700_000_000.0;

fn python() -> PathBuf {
    PathBuf::from(std::env::var_os("ODC_INTEROP_PYTHON").unwrap_or("python3".into()))
}

fn tempdir(name: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("odc-logs-{name}-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

/// Reads `path`, checks its detected format and its frames; `absolute`: the times count
/// from 1970 (else from the first frame); `remote_len`: the length the file keeps for the
/// remote frame.
fn check(path: &Path, format: Format, absolute: bool, remote_len: u8) {
    let bytes = std::fs::read(path).unwrap();
    assert_eq!(log::detect(&bytes), Some(format), "{}", path.display());
    let read = log::read(&bytes, format);
    assert_eq!(read.problems, [], "{}", path.display());
    let mut want = frames();
    want[1].1 = Frame::Can(CanFrame::remote(0x701, remote_len).unwrap());
    let got: Vec<&Frame> = read.entries.iter().map(|e| &e.frame).collect();
    let want_frames: Vec<&Frame> = want.iter().map(|(_, f)| f).collect();
    assert_eq!(got, want_frames, "{}", path.display());
    for (entry, (t, _)) in read.entries.iter().zip(&want) {
        let time = entry.time.unwrap();
        let expected = if absolute { T0 + t } else { *t };
        assert!((time - expected).abs() < 1e-3, "{}: time {time}, want {expected}", path.display());
    }
    println!(
        "{}: {} frames ({})",
        path.file_name().unwrap().to_string_lossy(),
        got.len(),
        format.name()
    );
}

fn python_can_and_scapy_logs_are_read() {
    let dir = tempdir("py");
    let out = Command::new(python())
        .arg(Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/write_logs.py"))
        .arg(&dir)
        .env("PYTHONDONTWRITEBYTECODE", "1")
        .stderr(Stdio::piped())
        .output()
        .unwrap();
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    // python-can's CanutilsLogWriter writes a remote frame as `701#R`, without its length.
    check(&dir.join("frames.log"), Format::Candump, true, 0);
    // ASC times count from the start of the measurement.
    check(&dir.join("frames.asc"), Format::Asc, false, 1);
    check(&dir.join("frames.blf"), Format::Blf, true, 1);
    check(&dir.join("frames.pcap"), Format::Pcap, true, 1);
    check(&dir.join("frames.pcapng"), Format::Pcap, true, 1);
    let _ = std::fs::remove_dir_all(&dir);
}

/// can-utils' converters on a candump `-l` log: `log2long` writes candump's screen lines
/// (its `sprint_long_canframe`), `log2asc` an ASC file.
fn can_utils_logs_are_read() {
    let have = |tool: &str| {
        Command::new(tool).arg("-h").stdout(Stdio::null()).stderr(Stdio::null()).status().is_ok()
    };
    if !have("log2long") || !have("log2asc") {
        assert!(
            std::env::var_os("ODC_INTEROP_REQUIRED").is_none(),
            "can-utils (log2long, log2asc) is not installed"
        );
        println!("skipped: can-utils (log2long, log2asc) is not installed");
        return;
    }
    let dir = tempdir("canutils");
    let compact = dir.join("frames.log");
    std::fs::write(
        &compact,
        "(1700000000.000000) can0 185#4006\n(1700000000.100000) can0 701#R1\n\
         (1700000000.200000) can0 12345678#0102\n\
         (1700000000.300000) can0 123##1000102030405060708090A0B\n\
         (1700000000.400000) can0 7FF#\n(1700000000.500000) can0 605#4000100000000000\n",
    )
    .unwrap();
    let long =
        Command::new("log2long").stdin(std::fs::File::open(&compact).unwrap()).output().unwrap();
    assert!(long.status.success());
    let long_path = dir.join("frames.long");
    std::fs::write(&long_path, &long.stdout).unwrap();
    // can-utils 2020.11's log2long prints a remote frame's length as 0 and CAN FD lines
    // without the flags.
    let bytes = std::fs::read(&long_path).unwrap();
    let read = log::read(&bytes, log::detect(&bytes).unwrap());
    assert_eq!(read.problems, [], "{}", String::from_utf8_lossy(&bytes));
    assert_eq!(read.entries.len(), 6, "{}", String::from_utf8_lossy(&bytes));
    let asc = Command::new("log2asc").args(["-I"]).arg(&compact).arg("can0").output().unwrap();
    assert!(asc.status.success());
    let asc_path = dir.join("frames.asc");
    std::fs::write(&asc_path, &asc.stdout).unwrap();
    check(&asc_path, Format::Asc, false, 1);
    // The screen lines: every frame but the flags and lengths log2long drops.
    let want = frames();
    for (i, (entry, (t, frame))) in read.entries.iter().zip(&want).enumerate() {
        assert!((entry.time.unwrap() - (T0 + t)).abs() < 1e-3);
        match (&entry.frame, frame) {
            (Frame::Fd(got), Frame::Fd(w)) => assert_eq!((got.id, &got.data), (w.id, &w.data)),
            (Frame::Can(got), Frame::Can(w)) if i == 1 => assert_eq!(got.id(), w.id()),
            (got, w) => assert_eq!(got, w),
        }
    }
    println!("log2long: {} frames; log2asc: 6 frames", read.entries.len());
    let _ = std::fs::remove_dir_all(&dir);
}

fn main() -> std::process::ExitCode {
    use odc_tests_support::{Need, Test};
    odc_tests_support::main(&[
        Test {
            name: "python_can_and_scapy_logs_are_read",
            run: python_can_and_scapy_logs_are_read,
            needs: &[Need::Python(&["can", "scapy"])],
        },
        Test { name: "can_utils_logs_are_read", run: can_utils_logs_are_read, needs: &[] },
    ])
}
