//! The process image of an EtherCAT device as a master lays it out (ETG.1000.4 sync
//! managers and FMMUs, ETG.2000 `PdoType@Sm`): the sync managers of one direction in index order, in each the assigned PDOs in
//! assignment order, their entries bit-packed in PDO order, padding entries as gaps, and each
//! sync manager's segment rounded up to whole bytes (its length register counts bytes).
//!
//! The bits are placed by `odc-layout`, the engine the derive and the checker use too, so the
//! generated `pdi` structs, their `#[derive(odc::Pdo)]` and this computation cannot disagree.

use std::collections::BTreeMap;

use odc_layout::{BitRange, Cursor};
use odc_model::{Device, Direction, Pdo};

/// Which PDOs each sync manager carries: sync manager → PDO mapping indexes, in order.
pub type Assignment = BTreeMap<u8, Vec<u16>>;

/// One placed PDO entry.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Placed {
    /// Position of the PDO in `device.pdos`.
    pub pdo: usize,
    /// Position of the entry in the PDO's entries.
    pub entry: usize,
    /// Where it is, in bits from the start of the direction's image.
    pub range: BitRange,
}

/// The part of an image one sync manager carries.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Segment {
    /// The sync manager.
    pub sm: u8,
    /// First byte of the segment in the image.
    pub byte_offset: u32,
    /// Bits the assigned PDOs use.
    pub bits: u32,
    /// Bytes of the segment (`bits` rounded up): the sync manager's length.
    pub bytes: u32,
    /// The assigned PDOs (positions in `device.pdos`), in order.
    pub pdos: Vec<usize>,
    /// Every entry of those PDOs, gaps included, in wire order.
    pub entries: Vec<Placed>,
}

/// The outputs (master → device) or inputs (device → master) of one device.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Image {
    /// Outputs carry receive PDOs, inputs transmit PDOs.
    pub direction: Direction,
    /// One per sync manager with PDOs assigned, in index order.
    pub segments: Vec<Segment>,
}

impl Image {
    /// Bytes of the image.
    pub fn len(&self) -> usize {
        self.segments.iter().map(|s| s.bytes as usize).sum()
    }

    /// Whether no PDO is assigned.
    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }
}

/// Why an image cannot be computed.
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum ImageError {
    /// The assignment names a PDO the device does not declare.
    UnknownPdo {
        /// The sync manager.
        sm: u8,
        /// The PDO index.
        index: u16,
    },
    /// The image is longer than `u32` bits.
    TooLong,
}

/// The default assignment of `device`: [`odc_model::ethercat::default_assignment`] (the rule
/// lives in the model so that the ESI front-end's synthesised assignment objects follow it
/// too).
pub fn default_assignment(device: &Device) -> Assignment {
    let sms = device.ethercat.as_ref().map(|e| e.sync_managers.as_slice()).unwrap_or_default();
    odc_model::ethercat::default_assignment(sms, &device.pdos)
}

/// The image of `direction` for `assignment`. A PDO is looked up by index among the PDOs of
/// that direction; the sync managers that carry PDOs of the other direction are not part of it.
///
/// # Errors
///
/// [`ImageError`].
pub fn image(
    device: &Device,
    assignment: &Assignment,
    direction: Direction,
) -> Result<Image, ImageError> {
    let mut segments = Vec::new();
    let mut byte = 0u32;
    for (&sm, indexes) in assignment {
        let mut pdos = Vec::new();
        for &index in indexes {
            let found = device
                .pdos
                .iter()
                .position(|p: &Pdo| p.mapping_index == index && p.direction == direction);
            match found {
                Some(i) => pdos.push(i),
                // The other direction's PDO: its sync manager belongs to the other image.
                None if device.pdos.iter().any(|p| p.mapping_index == index) => {}
                None => return Err(ImageError::UnknownPdo { sm, index }),
            }
        }
        if pdos.is_empty() {
            continue;
        }
        let base = byte.checked_mul(8).ok_or(ImageError::TooLong)?;
        let mut cursor = Cursor::new();
        let mut entries = Vec::new();
        for &p in &pdos {
            for (e, entry) in device.pdos[p].entries.iter().enumerate() {
                let at = cursor.place(u32::from(entry.bits)).ok_or(ImageError::TooLong)?;
                let offset = at.offset.checked_add(base).ok_or(ImageError::TooLong)?;
                entries.push(Placed { pdo: p, entry: e, range: BitRange::new(offset, at.bits) });
            }
        }
        let bits = cursor.position();
        let bytes = odc_layout::bytes_for_bits(bits);
        segments.push(Segment { sm, byte_offset: byte, bits, bytes, pdos, entries });
        byte = byte.checked_add(bytes).ok_or(ImageError::TooLong)?;
    }
    Ok(Image { direction, segments })
}

/// The outputs and inputs of the default assignment.
///
/// # Errors
///
/// [`ImageError`].
pub fn default_images(device: &Device) -> Result<(Image, Image), ImageError> {
    let a = default_assignment(device);
    Ok((image(device, &a, Direction::Rx)?, image(device, &a, Direction::Tx)?))
}

/// Where an alternative assignment comes from.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Origin {
    /// A `Dc/OpMode` with `Sm` elements of its own.
    DcOpMode,
    /// A Beckhoff `AlternativeSmMapping`.
    AlternativeSmMapping,
}

/// An assignment other than the default one that the ESI names.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Variant {
    /// The ESI's name for it (op-mode `Name`, mapping `Name`; may be empty).
    pub name: String,
    /// Where it comes from.
    pub origin: Origin,
    /// The assignment: the default one with the sync managers the variant lists replaced.
    pub assignment: Assignment,
}

/// Why a variant of the ESI has no image of its own.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Skipped {
    /// The ESI's name for it.
    pub name: String,
    /// Where it comes from.
    pub origin: Origin,
    /// Why.
    pub reason: String,
}

/// The DC op-modes and alternative mappings whose assignment differs from the default, in
/// file order (op-modes first), and those left out with the reason: an assignment equal to
/// the default one (or an earlier variant's), an oversampling factor above 1 (the entries of
/// an oversampled PDO repeat with index steps, `OSIndexInc`, which this layout does not
/// model), an unknown sync manager, or a PDO the device does not declare. Virtual sync
/// managers are left out as in [`default_assignment`].
pub fn variants(device: &Device) -> (Vec<Variant>, Vec<Skipped>) {
    let Some(ec) = device.ethercat.as_deref() else { return (Vec::new(), Vec::new()) };
    let default = default_assignment(device);
    let mut lists: Vec<(&str, Origin, &[odc_model::ethercat::SmAssignment])> = Vec::new();
    if let Some(dc) = &ec.dc {
        for m in dc.op_modes.iter().filter(|m| !m.sms.is_empty()) {
            lists.push((&m.name, Origin::DcOpMode, &m.sms));
        }
    }
    for m in &ec.alternative_sm_mappings {
        lists.push((&m.name, Origin::AlternativeSmMapping, &m.sms));
    }
    let (mut out, mut skipped) = (Vec::new(), Vec::new());
    for (name, origin, sms) in lists {
        let skip = |reason: String| Skipped { name: name.to_string(), origin, reason };
        let mut assignment = default.clone();
        let mut reason = None;
        for sm in sms {
            match ec.sync_managers.iter().find(|s| s.number == sm.number) {
                None => reason = Some(format!("sync manager {} is not declared", sm.number)),
                // Left out as in the default assignment.
                Some(s) if s.virtual_sm => continue,
                Some(_) => {}
            }
            if let Some(&(pdo, Some(f))) = sm.pdos.iter().find(|(_, f)| f.is_some_and(|f| f > 1)) {
                reason = Some(format!("PDO 0x{pdo:04X} is oversampled {f} times"));
            }
            if let Some(&(pdo, _)) =
                sm.pdos.iter().find(|(p, _)| !device.pdos.iter().any(|d| d.mapping_index == *p))
            {
                reason = Some(format!("PDO 0x{pdo:04X} is not declared"));
            }
            assignment.insert(sm.number, sm.pdos.iter().map(|(p, _)| *p).collect());
        }
        assignment.retain(|_, pdos| !pdos.is_empty());
        let twin = out.iter().find(|v: &&Variant| v.assignment == assignment);
        match (reason, twin) {
            (Some(r), _) => skipped.push(skip(r)),
            (None, _) if assignment == default => {
                skipped.push(skip("the same assignment as the default".to_string()));
            }
            (None, Some(t)) => skipped.push(skip(format!("the same assignment as `{}`", t.name))),
            (None, None) => out.push(Variant { name: name.to_string(), origin, assignment }),
        }
    }
    (out, skipped)
}
