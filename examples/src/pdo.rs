//! Process data through any object dictionary, as its mapping objects say: what a slave does
//! with an RPDO it receives and how it builds a TPDO.
//!
//! The mapping is read at run time from the communication (0x1400/0x1800 + n) and mapping
//! (0x1600/0x1A00 + n) objects of the dictionary, which the master wrote with its
//! configuration plan. Entries must be byte-aligned and whole bytes long, as every mapping of
//! the example drives is; dummy entries (indexes below 0x20) are skipped or sent as zeros.

use odc::slave::ObjectDictionary;
use odc::{MappingEntry, SdoAbort};

fn read_u32(od: &dyn ObjectDictionary, index: u16, sub: u8) -> Option<u32> {
    let mut buf = [0u8; 4];
    let n = od.read(index, sub, &mut buf).ok()?;
    let mut le = [0u8; 4];
    le.get_mut(..n)?.copy_from_slice(buf.get(..n)?);
    Some(u32::from_le_bytes(le))
}

/// The CAN-ID of a PDO whose communication object is `comm_index`, if it is valid (bit 31
/// clear) and an 11-bit identifier (bit 29 clear).
pub fn cob_id(od: &dyn ObjectDictionary, comm_index: u16) -> Option<u32> {
    let cob = odc::cob::CobId(read_u32(od, comm_index, 1)?);
    (cob.is_valid() && !cob.is_extended()).then_some(cob.can_id() & 0x7FF)
}

/// The transmission type of a PDO (communication sub-index 2); 255 (event-driven) when the
/// dictionary has none.
pub fn transmission_type(od: &dyn ObjectDictionary, comm_index: u16) -> u8 {
    read_u32(od, comm_index, 2).and_then(|v| u8::try_from(v).ok()).unwrap_or(255)
}

/// The entries of a mapping object (sub 0 is their number).
///
/// # Errors
///
/// The abort of a sub-index the dictionary does not answer.
pub fn mapping(
    od: &dyn ObjectDictionary,
    mapping_index: u16,
) -> Result<Vec<MappingEntry>, SdoAbort> {
    let count = read_u32(od, mapping_index, 0).ok_or(SdoAbort::NoSuchObject)?;
    (1..=count)
        .map(|sub| {
            let sub = u8::try_from(sub).map_err(|_| SdoAbort::InvalidValue)?;
            read_u32(od, mapping_index, sub).map(MappingEntry::from_u32).ok_or(SdoAbort::NoSuchSub)
        })
        .collect()
}

fn whole_bytes(e: &MappingEntry) -> Result<usize, SdoAbort> {
    if e.bits.is_multiple_of(8) {
        Ok(usize::from(e.bits / 8))
    } else {
        Err(SdoAbort::ParameterIncompatible)
    }
}

/// Writes the data of a received RPDO into the mapped objects.
///
/// # Errors
///
/// The dictionary's abort for an entry (a value out of range, say), or
/// [`SdoAbort::PdoLengthExceeded`] when the frame is shorter than the mapping.
pub fn receive(
    od: &mut dyn ObjectDictionary,
    entries: &[MappingEntry],
    data: &[u8],
) -> Result<(), SdoAbort> {
    let mut at = 0;
    for e in entries {
        let n = whole_bytes(e)?;
        let bytes = data.get(at..at + n).ok_or(SdoAbort::PdoLengthExceeded)?;
        if !e.is_dummy() {
            od.write(e.index, e.sub, bytes)?;
        }
        at += n;
    }
    Ok(())
}

/// The data of a TPDO, read from the mapped objects.
///
/// # Errors
///
/// The dictionary's abort for an entry, or [`SdoAbort::PdoLengthExceeded`] above 8 bytes.
pub fn transmit(od: &dyn ObjectDictionary, entries: &[MappingEntry]) -> Result<Vec<u8>, SdoAbort> {
    let mut out = Vec::new();
    for e in entries {
        let n = whole_bytes(e)?;
        let mut buf = [0u8; 8];
        let field = buf.get_mut(..n).ok_or(SdoAbort::PdoLengthExceeded)?;
        if !e.is_dummy() {
            od.read(e.index, e.sub, field)?;
        }
        out.extend_from_slice(field);
    }
    if out.len() > 8 {
        return Err(SdoAbort::PdoLengthExceeded);
    }
    Ok(out)
}
