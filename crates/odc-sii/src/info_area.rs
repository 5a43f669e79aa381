//! The info area, words 0x00–0x3F (ETG.2010; each word's source is in the crate
//! documentation).

use odc_model::ethercat::{EtherCat, SmUsage, SyncManager as EsiSm};

use crate::categories::input;
use crate::{Error, INFO_AREA, Note, crc8, protocol};

pub(crate) fn put16(image: &mut [u8], at: usize, v: u16) {
    if let Some(dst) = image.get_mut(at..at + 2) {
        dst.copy_from_slice(&v.to_le_bytes());
    }
}

fn put32(image: &mut [u8], at: usize, v: u32) {
    if let Some(dst) = image.get_mut(at..at + 4) {
        dst.copy_from_slice(&v.to_le_bytes());
    }
}

/// Words 0x00–0x3F, without the size word (set when the EEPROM size is known).
pub(crate) fn info_area(ec: &EtherCat, notes: &mut Vec<Note>) -> Result<Vec<u8>, Error> {
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
