//! What the bench tools (`odc sdo`, `nmt`, `lss`, `monitor`) share: the bus they talk on
//! (`--tcp` as `odc simulate` serves it, `--can` on Linux) and the devices they know
//! (`--node ID=FILE`).

use std::path::PathBuf;

use anyhow::{Context, bail};
use odc::can::CanFrame;
use odc::transport::Bus;
use odc::transport::tcp::TcpCan;
use odc_model::Device;

use crate::input;

/// The bus to use.
#[derive(clap::Args, Clone, Debug)]
#[command(group(clap::ArgGroup::new("bus").required(true).args(["tcp", "can"])))]
pub struct BusArgs {
    /// A virtual CAN bus over TCP, as `odc simulate --tcp` serves it (`localhost:PORT`,
    /// `127.0.0.1:PORT`, any host name).
    #[arg(long, value_name = "HOST:PORT")]
    pub tcp: Option<String>,
    /// A SocketCAN interface (Linux), such as `can0` or `vcan0`.
    #[arg(long, value_name = "IFACE")]
    pub can: Option<String>,
}

/// A connected bus.
pub enum Link {
    /// TCP.
    Tcp(TcpCan),
    /// SocketCAN.
    #[cfg(all(feature = "socketcan", target_os = "linux"))]
    Can(odc::transport::socketcan::SocketCan),
}

impl BusArgs {
    /// Connects.
    pub fn open(&self) -> anyhow::Result<Link> {
        match (&self.tcp, &self.can) {
            (Some(addr), _) => Ok(Link::Tcp(
                TcpCan::connect(addr.as_str())
                    .with_context(|| format!("--tcp {addr}: cannot connect"))?,
            )),
            (None, Some(iface)) => can(iface),
            (None, None) => bail!("give --tcp HOST:PORT or --can IFACE"),
        }
    }
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
        }
    }

    fn recv(&mut self, deadline: odc::time::Instant) -> std::io::Result<Option<CanFrame>> {
        match self {
            Link::Tcp(b) => b.recv(deadline),
            #[cfg(all(feature = "socketcan", target_os = "linux"))]
            Link::Can(b) => b.recv(deadline),
        }
    }

    fn now(&mut self) -> odc::time::Instant {
        match self {
            Link::Tcp(b) => b.now(),
            #[cfg(all(feature = "socketcan", target_os = "linux"))]
            Link::Can(b) => b.now(),
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
