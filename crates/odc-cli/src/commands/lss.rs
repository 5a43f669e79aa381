//! `odc lss`: layer setting services (CiA 305) from the command line.

use std::process::ExitCode;

use anyhow::bail;
use odc::lss::Identity;
use odc::master::Master;

use super::link::{BusArgs, parse_u64};

/// Find an unconfigured device and give it a node-ID, set its bit rate, store, ask who it is.
///
/// The device stays in LSS configuration state between two calls: `odc lss fastscan` and
/// then `odc lss set-id 5` configure the device the scan found.
#[derive(clap::Args)]
pub struct Args {
    /// What to do.
    action: Action,
    /// The argument of `select` (VENDOR:PRODUCT:REVISION:SERIAL, each decimal or 0x hex),
    /// `set-id` (1..=127, 255: none) and `set-bitrate` (kbit/s: 1000, 800, 500, 250, 125, 50,
    /// 20, 10).
    value: Option<String>,
    #[command(flatten)]
    bus: BusArgs,
    /// How long to wait for an answer, in ms (fastscan waits this long at each silent step).
    #[arg(long, default_value_t = 50)]
    timeout: u64,
}

#[derive(Clone, Copy, Debug, clap::ValueEnum)]
enum Action {
    /// Find one device without a node-ID (it stays in configuration state).
    Fastscan,
    /// Select the device with the LSS address given.
    Select,
    /// Every device into configuration state.
    All,
    /// Every device back to waiting state.
    Done,
    /// Give the device in configuration state the node-ID given.
    SetId,
    /// Set its bit rate.
    SetBitrate,
    /// Store its node-ID and bit rate.
    Store,
    /// Ask its LSS address and node-ID.
    Inquire,
}

/// CiA 305 table 1, bit timing table 0: the index of a bit rate.
fn bit_timing_index(kbit: u32) -> Option<u8> {
    Some(match kbit {
        1000 => 0,
        800 => 1,
        500 => 2,
        250 => 3,
        125 => 4,
        50 => 6,
        20 => 7,
        10 => 8,
        _ => return None,
    })
}

fn identity(text: &str) -> anyhow::Result<Identity> {
    let parts: Vec<u32> = text
        .split(':')
        .map(|p| parse_u64(p).and_then(|n| u32::try_from(n).ok()))
        .collect::<Option<_>>()
        .ok_or_else(|| anyhow::anyhow!("`{text}`: expected VENDOR:PRODUCT:REVISION:SERIAL"))?;
    let [vendor, product, revision, serial] = parts[..] else {
        bail!("`{text}`: expected four parts, VENDOR:PRODUCT:REVISION:SERIAL");
    };
    Ok(Identity { vendor, product, revision, serial })
}

fn show(id: &Identity) -> String {
    format!("0x{:08X}:0x{:08X}:0x{:08X}:0x{:08X}", id.vendor, id.product, id.revision, id.serial)
}

pub fn run(args: Args) -> anyhow::Result<ExitCode> {
    let mut master = Master::new(args.bus.open()?);
    let mut lss = master.lss().with_timeout(odc::time::Duration::from_millis(args.timeout));
    let e = |e: odc::master::Error<std::io::Error>| anyhow::anyhow!("{e}");
    let value =
        || args.value.clone().ok_or_else(|| anyhow::anyhow!("{:?} needs a value", args.action));
    let text = match args.action {
        Action::Fastscan => match lss.fastscan().map_err(e)? {
            Some(id) => format!("found {} (now in configuration state)", show(&id)),
            None => {
                super::out("no unconfigured device answered\n")?;
                return Ok(ExitCode::from(1));
            }
        },
        Action::Select => {
            let id = identity(&value()?)?;
            lss.switch_selective(id).map_err(e)?;
            format!("{} in configuration state", show(&id))
        }
        Action::All => {
            lss.switch_global(true).map_err(e)?;
            "every device in configuration state".into()
        }
        Action::Done => {
            lss.switch_global(false).map_err(e)?;
            "every device back in waiting state".into()
        }
        Action::SetId => {
            let id = value()?;
            let n = parse_u64(&id)
                .and_then(|n| u8::try_from(n).ok())
                .and_then(odc::cob::NodeId::from_lss)
                .ok_or_else(|| anyhow::anyhow!("`{id}`: a node-ID is 1..=127 or 255"))?;
            lss.configure_node_id(n).map_err(e)?;
            format!(
                "node-ID {} configured (it applies at the next reset communication)",
                odc::cob::NodeId::to_lss(n)
            )
        }
        Action::SetBitrate => {
            let text = value()?;
            let kbit: u32 =
                text.parse().map_err(|_| anyhow::anyhow!("`{text}`: a bit rate in kbit/s"))?;
            let Some(index) = bit_timing_index(kbit) else {
                bail!(
                    "{kbit} kbit/s is not in CiA 305's table (1000, 800, 500, 250, 125, 50, 20, 10)"
                );
            };
            lss.configure_bit_timing(0, index).map_err(e)?;
            format!("bit timing {kbit} kbit/s (table 0, index {index}) configured")
        }
        Action::Store => {
            lss.store().map_err(e)?;
            "configuration stored".into()
        }
        Action::Inquire => {
            let id = lss.inquire_identity().map_err(e)?;
            let node = lss.inquire_node_id().map_err(e)?;
            format!("{} node-ID {}", show(&id), odc::cob::NodeId::to_lss(node))
        }
    };
    super::out(&format!("{text}\n"))?;
    Ok(ExitCode::SUCCESS)
}
