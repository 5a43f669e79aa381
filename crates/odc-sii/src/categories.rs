//! The categories built from the ESI description (ETG.2010 layouts; each field's source is in
//! the crate documentation).

use odc_model::ethercat::{EtherCat, SmUsage};
use odc_model::{Device, Direction, Pdo, Span};

use crate::info::InfoValues;
use crate::strings::Strings;
use crate::{Error, Note};

/// Which names the categories carry (the others get string index 0).
#[derive(Clone, Copy, Debug)]
pub(crate) struct Names {
    /// PDO entry names.
    pub entries: bool,
    /// PDO names, DC op-mode names and descriptions, the device image's name.
    pub others: bool,
}

pub(crate) fn input(message: String, span: Option<Span>) -> Error {
    Error::Input { message, span }
}

pub(crate) fn general(
    device: &Device,
    ec: &EtherCat,
    extras: &InfoValues,
    names: Names,
    strings: &mut Strings,
) -> Vec<u8> {
    let mut g = vec![0u8; 32];
    // The order code is string 1: SOEM names a device by string 1, ethercrab by the order
    // index.
    g[2] = strings.index(device.device_info.order_code.as_deref().map(String::as_str));
    let name = ec.names.iter().find(|n| n.lc_id == Some(1033)).or_else(|| ec.names.first());
    g[3] = strings.index(name.map(|n| n.text.as_str()));
    g[0] = strings.index(ec.group.as_ref().map(|g| g.type_name.as_str()));
    g[1] = strings.index(extras.image.as_deref().filter(|_| names.others));
    if let Some(mb) = &ec.mailbox {
        if let Some(coe) = &mb.coe {
            g[5] = 0x01
                | u8::from(coe.sdo_info) << 1
                | u8::from(coe.pdo_assign) << 2
                | u8::from(coe.pdo_config) << 3
                | u8::from(coe.pdo_upload) << 4
                | u8::from(coe.complete_access) << 5;
        }
        g[6] = u8::from(mb.foe);
        g[7] = u8::from(mb.eoe);
        g[11] |= u8::from(mb.data_link_layer) << 2;
    }
    g[11] |= u8::from(extras.identification_reg134) << 3;
    g[11] |= u8::from(extras.identification_ado.is_some()) << 4;
    let current = extras.ebus_current.unwrap_or(0).clamp(i64::from(i16::MIN), i64::from(i16::MAX));
    g[12..14].copy_from_slice(&(current as i16).to_le_bytes());
    g[14] = g[0];
    let mut ports = 0u16;
    for (i, c) in ec.physics.as_deref().unwrap_or("").chars().take(4).enumerate() {
        let nibble = match c {
            'Y' => 1,
            'K' => 3,
            'H' => 4,
            _ => 0,
        };
        ports |= nibble << (4 * i);
    }
    g[16..18].copy_from_slice(&ports.to_le_bytes());
    let ado = extras.identification_ado.and_then(|v| u16::try_from(v).ok()).unwrap_or(0);
    g[18..20].copy_from_slice(&ado.to_le_bytes());
    g
}

/// An unknown usage text, noted (an empty `Fmmu`/`Sm` element is plainly unused).
fn unknown_usage(element: &'static str, number: usize, usage: &SmUsage, notes: &mut Vec<Note>) {
    if let SmUsage::Other(text) = usage
        && !text.is_empty()
    {
        notes.push(Note::UnknownUsage { element, number, text: text.clone() });
    }
}

pub(crate) fn fmmus(ec: &EtherCat, notes: &mut Vec<Note>) -> Vec<u8> {
    let mut out = Vec::with_capacity(ec.fmmus.len() + 1);
    for (i, f) in ec.fmmus.iter().enumerate() {
        out.push(match f.usage {
            SmUsage::Outputs => 1,
            SmUsage::Inputs => 2,
            SmUsage::MBoxState => 3,
            ref other => {
                unknown_usage("Fmmu", i, other, notes);
                0
            }
        });
    }
    if out.len() % 2 == 1 {
        out.push(0xFF);
    }
    out
}

pub(crate) fn sync_managers(ec: &EtherCat, notes: &mut Vec<Note>) -> Vec<u8> {
    let mut out = Vec::with_capacity(8 * ec.sync_managers.len());
    for (i, sm) in ec.sync_managers.iter().enumerate() {
        out.extend_from_slice(&sm.start_address.as_deref().copied().unwrap_or(0).to_le_bytes());
        let length = u16::try_from(sm.default_size.unwrap_or(0)).unwrap_or(u16::MAX);
        out.extend_from_slice(&length.to_le_bytes());
        out.push(sm.control_byte.as_deref().copied().unwrap_or(0));
        out.push(0);
        out.push(u8::from(sm.enable) | u8::from(sm.virtual_sm) << 2 | u8::from(sm.op_only) << 3);
        out.push(match sm.usage {
            SmUsage::MBoxOut => 1,
            SmUsage::MBoxIn => 2,
            SmUsage::Outputs => 3,
            SmUsage::Inputs => 4,
            ref other => {
                unknown_usage("Sm", i, other, notes);
                0
            }
        });
    }
    out
}

pub(crate) fn pdo_category(
    device: &Device,
    direction: Direction,
    names: Names,
    strings: &mut Strings,
    notes: &mut Vec<Note>,
) -> Result<Option<Vec<u8>>, Error> {
    let pdos: Vec<&Pdo> = device.pdos.iter().filter(|p| p.direction == direction).collect();
    if pdos.is_empty() {
        return Ok(None);
    }
    let mut out = Vec::new();
    for pdo in pdos {
        let count = u8::try_from(pdo.entries.len()).map_err(|_| {
            input(
                format!(
                    "PDO 0x{:04X} has {} entries; the SII counts them in a byte",
                    pdo.mapping_index,
                    pdo.entries.len()
                ),
                Some(pdo.span),
            )
        })?;
        out.extend_from_slice(&pdo.mapping_index.to_le_bytes());
        out.push(count);
        out.push(pdo.sync_manager.unwrap_or(0xFF));
        out.push(0);
        out.push(strings.index(Some(pdo.name.as_str()).filter(|_| names.others)));
        let flags = u16::from(pdo.mandatory)
            | u16::from(pdo.sync_manager.is_some()) << 1
            | u16::from(pdo.fixed) << 4;
        out.extend_from_slice(&flags.to_le_bytes());
        for e in &pdo.entries {
            let bits = u8::try_from(e.bits).map_err(|_| {
                input(
                    format!(
                        "entry 0x{:04X}:{:02X} has {} bits; the SII holds a bit length in a byte",
                        e.index, e.sub, e.bits
                    ),
                    Some(e.span),
                )
            })?;
            let data_type = match e.data_type {
                None => 0,
                Some(t) => u8::try_from(t.code()).unwrap_or_else(|_| {
                    notes.push(Note::NoTypeCode { index: e.index, sub: e.sub });
                    0
                }),
            };
            out.extend_from_slice(&e.index.to_le_bytes());
            out.push(e.sub);
            out.push(strings.index(e.name.as_deref().filter(|_| names.entries)));
            out.push(if e.is_gap() { 0 } else { data_type });
            out.push(bits);
            out.extend_from_slice(&0u16.to_le_bytes());
        }
    }
    Ok(Some(out))
}

pub(crate) fn dc_category(
    ec: &EtherCat,
    names: Names,
    strings: &mut Strings,
    notes: &mut Vec<Note>,
) -> Result<Option<Vec<u8>>, Error> {
    let Some(dc) = ec.dc.as_ref().filter(|dc| !dc.op_modes.is_empty()) else { return Ok(None) };
    let mut out = Vec::with_capacity(24 * dc.op_modes.len());
    for m in &dc.op_modes {
        if let Some(value) = m.cycle_time_sync1.filter(|&v| v != 0) {
            notes.push(Note::Sync1CycleTimeDropped { op_mode: m.name.clone(), value });
        }
        let out_of_range = |what: &str| {
            input(
                format!("DC op mode `{}`: {what} does not fit the SII field", m.name),
                Some(m.span),
            )
        };
        let shift = |v: Option<i64>, what: &str| -> Result<u32, Error> {
            let v = v.unwrap_or(0);
            // A shift time is a signed 32-bit value in the SII (two's complement).
            i32::try_from(v)
                .map(|v| v as u32)
                .or_else(|_| u32::try_from(v))
                .map_err(|_| out_of_range(what))
        };
        let factor = |v: Option<i64>, what: &str| -> Result<i16, Error> {
            i16::try_from(v.unwrap_or(0)).map_err(|_| out_of_range(what))
        };
        let assign = u16::try_from(m.assign_activate.unwrap_or(0))
            .map_err(|_| out_of_range("AssignActivate"))?;
        out.extend_from_slice(&m.cycle_time_sync0.unwrap_or(0).to_le_bytes());
        out.extend_from_slice(&shift(m.shift_time_sync0, "ShiftTimeSync0")?.to_le_bytes());
        out.extend_from_slice(&shift(m.shift_time_sync1, "ShiftTimeSync1")?.to_le_bytes());
        out.extend_from_slice(
            &factor(m.cycle_time_sync1_factor, "CycleTimeSync1@Factor")?.to_le_bytes(),
        );
        out.extend_from_slice(&assign.to_le_bytes());
        out.extend_from_slice(
            &factor(m.cycle_time_sync0_factor, "CycleTimeSync0@Factor")?.to_le_bytes(),
        );
        out.push(strings.index(Some(m.name.as_str()).filter(|_| names.others)));
        out.push(strings.index(m.desc.as_deref().filter(|_| names.others)));
        out.extend_from_slice(&[0; 4]);
    }
    Ok(Some(out))
}
