//! The process image of an EtherCAT device as a master lays it out (ETG.1000.4 §6.7, ETG.2000
//! §5.4.4): the sync managers of one direction in index order, in each the assigned PDOs in
//! assignment order, their entries bit-packed in PDO order, padding entries as gaps, and each
//! sync manager's segment rounded up to whole bytes (its length register counts bytes).
//!
//! The bits are placed by `odc-layout`, the engine the derive and the checker use too, so the
//! generated `pdi` structs, their `#[derive(odc::Pdo)]` and this computation cannot disagree.

use std::collections::BTreeMap;

use odc_layout::{BitRange, Cursor};
use odc_model::{Device, Direction, Pdo, ethercat::SmUsage};

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

/// The default assignment: each PDO with an `Sm` attribute on that sync manager, and each
/// `Mandatory` PDO without one on the first sync manager of its direction's usage (`Outputs`
/// for RxPDOs, `Inputs` for TxPDOs); in file order. A PDO's `Fixed` says only that its
/// mapping cannot change, not that it is assigned. A PDO that excludes, or is excluded by, a
/// PDO assigned before it (`Exclude`) is left out, as TwinCAT does. Sync managers marked `Virtual` are left
/// out: they are no sync manager of the ESC but ESC registers (0x0981 DC activation, 0x0990
/// SYNC0 start time, ...) that TwinCAT maps with an FMMU of their own; a master that
/// configures sync managers from the SII (ethercrab, SOEM) has no such segment.
pub fn default_assignment(device: &Device) -> Assignment {
    let sms = device.ethercat.as_ref().map(|e| e.sync_managers.as_slice()).unwrap_or_default();
    let first =
        |usage: SmUsage| sms.iter().find(|s| s.usage == usage && !s.virtual_sm).map(|s| s.number);
    let is_virtual = |n: u8| sms.iter().any(|s| s.number == n && s.virtual_sm);
    let mut out = Assignment::new();
    for pdo in &device.pdos {
        let sm = pdo.sync_manager.or_else(|| {
            pdo.mandatory.then_some(()).and_then(|()| match pdo.direction {
                Direction::Rx => first(SmUsage::Outputs),
                Direction::Tx => first(SmUsage::Inputs),
            })
        });
        let Some(sm) = sm.filter(|&n| !is_virtual(n)) else { continue };
        let clash = out.values().flatten().any(|&other| {
            pdo.excludes.contains(&other)
                || device
                    .pdos
                    .iter()
                    .any(|p| p.mapping_index == other && p.excludes.contains(&pdo.mapping_index))
        });
        if !clash {
            out.entry(sm).or_default().push(pdo.mapping_index);
        }
    }
    out
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
