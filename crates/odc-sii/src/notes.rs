//! What an image says differently from the ESI: the notes a writer returns beside the image.

use std::fmt;

/// Something the image does not carry exactly as the ESI says, though it could be written.
#[derive(Clone, Debug, PartialEq, Eq)]
#[non_exhaustive]
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
    /// The ESI gives its own category of a type odc writes (`Eeprom/Category` with a standard
    /// `CatNo`): written as given in place of the generated one.
    EsiCategory {
        /// Its `CatNo`.
        cat_no: u16,
        /// Its length in bytes.
        bytes: usize,
        /// What in it does not follow ETG.2010's layout for that type, if anything.
        odd: Option<String>,
    },
    /// The content did not fit `Eeprom/ByteSize`: optional parts were left out (see
    /// [`Omission`] for the order).
    LeftOut {
        /// Bytes the image needs with everything.
        full: usize,
        /// `ByteSize`.
        byte_size: u32,
        /// What was left out, in the order it was, with how many items each.
        omitted: Vec<(Omission, usize)>,
    },
    /// The content did not fit `Eeprom/ByteSize` and the caller allowed a larger EEPROM
    /// ([`crate::Fit::Grow`]): nothing was left out, the image and its size word are larger.
    Grown {
        /// `ByteSize`.
        byte_size: u32,
        /// The size written (a power of two, at least the image).
        size: usize,
    },
}

/// The optional parts of an image, in the order they are left out when the content does not
/// fit `Eeprom/ByteSize` (the reasons are in the crate documentation, "Fitting").
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord, Hash)]
pub enum Omission {
    /// The names of PDO entries (string index 0).
    EntryNames,
    /// The names of PDOs, of DC op modes and their descriptions, and the device image's name.
    OtherNames,
    /// The DC category.
    Dc,
    /// The FMMU category.
    Fmmu,
    /// The TxPDO and RxPDO categories.
    Pdos,
    /// The General category, and with it the strings category (the device's name, order
    /// code and group).
    General,
    /// The SyncManager category.
    SyncManagers,
    /// The end marker of the category list: an EEPROM of 128 bytes (1 KiBit) holds the info
    /// area alone, and a master reading on from word 0x40 reads what the EEPROM answers there.
    EndMarker,
}

impl Omission {
    /// Every omission, in the order they are made.
    pub const ORDER: [Omission; 8] = [
        Omission::EntryNames,
        Omission::OtherNames,
        Omission::Dc,
        Omission::Fmmu,
        Omission::Pdos,
        Omission::General,
        Omission::SyncManagers,
        Omission::EndMarker,
    ];

    /// What was left out, for `count` items.
    pub fn describe(self, count: usize) -> String {
        let s = |n: usize| if n == 1 { "" } else { "s" };
        match self {
            Omission::EntryNames => format!("the names of {count} PDO entr{}", ies(count)),
            Omission::OtherNames => {
                format!("{count} name{} of PDOs, DC op modes and the device image", s(count))
            }
            Omission::Dc => format!("the DC category ({count} op mode{})", s(count)),
            Omission::Fmmu => format!("the FMMU category ({count} FMMU{})", s(count)),
            Omission::Pdos => format!("the TxPDO and RxPDO categories ({count} PDO{})", s(count)),
            Omission::General => {
                "the General category and the strings category (device name, order code, group)"
                    .to_string()
            }
            Omission::SyncManagers => {
                format!("the SyncManager category ({count} sync manager{})", s(count))
            }
            Omission::EndMarker => "the end marker of the category list (a 128-byte EEPROM holds \
                                    the info area alone; a master reading on from word 0x40 \
                                    reads what the EEPROM answers there)"
                .to_string(),
        }
    }
}

fn ies(n: usize) -> &'static str {
    if n == 1 { "y" } else { "ies" }
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
            Note::EsiCategory { cat_no, bytes, odd } => {
                write!(
                    f,
                    "the ESI's own category {cat_no} ({bytes} bytes) is written as given, in \
                     place of the one odc would write"
                )?;
                match odd {
                    Some(odd) => write!(f, "; {odd}"),
                    None => Ok(()),
                }
            }
            Note::LeftOut { full, byte_size, omitted } => {
                let what: Vec<String> = omitted.iter().map(|(o, n)| o.describe(*n)).collect();
                write!(
                    f,
                    "the SII image needs {full} bytes with everything, `Eeprom/ByteSize` is \
                     {byte_size}: left out {}",
                    what.join("; ")
                )
            }
            Note::Grown { byte_size, size } => write!(
                f,
                "the SII image does not fit `Eeprom/ByteSize` {byte_size}: written for an \
                 EEPROM of {size} bytes (size word {})",
                size / 128 - 1
            ),
        }
    }
}
