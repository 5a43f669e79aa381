//! Building an SII image from an ESI device: the categories in order, then the fit to
//! `Eeprom/ByteSize` (the layout, every field's source and the order of omissions are in the
//! crate documentation).

use std::collections::BTreeSet;

use odc_model::ethercat::{EepromCategory, EtherCat};
use odc_model::{Device, Direction, Span};

use crate::categories::{Names, dc_category, fmmus, general, input, pdo_category, sync_managers};
use crate::info::info_values;
use crate::info_area::{info_area, put16};
use crate::strings::Strings;
use crate::{Error, INFO_AREA, Note, Omission, category};

/// What to do when the content does not fit `Eeprom/ByteSize`.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
#[non_exhaustive]
pub enum Fit {
    /// Leave out optional parts, in [`Omission::ORDER`], until the image fits
    /// ([`Note::LeftOut`] says what); [`Error::DoesNotFit`] when the rest does not.
    #[default]
    Omit,
    /// Leave nothing out: the image is written for a larger EEPROM, the smallest power of two
    /// that holds it ([`Note::Grown`]).
    Grow,
}

/// How to write an image.
#[derive(Clone, Debug, Default)]
#[non_exhaustive]
pub struct Options {
    /// What to do when the content does not fit `Eeprom/ByteSize`.
    pub fit: Fit,
}

impl Options {
    /// These options with `fit`.
    pub fn fit(mut self, fit: Fit) -> Options {
        self.fit = fit;
        self
    }
}

/// The SII image of an ESI device ([`Options::default`]: optional parts left out where the
/// content does not fit).
pub fn write(device: &Device) -> Result<Vec<u8>, Error> {
    write_with_notes(device).map(|(image, _)| image)
}

/// [`write()`], with what the image could not carry exactly as the ESI says.
pub fn write_with_notes(device: &Device) -> Result<(Vec<u8>, Vec<Note>), Error> {
    write_with(device, &Options::default())
}

/// The image with `options`, and its notes.
///
/// A device whose ESI gives the whole image (`Eeprom/Data`, without `ConfigData`) gets that
/// image as it is; [`write_from_description`] builds one from the description instead.
pub fn write_with(device: &Device, options: &Options) -> Result<(Vec<u8>, Vec<Note>), Error> {
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
    build(device, ec, options)
}

/// The image built from the device's description (identity, `ConfigData`, SMs, PDOs, ...),
/// even where the ESI also gives a whole image (`Eeprom/Data`): to compare the two.
pub fn write_from_description(device: &Device) -> Result<(Vec<u8>, Vec<Note>), Error> {
    let ec = device.ethercat.as_deref().ok_or(Error::NotEtherCat)?;
    build(device, ec, &Options::default())
}

/// Builds the image, leaving out what `options` and `ByteSize` ask, and sizes it.
fn build(device: &Device, ec: &EtherCat, options: &Options) -> Result<(Vec<u8>, Vec<Note>), Error> {
    let ee = ec.eeprom.as_ref();
    let byte_size = ee.and_then(|e| e.byte_size);
    let span = ee.and_then(|e| e.spans.byte_size);
    let mut left_out = BTreeSet::new();
    let (mut image, mut notes) = assemble(device, ec, &left_out)?;
    let full = image.len();
    match byte_size {
        None => {
            let size = image.len().next_power_of_two().max(INFO_AREA);
            finish(&mut image, size);
        }
        Some(byte_size) if fits(&image, byte_size) => finish(&mut image, byte_size as usize),
        Some(byte_size) if options.fit == Fit::Grow => {
            let size = image.len().next_power_of_two().max(INFO_AREA);
            notes.push(Note::Grown { byte_size, size });
            finish(&mut image, size);
        }
        Some(byte_size) => {
            let mut omitted = Vec::new();
            // The end marker is not a part `assemble` leaves out: `fits` and `finish` cut it.
            for step in Omission::ORDER.into_iter().filter(|&o| o != Omission::EndMarker) {
                left_out.insert(step);
                let (smaller, smaller_notes) = assemble(device, ec, &left_out)?;
                if smaller.len() < image.len() {
                    omitted.push((step, count(device, ec, step)));
                }
                (image, notes) = (smaller, smaller_notes);
                if fits(&image, byte_size) {
                    break;
                }
            }
            if !fits(&image, byte_size) {
                return Err(Error::DoesNotFit { needed: image.len(), full, byte_size, span });
            }
            if image.len() > byte_size as usize {
                omitted.push((Omission::EndMarker, 1));
            }
            notes.push(Note::LeftOut { full, byte_size, omitted });
            finish(&mut image, byte_size as usize);
        }
    }
    // The size word is for `ByteSize` only where the image was not grown.
    if let Some(byte_size) = byte_size
        && byte_size % 128 != 0
        && image.len() == byte_size as usize
    {
        notes.push(Note::SizeNotWholeKibit(byte_size));
    }
    Ok((image, notes))
}

/// Whether `image` (ending with the end marker) fits an EEPROM of `byte_size` bytes. An
/// EEPROM of 128 bytes (1 KiBit) holds the info area alone: an image without categories fits
/// it without its end marker.
fn fits(image: &[u8], byte_size: u32) -> bool {
    let size = byte_size as usize;
    image.len() <= size || (image.len() == INFO_AREA + 2 && size >= INFO_AREA)
}

/// Cuts or pads the image to `size` bytes (0xFF, as erased) and writes the size word.
fn finish(image: &mut Vec<u8>, size: usize) {
    let kibit = u16::try_from(size / 128).unwrap_or(u16::MAX);
    put16(image, 0x7C, kibit.saturating_sub(1));
    // Only an image without categories is ever cut (its end marker, see `fits`).
    image.resize(size, 0xFF);
}

/// How many items `step` leaves out (for the note).
fn count(device: &Device, ec: &EtherCat, step: Omission) -> usize {
    let named = |t: Option<&str>| usize::from(t.is_some_and(|t| !t.trim().is_empty()));
    match step {
        Omission::EntryNames => {
            device.pdos.iter().flat_map(|p| &p.entries).map(|e| named(e.name.as_deref())).sum()
        }
        Omission::OtherNames => {
            let pdos: usize = device.pdos.iter().map(|p| named(Some(&p.name))).sum();
            let dc: usize = ec
                .dc
                .iter()
                .flat_map(|dc| &dc.op_modes)
                .map(|m| named(Some(&m.name)) + named(m.desc.as_deref()))
                .sum();
            pdos + dc + named(info_values(ec).image.as_deref())
        }
        Omission::Dc => ec.dc.as_ref().map_or(0, |dc| dc.op_modes.len()),
        Omission::Fmmu => ec.fmmus.len(),
        Omission::Pdos => device.pdos.len(),
        Omission::General => 1,
        Omission::SyncManagers => ec.sync_managers.len(),
        Omission::EndMarker => 1,
    }
}

/// The image up to and with its end marker, without the parts in `left_out`.
fn assemble(
    device: &Device,
    ec: &EtherCat,
    left_out: &BTreeSet<Omission>,
) -> Result<(Vec<u8>, Vec<Note>), Error> {
    let mut notes = Vec::new();
    let mut image = info_area(ec, &mut notes)?;
    let given: &[EepromCategory] = ec.eeprom.as_ref().map_or(&[], |e| &e.categories);
    if let Some(c) = given.iter().find(|c| c.cat_no == category::END) {
        return Err(input(
            "`CatNo` 65535 (0xFFFF) ends the category list; it is not a category".into(),
            Some(c.span),
        ));
    }
    let gives = |kind: u16| given.iter().any(|c| c.cat_no == kind);
    let keep = |o: Omission| !left_out.contains(&o);
    let names = Names { entries: keep(Omission::EntryNames), others: keep(Omission::OtherNames) };
    // Generated indexes would point into the ESI's own strings, so none is made then.
    let mut strings =
        if gives(category::STRINGS) { Strings::disabled() } else { Strings::default() };
    // Device strings first: they matter most when the table fills up.
    let general = (keep(Omission::General) && !gives(category::GENERAL))
        .then(|| general(device, ec, &info_values(ec), names, &mut strings));
    if gives(category::GENERAL) {
        // Still string 1, which SOEM shows as the device's name.
        strings.index(device.device_info.order_code.as_deref().map(String::as_str));
    }
    let mut pdos = |dir: Direction, kind: u16, notes: &mut Vec<Note>| {
        if keep(Omission::Pdos) && !gives(kind) {
            pdo_category(device, dir, names, &mut strings, notes)
        } else {
            Ok(None)
        }
    };
    let tx = pdos(Direction::Tx, category::TX_PDO, &mut notes)?;
    let rx = pdos(Direction::Rx, category::RX_PDO, &mut notes)?;
    let dc = match keep(Omission::Dc) && !gives(category::DC) {
        true => dc_category(ec, names, &mut strings, &mut notes)?,
        false => None,
    };
    notes.append(&mut strings.notes);
    let fmmu = (keep(Omission::Fmmu) && !gives(category::FMMU) && !ec.fmmus.is_empty())
        .then(|| fmmus(ec, &mut notes));
    let sms = (keep(Omission::SyncManagers)
        && !gives(category::SYNC_MANAGER)
        && !ec.sync_managers.is_empty())
    .then(|| sync_managers(ec, &mut notes));

    let generated = [
        (category::STRINGS, (!strings.is_empty()).then(|| strings.bytes())),
        (category::GENERAL, general),
        (category::FMMU, fmmu),
        (category::SYNC_MANAGER, sms),
        (category::TX_PDO, tx),
        (category::RX_PDO, rx),
        (category::DC, dc),
    ];
    let kinds = generated.each_ref().map(|(kind, _)| *kind);
    for (kind, data) in generated {
        if gives(kind) {
            for c in given.iter().filter(|c| c.cat_no == kind) {
                notes.push(Note::EsiCategory {
                    cat_no: kind,
                    bytes: c.data.len(),
                    odd: crate::layout::odd(kind, &c.data),
                });
                push_category(&mut image, kind, &c.data, Some(c.span))?;
            }
        } else if let Some(data) = data {
            push_category(&mut image, kind, &data, None)?;
        }
    }
    // The others (vendor categories, and types odc does not write) after them, in ESI order.
    for c in given.iter().filter(|c| !kinds.contains(&c.cat_no)) {
        push_category(&mut image, c.cat_no, &c.data, Some(c.span))?;
    }
    image.extend_from_slice(&category::END.to_le_bytes());
    Ok((image, notes))
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
