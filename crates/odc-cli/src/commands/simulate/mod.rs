//! `odc simulate`: a device file as a live device, to test a master against: a CANopen device
//! on a CAN bus (`--tcp`, `--can`), or EtherCAT devices on a network interface (`--interface`).

use std::path::Path;
use std::process::ExitCode;

use anyhow::{Context, bail};
use odc_sim::{SimDevice, VirtualBus};

use crate::input;

mod ethercat;
mod stop;

/// Run a device file as a CANopen device: its object dictionary (from the model, with the
/// file's defaults, limits and access rights) served by odc's node (NMT and boot-up,
/// heartbeat, guarding, SYNC, PDOs, EMCY, SDO, LSS), and for a CiA 402 drive the state
/// machine and a simple axis (profile position, profile velocity).
///
/// `--tcp` listens and is a virtual CAN bus: every connected client is a node on it, frames
/// from one client go to the device and to every other client (16-byte SocketCAN-layout
/// records, see tests/interop/README.md). The first line on standard output is
/// `listening on HOST:PORT`.
///
/// It runs until SIGINT (Ctrl-C) or SIGTERM, so it serves as well under `nohup`, systemd or CI
/// (standard input /dev/null) as in a terminal; `--stop-on-eof` also stops it at the end of
/// standard input, for a script that holds a pipe to it.
///
/// `--interface` runs ESI devices as EtherCAT SubDevices on a network interface (such as one
/// end of a veth pair; root or CAP_NET_RAW): an emulated slave controller each (registers,
/// SII EEPROM from the ESI, AL states, mailbox with CoE, process data through the FMMUs), in
/// the order of the files, first next to the master. `FILE@DEVICE` picks a device of a file
/// with several.
#[derive(clap::Args)]
#[command(group(clap::ArgGroup::new("bus").required(true).args(["tcp", "can", "interface"])))]
pub struct Args {
    /// EDS or DCF file; with --interface, ESI files (`FILE@DEVICE` for one of several).
    #[arg(required = true, value_name = "FILE")]
    files: Vec<String>,
    /// The node-ID of the CANopen device: 1–127, or 255 for none (CiA 305: the device waits
    /// for an LSS master to find it with fastscan and give it one).
    #[arg(long, value_parser = parse_node_id)]
    node_id: Option<u8>,
    /// Listen on HOST:PORT as a virtual bus (port 0: a free port).
    #[arg(long, value_name = "HOST:PORT")]
    tcp: Option<String>,
    /// A SocketCAN interface (can0, vcan0).
    #[arg(long, value_name = "IFACE")]
    can: Option<String>,
    /// A network interface for EtherCAT (Linux): the devices answer a master on its wire.
    #[arg(long, value_name = "IFACE")]
    interface: Option<String>,
    /// Also stop at the end of standard input (a script closes the pipe it holds).
    #[arg(long)]
    stop_on_eof: bool,
    #[command(flatten)]
    levels: input::Levels,
}

pub fn run(args: Args) -> anyhow::Result<ExitCode> {
    if let Some(iface) = &args.interface {
        return ethercat::run(&args.files, &args.levels, iface, args.stop_on_eof);
    }
    let [file] = &args.files[..] else {
        bail!("a CANopen device is one file; several files make an EtherCAT line (--interface)")
    };
    let Some(node_id) = args.node_id else {
        bail!("--node-id N: the CANopen device's node-ID (1..=127, or 255 for none)")
    };
    let loaded = input::load(Path::new(file), &args.levels)?;
    super::gate_bus(&loaded)?;
    let model = loaded.device()?;
    if model.ethercat.is_some() {
        bail!(
            "{}: an EtherCAT device runs on a network interface (--interface IFACE)",
            loaded.file_name()
        );
    }
    // 255: no node-ID (CiA 305), `None` here.
    let node_id = odc::cob::NodeId::from_lss(node_id).context("--node-id: 1..=127 or 255")?;
    let mut device = SimDevice::new(model, node_id);
    let what = if device.is_drive() { ", a CiA 402 drive" } else { "" };
    let node = node_id.map_or_else(
        || "without node-ID (waiting for LSS)".to_owned(),
        |id| format!("as node {id}"),
    );
    elog!("simulating {} {node}{what}: {} entries", model.name(), device.dictionary().len());
    match (args.tcp, args.can) {
        (Some(addr), _) => tcp(addr, &mut device, args.stop_on_eof),
        (None, Some(iface)) => can(&iface, &mut device, args.stop_on_eof),
        // clap's group requires one of the two.
        (None, None) => bail!("give --tcp HOST:PORT or --can IFACE"),
    }
}

/// `--node-id`: 1–127, or 255 (none).
fn parse_node_id(text: &str) -> Result<u8, String> {
    match text.parse::<u8>() {
        Ok(n @ (1..=127 | 255)) => Ok(n),
        _ => Err(format!("`{text}`: a node-ID is 1..=127, or 255 for none (LSS)")),
    }
}

fn tcp(addr: String, device: &mut SimDevice, stop_on_eof: bool) -> anyhow::Result<ExitCode> {
    let bus =
        VirtualBus::bind(addr.as_str()).with_context(|| format!("cannot listen on {addr}"))?;
    super::out_flushed(&format!("listening on {}\n", bus.local_addr()))?;
    let stop = bus.stop_handle();
    stop::on_stop(stop_on_eof, move || stop.stop())?;
    bus.run(device, &mut |event| elog!("{event}"));
    Ok(ExitCode::SUCCESS)
}

#[cfg(not(all(feature = "socketcan", target_os = "linux")))]
fn can(iface: &str, _device: &mut SimDevice, _stop_on_eof: bool) -> anyhow::Result<ExitCode> {
    bail!("--can {iface}: this odc was built without SocketCAN (Linux, cargo feature `socketcan`)")
}

/// The device on a SocketCAN interface until a signal (or the end of standard input, when
/// asked).
#[cfg(all(feature = "socketcan", target_os = "linux"))]
fn can(iface: &str, device: &mut SimDevice, stop_on_eof: bool) -> anyhow::Result<ExitCode> {
    use std::sync::atomic::Ordering;
    let mut bus = odc::transport::socketcan::SocketCan::open(iface)
        .with_context(|| format!("--can {iface}: cannot open the SocketCAN interface"))?;
    elog!("on {iface}");
    let stop = stop::flag(stop_on_eof)?;
    let tick_ms = u64::try_from(odc_sim::TICK.as_millis()).unwrap_or(10);
    odc_sim::run_on_bus(&mut bus, device, tick_ms, || stop.load(Ordering::Relaxed))
        .with_context(|| format!("--can {iface}"))?;
    Ok(ExitCode::SUCCESS)
}
