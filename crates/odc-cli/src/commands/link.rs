//! What the bench tools (`odc sdo`, `nmt`, `lss`, `monitor`) share: the bus they talk on
//! (`--tcp` as `odc simulate` serves it, `--can` on Linux, `--socketcand` for a socketcand
//! server, `--slcan` for a serial adapter) and the devices they know (`--node ID=FILE`).

use std::path::PathBuf;

use anyhow::{Context, bail};
use odc::can::CanFrame;
use odc::transport::Bus;
use odc::transport::slcan::Bitrate;
use odc::transport::slcan::serial::Slcan;
use odc::transport::socketcand::Socketcand;
use odc::transport::tcp::TcpCan;
use odc_model::Device;

use crate::input;

/// The bus to use.
#[derive(clap::Args, Clone, Debug)]
#[command(group(clap::ArgGroup::new("bus").required(true).args(["tcp", "can", "socketcand", "slcan"])))]
pub struct BusArgs {
    /// A virtual CAN bus over TCP, as `odc simulate --tcp` serves it (`localhost:PORT`,
    /// `127.0.0.1:PORT`, any host name).
    #[arg(long, value_name = "HOST:PORT")]
    pub tcp: Option<String>,
    /// A SocketCAN interface (Linux), such as `can0` or `vcan0`.
    #[arg(long, value_name = "IFACE")]
    pub can: Option<String>,
    /// A socketcand server (`HOST:PORT`, `/CHANNEL` for a bus other than `can0`), such as
    /// `odc simulate --socketcand` or socketcand on a Linux machine with the adapter.
    #[arg(long, value_name = "HOST:PORT[/CHANNEL]")]
    pub socketcand: Option<String>,
    /// An slcan (Lawicel) adapter on a serial port: `DEVICE[@BITRATE]`, such as
    /// `/dev/ttyACM0@500000` or `COM3@125k`; without a bit rate the adapter keeps its own.
    #[arg(long, value_name = "DEVICE[@BITRATE]")]
    pub slcan: Option<String>,
}

/// The bus socketcand serves when `--socketcand` names none.
pub const DEFAULT_CHANNEL: &str = "can0";

/// `HOST:PORT[/CHANNEL]`: the address and the bus name (`can0` when none).
pub fn split_channel(text: &str) -> (&str, &str) {
    match text.rsplit_once('/') {
        Some((addr, channel)) => (addr, channel),
        None => (text, DEFAULT_CHANNEL),
    }
}

/// A connected bus.
pub enum Link {
    /// TCP.
    Tcp(TcpCan),
    /// SocketCAN.
    #[cfg(all(feature = "socketcan", target_os = "linux"))]
    Can(odc::transport::socketcan::SocketCan),
    /// A socketcand server.
    Socketcand(Socketcand),
    /// An slcan adapter.
    Slcan(Box<Slcan>),
}

impl BusArgs {
    /// Connects.
    pub fn open(&self) -> anyhow::Result<Link> {
        if let Some(text) = &self.socketcand {
            let (addr, channel) = split_channel(text);
            let link = Socketcand::connect(addr, channel)
                .with_context(|| format!("--socketcand {text}: cannot open bus {channel}"))?;
            return Ok(Link::Socketcand(link));
        }
        match (&self.tcp, &self.can) {
            (Some(addr), _) => Ok(Link::Tcp(
                TcpCan::connect(addr.as_str())
                    .with_context(|| format!("--tcp {addr}: cannot connect"))?,
            )),
            (None, Some(iface)) => can(iface),
            (None, None) => match &self.slcan {
                Some(spec) => slcan(spec),
                None => bail!(
                    "give --tcp HOST:PORT, --can IFACE, --socketcand HOST:PORT or --slcan DEVICE"
                ),
            },
        }
    }
}

/// `--slcan DEVICE[@BITRATE]`: the adapter opened as its host.
fn slcan(spec: &str) -> anyhow::Result<Link> {
    let (device, bitrate) = parse_slcan(spec)?;
    let bus = Slcan::open(device, bitrate)
        .with_context(|| format!("--slcan {device}: cannot open the serial port"))?;
    Ok(Link::Slcan(Box::new(bus)))
}

/// `DEVICE[@BITRATE]`: the port and the bit rate (`500000`, `500k`, `1M`) of an `Sn` command.
pub fn parse_slcan(spec: &str) -> anyhow::Result<(&str, Option<Bitrate>)> {
    let Some((device, rate)) = spec.rsplit_once('@') else {
        return Ok((spec, None));
    };
    let lower = rate.to_ascii_lowercase();
    let bps = match (lower.strip_suffix('k'), lower.strip_suffix('m')) {
        (Some(k), _) => k.parse::<u32>().ok().and_then(|k| k.checked_mul(1000)),
        (_, Some(m)) => m.parse::<u32>().ok().and_then(|m| m.checked_mul(1_000_000)),
        _ => lower.parse().ok(),
    };
    let bitrate = bps.and_then(Bitrate::from_bits_per_second).with_context(|| {
        format!(
            "--slcan {spec}: `{rate}` is no slcan bit rate (S0-S8: 10k, 20k, 50k, 100k, 125k, \
             250k, 500k, 800k, 1M)"
        )
    })?;
    Ok((device, Some(bitrate)))
}

#[cfg(all(feature = "socketcan", target_os = "linux"))]
fn can(iface: &str) -> anyhow::Result<Link> {
    Ok(Link::Can(
        odc::transport::socketcan::SocketCan::open(iface)
            .with_context(|| format!("--can {iface}: cannot open the SocketCAN interface"))?,
    ))
}

#[cfg(not(all(feature = "socketcan", target_os = "linux")))]
fn can(iface: &str) -> anyhow::Result<Link> {
    bail!("--can {iface}: this odc was built without SocketCAN (Linux, cargo feature `socketcan`)")
}

impl Bus for Link {
    type Error = std::io::Error;

    fn send(&mut self, frame: &CanFrame) -> std::io::Result<()> {
        match self {
            Link::Tcp(b) => b.send(frame),
            #[cfg(all(feature = "socketcan", target_os = "linux"))]
            Link::Can(b) => b.send(frame),
            Link::Socketcand(b) => b.send(frame),
            Link::Slcan(b) => b.send(frame),
        }
    }

    fn recv(&mut self, deadline: odc::time::Instant) -> std::io::Result<Option<CanFrame>> {
        match self {
            Link::Tcp(b) => b.recv(deadline),
            #[cfg(all(feature = "socketcan", target_os = "linux"))]
            Link::Can(b) => b.recv(deadline),
            Link::Socketcand(b) => b.recv(deadline),
            Link::Slcan(b) => b.recv(deadline),
        }
    }

    fn now(&mut self) -> odc::time::Instant {
        match self {
            Link::Tcp(b) => b.now(),
            #[cfg(all(feature = "socketcan", target_os = "linux"))]
            Link::Can(b) => b.now(),
            Link::Socketcand(b) => b.now(),
            Link::Slcan(b) => b.now(),
        }
    }
}

/// `ID=FILE`: a node and the device file that describes it.
#[derive(Clone, Debug)]
pub struct NodeSpec {
    /// The node-ID.
    pub id: odc::cob::NodeId,
    /// The device file.
    pub file: PathBuf,
}

impl std::str::FromStr for NodeSpec {
    type Err = String;

    fn from_str(s: &str) -> Result<Self, String> {
        let (id, file) = s.split_once('=').ok_or("expected ID=FILE, such as 5=eds/lxm23a.eds")?;
        let id =
            parse_u8(id).and_then(odc::cob::NodeId::new).ok_or("the node-ID must be 1..=127")?;
        Ok(NodeSpec { id, file: file.into() })
    }
}

/// A number in decimal or `0x` hexadecimal.
pub fn parse_u64(s: &str) -> Option<u64> {
    let s = s.trim();
    match s.strip_prefix("0x").or_else(|| s.strip_prefix("0X")) {
        Some(h) => u64::from_str_radix(h, 16).ok(),
        None => s.parse().ok(),
    }
}

fn parse_u8(s: &str) -> Option<u8> {
    parse_u64(s).and_then(|n| u8::try_from(n).ok())
}

/// The device of a node's file (the file's one device), checked at the levels of `rules`.
pub fn load(spec: &NodeSpec, rules: &input::Rules) -> anyhow::Result<Device> {
    Ok(load_with_process_data(spec, rules)?.0)
}

/// The device of a node's file and the process data its overlay lays out
/// (`[[process-data]]`), for the monitor.
pub fn load_with_process_data(
    spec: &NodeSpec,
    rules: &input::Rules,
) -> anyhow::Result<(Device, Vec<odc_monitor::ProcessLayout>)> {
    let levels = input::Levels { rules: rules.clone(), device: None };
    let loaded = input::load(&spec.file, &levels)?;
    super::gate_bus(&loaded)?;
    let layouts = loaded
        .codegen
        .process_data
        .iter()
        .filter_map(|p| {
            let cob_base = parse_u64(&p.cob_id).and_then(|n| u32::try_from(n).ok())?;
            let fields = p.fields.iter().map(|f| (f.name.clone(), f.ty.clone())).collect();
            Some(odc_monitor::ProcessLayout { name: p.name.clone(), cob_base, fields })
        })
        .collect();
    Ok((loaded.device()?.clone(), layouts))
}
