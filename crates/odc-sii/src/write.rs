//! Building an SII image from an ESI device (the layout and every field's source are in the
//! crate documentation).

use std::fmt;

use odc_model::ethercat::{EtherCat, SmUsage, SyncManager as EsiSm};
use odc_model::{Device, Direction, Pdo, Span};

use crate::info::{InfoValues, info_values};
use crate::{Error, INFO_AREA, category, crc8, protocol};

/// Something the image does not carry exactly as the ESI says, though it could be written.
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum Note {
    /// `ConfigData` gives a checksum (its bytes 14–15) that is not the CRC-8 of its first 14
    /// bytes; the image has the computed one.
    ChecksumDiffers {
        /// The ESI's checksum byte.
        given: u8,
        /// The checksum written.
        computed: u8,
    },
    /// The strings category is full (255 strings): this text has index 0 (no string).
    StringTableFull(String),
    /// A text longer than 255 bytes, cut to 255.
    StringCut(String),
    /// A PDO entry whose data type has no one-byte CoE code: written as 0.
    NoTypeCode {
        /// PDO entry index.
        index: u16,
        /// PDO entry sub-index.
        sub: u8,
    },
    /// `ByteSize` is not a whole number of KiBit (128 bytes): the size word rounds down.
    SizeNotWholeKibit(u32),
    /// An `Fmmu` or `Sm` whose text is none of the usages ETG.2010 codes: written as 0
    /// (unused).
    UnknownUsage {
        /// `Fmmu` or `Sm`.
        element: &'static str,
        /// Its position (0-based).
        number: usize,
        /// Its text.
        text: String,
    },
    /// A DC op mode's `CycleTimeSync1` value: the DC category has a field for its factor only.
    Sync1CycleTimeDropped {
        /// The op mode's name.
        op_mode: String,
        /// The value left out.
        value: u32,
    },
}

impl fmt::Display for Note {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Note::ChecksumDiffers { given, computed } => write!(
                f,
                "`ConfigData` gives checksum 0x{given:02X}; the CRC-8 of its first 14 bytes \
                 is 0x{computed:02X}, written instead"
            ),
            Note::StringTableFull(t) => {
                write!(f, "the strings category is full (255 strings): \"{t}\" has no string")
            }
            Note::StringCut(t) => write!(f, "\"{t}\" is longer than 255 bytes: cut to 255"),
            Note::NoTypeCode { index, sub } => write!(
                f,
                "entry 0x{index:04X}:{sub:02X}: its data type has no one-byte CoE code, written as 0"
            ),
            Note::UnknownUsage { element, number, text } => write!(
                f,
                "{element} {number}: `{text}` is not a usage the SII codes, written as 0 (unused)"
            ),
            Note::Sync1CycleTimeDropped { op_mode, value } => write!(
                f,
                "DC op mode `{op_mode}`: `CycleTimeSync1` {value} has no field in the SII DC \
                 category (only its factor), left out"
            ),
            Note::SizeNotWholeKibit(n) => write!(
                f,
                "`ByteSize` {n} is not a multiple of 128 bytes: the size word says {} bytes",
                n / 128 * 128
            ),
        }
    }
}

/// The SII image of an ESI device.
pub fn write(device: &Device) -> Result<Vec<u8>, Error> {
    write_with_notes(device).map(|(image, _)| image)
}

/// [`write()`], with what the image could not carry exactly as the ESI says.
///
/// A device whose ESI gives the whole image (`Eeprom/Data`, without `ConfigData`) gets that
/// image as it is; [`write_from_description`] builds one from the description instead.
pub fn write_with_notes(device: &Device) -> Result<(Vec<u8>, Vec<Note>), Error> {
    let ec = device.ethercat.as_deref().ok_or(Error::NotEtherCat)?;
    if let Some(ee) = &ec.eeprom
        && !ee.data.is_empty()
        && ee.config_data.is_empty()
    {
        if ee.data.len() < INFO_AREA {
            return Err(input(
                format!(
                    "`Eeprom/Data` has {} bytes, less than the 128-byte info area",
                    ee.data.len()
                ),
                ee.spans.data,
            ));
        }
        return Ok((ee.data.clone(), Vec::new()));
    }
    write_from_description(device)
}

/// The image built from the device's description (identity, `ConfigData`, SMs, PDOs, ...),
/// even where the ESI also gives a whole image (`Eeprom/Data`): to compare the two.
pub fn write_from_description(device: &Device) -> Result<(Vec<u8>, Vec<Note>), Error> {
    let ec = device.ethercat.as_deref().ok_or(Error::NotEtherCat)?;
    let mut notes = Vec::new();
    let mut image = info_area(ec, &mut notes)?;
    let extras = info_values(ec);
    let mut strings = Strings::default();
    // Device strings first: they matter most when the table fills up.
    let general = general(device, ec, &extras, &mut strings);
    let tx = pdo_category(device, Direction::Tx, &mut strings, &mut notes)?;
    let rx = pdo_category(device, Direction::Rx, &mut strings, &mut notes)?;
    let dc = dc_category(ec, &mut strings, &mut notes)?;
    notes.append(&mut strings.notes);

    push_category(&mut image, category::STRINGS, &strings.bytes(), None)?;
    push_category(&mut image, category::GENERAL, &general, None)?;
    if !ec.fmmus.is_empty() {
        push_category(&mut image, category::FMMU, &fmmus(ec, &mut notes), None)?;
    }
    if !ec.sync_managers.is_empty() {
        let sms = sync_managers(ec, &mut notes);
        push_category(&mut image, category::SYNC_MANAGER, &sms, None)?;
    }
    for (kind, data) in [(category::TX_PDO, tx), (category::RX_PDO, rx), (category::DC, dc)] {
        if let Some(data) = data {
            push_category(&mut image, kind, &data, None)?;
        }
    }
    for c in ec.eeprom.iter().flat_map(|ee| &ee.categories) {
        if is_standard(c.cat_no) {
            return Err(input(
                format!(
                    "vendor category `CatNo` {} is a category odc writes from the ESI itself",
                    c.cat_no
                ),
                Some(c.span),
            ));
        }
        push_category(&mut image, c.cat_no, &c.data, Some(c.span))?;
    }
    image.extend_from_slice(&category::END.to_le_bytes());
    finish_size(&mut image, ec, &mut notes)?;
    Ok((image, notes))
}

fn input(message: String, span: Option<Span>) -> Error {
    Error::Input { message, span }
}

fn is_standard(cat_no: u16) -> bool {
    use category::*;
    matches!(
        cat_no,
        STRINGS | DATA_TYPES | GENERAL | FMMU | SYNC_MANAGER | TX_PDO | RX_PDO | DC | END
    )
}

fn put16(image: &mut [u8], at: usize, v: u16) {
    if let Some(dst) = image.get_mut(at..at + 2) {
        dst.copy_from_slice(&v.to_le_bytes());
    }
}

fn put32(image: &mut [u8], at: usize, v: u32) {
    if let Some(dst) = image.get_mut(at..at + 4) {
        dst.copy_from_slice(&v.to_le_bytes());
    }
}

/// Words 0x00–0x3F, without the size word (set by [`finish_size`]).
fn info_area(ec: &EtherCat, notes: &mut Vec<Note>) -> Result<Vec<u8>, Error> {
    let mut image = vec![0u8; INFO_AREA];
    if let Some(ee) = &ec.eeprom {
        let config = &ee.config_data;
        if config.len() > 16 {
            return Err(input(
                format!(
                    "`ConfigData` has {} bytes; SII words 0–7 hold 16 (14 and the checksum)",
                    config.len()
                ),
                ee.spans.config_data,
            ));
        }
        let n = config.len().min(14);
        image[..n].copy_from_slice(&config[..n]);
        let computed = crc8(&image[..14]);
        if let Some(&given) = config.get(14)
            && given != computed
        {
            notes.push(Note::ChecksumDiffers { given, computed });
        }
        if !ee.boot_strap.is_empty() {
            if ee.boot_strap.len() != 8 {
                return Err(input(
                    format!(
                        "`BootStrap` has {} bytes; SII words 0x14–0x17 hold 8",
                        ee.boot_strap.len()
                    ),
                    ee.spans.boot_strap,
                ));
            }
            image[0x28..0x30].copy_from_slice(&ee.boot_strap);
        }
    }
    image[14] = crc8(&image[..14]);
    put32(&mut image, 0x10, ec.vendor_id.unwrap_or(0));
    put32(&mut image, 0x14, ec.product_code.unwrap_or(0));
    put32(&mut image, 0x18, ec.revision.unwrap_or(0));
    put32(&mut image, 0x1C, ec.serial_no.unwrap_or(0));
    for (usage, at) in [(SmUsage::MBoxOut, 0x30), (SmUsage::MBoxIn, 0x34)] {
        if let Some(sm) = ec.sync_managers.iter().find(|s| s.usage == usage) {
            put16(&mut image, at, sm.start_address.as_deref().copied().unwrap_or(0));
            put16(&mut image, at + 2, sm_mailbox_size(sm));
        }
    }
    put16(&mut image, 0x38, protocols(ec));
    put16(&mut image, 0x7E, 1);
    Ok(image)
}

/// A mailbox SM's size: `DefaultSize`, else `MinSize` (the length register is 16 bits; the
/// front-end keeps these values in range).
fn sm_mailbox_size(sm: &EsiSm) -> u16 {
    let size = sm.default_size.or(sm.min_size).unwrap_or(0);
    u16::try_from(size).unwrap_or(u16::MAX)
}

fn protocols(ec: &EtherCat) -> u16 {
    let Some(mb) = &ec.mailbox else { return 0 };
    [
        (mb.aoe, protocol::AOE),
        (mb.eoe, protocol::EOE),
        (mb.coe.is_some(), protocol::COE),
        (mb.foe, protocol::FOE),
        (mb.soe.is_some(), protocol::SOE),
        (mb.voe, protocol::VOE),
    ]
    .iter()
    .filter(|(on, _)| *on)
    .fold(0, |acc, (_, bit)| acc | bit)
}

/// The strings category under construction: texts by first use, each once.
#[derive(Default)]
struct Strings {
    texts: Vec<Vec<u8>>,
    notes: Vec<Note>,
}

impl Strings {
    /// The 1-based index of `text`, added if new; 0 for no text or a full table.
    fn index(&mut self, text: Option<&str>) -> u8 {
        let Some(text) = text.map(str::trim).filter(|t| !t.is_empty()) else { return 0 };
        let mut end = text.len().min(255);
        while !text.is_char_boundary(end) {
            end -= 1;
        }
        let bytes = &text.as_bytes()[..end];
        if let Some(i) = self.texts.iter().position(|t| t == bytes) {
            return u8::try_from(i + 1).unwrap_or(0);
        }
        if self.texts.len() == 255 {
            self.notes.push(Note::StringTableFull(text.to_string()));
            return 0;
        }
        if end < text.len() {
            self.notes.push(Note::StringCut(text.to_string()));
        }
        self.texts.push(bytes.to_vec());
        u8::try_from(self.texts.len()).unwrap_or(0)
    }

    fn bytes(&self) -> Vec<u8> {
        // At most 255 texts of at most 255 bytes: `index` keeps both bounds.
        let mut out = vec![u8::try_from(self.texts.len()).unwrap_or(u8::MAX)];
        for t in &self.texts {
            out.push(u8::try_from(t.len()).unwrap_or(u8::MAX));
            out.extend_from_slice(t);
        }
        out
    }
}

fn general(device: &Device, ec: &EtherCat, extras: &InfoValues, strings: &mut Strings) -> Vec<u8> {
    let mut g = vec![0u8; 32];
    g[0] = strings.index(ec.group.as_ref().map(|g| g.type_name.as_str()));
    g[1] = strings.index(extras.image.as_deref());
    g[2] = strings.index(device.device_info.order_code.as_deref().map(String::as_str));
    let name = ec.names.iter().find(|n| n.lc_id == Some(1033)).or_else(|| ec.names.first());
    g[3] = strings.index(name.map(|n| n.text.as_str()));
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

fn fmmus(ec: &EtherCat, notes: &mut Vec<Note>) -> Vec<u8> {
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

fn sync_managers(ec: &EtherCat, notes: &mut Vec<Note>) -> Vec<u8> {
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

fn pdo_category(
    device: &Device,
    direction: Direction,
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
        out.push(strings.index(Some(&pdo.name)));
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
            out.push(strings.index(e.name.as_deref()));
            out.push(if e.is_gap() { 0 } else { data_type });
            out.push(bits);
            out.extend_from_slice(&0u16.to_le_bytes());
        }
    }
    Ok(Some(out))
}

fn dc_category(
    ec: &EtherCat,
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
        out.push(strings.index(Some(&m.name)));
        out.push(strings.index(m.desc.as_deref()));
        out.extend_from_slice(&[0; 4]);
    }
    Ok(Some(out))
}

fn push_category(
    image: &mut Vec<u8>,
    kind: u16,
    data: &[u8],
    span: Option<Span>,
) -> Result<(), Error> {
    let words = u16::try_from(data.len().div_ceil(2)).map_err(|_| {
        input(format!("category {kind} has {} bytes, more than 65535 words", data.len()), span)
    })?;
    image.extend_from_slice(&kind.to_le_bytes());
    image.extend_from_slice(&words.to_le_bytes());
    image.extend_from_slice(data);
    if data.len() % 2 == 1 {
        image.push(0);
    }
    Ok(())
}

/// Pads the image to the EEPROM size (0xFF, as erased) and writes the size word.
fn finish_size(image: &mut Vec<u8>, ec: &EtherCat, notes: &mut Vec<Note>) -> Result<(), Error> {
    let ee = ec.eeprom.as_ref();
    let size = match ee.and_then(|e| e.byte_size) {
        Some(byte_size) => {
            let span = ee.and_then(|e| e.spans.byte_size);
            if (byte_size as usize) < image.len() {
                return Err(Error::DoesNotFit { needed: image.len(), byte_size, span });
            }
            if byte_size % 128 != 0 {
                notes.push(Note::SizeNotWholeKibit(byte_size));
            }
            byte_size as usize
        }
        None => image.len().next_power_of_two().max(INFO_AREA),
    };
    let kibit = u16::try_from(size / 128).unwrap_or(u16::MAX);
    put16(image, 0x7C, kibit.saturating_sub(1));
    image.resize(size, 0xFF);
    Ok(())
}
