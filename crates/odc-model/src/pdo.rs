//! PDOs: the process data a device exchanges cyclically, in one shape for both buses.

use serde::Serialize;

use crate::device::Device;
use crate::span::Span;
use crate::types::{DataType, Direction};
use crate::value::Value;

/// One PDO of the default mapping.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Pdo {
    /// Receive (master → device) or transmit (device → master).
    pub direction: Direction,
    /// The mapping object: 0x1600–0x17FF (Rx) or 0x1A00–0x1BFF (Tx).
    #[serde(serialize_with = "crate::hex::index")]
    pub mapping_index: u16,
    /// CANopen: the communication object 0x1400–0x15FF / 0x1800–0x19FF, when present.
    #[serde(serialize_with = "crate::hex::index_opt")]
    pub comm_index: Option<u16>,
    /// The name the file gives the PDO (ESI `Name`, EDS mapping object `ParameterName`).
    pub name: String,
    /// CANopen COB-ID (communication sub 1), possibly `$NODEID`-relative.
    pub cob_id: Option<Value>,
    /// CANopen transmission type (communication sub 2).
    pub transmission_type: Option<u8>,
    /// CANopen inhibit time in 100 µs (communication sub 3).
    pub inhibit_time: Option<u16>,
    /// CANopen event timer in ms (communication sub 5).
    pub event_timer: Option<u16>,
    /// CANopen SYNC start value (communication sub 6).
    pub sync_start: Option<u8>,
    /// The mapped entries in wire order.
    pub entries: Vec<PdoEntry>,
    /// EtherCAT: the sync manager that carries the PDO by default.
    pub sync_manager: Option<u8>,
    /// EtherCAT: the mapping cannot be changed.
    pub fixed: bool,
    /// EtherCAT: the PDO must be assigned.
    pub mandatory: bool,
    /// EtherCAT: PDOs that cannot be assigned together with this one.
    pub excludes: Vec<u16>,
    /// Where the PDO is defined (mapping object section or `<RxPdo>` element).
    pub span: Span,
}

impl Pdo {
    /// Total mapped length in bits.
    pub fn bits(&self) -> u32 {
        self.entries.iter().map(|e| u32::from(e.bits)).sum()
    }
}

/// One mapping entry: an object (or a gap) of a given length.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct PdoEntry {
    /// Index of the mapped object; a CANopen dummy entry maps a data-type index (0x0001–0x0007),
    /// an EtherCAT gap has index 0.
    #[serde(serialize_with = "crate::hex::index")]
    pub index: u16,
    /// Sub-index of the mapped object.
    #[serde(serialize_with = "crate::hex::sub")]
    pub sub: u8,
    /// Length in bits.
    pub bits: u16,
    /// ESI entry name.
    pub name: Option<String>,
    /// ESI entry data type.
    pub data_type: Option<DataType>,
    /// Where the entry is written.
    pub span: Span,
}

impl PdoEntry {
    /// Whether the entry only fills space (CANopen dummy mapping or EtherCAT gap).
    pub fn is_gap(&self) -> bool {
        self.index < 0x1000
    }

    /// Decodes a CANopen mapping value `0xIIIISSLL`.
    pub fn from_mapping_value(value: u32, span: Span) -> PdoEntry {
        PdoEntry {
            index: (value >> 16) as u16,
            sub: (value >> 8) as u8,
            bits: (value & 0xFF) as u16,
            name: None,
            data_type: None,
            span,
        }
    }

    /// The CANopen mapping value `0xIIIISSLL`.
    pub fn mapping_value(&self) -> u32 {
        (u32::from(self.index) << 16) | (u32::from(self.sub) << 8) | u32::from(self.bits & 0xFF)
    }
}

/// Reads the default PDO mapping of a CANopen device from its 0x1400–0x1BFF objects.
///
/// A mapping object defines a PDO when its sub 0 (the entry count) has a value; entries whose
/// value is not a number are skipped here and reported by the checker. The value the device
/// starts with is used: ParameterValue (DCF) over DefaultValue.
pub fn resolve_canopen_pdos(dev: &Device) -> Vec<Pdo> {
    let mut pdos = Vec::new();
    for (&index, object) in dev.objects.range(0x1600..=0x1BFF) {
        let (direction, comm_index) = match index {
            0x1600..=0x17FF => (Direction::Rx, index - 0x200),
            0x1A00..=0x1BFF => (Direction::Tx, index - 0x200),
            _ => continue,
        };
        let Some(count) = object.sub(0).and_then(initial_u64) else { continue };
        let entries = (1..=count.min(0x40))
            .filter_map(|sub| {
                let s = object.sub(sub as u8)?;
                let value = initial_u64(s)?;
                // The entry is where its value is written (`DefaultValue=`, `ParameterValue=`
                // or a `[IIIIValue]` line), else the sub-object.
                let span = s.initial_value().map_or(s.span, |v| v.span);
                let span = if span.is_dummy() { s.span } else { span };
                Some(PdoEntry::from_mapping_value(value as u32, span))
            })
            .collect();
        let comm = dev.objects.get(&comm_index);
        let comm_value = |sub: u8| comm.and_then(|c| c.sub(sub)).and_then(|s| s.initial_value());
        let comm_u64 = |sub: u8| comm.and_then(|c| c.sub(sub)).and_then(initial_u64);
        pdos.push(Pdo {
            direction,
            mapping_index: index,
            comm_index: comm.map(|_| comm_index),
            name: object.name.clone(),
            cob_id: comm_value(1).map(|v| v.value.clone()),
            transmission_type: comm_u64(2).map(|v| v as u8),
            inhibit_time: comm_u64(3).map(|v| v as u16),
            event_timer: comm_u64(5).map(|v| v as u16),
            sync_start: comm_u64(6).map(|v| v as u8),
            entries,
            sync_manager: None,
            fixed: false,
            mandatory: false,
            excludes: Vec::new(),
            span: object.span,
        });
    }
    pdos
}

fn initial_u64(sub: &crate::SubObject) -> Option<u64> {
    match sub.initial_value()?.value {
        Value::Unsigned(u) => Some(u),
        Value::Signed(i) => u64::try_from(i).ok(),
        _ => None,
    }
}
