//! `odc simulate FILE.xml... --interface IFACE`: ESI devices as EtherCAT SubDevices on a
//! network interface, in a line in the order of the files.

use std::path::Path;
use std::process::ExitCode;

use anyhow::{Context, bail};
use odc_sim::ethercat::{Chain, SubDevice};

use crate::input;

/// Loads each `FILE[@DEVICE]`, builds the line of devices and serves it on `iface` until the
/// first SIGINT or SIGTERM (or the end of standard input with `stop_on_eof`).
pub fn run(
    files: &[String],
    levels: &input::Levels,
    iface: &str,
    stop_on_eof: bool,
) -> anyhow::Result<ExitCode> {
    let mut devices = Vec::with_capacity(files.len());
    for spec in files {
        let (path, levels) = split_spec(spec, levels);
        let loaded = input::load(path, &levels)?;
        super::super::gate_bus(&loaded)?;
        unmapped(spec, &loaded);
        let model = loaded.device()?;
        let Some(ecat) = model.ethercat.as_deref() else {
            bail!("{}: --interface runs EtherCAT devices (ESI); this is a CANopen device", spec)
        };
        let device = SubDevice::new(model)
            .with_context(|| format!("{spec}: cannot make the device's SII image"))?;
        elog!(
            "device {}: {} (vendor {:#010x}, product {:#010x}), {} dictionary entries",
            devices.len() + 1,
            device.name(),
            ecat.vendor_id.unwrap_or(0),
            ecat.product_code.unwrap_or(0),
            device.dictionary().len()
        );
        devices.push(device);
    }
    serve(iface, Chain::new(devices), stop_on_eof)
}

/// Names at load what the device will refuse at SAFE-OP (#31): a PDO entry whose object the
/// dictionary does not have (the checker's T601) makes the firmware stack answer AL status
/// 0x0025 (invalid output mapping, an RxPDO) or 0x0024 (invalid input mapping, a TxPDO)
/// while that PDO is assigned.
fn unmapped(spec: &str, loaded: &odc_pipeline::Loaded) {
    for d in loaded.warnings().filter(|d| d.code == "T601") {
        let code = match d.object {
            Some((0x1600..=0x17FF, _)) => "0x0025 (invalid output mapping)",
            _ => "0x0024 (invalid input mapping)",
        };
        elog!(
            "{spec}: {}: SAFE-OP is refused with AL status {code} while it is assigned",
            d.message
        );
    }
}

/// `FILE@DEVICE` (when FILE exists) as the file and `--device DEVICE`; anything else as a
/// file with the command line's `--device`.
fn split_spec<'a>(spec: &'a str, levels: &input::Levels) -> (&'a Path, input::Levels) {
    let mut levels = levels.clone();
    if let Some((file, device)) = spec.rsplit_once('@')
        && Path::new(file).is_file()
    {
        levels.device = Some(device.to_owned());
        return (Path::new(file), levels);
    }
    (Path::new(spec), levels)
}

#[cfg(not(target_os = "linux"))]
fn serve(iface: &str, _chain: Chain, _stop_on_eof: bool) -> anyhow::Result<ExitCode> {
    bail!("--interface {iface}: raw Ethernet frames are supported on Linux only")
}

#[cfg(target_os = "linux")]
fn serve(iface: &str, mut chain: Chain, stop_on_eof: bool) -> anyhow::Result<ExitCode> {
    use std::sync::atomic::Ordering;
    use std::time::Instant;
    if is_down(iface) {
        bail!(
            "--interface {iface}: the interface is down; bring it up first \
             (`ip link set {iface} up`, as root)"
        );
    }
    let mut endpoint = odc_sim::EthernetEndpoint::open(iface)
        .with_context(|| format!("--interface {iface}: cannot open it for raw frames"))?;
    super::super::out_flushed(&format!("serving {} devices on {iface}\n", chain.devices().len()))?;
    let stop = super::stop::flag(stop_on_eof)?;
    let start = Instant::now();
    let clock = || u64::try_from(start.elapsed().as_nanos()).unwrap_or(u64::MAX);
    let served = endpoint
        .serve(|frame| chain.process(frame, clock()).is_ok(), || stop.load(Ordering::Relaxed))
        .with_context(|| {
            // The raw socket reports an interface taken down under it only as a poll error.
            if is_down(iface) {
                format!("--interface {iface}: the interface went down")
            } else {
                format!("--interface {iface}")
            }
        })?;
    elog!(
        "{} frames ({} datagrams) served, {} malformed or not EtherCAT",
        served.frames,
        chain.datagrams(),
        served.ignored
    );
    for (k, device) in chain.devices().iter().enumerate() {
        elog!(
            "device {}: AL state {:#04x}, status code {:#06x}",
            k + 1,
            device.al_state(),
            device.al_status_code()
        );
    }
    Ok(ExitCode::SUCCESS)
}

/// Whether the interface exists and is administratively down (`IFF_UP` clear in
/// `/sys/class/net/IFACE/flags`): a raw socket on it fails at the first poll with no word
/// of why.
#[cfg(target_os = "linux")]
fn is_down(iface: &str) -> bool {
    const IFF_UP: u32 = 0x1;
    let Ok(text) = std::fs::read_to_string(Path::new("/sys/class/net").join(iface).join("flags"))
    else {
        return false;
    };
    let hex = text.trim().trim_start_matches("0x");
    u32::from_str_radix(hex, 16).is_ok_and(|flags| flags & IFF_UP == 0)
}
