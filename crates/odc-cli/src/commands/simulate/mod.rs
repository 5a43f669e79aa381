//! `odc simulate`: device files as live devices, to test a master against: CANopen devices on
//! one CAN bus (`--tcp`, `--socketcand`, `--can`, behind an slcan adapter with `--slcan`), or
//! EtherCAT devices on a network interface (`--interface`).

use std::path::Path;
use std::process::ExitCode;

use anyhow::{Context, bail};
use odc_sim::{SimDevice, VirtualBus};

use super::link::split_channel;

use crate::input;

mod ethercat;
mod slcan;
mod stop;

/// Run device files as CANopen devices: each one's object dictionary (from the model, with the
/// file's defaults, limits and access rights) served by odc's node (NMT and boot-up,
/// heartbeat, guarding, SYNC, PDOs, EMCY, SDO, LSS), and for a CiA 402 drive the state
/// machine and a simple axis (profile position, profile velocity). Several files are several
/// nodes on one bus: `A.eds --node-id 1 B.eds --node-id 2`, or `A.eds@1 B.eds@2`; each
/// hears the others' frames as on a real bus.
///
/// `--tcp` listens and is a virtual CAN bus: every connected client is a node on it, frames
/// from one client go to the devices and to every other client (16-byte SocketCAN-layout
/// records, see tests/interop/README.md). `--socketcand` is the same bus served with
/// socketcand's protocol (raw mode; bus `can0` unless `HOST:PORT/CHANNEL` names another), for
/// python-can's `socketcand` interface and the bench commands' `--socketcand`. The first line
/// on standard output is `listening on HOST:PORT`.
///
/// It runs until SIGINT (Ctrl-C) or SIGTERM, so it serves as well under `nohup`, systemd or CI
/// (standard input /dev/null) as in a terminal; `--stop-on-eof` also stops it at the end of
/// standard input, for a script that holds a pipe to it.
///
/// `--slcan` is the device behind an slcan (Lawicel) adapter: `pty` makes a pseudo-terminal
/// and prints `listening on /dev/pts/N` first, the path for the host (python-can's `slcan`
/// interface, `odc sdo --slcan`); a serial device's path serves on that port.
///
/// `--interface` runs ESI devices as EtherCAT SubDevices on a network interface (such as one
/// end of a veth pair; root or CAP_NET_RAW): an emulated slave controller each (registers,
/// SII EEPROM from the ESI, AL states, mailbox with CoE, process data through the FMMUs), in
/// the order of the files, first next to the master. `FILE@DEVICE` picks a device of a file
/// with several.
#[derive(clap::Args)]
#[command(group(clap::ArgGroup::new("bus").required(true).args(["tcp", "can", "socketcand", "slcan", "interface"])))]
pub struct Args {
    /// EDS or DCF files (`FILE@ID` gives the node-ID); with --interface, ESI files
    /// (`FILE@DEVICE` for one of several).
    #[arg(required = true, value_name = "FILE")]
    files: Vec<String>,
    /// The node-ID of a CANopen device: 1–127, or 255 for none (CiA 305: the device waits
    /// for an LSS master to find it with fastscan and give it one). One per file without
    /// `@ID`, in the order of the files.
    #[arg(long, value_parser = parse_node_id)]
    node_id: Vec<u8>,
    /// Listen on HOST:PORT as a virtual bus (port 0: a free port).
    #[arg(long, value_name = "HOST:PORT")]
    tcp: Option<String>,
    /// Listen on HOST:PORT as a socketcand server of bus CHANNEL (default `can0`).
    #[arg(long, value_name = "HOST:PORT[/CHANNEL]")]
    socketcand: Option<String>,
    /// A SocketCAN interface (can0, vcan0).
    #[arg(long, value_name = "IFACE")]
    can: Option<String>,
    /// Behind an slcan adapter: `pty` (a new pseudo-terminal, its path printed) or a serial
    /// device.
    #[arg(long, value_name = "pty|DEVICE")]
    slcan: Option<String>,
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
    let mut devices = Vec::new();
    let pairs = pair_node_ids(&args.files, &args.node_id)?;
    // 255 (no node-ID) may be several: LSS tells them apart by their identities.
    for (k, (file, id)) in pairs.iter().enumerate() {
        if let Some((other, _)) = pairs.iter().take(k).find(|(_, n)| n == id && *id != 255) {
            bail!(
                "node-ID {id} is given to both {other} and {file}: each node on a bus has its own"
            );
        }
    }
    for (file, node_id) in pairs {
        let loaded = input::load(Path::new(&file), &args.levels)?;
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
        let device = SimDevice::new(model, node_id);
        let what = if device.is_drive() { ", a CiA 402 drive" } else { "" };
        let node = node_id.map_or_else(
            || "without node-ID (waiting for LSS)".to_owned(),
            |id| format!("as node {id}"),
        );
        elog!("simulating {} {node}{what}: {} entries", model.name(), device.dictionary().len());
        devices.push(device);
    }
    if let Some(addr) = args.socketcand {
        return socketcand(&addr, &mut devices, args.stop_on_eof);
    }
    if let Some(spec) = &args.slcan {
        return slcan::run(spec, &mut devices, args.stop_on_eof);
    }
    match (args.tcp, args.can) {
        (Some(addr), _) => tcp(addr, &mut devices, args.stop_on_eof),
        (None, Some(iface)) => can(&iface, &mut devices, args.stop_on_eof),
        // clap's group requires one of them.
        (None, None) => {
            bail!("give --tcp HOST:PORT, --socketcand HOST:PORT, --can IFACE or --slcan pty|DEVICE")
        }
    }
}

/// Each file with its node-ID: `FILE@ID`, or the next `--node-id` in order.
fn pair_node_ids(files: &[String], node_ids: &[u8]) -> anyhow::Result<Vec<(String, u8)>> {
    let mut given = node_ids.iter();
    let mut pairs = Vec::new();
    for text in files {
        let at = text.rsplit_once('@').filter(|_| !Path::new(text).exists());
        let (file, id) = match at {
            Some((file, id)) => {
                let id = parse_node_id(id).map_err(|e| anyhow::anyhow!("{text}: {e}"))?;
                (file.to_owned(), id)
            }
            None => {
                let Some(&id) = given.next() else {
                    bail!(
                        "{text}: no node-ID: give --node-id N (1..=127, or 255 for none) for it, \
                         or write {text}@N"
                    )
                };
                (text.clone(), id)
            }
        };
        pairs.push((file, id));
    }
    if given.next().is_some() {
        bail!(
            "{} --node-id values for {} files without @ID: one each, in the order of the files",
            node_ids.len(),
            node_ids.len() - given.len() - 1
        );
    }
    Ok(pairs)
}

/// `--node-id`: 1–127, or 255 (none).
fn parse_node_id(text: &str) -> Result<u8, String> {
    match text.parse::<u8>() {
        Ok(n @ (1..=127 | 255)) => Ok(n),
        _ => Err(format!("`{text}`: a node-ID is 1..=127, or 255 for none (LSS)")),
    }
}

fn tcp(addr: String, devices: &mut [SimDevice], stop_on_eof: bool) -> anyhow::Result<ExitCode> {
    let bus =
        VirtualBus::bind(addr.as_str()).with_context(|| format!("cannot listen on {addr}"))?;
    serve(bus, devices, stop_on_eof)
}

/// The bus as a socketcand server.
fn socketcand(
    text: &str,
    devices: &mut [SimDevice],
    stop_on_eof: bool,
) -> anyhow::Result<ExitCode> {
    let (addr, channel) = split_channel(text);
    let bus = VirtualBus::bind_socketcand(addr, channel)
        .with_context(|| format!("--socketcand {text}: cannot listen on {addr}"))?;
    elog!("serving bus {channel} as socketcand (raw mode)");
    serve(bus, devices, stop_on_eof)
}

fn serve(
    bus: VirtualBus,
    devices: &mut [SimDevice],
    stop_on_eof: bool,
) -> anyhow::Result<ExitCode> {
    super::out_flushed(&format!("listening on {}\n", bus.local_addr()))?;
    let stop = bus.stop_handle();
    stop::on_stop(stop_on_eof, move || stop.stop())?;
    bus.run_all(devices, &mut |event| elog!("{event}"));
    Ok(ExitCode::SUCCESS)
}

#[cfg(not(all(feature = "socketcan", target_os = "linux")))]
fn can(iface: &str, _devices: &mut [SimDevice], _stop_on_eof: bool) -> anyhow::Result<ExitCode> {
    bail!("--can {iface}: this odc was built without SocketCAN (Linux, cargo feature `socketcan`)")
}

/// The devices on a SocketCAN interface until a signal (or the end of standard input, when
/// asked).
#[cfg(all(feature = "socketcan", target_os = "linux"))]
fn can(iface: &str, devices: &mut [SimDevice], stop_on_eof: bool) -> anyhow::Result<ExitCode> {
    use std::sync::atomic::Ordering;
    let mut bus = odc::transport::socketcan::SocketCan::open(iface)
        .with_context(|| format!("--can {iface}: cannot open the SocketCAN interface"))?;
    elog!("on {iface}");
    let stop = stop::flag(stop_on_eof)?;
    let tick_ms = u64::try_from(odc_sim::TICK.as_millis()).unwrap_or(10);
    odc_sim::run_all_on_bus(&mut bus, devices, tick_ms, || stop.load(Ordering::Relaxed))
        .with_context(|| format!("--can {iface}"))?;
    Ok(ExitCode::SUCCESS)
}
