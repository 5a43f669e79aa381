//! `odc sdo read|write`: one object of a node, named and typed by its device file.

use std::process::ExitCode;

use anyhow::{Context, bail};
use odc::master::{Error as MasterError, Master};
use odc::sdo::SdoError;
use odc_model::{DataType, Device, Value};

use super::link::{BusArgs, NodeSpec, load};

/// Read or write one object of a node over SDO: OBJECT as `0x6060`, `0x1018:01` (or
/// `0x1018sub1`), or the object's name in the device file (`Controlword`,
/// `Identity object/Vendor-ID`); values parsed and printed by the file's data type. An abort
/// prints its CiA 301 meaning and exits 1.
#[derive(clap::Args)]
pub struct Args {
    #[command(subcommand)]
    op: Op,
}

#[derive(clap::Subcommand)]
enum Op {
    /// Read (upload) an object.
    Read(Common),
    /// Write (download) a value: integers in decimal or 0x hex, reals, text for strings,
    /// hex bytes (`01 02 0A`) for octet strings and domains.
    Write {
        #[command(flatten)]
        common: Common,
        /// The value (a negative number is a value, not an option).
        #[arg(allow_hyphen_values = true)]
        value: String,
    },
}

#[derive(clap::Args)]
struct Common {
    /// `ID=FILE`: the node and the device file that names and types its objects.
    #[arg(long, value_name = "ID=FILE")]
    node: NodeSpec,
    /// `0x6060`, `0x1018:01`, `0x1018sub1`, or a name from the file.
    object: String,
    #[command(flatten)]
    bus: BusArgs,
    /// How long to wait for each answer, in ms.
    #[arg(long, default_value_t = 1000)]
    timeout: u64,
    /// Rule levels for the device file.
    #[command(flatten)]
    rules: crate::input::Rules,
}

/// An object of the file, resolved.
struct Target {
    index: u16,
    sub: u8,
    name: String,
    data_type: DataType,
}

pub fn run(args: Args) -> anyhow::Result<ExitCode> {
    let (common, value) = match &args.op {
        Op::Read(c) => (c, None),
        Op::Write { common, value } => (common, Some(value.as_str())),
    };
    let device = load(&common.node, &common.rules)?;
    let target = resolve(&device, &common.object)?;
    let node = common.node.id;
    let payload = match value {
        Some(text) => Some(parse_value(text, target.data_type, node).with_context(|| {
            format!("`{text}` is no value of {} ({})", target.name, target.data_type.name())
        })?),
        None => None,
    };
    let mut master = Master::new(common.bus.open()?).with_timeout(common.timeout);
    let at = format!("0x{:04X}:{:02X} {}", target.index, target.sub, target.name);
    let result = match &payload {
        Some(bytes) => master.download(node, target.index, target.sub, bytes).map(|()| None),
        None => master.upload(node, target.index, target.sub).map(Some),
    };
    match result {
        Ok(Some(bytes)) => {
            let shown = odc_model::wire::decode(&bytes, target.data_type).map_or_else(
                || format!("{} (raw, not a {})", hex(&bytes), target.data_type.name()),
                |v| odc_monitor::show(&v),
            );
            super::out(&format!("{at} = {shown}\n"))?;
            Ok(ExitCode::SUCCESS)
        }
        Ok(None) => {
            super::out(&format!("{at} := {}\n", value.unwrap_or_default()))?;
            Ok(ExitCode::SUCCESS)
        }
        Err(MasterError::Sdo { error: SdoError::Remote(a) | SdoError::Local(a), .. }) => {
            eprintln!("error: {at}: {a}");
            Ok(ExitCode::from(1))
        }
        Err(e) => Err(anyhow::anyhow!("{at}: {e}")),
    }
}

/// `0x6060`, `0x1018:01`, `0x1018sub1`, `6060`, or a name.
fn resolve(device: &Device, spec: &str) -> anyhow::Result<Target> {
    let target = |index: u16, sub: u8| -> anyhow::Result<Target> {
        let object = device
            .objects
            .get(&index)
            .with_context(|| format!("the device file has no object 0x{index:04X}"))?;
        let s = object
            .sub(sub)
            .with_context(|| format!("object 0x{index:04X} has no sub-index 0x{sub:02X}"))?;
        let name = if object.kind.has_subs() {
            format!("{}/{}", object.name, s.name)
        } else {
            object.name.clone()
        };
        Ok(Target { index, sub, name, data_type: s.data_type })
    };
    let lower = spec.to_ascii_lowercase();
    let split = lower.split_once(':').or_else(|| lower.split_once("sub"));
    let (i, s) = split.map_or((lower.as_str(), None), |(i, s)| (i, Some(s)));
    // Indexes and sub-indexes are hexadecimal, as CiA 301 writes them (`0x` optional).
    let hex_digits = |t: &str| !t.is_empty() && t.chars().all(|c| c.is_ascii_hexdigit());
    let i = i.trim();
    let index_text = i.strip_prefix("0x").or_else(|| (i.len() == 4).then_some(i));
    if let Some(h) = index_text.filter(|h| hex_digits(h))
        && let Ok(index) = u16::from_str_radix(h, 16)
    {
        let sub = match s.map(|s| s.trim().trim_start_matches("0x")) {
            Some(t) => u8::from_str_radix(t, 16)
                .ok()
                .filter(|_| hex_digits(t))
                .with_context(|| format!("`{spec}`: the sub-index is not a hex number"))?,
            None => 0,
        };
        return target(index, sub);
    }
    // A name: an object's (its sub 0 for a VAR), `object/sub-object`, or a sub-object's
    // when only one has it.
    let mut found = Vec::new();
    for o in device.objects.values() {
        for s in o.subs.values() {
            let full = format!("{}/{}", o.name, s.name).to_ascii_lowercase();
            let var = !o.kind.has_subs() && o.name.to_ascii_lowercase() == lower;
            if var || full == lower || (o.kind.has_subs() && s.name.to_ascii_lowercase() == lower) {
                found.push((o.index, s.sub_index));
            }
        }
    }
    match found.as_slice() {
        [(i, s)] => target(*i, *s),
        [] => {
            let near: Vec<String> = device
                .objects
                .values()
                .filter(|o| o.name.to_ascii_lowercase().contains(&lower))
                .take(8)
                .map(|o| format!("0x{:04X} {}", o.index, o.name))
                .collect();
            if near.is_empty() {
                bail!("no object is called `{spec}` in the device file");
            }
            bail!("no object is called `{spec}`; did you mean one of:\n  {}", near.join("\n  "))
        }
        many => {
            let list: Vec<String> =
                many.iter().map(|(i, s)| format!("0x{i:04X}:{s:02X}")).collect();
            bail!("`{spec}` names {} entries ({}); give the index", many.len(), list.join(", "))
        }
    }
}

/// A value given on the command line, as the bytes of `dt`.
fn parse_value(text: &str, dt: DataType, node: odc::cob::NodeId) -> anyhow::Result<Vec<u8>> {
    let value = odc_eds::read_value(text, dt).map_err(|e| anyhow::anyhow!("{e:?}"))?;
    let value = match value {
        Value::NodeIdPlus(n) => Value::Signed(n + i64::from(node.get())),
        v => v,
    };
    odc_model::wire::encode(&value, dt).context("out of the type's range")
}

fn hex(bytes: &[u8]) -> String {
    bytes.iter().map(|b| format!("{b:02X}")).collect::<Vec<_>>().join(" ")
}
