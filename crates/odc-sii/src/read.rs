//! Decoding an SII image: the info area and the categories, as [`crate::write`] lays them out
//! (ETG.2010), for `odc info eeprom.bin` and for checking written images.
//!
//! Lenient where masters are: a sync manager or DC category whose length is not whole records
//! (an ESI's own category, written as given) yields its whole records, as SOEM counts them;
//! an image of exactly the 128-byte info area (a 1 KiBit EEPROM) has no categories.

use crate::{Error, INFO_AREA, category, crc8};

/// A decoded SII image.
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub struct Sii {
    /// Words 0x00–0x3F.
    pub info: InfoArea,
    /// The strings category; string index `i` (1-based) is `strings[i - 1]`.
    pub strings: Vec<String>,
    /// The general category.
    pub general: Option<General>,
    /// FMMU usages (1 outputs, 2 inputs, 3 mailbox state, 0 unused), padding removed.
    pub fmmus: Vec<u8>,
    /// The sync manager category.
    pub sync_managers: Vec<SyncManager>,
    /// The TxPDO category.
    pub tx_pdos: Vec<SiiPdo>,
    /// The RxPDO category.
    pub rx_pdos: Vec<SiiPdo>,
    /// The DC category.
    pub dc: Vec<DcOpMode>,
    /// Every category in image order, with its bytes (vendor ones are only here).
    pub categories: Vec<Category>,
}

impl Sii {
    /// The string with a 1-based index; `None` for 0 (no string) or an index past the table.
    pub fn string(&self, index: u8) -> Option<&str> {
        let i = usize::from(index).checked_sub(1)?;
        self.strings.get(i).map(String::as_str)
    }
}

/// The info area (words 0x00–0x3F).
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub struct InfoArea {
    /// Word 0: PDI control.
    pub pdi_control: u16,
    /// Word 1: PDI configuration.
    pub pdi_config: u16,
    /// Word 2: sync impulse length (10 ns units).
    pub sync_impulse: u16,
    /// Word 3: extended PDI configuration.
    pub pdi_config2: u16,
    /// Word 4: configured station alias.
    pub alias: u16,
    /// Word 7, low byte: the checksum as stored.
    pub checksum: u8,
    /// Whether the stored checksum is the CRC-8 of bytes 0..14.
    pub checksum_ok: bool,
    /// Words 8–9.
    pub vendor_id: u32,
    /// Words 0xA–0xB.
    pub product_code: u32,
    /// Words 0xC–0xD.
    pub revision: u32,
    /// Words 0xE–0xF.
    pub serial: u32,
    /// Words 0x14–0x17.
    pub bootstrap: MailboxArea,
    /// Words 0x18–0x1B.
    pub standard: MailboxArea,
    /// Word 0x1C (see [`crate::protocol`]).
    pub mailbox_protocols: u16,
    /// Word 0x3E: EEPROM size in KiBit − 1.
    pub size_word: u16,
    /// Word 0x3F.
    pub version: u16,
}

impl InfoArea {
    /// The EEPROM size in bytes the size word gives.
    pub fn eeprom_bytes(&self) -> u32 {
        (u32::from(self.size_word) + 1) * 128
    }
}

/// Mailbox offsets and sizes (receive = master → device).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct MailboxArea {
    /// Receive mailbox offset.
    pub receive_offset: u16,
    /// Receive mailbox size.
    pub receive_size: u16,
    /// Send mailbox offset.
    pub send_offset: u16,
    /// Send mailbox size.
    pub send_size: u16,
}

/// The general category (bytes missing in a short one read as 0).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct General {
    /// Group string index.
    pub group: u8,
    /// Image string index.
    pub image: u8,
    /// Order code string index.
    pub order: u8,
    /// Device name string index.
    pub name: u8,
    /// CoE details (bit 0 SDO, 1 SDO info, 2 PDO assign, 3 PDO config, 4 upload, 5 complete access).
    pub coe_details: u8,
    /// FoE details.
    pub foe_details: u8,
    /// EoE details.
    pub eoe_details: u8,
    /// SoE channels.
    pub soe_channels: u8,
    /// DS402 channels.
    pub ds402_channels: u8,
    /// SysmanClass.
    pub sysman_class: u8,
    /// Flags.
    pub flags: u8,
    /// Current on E-bus in mA.
    pub ebus_current: i16,
    /// Physical ports, one nibble each.
    pub ports: u16,
    /// Physical memory address.
    pub physical_memory_address: u16,
}

/// One sync manager entry.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct SyncManager {
    /// Physical start address.
    pub start_address: u16,
    /// Length.
    pub length: u16,
    /// Control register.
    pub control: u8,
    /// Status register.
    pub status: u8,
    /// Enable byte.
    pub enable: u8,
    /// Type (1 mailbox out, 2 mailbox in, 3 outputs, 4 inputs).
    pub kind: u8,
}

/// One PDO of a PDO category.
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub struct SiiPdo {
    /// PDO index.
    pub index: u16,
    /// Sync manager (0xFF: none).
    pub sync_manager: u8,
    /// DC synchronisation.
    pub dc_sync: u8,
    /// Name string index.
    pub name: u8,
    /// Flags.
    pub flags: u16,
    /// Entries.
    pub entries: Vec<SiiPdoEntry>,
}

/// One PDO entry.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct SiiPdoEntry {
    /// Object index (0 for a gap).
    pub index: u16,
    /// Sub-index.
    pub sub: u8,
    /// Name string index.
    pub name: u8,
    /// CoE data type code.
    pub data_type: u8,
    /// Bit length.
    pub bits: u8,
    /// Flags.
    pub flags: u16,
}

/// One DC op mode.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct DcOpMode {
    /// SYNC0 cycle time.
    pub cycle_time0: u32,
    /// SYNC0 shift time.
    pub shift_time0: u32,
    /// SYNC1 shift time.
    pub shift_time1: u32,
    /// SYNC1 cycle factor.
    pub sync1_factor: i16,
    /// AssignActivate (registers 0x0980–0x0981).
    pub assign_activate: u16,
    /// SYNC0 cycle factor.
    pub sync0_factor: i16,
    /// Name string index.
    pub name: u8,
    /// Description string index.
    pub desc: u8,
}

/// A category as stored.
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub struct Category {
    /// Type word.
    pub kind: u16,
    /// Byte offset of its header in the image.
    pub offset: usize,
    /// Its data (length word × 2 bytes).
    pub data: Vec<u8>,
}

fn u16_at(b: &[u8], at: usize) -> u16 {
    u16::from_le_bytes([byte(b, at), byte(b, at + 1)])
}

fn u32_at(b: &[u8], at: usize) -> u32 {
    u32::from(u16_at(b, at)) | (u32::from(u16_at(b, at + 2)) << 16)
}

/// A byte, 0 past the end (callers check lengths where a short record is an error).
fn byte(b: &[u8], at: usize) -> u8 {
    b.get(at).copied().unwrap_or(0)
}

fn malformed(offset: usize, message: impl Into<String>) -> Error {
    Error::Malformed { offset, message: message.into() }
}

/// Decodes an SII image.
pub fn read(bytes: &[u8]) -> Result<Sii, Error> {
    if bytes.len() < INFO_AREA {
        return Err(malformed(
            bytes.len(),
            format!("{} bytes: an SII image has a 128-byte info area", bytes.len()),
        ));
    }
    let b = bytes;
    let mailbox = |at: usize| MailboxArea {
        receive_offset: u16_at(b, at),
        receive_size: u16_at(b, at + 2),
        send_offset: u16_at(b, at + 4),
        send_size: u16_at(b, at + 6),
    };
    let checksum = byte(b, 14);
    let info = InfoArea {
        pdi_control: u16_at(b, 0),
        pdi_config: u16_at(b, 2),
        sync_impulse: u16_at(b, 4),
        pdi_config2: u16_at(b, 6),
        alias: u16_at(b, 8),
        checksum,
        checksum_ok: bytes.get(..14).is_some_and(|h| crc8(h) == checksum),
        vendor_id: u32_at(b, 0x10),
        product_code: u32_at(b, 0x14),
        revision: u32_at(b, 0x18),
        serial: u32_at(b, 0x1C),
        bootstrap: mailbox(0x28),
        standard: mailbox(0x30),
        mailbox_protocols: u16_at(b, 0x38),
        size_word: u16_at(b, 0x7C),
        version: u16_at(b, 0x7E),
    };
    let mut sii = Sii { info, ..Sii::default() };
    let mut at = INFO_AREA;
    // A 1 KiBit EEPROM: the info area alone, no room for the end marker.
    while bytes.len() > INFO_AREA {
        if at + 2 > bytes.len() {
            return Err(malformed(at, "the category list has no end marker (0xFFFF)"));
        }
        let kind = u16_at(b, at);
        if kind == category::END {
            break;
        }
        if at + 4 > bytes.len() {
            return Err(malformed(at, format!("category {kind} has no length word")));
        }
        let words = usize::from(u16_at(b, at + 2));
        let data = bytes.get(at + 4..at + 4 + 2 * words).ok_or_else(|| {
            malformed(at, format!("category {kind} has {words} words, past the image's end"))
        })?;
        let body = at + 4;
        match kind {
            category::STRINGS => sii.strings = strings(data, body)?,
            category::GENERAL => sii.general = Some(general(data)),
            category::FMMU => {
                sii.fmmus = data.to_vec();
                if sii.fmmus.last() == Some(&0xFF) {
                    sii.fmmus.pop();
                }
            }
            category::SYNC_MANAGER => {
                sii.sync_managers = data
                    .chunks_exact(8)
                    .map(|r| SyncManager {
                        start_address: u16_at(r, 0),
                        length: u16_at(r, 2),
                        control: byte(r, 4),
                        status: byte(r, 5),
                        enable: byte(r, 6),
                        kind: byte(r, 7),
                    })
                    .collect();
            }
            category::TX_PDO => sii.tx_pdos = pdos(data, body)?,
            category::RX_PDO => sii.rx_pdos = pdos(data, body)?,
            category::DC => {
                sii.dc = data
                    .chunks_exact(24)
                    .map(|r| DcOpMode {
                        cycle_time0: u32_at(r, 0),
                        shift_time0: u32_at(r, 4),
                        shift_time1: u32_at(r, 8),
                        sync1_factor: u16_at(r, 12) as i16,
                        assign_activate: u16_at(r, 14),
                        sync0_factor: u16_at(r, 16) as i16,
                        name: byte(r, 18),
                        desc: byte(r, 19),
                    })
                    .collect();
            }
            _ => {}
        }
        sii.categories.push(Category { kind, offset: at, data: data.to_vec() });
        at = body + 2 * words;
    }
    Ok(sii)
}

fn strings(data: &[u8], at: usize) -> Result<Vec<String>, Error> {
    let count = usize::from(byte(data, 0));
    let mut out = Vec::with_capacity(count);
    let mut i = 1;
    for n in 0..count {
        let len = usize::from(byte(data, i));
        let text = data.get(i + 1..i + 1 + len).ok_or_else(|| {
            malformed(at + i, format!("string {} of {len} bytes runs past its category", n + 1))
        })?;
        out.push(String::from_utf8_lossy(text).into_owned());
        i += 1 + len;
    }
    Ok(out)
}

fn general(d: &[u8]) -> General {
    General {
        group: byte(d, 0),
        image: byte(d, 1),
        order: byte(d, 2),
        name: byte(d, 3),
        coe_details: byte(d, 5),
        foe_details: byte(d, 6),
        eoe_details: byte(d, 7),
        soe_channels: byte(d, 8),
        ds402_channels: byte(d, 9),
        sysman_class: byte(d, 10),
        flags: byte(d, 11),
        ebus_current: u16_at(d, 12) as i16,
        ports: u16_at(d, 16),
        physical_memory_address: u16_at(d, 18),
    }
}

fn pdos(data: &[u8], at: usize) -> Result<Vec<SiiPdo>, Error> {
    let mut out = Vec::new();
    let mut i = 0;
    while i < data.len() {
        let head = data
            .get(i..i + 8)
            .ok_or_else(|| malformed(at + i, "a PDO header runs past its category"))?;
        let n = usize::from(byte(head, 2));
        let body = data.get(i + 8..i + 8 + 8 * n).ok_or_else(|| {
            malformed(
                at + i,
                format!("PDO 0x{:04X}: {n} entries run past its category", u16_at(head, 0)),
            )
        })?;
        out.push(SiiPdo {
            index: u16_at(head, 0),
            sync_manager: byte(head, 3),
            dc_sync: byte(head, 4),
            name: byte(head, 5),
            flags: u16_at(head, 6),
            entries: body
                .chunks_exact(8)
                .map(|e| SiiPdoEntry {
                    index: u16_at(e, 0),
                    sub: byte(e, 2),
                    name: byte(e, 3),
                    data_type: byte(e, 4),
                    bits: byte(e, 5),
                    flags: u16_at(e, 6),
                })
                .collect(),
        });
        i += 8 + 8 * n;
    }
    Ok(out)
}
