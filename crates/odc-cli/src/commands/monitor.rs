//! `odc monitor`: a bus, live or from a log file, decoded with the device files.

use std::path::PathBuf;
use std::process::ExitCode;

use anyhow::Context;
use odc::transport::Bus;
use odc_monitor::{Decoder, Record, log};

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

/// A log file's format.
#[derive(Clone, Copy, Debug, Default, clap::ValueEnum)]
pub enum LogFormat {
    /// Told from the content.
    #[default]
    Auto,
    /// candump: `-l` lines or its screen lines.
    Candump,
    /// Vector ASC.
    Asc,
    /// Vector BLF.
    Blf,
    /// pcap or pcapng, link type 227 (SocketCAN).
    Pcap,
}

/// Print every frame of a bus decoded with the device files: NMT and heartbeat states, SDO
/// requests and answers with the object's name and typed value (segmented and block transfers
/// put together), PDOs split into named fields (following remaps seen on the bus), EMCY with
/// its meaning, SYNC, LSS; unknown frames raw. Live (`--tcp`, `--can`, `--socketcand`,
/// `--slcan`, until the bus closes) or from a log file (`--log`): candump's `-l` and screen
/// formats (CAN FD lines too), Vector ASC and BLF (as python-can writes them), pcap and pcapng
/// SocketCAN captures (Wireshark, tcpdump); the format is told from the file's content, or
/// named with `--log-format`. CAN FD frames are printed raw.
#[derive(clap::Args)]
#[command(group(clap::ArgGroup::new("source").required(true).args(["tcp", "can", "socketcand", "slcan", "log"])))]
pub struct Args {
    /// A virtual CAN bus over TCP, as `odc simulate --tcp` serves it.
    #[arg(long, value_name = "HOST:PORT")]
    tcp: Option<String>,
    /// A SocketCAN interface (Linux).
    #[arg(long, value_name = "IFACE")]
    can: Option<String>,
    /// A socketcand server (`HOST:PORT`, `/CHANNEL` for a bus other than `can0`).
    #[arg(long, value_name = "HOST:PORT[/CHANNEL]")]
    socketcand: Option<String>,
    /// An slcan adapter on a serial port: `DEVICE[@BITRATE]`.
    #[arg(long, value_name = "DEVICE[@BITRATE]")]
    slcan: Option<String>,
    /// A log file: candump, ASC, BLF, pcap or pcapng.
    #[arg(long, value_name = "FILE")]
    log: Option<PathBuf>,
    /// The log's format, when its content does not tell.
    #[arg(long, value_enum, default_value_t, requires = "log")]
    log_format: LogFormat,
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
        let bytes =
            std::fs::read(path).with_context(|| format!("cannot read {}", path.display()))?;
        let format = match args.log_format {
            LogFormat::Auto => log::detect(&bytes).with_context(|| {
                format!(
                    "{}: not a log format odc reads; name it with --log-format (candump, asc, \
                     blf, pcap)",
                    path.display()
                )
            })?,
            LogFormat::Candump => log::Format::Candump,
            LogFormat::Asc => log::Format::Asc,
            LogFormat::Blf => log::Format::Blf,
            LogFormat::Pcap => log::Format::Pcap,
        };
        let read = log::read(&bytes, format);
        for entry in &read.entries {
            match &entry.frame {
                log::Frame::Can(frame) => print(&decoder.decode(frame, entry.time))?,
                log::Frame::Fd(frame) => print(&log::fd_record(frame, entry.time))?,
            }
        }
        for problem in &read.problems {
            eprintln!("{}:{}: error: {}", path.display(), problem.at, problem.message);
        }
        return Ok(if read.problems.is_empty() { ExitCode::SUCCESS } else { ExitCode::from(1) });
    }
    let bus = BusArgs {
        tcp: args.tcp.clone(),
        can: args.can.clone(),
        socketcand: args.socketcand.clone(),
        slcan: args.slcan.clone(),
    };
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
