//! `odc conformance`: test a live CANopen device against its device file and CiA 301/402.

use std::path::PathBuf;
use std::process::ExitCode;

use anyhow::{Context, anyhow, bail};
use odc_conformance::{Group, Options};

use super::link::BusArgs;
use crate::input;

/// Test a live CANopen device (real, or `odc simulate`) against its device file and CiA
/// 301/402, in the spirit of CiA 310: identity, every entry (exists, size, access, limits,
/// defaults after the resets), the SDO protocol, NMT and error control (heartbeat, guarding),
/// PDOs, EMCY, LSS and a CiA 402 drive's state machine and modes.
///
/// Each check names its clause and ends pass, FAIL (with its frames) or n/a (with why). The
/// checks write and restore parameters, reset the node, and pass a CiA 402 drive through
/// "operation enabled": run it on a bench, not on a machine. Exit status 0 when no check
/// failed, 1 when one did, 2 for usage errors, a device file refused by its checks or a bus
/// that cannot be opened.
#[derive(clap::Args)]
pub struct Args {
    /// The device's EDS, DCF or XDD file.
    file: PathBuf,
    /// The device's node-ID, 1–127.
    #[arg(long, value_parser = clap::value_parser!(u8).range(1..=127))]
    node_id: u8,
    #[command(flatten)]
    bus: BusArgs,
    /// Write the report to FILE.json or FILE.html (by the extension).
    #[arg(long, value_name = "FILE")]
    report: Option<PathBuf>,
    /// Only these groups (identity, entries, sdo, nmt, pdo, emcy, lss, cia402); all by default.
    #[arg(long, value_name = "GROUP")]
    group: Vec<String>,
    /// Also run the 0x1011 "load" check, which restores the device's factory defaults (the
    /// parameters it has stored are lost).
    #[arg(long)]
    restore_defaults: bool,
    /// How long to wait for an answer, in ms.
    #[arg(long, value_name = "MS", default_value_t = 1000)]
    timeout: u64,
    /// How late a frame may be received, in ms: a heartbeat gap may differ from the period,
    /// a PDO gap fall short of the inhibit time, by this much.
    #[arg(long, value_name = "MS", default_value_t = 20, alias = "heartbeat-tolerance")]
    timing_tolerance: u64,
    #[command(flatten)]
    levels: input::Levels,
}

pub fn run(args: Args) -> anyhow::Result<ExitCode> {
    let mut groups = Vec::new();
    for name in &args.group {
        let names = Group::ALL.map(Group::name).join(", ");
        groups.push(
            Group::from_name(name)
                .ok_or_else(|| anyhow!("--group {name}: no such group (one of {names})"))?,
        );
    }
    let report_format = match &args.report {
        Some(p) => match p.extension().and_then(|e| e.to_str()) {
            Some(e) if e.eq_ignore_ascii_case("json") => Some((p, false)),
            Some(e) if e.eq_ignore_ascii_case("html") || e.eq_ignore_ascii_case("htm") => {
                Some((p, true))
            }
            _ => bail!("--report {}: give a .json or .html file", p.display()),
        },
        None => None,
    };
    let loaded = input::load(&args.file, &args.levels)?;
    // A refused file is a load error here (exit 2): exit 1 means the device failed a check.
    super::gate(&loaded).map_err(|e| anyhow!("{e:#}"))?;
    let device = loaded.device()?;
    if device.ethercat.is_some() {
        bail!("{}: an EtherCAT device; odc conformance tests CANopen devices", loaded.file_name());
    }
    let node = odc::cob::NodeId::new(args.node_id).context("--node-id: 1..=127")?;
    let bus = args.bus.open()?;
    let options = Options {
        timeout_ms: args.timeout,
        timing_tolerance_ms: args.timing_tolerance,
        restore_defaults: args.restore_defaults,
        groups,
        ..Options::default()
    };
    let report = odc_conformance::run(device, node, bus, &options);
    super::out(&report.summary())?;
    if let Some((path, html)) = report_format {
        let text = if html { report.to_html() } else { report.to_json() + "\n" };
        input::write_atomic(path, text.as_bytes())?;
    }
    Ok(if report.counts.fail > 0 { ExitCode::from(1) } else { ExitCode::SUCCESS })
}
