//! `odc sdo read|write`: one object of a node, named and typed by its device file.

use std::process::ExitCode;

use anyhow::{Context, bail};
use odc::master::{Error as MasterError, Master};
use odc::sdo::SdoError;
use odc_model::{DataType, Device, Value};

use super::link::{BusArgs, NodeSpec, load};

/// Read or write one object of a node over SDO: OBJECT as `0x6060`, `0x1018:01` (or
/// `0x1018sub1`), or the object's name in the device file (`Controlword`,
/// `Identity object/Vendor-ID`; a record's or array's name reads each sub-object); values
/// parsed and printed by the file's data type. An index the file lacks is still read (raw
/// bytes) or written (hex bytes). A name the file lacks is answered with the near ones (edit
/// distance). An abort prints its CiA 301 meaning and exits 1.
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

/// An object of the node, resolved: by the file when it has it.
struct Target {
    index: u16,
    sub: u8,
    name: String,
    /// `None`: the file does not have it (read raw, written as hex bytes).
    data_type: Option<DataType>,
}

pub fn run(args: Args) -> anyhow::Result<ExitCode> {
    let (common, value) = match &args.op {
        Op::Read(c) => (c, None),
        Op::Write { common, value } => (common, Some(value.as_str())),
    };
    let device = load(&common.node, &common.rules)?;
    let targets = resolve(&device, &common.object)?;
    let node = common.node.id;
    let mut master = Master::new(common.bus.open()?)
        .with_timeout(odc::time::Duration::from_millis(common.timeout));
    let Some(text) = value else {
        let mut code = ExitCode::SUCCESS;
        for target in &targets {
            if !read(&mut master, node, target)? {
                code = ExitCode::from(1);
            }
        }
        return Ok(code);
    };
    let [target] = &targets[..] else {
        let subs: Vec<String> = targets.iter().map(|t| format!("`{}`", t.name)).collect();
        bail!("`{}` has sub-objects; write one of them: {}", common.object, subs.join(", "));
    };
    // An object the file lacks takes hex bytes, as an octet string.
    let dt = target.data_type.unwrap_or(DataType::OctetString);
    let payload = parse_value(text, dt, node)
        .with_context(|| format!("`{text}` is no value of {} ({})", target.name, dt.name()))?;
    let at = at(target);
    match master.download(node, target.index, target.sub, &payload) {
        Ok(()) => {
            super::out(&format!("{at} := {text}\n"))?;
            Ok(ExitCode::SUCCESS)
        }
        Err(MasterError::Sdo { error: SdoError::Remote(a) | SdoError::Local(a), .. }) => {
            eprintln!("error: {at}: {a}");
            Ok(ExitCode::from(1))
        }
        // No response: the master's error says whether the node was heard at all.
        Err(e @ MasterError::Timeout { .. }) => {
            eprintln!("error: {at}: {e}");
            Ok(ExitCode::from(1))
        }
        Err(e) => Err(anyhow::anyhow!("{at}: {e}")),
    }
}

/// `0x6081:00 Profile velocity`.
fn at(target: &Target) -> String {
    format!("0x{:04X}:{:02X} {}", target.index, target.sub, target.name)
}

/// Reads and prints one entry; `false` when the node aborted or did not answer.
fn read<B: odc::transport::Bus<Error = std::io::Error>>(
    master: &mut Master<B>,
    node: odc::cob::NodeId,
    target: &Target,
) -> anyhow::Result<bool> {
    let at = at(target);
    match master.upload(node, target.index, target.sub) {
        Ok(bytes) => {
            let shown = match target.data_type {
                Some(dt) => odc_model::wire::decode(&bytes, dt).map_or_else(
                    || format!("{} (raw, not a {})", hex(&bytes), dt.name()),
                    |v| odc_monitor::show(&v),
                ),
                None => format!("{} (raw)", hex(&bytes)),
            };
            super::out(&format!("{at} = {shown}\n"))?;
            Ok(true)
        }
        Err(MasterError::Sdo { error: SdoError::Remote(a) | SdoError::Local(a), .. }) => {
            eprintln!("error: {at}: {a}");
            Ok(false)
        }
        // No response: the master's error says whether the node was heard at all.
        Err(e @ MasterError::Timeout { .. }) => {
            eprintln!("error: {at}: {e}");
            Ok(false)
        }
        Err(e) => Err(anyhow::anyhow!("{at}: {e}")),
    }
}

/// `0x6060`, `0x1018:01`, `0x1018sub1`, `6060`, or a name: one entry, or every sub-object of
/// a record or array named as a whole (for a read).
fn resolve(device: &Device, spec: &str) -> anyhow::Result<Vec<Target>> {
    let target = |index: u16, sub: u8| -> Target {
        let Some(object) = device.objects.get(&index) else {
            return Target { index, sub, name: "(not in the device file)".into(), data_type: None };
        };
        let Some(s) = object.sub(sub) else {
            let name = format!("{}/(sub-index not in the device file)", object.name);
            return Target { index, sub, name, data_type: None };
        };
        let name = if object.kind.has_subs() {
            format!("{}/{}", object.name, s.name)
        } else {
            object.name.clone()
        };
        Target { index, sub, name, data_type: Some(s.data_type) }
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
        // An index the file lacks is still read from the node (raw bytes).
        return Ok(vec![target(index, sub)]);
    }
    // A name: an object's (its sub 0 for a VAR, every sub-object for a record or array),
    // `object/sub-object`, or a sub-object's when only one has it.
    let mut found = Vec::new();
    for o in device.objects.values() {
        if o.kind.has_subs() && o.name.to_ascii_lowercase() == lower {
            return Ok(o.subs.keys().map(|&s| target(o.index, s)).collect());
        }
        for s in o.subs.values() {
            let full = format!("{}/{}", o.name, s.name).to_ascii_lowercase();
            let var = !o.kind.has_subs() && o.name.to_ascii_lowercase() == lower;
            if var || full == lower || (o.kind.has_subs() && s.name.to_ascii_lowercase() == lower) {
                found.push((o.index, s.sub_index));
            }
        }
    }
    match found.as_slice() {
        [(i, s)] => Ok(vec![target(*i, *s)]),
        [] => {
            let near = near_names(device, &lower);
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

/// The file's names nearest to `lower` (lower case): those that contain it, then those within
/// a small edit distance (a typo), best first, at most 8, as `0x6081 Profile velocity`.
fn near_names(device: &Device, lower: &str) -> Vec<String> {
    let mut scored: Vec<(f64, String)> = Vec::new();
    for o in device.objects.values() {
        let name = o.name.to_ascii_lowercase();
        let score = if name.contains(lower) {
            2.0
        } else {
            strsim::normalized_damerau_levenshtein(&name, lower)
        };
        if score >= 0.7 {
            scored.push((score, format!("0x{:04X} {}", o.index, o.name)));
        }
    }
    // Stable: equal scores keep the file's order (by index).
    scored.sort_by(|a, b| b.0.total_cmp(&a.0));
    scored.into_iter().take(8).map(|(_, s)| s).collect()
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
