//! `odc sdo` (the binary) against python-canopen's `LocalNode` (tests/interop/python/slave.py)
//! serving each device file of `eds/`, on a virtual bus with no device of its own
//! (`odc_sim::VirtualBus::run_hub`): every readable object read by its name in the file (by
//! index where the name is not unique) and its value compared with the file's default that
//! LocalNode serves; every writable one of a number type written and read back. The counts
//! are printed.
#![allow(clippy::unwrap_used, clippy::expect_used, clippy::panic)]

use std::path::{Path, PathBuf};
use std::process::{Command, Stdio};

use odc::transport::Bus;
use odc::transport::tcp::TcpCan;
use odc_model::{Device, Value, ValueClass};

fn repo(path: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../..").join(path)
}

fn odc(args: &[&str]) -> std::process::Output {
    Command::new(env!("CARGO_BIN_EXE_odc")).args(args).output().expect("odc runs")
}

/// The spec `odc sdo` takes for an entry: its name when that names it alone.
fn spec(dev: &Device, index: u16, sub: u8) -> (String, bool) {
    let o = &dev.objects[&index];
    let s = o.sub(sub).unwrap();
    let name = if o.kind.has_subs() { format!("{}/{}", o.name, s.name) } else { o.name.clone() };
    let lower = name.to_ascii_lowercase();
    let clashes = dev
        .objects
        .values()
        .flat_map(|o| o.subs.values().map(move |s| (o, s)))
        .filter(|(o, s)| {
            let full = format!("{}/{}", o.name, s.name).to_ascii_lowercase();
            (!o.kind.has_subs() && o.name.to_ascii_lowercase() == lower)
                || full == lower
                || (o.kind.has_subs() && s.name.to_ascii_lowercase() == lower)
        })
        .count();
    // A name that reads as an index (`1000`) or holds `:` is given by index too.
    let numeric = name.len() == 4 && name.chars().all(|c| c.is_ascii_hexdigit());
    if clashes == 1
        && !name.contains(':')
        && !name.to_ascii_lowercase().contains("sub")
        && !numeric
        && !name.is_empty()
    {
        (name, true)
    } else {
        (format!("0x{index:04X}:{sub:02X}"), false)
    }
}

fn odc_sdo_reads_and_writes_python_canopen_by_name() {
    let python = PathBuf::from(std::env::var_os("ODC_INTEROP_PYTHON").unwrap_or("python3".into()));
    let mut failures = Vec::new();
    println!(
        "{:<16} {:>5} {:>7} {:>8} {:>6} {:>7} {:>9}",
        "device", "read", "by name", "matched", "no-def", "written", "read-back"
    );
    for name in ["lxm23a", "lexium-mdrive", "servoone", "lenze-e94aycca", "linmot-e1200"] {
        let file = repo(&format!("eds/{name}.eds"));
        let dev =
            odc_pipeline::load(&file, &odc_pipeline::Options::new()).unwrap().devices.remove(0);
        let hub = odc_sim::VirtualBus::bind("127.0.0.1:0").unwrap();
        let addr = hub.local_addr().to_string();
        let stop = hub.stop_handle();
        let hub_thread = std::thread::spawn(move || hub.run_hub(&mut |_| {}));
        // Connected before the node starts, to see its boot-up.
        let mut watch = TcpCan::connect(&addr).unwrap();
        let mut peer = Command::new(&python)
            .arg(repo("tests/interop/python/slave.py"))
            .args(["--connect", &addr, "--eds", file.to_str().unwrap(), "--node", "5"])
            .env("PYTHONDONTWRITEBYTECODE", "1")
            .stdout(Stdio::null())
            .stderr(Stdio::piped())
            .spawn()
            .unwrap();
        let deadline = watch.now() + odc::time::Duration::from_millis(30_000);
        loop {
            match watch.recv(deadline).unwrap() {
                Some(f) if f.id() == 0x705 && f.bytes() == [0] => break,
                Some(_) => {}
                None => panic!("{name}: no boot-up from LocalNode"),
            }
        }
        let node = format!("5={}", file.display());
        let sdo = |args: &[&str]| {
            let mut all = vec!["sdo"];
            all.extend_from_slice(args);
            all.extend_from_slice(&["--node", &node, "--tcp", &addr, "--timeout", "2000"]);
            odc(&all)
        };
        let (mut read, mut by_name, mut matched, mut no_default, mut written, mut back) =
            (0, 0, 0, 0, 0, 0);
        for o in dev.objects.values() {
            for s in o.subs.values() {
                let (index, sub) = (o.index, s.sub_index);
                let (spec, named) = spec(&dev, index, sub);
                if s.access.readable() {
                    read += 1;
                    by_name += usize::from(named);
                    let out = sdo(&["read", &spec]);
                    let stdout = String::from_utf8_lossy(&out.stdout).into_owned();
                    let stderr = String::from_utf8_lossy(&out.stderr).into_owned();
                    // The file's default as LocalNode serves it, in odc's words.
                    let want = s.default.as_ref().and_then(|d| {
                        let v = match &d.value {
                            Value::NodeIdPlus(n) => Value::Unsigned(u64::try_from(n + 5).ok()?),
                            v => v.clone(),
                        };
                        let bytes = odc_model::wire::encode(&v, s.data_type)?;
                        odc_model::wire::decode(&bytes, s.data_type).map(|v| odc_monitor::show(&v))
                    });
                    match (&want, out.status.code()) {
                        (Some(w), Some(0)) if stdout.trim_end().ends_with(&format!("= {w}")) => {
                            matched += 1
                        }
                        // LocalNode has no value for an entry without default (0x08000024
                        // "no data available" or 0x060A0023 "resource not available").
                        (None, Some(1))
                            if stderr.contains("0x08000024") || stderr.contains("0x060A0023") =>
                        {
                            no_default += 1
                        }
                        _ => failures.push(format!(
                            "{name} read {spec}: want {want:?}, got {stdout}{stderr}"
                        )),
                    }
                }
                // Every writable (and readable) entry but the PDO parameters (a new mapping
                // or COB-ID is the plans' business): a value of its type in its limits.
                let limit = || match (&s.low_limit, &s.high_limit) {
                    (Some(lo), _) => Some(odc_analysis::value_text(&lo.value)),
                    (None, Some(hi)) => Some(odc_analysis::value_text(&hi.value)),
                    _ => None,
                };
                let value = match s.data_type.class() {
                    ValueClass::Unsigned(_) | ValueClass::Signed(_) => {
                        Some(limit().unwrap_or_else(|| "1".to_owned()))
                    }
                    ValueClass::Bool => Some("1".to_owned()),
                    ValueClass::Real32 | ValueClass::Real64 => {
                        Some(limit().unwrap_or_else(|| "1.5".to_owned()))
                    }
                    ValueClass::Text => Some("odc".to_owned()),
                    ValueClass::Bytes => Some("0102".to_owned()),
                    _ => None,
                };
                let pdo_parameter = (0x1400..=0x1BFF).contains(&index);
                if let Some(value) =
                    value.filter(|_| s.access.writable() && s.access.readable() && !pdo_parameter)
                {
                    written += 1;
                    let out = sdo(&["write", &spec, &value]);
                    if out.status.code() != Some(0) {
                        failures.push(format!(
                            "{name} write {spec} {value}: {}",
                            String::from_utf8_lossy(&out.stderr)
                        ));
                        continue;
                    }
                    let out = sdo(&["read", &spec]);
                    let shown = String::from_utf8_lossy(&out.stdout).into_owned();
                    let want = odc_eds::read_value(&value, s.data_type).ok().and_then(|v| {
                        let bytes = odc_model::wire::encode(&v, s.data_type)?;
                        odc_model::wire::decode(&bytes, s.data_type).map(|v| odc_monitor::show(&v))
                    });
                    match want {
                        Some(w) if shown.trim_end().ends_with(&format!("= {w}")) => back += 1,
                        _ => failures
                            .push(format!("{name} read back {spec}: want {want:?}, got {shown}")),
                    }
                }
            }
        }
        println!(
            "{name:<16} {read:>5} {by_name:>7} {matched:>8} {no_default:>6} {written:>7} {back:>9}"
        );
        drop(watch);
        let _ = peer.kill();
        let _ = peer.wait();
        stop.stop();
        hub_thread.join().unwrap();
    }
    assert!(failures.is_empty(), "{} disagreements:\n{}", failures.len(), failures.join("\n"));
}

/// The tests, with what each needs of the machine (odc_tests_support: ignored with the reason
/// where a need is missing).
fn main() -> std::process::ExitCode {
    #[allow(unused_imports)]
    use odc_tests_support::{Need, Test};
    odc_tests_support::main(&[Test {
        name: "odc_sdo_reads_and_writes_python_canopen_by_name",
        run: odc_sdo_reads_and_writes_python_canopen_by_name,
        needs: &[Need::Python(&["canopen", "can"])],
    }])
}
