//! A CANopen bus in the words of its device files (`odc monitor`): every frame one
//! [`Record`], decoded by the predefined connection set of CiA 301 and the devices known by
//! node-ID: NMT commands, boot-up and heartbeat states, SDO requests and answers with the
//! object's name and typed value (segmented and block transfers put back together), PDOs split
//! into named, typed fields by the device's mapping (following remaps seen on the bus: SDO
//! writes to 0x1400–0x1BFF), EMCY with its meaning, SYNC, TIME, LSS. A frame nothing explains
//! is shown raw, never dropped.
//!
//! - [`Decoder`]: frames in, records out;
//! - [`candump`]: the lines of a candump log.
#![cfg_attr(not(test), deny(clippy::unwrap_used, clippy::expect_used, clippy::panic))]

pub mod candump;
mod pdo;
mod sdo;

use std::collections::BTreeMap;
use std::fmt;

use odc::can::CanFrame;
use odc_model::{DataType, Device, Value};
use serde::Serialize;

/// One named, typed value of a frame (a PDO field, an SDO transfer's value).
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Field {
    /// `0x6041:00`.
    pub object: String,
    /// The object's name in the device file (empty when unknown).
    pub name: String,
    /// The value as a person reads it.
    pub value: String,
}

/// A frame, decoded.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Record {
    /// Seconds (from the log, or since the monitor started).
    pub time: Option<f64>,
    /// CAN-ID.
    pub id: u32,
    /// Extended (29-bit) frame.
    #[serde(skip_serializing_if = "std::ops::Not::not")]
    pub extended: bool,
    /// Remote frame.
    #[serde(skip_serializing_if = "std::ops::Not::not")]
    pub remote: bool,
    /// The data bytes in hex.
    pub data: String,
    /// What the frame is (`NMT`, `SYNC`, `EMCY`, `TPDO1`, `SDO request`, `heartbeat`, …, or
    /// `unknown`).
    pub kind: String,
    /// The node it concerns.
    pub node: Option<u8>,
    /// What it says.
    pub text: String,
    /// Its values.
    #[serde(skip_serializing_if = "Vec::is_empty")]
    pub fields: Vec<Field>,
}

impl fmt::Display for Record {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        if let Some(t) = self.time {
            write!(f, "{t:>17.6}  ")?;
        }
        let id =
            if self.extended { format!("{:08X}", self.id) } else { format!("{:03X}", self.id) };
        write!(f, "{id:>8}  {:<23}  {}", self.data, self.kind)?;
        if let Some(n) = self.node {
            write!(f, " node {n}")?;
        }
        if !self.text.is_empty() {
            write!(f, ": {}", self.text)?;
        }
        for (k, field) in self.fields.iter().enumerate() {
            let sep = if k == 0 && self.text.is_empty() {
                ": "
            } else if k == 0 {
                " "
            } else {
                ", "
            };
            let name =
                if field.name.is_empty() { field.object.as_str() } else { field.name.as_str() };
            write!(f, "{sep}{name} = {}", field.value)?;
        }
        Ok(())
    }
}

/// Process data a device file cannot map, as its overlay lays it out (`[[process-data]]`:
/// named fields, byte-packed, little-endian; LinMot's built-in Control Word and motion command
/// words): frames on `$NODEID + cob_base` split into those fields.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct ProcessLayout {
    /// The layout's name (`RxPdo1`).
    pub name: String,
    /// CAN-ID minus the node-ID.
    pub cob_base: u32,
    /// Field names and types (`u8`, `u16`, `u32`, `i8`, `i16`, `i32`), in wire order.
    pub fields: Vec<(String, String)>,
}

/// What the decoder knows of a node: its device, its PDO mappings as they are now, and its
/// overlay's process data.
struct Node {
    device: Device,
    pdos: pdo::Mappings,
    process: Vec<ProcessLayout>,
}

/// Frames in, records out.
pub struct Decoder {
    nodes: BTreeMap<u8, Node>,
    sdo: sdo::Sdo,
}

impl Decoder {
    /// A decoder that knows these devices by node-ID.
    pub fn new(devices: Vec<(u8, Device)>) -> Self {
        let nodes = devices
            .into_iter()
            .map(|(id, device)| {
                let pdos = pdo::Mappings::of(&device, id);
                (id, Node { device, pdos, process: Vec::new() })
            })
            .collect();
        Decoder { nodes, sdo: sdo::Sdo::default() }
    }

    /// Also splits the frames of `node` that its overlay lays out (the device file maps
    /// nothing there).
    pub fn with_process_data(mut self, node: u8, layouts: Vec<ProcessLayout>) -> Self {
        if let Some(n) = self.nodes.get_mut(&node) {
            n.process = layouts;
        }
        self
    }

    /// One frame.
    pub fn decode(&mut self, frame: &CanFrame, time: Option<f64>) -> Record {
        let data: Vec<String> = frame.bytes().iter().map(|b| format!("{b:02X}")).collect();
        let mut r = Record {
            time,
            id: frame.id(),
            extended: frame.is_extended(),
            remote: frame.is_remote(),
            data: if frame.is_remote() {
                format!("remote, {} bytes", frame.len())
            } else {
                data.join(" ")
            },
            kind: "unknown".into(),
            node: None,
            text: String::new(),
            fields: Vec::new(),
        };
        if frame.is_extended() {
            r.kind = "extended".into();
            return r;
        }
        let b = frame.bytes();
        let id = frame.id();
        let node_of = |base: u32| u8::try_from(id - base).ok();
        match id {
            0x000 => {
                r.kind = "NMT".into();
                let cmd = b.first().copied().and_then(odc::nmt::NmtCommand::from_u8);
                let target = b.get(1).copied();
                r.text = match (cmd, target) {
                    (Some(c), Some(0)) => format!("{c:?} all nodes"),
                    (Some(c), Some(n)) => {
                        r.node = Some(n);
                        format!("{c:?}")
                    }
                    _ => "not an NMT command".into(),
                };
            }
            0x080 => {
                r.kind = "SYNC".into();
                if let Some(c) = b.first() {
                    r.text = format!("counter {c}");
                }
            }
            0x081..=0x0FF => {
                r.kind = "EMCY".into();
                r.node = node_of(0x80);
                r.text = match odc::emcy::EmcyFrame::decode(b) {
                    Ok(e) => format!(
                        "{} {:?} class (error register 0x{:02X}), manufacturer bytes {}",
                        e.code,
                        e.code.class(),
                        e.register.0,
                        e.manufacturer
                            .iter()
                            .map(|b| format!("{b:02X}"))
                            .collect::<Vec<_>>()
                            .join(" ")
                    ),
                    Err(e) => e.to_string(),
                };
            }
            0x100 => r.kind = "TIME".into(),
            0x181..=0x57F => self.pdo(&mut r, b),
            0x581..=0x5FF | 0x601..=0x67F => {
                let request = id >= 0x600;
                let node = node_of(if request { 0x600 } else { 0x580 }).unwrap_or(0);
                r.kind = if request { "SDO request" } else { "SDO response" }.into();
                r.node = Some(node);
                let said = self.sdo.frame(node, request, b);
                r.text = said.text;
                if let Some((i, s)) = said.addr {
                    let name = self.name(node, i, s);
                    let at = format!("0x{i:04X}:{s:02X}");
                    // The name once: in the text, or with the value when there is one; the
                    // address once: a value without a name is shown at its address.
                    r.text = if name.is_empty() && said.done.is_some() {
                        r.text
                    } else if name.is_empty() || said.done.is_some() {
                        format!("{} {at}", r.text)
                    } else {
                        format!("{} {at} {name}", r.text)
                    };
                }
                if let Some((i, s, bytes, write)) = said.done {
                    let value = self.value(node, i, s, &bytes);
                    let object = format!("0x{i:04X}:{s:02X}");
                    r.fields.push(Field { object, name: self.name(node, i, s), value });
                    if write {
                        self.remapped(node, i, s, &bytes);
                    }
                }
            }
            0x701..=0x77F => {
                r.node = node_of(0x700);
                r.kind = "heartbeat".into();
                r.text = match b {
                    [0] => "boot-up".into(),
                    [s] => odc::nmt::NmtState::from_u8(*s).map_or_else(
                        || format!("state 0x{s:02X}?"),
                        |st| {
                            let toggle = if s & 0x80 != 0 { " (toggle 1)" } else { "" };
                            format!("{st:?}{toggle}")
                        },
                    ),
                    [] if frame.is_remote() => "guarding request".into(),
                    _ => "not a heartbeat".into(),
                };
                if frame.is_remote() {
                    r.text = "node guarding request".into();
                }
            }
            0x7E5 => {
                r.kind = "LSS request".into();
                r.text = odc::lss::Request::decode(b)
                    .map_or_else(|| "not an LSS request".into(), |q| format!("{q:?}"));
            }
            0x7E4 => {
                r.kind = "LSS response".into();
                r.text = odc::lss::Response::decode(b)
                    .map_or_else(|| "not an LSS response".into(), |q| format!("{q:?}"));
            }
            _ => {}
        }
        r
    }

    /// The name of `index:sub` in `node`'s device file (`object/sub-object` in a record).
    fn name(&self, node: u8, index: u16, sub: u8) -> String {
        let Some(o) = self.nodes.get(&node).and_then(|n| n.device.objects.get(&index)) else {
            return String::new();
        };
        match (o.kind.has_subs(), o.sub(sub)) {
            (true, Some(s)) => format!("{}/{}", o.name, s.name),
            _ => o.name.clone(),
        }
    }

    fn data_type(&self, node: u8, index: u16, sub: u8) -> Option<DataType> {
        self.nodes.get(&node)?.device.objects.get(&index)?.sub(sub).map(|s| s.data_type)
    }

    /// A value by its type in the device file; hex bytes when unknown or not of the type.
    fn value(&self, node: u8, index: u16, sub: u8, bytes: &[u8]) -> String {
        let raw = || bytes.iter().map(|b| format!("{b:02X}")).collect::<Vec<_>>().join(" ");
        let Some(dt) = self.data_type(node, index, sub) else { return raw() };
        // An expedited answer without size may carry 4 bytes for a narrower type.
        let bits = dt.bit_size().map(|b| (b as usize).div_ceil(8));
        let bytes = match bits {
            Some(n) if bytes.len() > n && bytes.len() == 4 => bytes.get(..n).unwrap_or(bytes),
            _ => bytes,
        };
        let shown = odc_model::wire::decode(bytes, dt).map_or_else(raw, |v| show(&v));
        match (index, bytes) {
            (0x6040 | 0x6041, [lo, hi]) => {
                format!("{shown}{}", cia402(index, u16::from_le_bytes([*lo, *hi])))
            }
            (0x6060 | 0x6061, [v]) => format!("{shown} ({})", mode_name(i8::from_le_bytes([*v]))),
            _ => shown,
        }
    }

    /// An SDO write that changes a PDO's COB-ID or mapping: the decoder follows it.
    fn remapped(&mut self, node: u8, index: u16, sub: u8, bytes: &[u8]) {
        if let Some(n) = self.nodes.get_mut(&node) {
            n.pdos.sdo_write(node, index, sub, bytes);
        }
    }

    fn pdo(&self, r: &mut Record, b: &[u8]) {
        let (kind, node) = pdo::name(r.id);
        r.kind = kind;
        r.node = node;
        for (n, known) in &self.nodes {
            let layout = known.process.iter().find(|l| l.cob_base + u32::from(*n) == r.id);
            if let Some(l) = layout {
                r.node = Some(*n);
                r.text = l.name.clone();
                r.fields = pdo::process_fields(l, b);
                return;
            }
            if let Some(m) = known.pdos.by_cob(r.id) {
                r.node = Some(*n);
                r.fields = m.fields(&known.device, b);
                if m.bits.div_ceil(8) as usize != b.len() {
                    r.text = format!("{} bytes, the mapping has {} bits", b.len(), m.bits);
                }
                return;
            }
        }
    }
}

/// The CiA 402 name of a mode of operation (0x6060, 0x6061): `Profile position mode (pp)`.
pub(crate) fn mode_name(v: i8) -> &'static str {
    match odc_analysis::cia402::MODES.iter().find(|m| m.value == v) {
        Some(m) => m.text.trim_end_matches('.'),
        None if v == 0 => "no mode",
        None if v < 0 => "manufacturer-specific",
        None => "reserved",
    }
}

/// What a CiA 402 controlword (0x6040) commands or a statusword (0x6041) reports, as a
/// suffix of its value: ` (shutdown)`, ` (operation enabled)`.
pub(crate) fn cia402(index: u16, word: u16) -> String {
    match index {
        0x6040 => format!(" ({:?})", odc::cia402::Controlword(word).command()),
        0x6041 => {
            odc::cia402::Statusword(word).state().map_or_else(String::new, |s| format!(" ({s})"))
        }
        _ => String::new(),
    }
}

/// A value as a person reads it: integers in decimal (unsigned also in hex), reals, quoted
/// text, bytes in hex.
pub fn show(v: &Value) -> String {
    match v {
        Value::Bool(b) => b.to_string(),
        Value::Unsigned(u) => format!("{u} (0x{u:X})"),
        Value::Signed(i) => i.to_string(),
        Value::Real32(bits) => f32::from_bits(*bits).to_string(),
        Value::Real64(bits) => f64::from_bits(*bits).to_string(),
        Value::Text(t) => format!("{t:?}"),
        Value::Bytes(b) => b.iter().map(|b| format!("{b:02X}")).collect::<Vec<_>>().join(" "),
        Value::Unicode(u) => format!("{:?}", String::from_utf16_lossy(u)),
        Value::Time { ms, days } => format!("{days} days {ms} ms"),
        Value::NodeIdPlus(n) => format!("$NODEID+{n}"),
        Value::Invalid(t) => format!("invalid `{t}`"),
    }
}
