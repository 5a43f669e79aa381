//! SII EEPROM images (ETG.2010) for EtherCAT devices: [`write()`] builds one from an ESI device,
//! [`read`] decodes one.
//!
//! A firmware engineer building an EtherCAT device needs the EEPROM content the ESI describes
//! (siitool, the SOES EEPROM generator and Beckhoff's SSC tool make it today). The image is
//! little-endian, addressed in 16-bit words.
//!
//! # Info area (words 0x00–0x3F)
//!
//! | word | field | source |
//! |---|---|---|
//! | 0x00–0x06 | PDI control, PDI configuration, sync impulse length, extended PDI configuration, configured station alias, 2 reserved words | `Eeprom/ConfigData`, byte by byte in EEPROM order (up to 14 bytes); what it does not give is 0 (ETG.2010: reserved words are 0, alias 0 = none) |
//! | 0x07 | checksum | CRC-8 of bytes 0..14, polynomial x⁸+x²+x+1 (0x07), initial 0xFF, no reflection, in the low byte; high byte 0. Bytes 14–15 of a 16-byte `ConfigData` (a checksum the ESI gives) are not copied: the checksum is always computed, and [`Note::ChecksumDiffers`] says when the ESI's differs |
//! | 0x08–0x0F | vendor ID, product code, revision, serial number (u32 each) | `Vendor/Id`, `Type@ProductCode`, `Type@RevisionNo`, `Type@SerialNo`; 0 when not given |
//! | 0x10–0x13 | execution delay, port 0/1 delay, reserved | 0 (ETG.2010 default; the ESI has no source) |
//! | 0x14–0x17 | bootstrap mailbox: receive offset, size, send offset, size | `Eeprom/BootStrap` (8 bytes in EEPROM order); 0 when absent (no bootstrap mailbox) |
//! | 0x18–0x1B | standard mailbox: receive offset, size, send offset, size | `Sm` with text `MBoxOut` (receive = master → device) and `MBoxIn`: `StartAddress`, `DefaultSize` (else `MinSize`); 0 when the device has no such SM |
//! | 0x1C | mailbox protocols | `Mailbox`: AoE 0x01, EoE 0x02, CoE 0x04, FoE 0x08, SoE 0x10, VoE 0x20 |
//! | 0x1D–0x3D | reserved | 0 |
//! | 0x3E | EEPROM size | `Eeprom/ByteSize` as KiBit − 1 (ETG.2010: 0 = 1 KiBit); without `ByteSize`, the image rounded up to a power of two of at least 128 bytes |
//! | 0x3F | version | 1 (ETG.2010) |
//!
//! # Categories (from word 0x40)
//!
//! Each is a type word, a length word (in words) and its data, padded to a word with 0; the
//! list ends with type 0xFFFF. They come in this order:
//!
//! - **Strings (10)**: a count byte, then each string as a length byte and its bytes (UTF-8, as
//!   the ESI text; ASCII in practice). Index 0 means "no string". At most 255 strings of at most
//!   255 bytes: a name past the 255th gets index 0 and a longer text is cut, each with a
//!   [`Note`]. Strings are added in this order, each text once: group, image, order code, device
//!   name, then PDO and entry names, then DC op-mode names and descriptions.
//! - **General (30)**, 32 bytes: group index (`GroupType`, also in byte 14), image index
//!   (`Image16x14`), order index (`Type` text), name index (`Name`, English if given), CoE
//!   details (bit 0 SDO = the device has `Mailbox/CoE`, then `@SdoInfo` bit 1, `@PdoAssign` 2,
//!   `@PdoConfig` 3, `@PdoUpload` 4, `@CompleteAccess` 5), FoE details (1 with `Mailbox/FoE`),
//!   EoE details (1 with `Mailbox/EoE`), SoE channels, DS402 channels and SysmanClass 0
//!   (ETG.2010: reserved), flags (bit 2 `Mailbox@DataLinkLayer`, bit 3
//!   `Info/IdentificationReg134`, bit 4 `Info/IdentificationAdo` given; bits 0–1 EnableSafeOp
//!   and EnableNotLRW 0, ETG.2010 default, the ESI has no source), current on E-bus
//!   (`Info/Electrical/EBusCurrent`, mA, signed; 0 when absent), physical ports (`Device@Physics`,
//!   one nibble a port: `Y` MII 1, `K` E-bus 3, `H` fast hot connect 4, other 0),
//!   physical memory address (`Info/IdentificationAdo`, else 0), the rest 0.
//! - **FMMU (40)**: one byte per `Fmmu`: `Outputs` 1, `Inputs` 2, `MBoxState` 3, other 0 (an
//!   unknown text with a [`Note`]); an odd count is padded with 0xFF (read as unused, as
//!   ethercrab does).
//! - **SyncManager (41)**: 8 bytes per `Sm`: `@StartAddress`, length (`@DefaultSize`, else 0 =
//!   the master computes it), `@ControlByte`, status 0, enable byte (bit 0 `@Enable`, bit 2
//!   `@Virtual`, bit 3 `@OpOnly`), type (`MBoxOut` 1, `MBoxIn` 2, `Outputs` 3, `Inputs` 4, other 0, an unknown text with a [`Note`]).
//! - **TxPDO (50)** and **RxPDO (51)**: per PDO 8 bytes (index, entry count, sync manager
//!   (`@Sm`, 0xFF when the ESI assigns the PDO to none), DC synchronisation 0 (the ESI gives it
//!   per op mode, not per PDO), name index, flags (ETG.2010 table 14): bit 0 `@Mandatory`, bit 1
//!   PdoDefault (`@Sm` given), bit 4 `@Fixed`; the others 0), then 8 bytes per entry (index, sub-index, name index, CoE
//!   data type code of `DataType` (0 for a gap or a type without one), bit length, flags 0).
//!   Written only when the device has PDOs of that direction.
//! - **DC (60)**, only when the ESI has `Dc/OpMode`s: 24 bytes per op mode: `CycleTimeSync0`,
//!   `ShiftTimeSync0`, `ShiftTimeSync1` (u32), `CycleTimeSync1@Factor` (i16), `AssignActivate`
//!   (u16), `CycleTimeSync0@Factor` (i16), name and description (`Desc`) indexes, 4 reserved
//!   bytes 0. ETG.2010 has no field for `CycleTimeSync1`'s own value (siitool adds one, which
//!   the standard does not have): a non-zero one is left out with a [`Note`].
//! - **Vendor categories**: every `Eeprom/Category` as written: `CatNo` as the type word, its
//!   data verbatim (an odd length padded with 0).
//!
//! The image is padded with 0xFF (an erased EEPROM) to `ByteSize`; an image larger than
//! `ByteSize` is an [`Error::DoesNotFit`]. A device whose ESI gives only `Eeprom/Data` (a whole
//! image) gets that image, checked to be at least the info area.

mod info;
mod read;
mod write;

pub use read::{
    Category, DcOpMode, General, InfoArea, MailboxArea, Sii, SiiPdo, SiiPdoEntry, SyncManager, read,
};
pub use write::{Note, write, write_from_description, write_with_notes};

use odc_model::Span;

/// Category types of ETG.2010.
pub mod category {
    /// Strings.
    pub const STRINGS: u16 = 10;
    /// Data types (reserved for future use).
    pub const DATA_TYPES: u16 = 20;
    /// General.
    pub const GENERAL: u16 = 30;
    /// FMMU usage.
    pub const FMMU: u16 = 40;
    /// Sync managers.
    pub const SYNC_MANAGER: u16 = 41;
    /// Transmit PDOs (device → master).
    pub const TX_PDO: u16 = 50;
    /// Receive PDOs (master → device).
    pub const RX_PDO: u16 = 51;
    /// Distributed clocks.
    pub const DC: u16 = 60;
    /// End of the category list.
    pub const END: u16 = 0xFFFF;
}

/// Bits of the mailbox protocol word (word 0x1C).
pub mod protocol {
    /// ADS over EtherCAT.
    pub const AOE: u16 = 0x01;
    /// Ethernet over EtherCAT.
    pub const EOE: u16 = 0x02;
    /// CAN application protocol over EtherCAT.
    pub const COE: u16 = 0x04;
    /// File access over EtherCAT.
    pub const FOE: u16 = 0x08;
    /// Servo profile over EtherCAT.
    pub const SOE: u16 = 0x10;
    /// Vendor-specific protocol over EtherCAT.
    pub const VOE: u16 = 0x20;
}

/// Size of the info area in bytes (words 0x00–0x3F).
pub const INFO_AREA: usize = 128;

/// Why an image cannot be written or read.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
pub enum Error {
    /// The device is not an EtherCAT device (no ESI part).
    #[error("the device has no EtherCAT description (an SII image needs an ESI device)")]
    NotEtherCat,
    /// A part of the ESI does not fit its place in the SII.
    #[error("{message}")]
    Input {
        /// What is wrong.
        message: String,
        /// Where it is written, when known.
        span: Option<Span>,
    },
    /// The image is larger than the EEPROM the ESI declares.
    #[error("the SII image needs {needed} bytes, but `Eeprom/ByteSize` is {byte_size}")]
    DoesNotFit {
        /// Bytes the image needs (with its end marker).
        needed: usize,
        /// `ByteSize`.
        byte_size: u32,
        /// Span of `ByteSize`.
        span: Option<Span>,
    },
    /// An image being read is malformed.
    #[error("byte 0x{offset:04X}: {message}")]
    Malformed {
        /// Byte offset of the problem.
        offset: usize,
        /// What is wrong.
        message: String,
    },
}

impl Error {
    /// Where in the ESI the problem is, when known.
    pub fn span(&self) -> Option<Span> {
        match self {
            Error::Input { span, .. } | Error::DoesNotFit { span, .. } => *span,
            Error::NotEtherCat | Error::Malformed { .. } => None,
        }
    }
}

/// The SII checksum (word 7): CRC-8 over `bytes`, polynomial 0x07, initial value 0xFF, MSB
/// first, no final XOR (ETG.2010).
pub fn crc8(bytes: &[u8]) -> u8 {
    let mut crc = 0xFFu8;
    for &b in bytes {
        crc ^= b;
        for _ in 0..8 {
            crc = if crc & 0x80 != 0 { (crc << 1) ^ 0x07 } else { crc << 1 };
        }
    }
    crc
}
