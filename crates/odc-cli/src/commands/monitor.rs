//! `odc monitor`: a bus, live or from a candump log, decoded with the device files.

use std::io::{BufRead, BufReader};
use std::path::PathBuf;
use std::process::ExitCode;

use anyhow::Context;
use odc::transport::Bus;
use odc_monitor::{Decoder, Record, candump};

use super::link::{BusArgs, NodeSpec, load_with_process_data};

/// How records are printed.
#[derive(Clone, Copy, Debug, Default, clap::ValueEnum)]
pub enum MonitorFormat {
    /// One line per frame.
    #[default]
    Human,
    /// One JSON object per frame, one per line.
    Json,
}

/// Print every frame of a bus decoded with the device files: NMT and heartbeat states, SDO
/// requests and answers with the object's name and typed value (segmented and block transfers
/// put together), PDOs split into named fields (following remaps seen on the bus), EMCY with
/// its meaning, SYNC, LSS; unknown frames raw. Live (`--tcp`, `--can`, until the bus closes)
/// or from a candump log (`--log`: `(1700000000.000000) can0 185#4006`).
#[derive(clap::Args)]
#[command(group(clap::ArgGroup::new("source").required(true).args(["tcp", "can", "log"])))]
pub struct Args {
    /// A virtual CAN bus over TCP, as `odc simulate --tcp` serves it.
    #[arg(long, value_name = "HOST:PORT")]
    tcp: Option<String>,
    /// A SocketCAN interface (Linux).
    #[arg(long, value_name = "IFACE")]
    can: Option<String>,
    /// A candump log file (`candump -l` / `-L`).
    #[arg(long, value_name = "FILE")]
    log: Option<PathBuf>,
    /// `ID=FILE`: a node and its device file (repeatable).
    #[arg(long, value_name = "ID=FILE")]
    node: Vec<NodeSpec>,
    /// Output format.
    #[arg(long, value_enum, default_value_t)]
    format: MonitorFormat,
    /// Rule levels for the device files.
    #[command(flatten)]
    rules: crate::input::Rules,
}

pub fn run(args: Args) -> anyhow::Result<ExitCode> {
    let mut devices = Vec::new();
    let mut process = Vec::new();
    for spec in &args.node {
        let (device, layouts) = load_with_process_data(spec, &args.rules)?;
        devices.push((spec.id.get(), device));
        process.push((spec.id, layouts));
    }
    let mut decoder = Decoder::new(devices);
    for (node, layouts) in process {
        decoder = decoder.with_process_data(node.get(), layouts);
    }
    let print = |r: &Record| -> anyhow::Result<()> {
        let line = match args.format {
            MonitorFormat::Human => r.to_string(),
            MonitorFormat::Json => serde_json::to_string(r)?,
        };
        super::out(&format!("{line}\n"))
    };
    if let Some(path) = &args.log {
        let file =
            std::fs::File::open(path).with_context(|| format!("cannot read {}", path.display()))?;
        let mut bad = 0;
        for (n, line) in BufReader::new(file).lines().enumerate() {
            let line = line.with_context(|| format!("cannot read {}", path.display()))?;
            match candump::parse_line(&line) {
                Ok(Some(f)) => print(&decoder.decode(&f.frame, Some(f.time)))?,
                Ok(None) => {}
                Err(e) => {
                    bad += 1;
                    eprintln!("{}:{}: error: {e}", path.display(), n + 1);
                }
            }
        }
        return Ok(if bad == 0 { ExitCode::SUCCESS } else { ExitCode::from(1) });
    }
    let bus = BusArgs { tcp: args.tcp.clone(), can: args.can.clone() };
    let mut link = bus.open()?;
    let start = std::time::Instant::now();
    loop {
        let deadline = link.now() + odc::time::Duration::from_secs(1);
        match link.recv(deadline) {
            Ok(Some(frame)) => print(&decoder.decode(&frame, Some(start.elapsed().as_secs_f64())))?,
            Ok(None) => {}
            Err(e) if e.kind() == std::io::ErrorKind::UnexpectedEof => {
                return Ok(ExitCode::SUCCESS);
            }
            Err(e) => return Err(e).context("the bus"),
        }
    }
}
