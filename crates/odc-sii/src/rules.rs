//! The diagnostic codes of the SII writer, for the drivers' registry (`odc_pipeline::registry`):
//! `odc explain S701`, and levels (`-A S701`, `-W S702`) as for every other rule.

use odc_model::{RuleInfo, Severity};

/// The codes, by name.
pub mod codes {
    /// The image does not fit `Eeprom/ByteSize` even with every optional part left out.
    pub const DOES_NOT_FIT: &str = "S701";
    /// Optional parts were left out to fit `Eeprom/ByteSize`.
    pub const LEFT_OUT: &str = "S702";
    /// A value written otherwise than the ESI gives it ([`crate::Note`]).
    pub const ADJUSTED: &str = "S703";
}

/// Every code the SII writer's drivers report, in code order.
pub static RULES: &[RuleInfo] = &[
    RuleInfo {
        code: codes::DOES_NOT_FIT,
        name: "sii-does-not-fit",
        group: "sii",
        default: Severity::Error,
        summary: "the SII image does not fit `Eeprom/ByteSize`, even with every optional part left out",
        explanation: "An SII image is the 128-byte info area (ETG.2010 words 0x00-0x3F) and a \
                      list of categories. Where the content is larger than the EEPROM the ESI \
                      declares (`Eeprom/ByteSize`), `odc sii` leaves out optional parts (S702) \
                      until it fits. What is left is the info area and the ESI's own \
                      `Eeprom/Category` elements, written as given: when even these do not fit \
                      (or `ByteSize` is below 128 bytes), the image is refused. Fix the ESI \
                      (a larger `ByteSize`, if the device's EEPROM is larger), or write the \
                      image for a larger EEPROM: `odc sii --grow`, or set this rule to `warn` \
                      or `allow`, which writes everything into the smallest power-of-two EEPROM \
                      that holds it.",
    },
    RuleInfo {
        code: codes::LEFT_OUT,
        name: "sii-content-left-out",
        group: "sii",
        default: Severity::Warning,
        summary: "optional parts of the SII image were left out to fit `Eeprom/ByteSize`",
        explanation: "The content of the SII image is larger than `Eeprom/ByteSize`, so \
                      optional parts were left out, in this order, until it fit: the names of \
                      PDO entries; the names of PDOs and DC op modes and the image name; the DC \
                      category; the FMMU category; the TxPDO and RxPDO categories; the General \
                      category with the strings; the SyncManager category; in a 128-byte EEPROM, the end marker. The message names \
                      what was left out. A master that reads the device's description from the \
                      ESI (TwinCAT, an ENI) needs none of it; one that configures from the SII \
                      alone (SOEM, ethercrab) falls back to CoE or its defaults for what is \
                      missing. `odc sii --grow` writes everything into a larger EEPROM instead; \
                      deny this rule to refuse an image that leaves anything out. The order and \
                      its reasons are in the odc-sii crate documentation.",
    },
    RuleInfo {
        code: codes::ADJUSTED,
        name: "sii-value-adjusted",
        group: "sii",
        default: Severity::Note,
        summary: "a value of the SII image is written otherwise than the ESI gives it",
        explanation: "The SII image carries something not exactly as the ESI gives it: a \
                      checksum in `ConfigData` that is not the CRC-8 of its bytes (the computed \
                      one is written), a text past the 255 strings or longer than 255 bytes, a \
                      data type without a one-byte CoE code, an `Fmmu`/`Sm` usage ETG.2010 has \
                      no code for, a `CycleTimeSync1` value (the DC category holds only its \
                      factor), a `ByteSize` that is not whole KiBit, the ESI's own standard \
                      category written in place of the generated one, or an EEPROM larger than \
                      `ByteSize` because `--grow` asked for it. The message says which.",
    },
];
