//! The vocabulary of CiA 301 / ETG.1000.6 object dictionaries: data types, object kinds, access.

use serde::Serialize;

/// A CiA 301 data type (Table 44 and 45), or one the file defines itself.
///
/// `Bit(n)` is EtherCAT's BIT1..BIT8 (a field narrower than a byte); `Profile(code)` is any
/// other code: profile-defined types (0x40–0x25F) and codes CiA 301 reserves.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord, Serialize)]
#[allow(missing_docs)] // each variant is the CiA 301 name of its code
pub enum DataType {
    Boolean,
    Integer8,
    Integer16,
    Integer32,
    Unsigned8,
    Unsigned16,
    Unsigned32,
    Real32,
    VisibleString,
    OctetString,
    UnicodeString,
    TimeOfDay,
    TimeDifference,
    Domain,
    Integer24,
    Real64,
    Integer40,
    Integer48,
    Integer56,
    Integer64,
    Unsigned24,
    Unsigned40,
    Unsigned48,
    Unsigned56,
    Unsigned64,
    PdoCommPar,
    PdoMapping,
    SdoParameter,
    Identity,
    /// EtherCAT BITn, n in 1..=8.
    Bit(u8),
    /// Any other code: profile-defined (0x40..=0x25F) or reserved.
    Profile(u16),
}

/// What a value of a [`DataType`] is, for parsing literals and choosing Rust types.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum ValueClass {
    /// BOOLEAN and BIT1.
    Bool,
    /// UNSIGNEDn and BITn (n > 1), with the bit width.
    Unsigned(u32),
    /// INTEGERn, with the bit width.
    Signed(u32),
    /// REAL32.
    Real32,
    /// REAL64.
    Real64,
    /// VISIBLE_STRING.
    Text,
    /// OCTET_STRING and DOMAIN.
    Bytes,
    /// UNICODE_STRING (UTF-16 code units).
    Unicode,
    /// TIME_OF_DAY and TIME_DIFFERENCE: milliseconds and days.
    Time,
    /// Complex and profile types: no literal form of their own.
    Structured,
}

impl DataType {
    /// The type for a CiA 301 code.
    pub fn from_code(code: u16) -> DataType {
        use DataType::*;
        match code {
            0x01 => Boolean,
            0x02 => Integer8,
            0x03 => Integer16,
            0x04 => Integer32,
            0x05 => Unsigned8,
            0x06 => Unsigned16,
            0x07 => Unsigned32,
            0x08 => Real32,
            0x09 => VisibleString,
            0x0A => OctetString,
            0x0B => UnicodeString,
            0x0C => TimeOfDay,
            0x0D => TimeDifference,
            0x0F => Domain,
            0x10 => Integer24,
            0x11 => Real64,
            0x12 => Integer40,
            0x13 => Integer48,
            0x14 => Integer56,
            0x15 => Integer64,
            0x16 => Unsigned24,
            0x18 => Unsigned40,
            0x19 => Unsigned48,
            0x1A => Unsigned56,
            0x1B => Unsigned64,
            0x20 => PdoCommPar,
            0x21 => PdoMapping,
            0x22 => SdoParameter,
            0x23 => Identity,
            0x30..=0x37 => Bit((code - 0x2F) as u8),
            other => Profile(other),
        }
    }

    /// The CiA 301 code; `Bit(n)` has ETG.1000.6's 0x0030 + n − 1 (BIT1..BIT8).
    pub fn code(self) -> u16 {
        use DataType::*;
        match self {
            Boolean => 0x01,
            Integer8 => 0x02,
            Integer16 => 0x03,
            Integer32 => 0x04,
            Unsigned8 => 0x05,
            Unsigned16 => 0x06,
            Unsigned32 => 0x07,
            Real32 => 0x08,
            VisibleString => 0x09,
            OctetString => 0x0A,
            UnicodeString => 0x0B,
            TimeOfDay => 0x0C,
            TimeDifference => 0x0D,
            Domain => 0x0F,
            Integer24 => 0x10,
            Real64 => 0x11,
            Integer40 => 0x12,
            Integer48 => 0x13,
            Integer56 => 0x14,
            Integer64 => 0x15,
            Unsigned24 => 0x16,
            Unsigned40 => 0x18,
            Unsigned48 => 0x19,
            Unsigned56 => 0x1A,
            Unsigned64 => 0x1B,
            PdoCommPar => 0x20,
            PdoMapping => 0x21,
            SdoParameter => 0x22,
            Identity => 0x23,
            Bit(n) => 0x2F + u16::from(n),
            Profile(code) => code,
        }
    }

    /// What kind of value this type holds.
    pub fn class(self) -> ValueClass {
        use DataType::*;
        match self {
            Boolean | Bit(1) => ValueClass::Bool,
            Bit(n) => ValueClass::Unsigned(u32::from(n)),
            Unsigned8 => ValueClass::Unsigned(8),
            Unsigned16 => ValueClass::Unsigned(16),
            Unsigned24 => ValueClass::Unsigned(24),
            Unsigned32 => ValueClass::Unsigned(32),
            Unsigned40 => ValueClass::Unsigned(40),
            Unsigned48 => ValueClass::Unsigned(48),
            Unsigned56 => ValueClass::Unsigned(56),
            Unsigned64 => ValueClass::Unsigned(64),
            Integer8 => ValueClass::Signed(8),
            Integer16 => ValueClass::Signed(16),
            Integer24 => ValueClass::Signed(24),
            Integer32 => ValueClass::Signed(32),
            Integer40 => ValueClass::Signed(40),
            Integer48 => ValueClass::Signed(48),
            Integer56 => ValueClass::Signed(56),
            Integer64 => ValueClass::Signed(64),
            Real32 => ValueClass::Real32,
            Real64 => ValueClass::Real64,
            VisibleString => ValueClass::Text,
            OctetString | Domain => ValueClass::Bytes,
            UnicodeString => ValueClass::Unicode,
            TimeOfDay | TimeDifference => ValueClass::Time,
            PdoCommPar | PdoMapping | SdoParameter | Identity | Profile(_) => {
                ValueClass::Structured
            }
        }
    }

    /// Size in bits of a value of a fixed-size type; `None` for strings, domains and structures.
    pub fn bit_size(self) -> Option<u32> {
        match self.class() {
            ValueClass::Bool => Some(1),
            ValueClass::Unsigned(n) | ValueClass::Signed(n) => Some(n),
            ValueClass::Real32 => Some(32),
            ValueClass::Real64 => Some(64),
            ValueClass::Time => Some(48),
            _ => None,
        }
    }

    /// The CiA 301 name, e.g. `UNSIGNED16`.
    pub fn name(self) -> std::borrow::Cow<'static, str> {
        use DataType::*;
        let s = match self {
            Boolean => "BOOLEAN",
            Integer8 => "INTEGER8",
            Integer16 => "INTEGER16",
            Integer32 => "INTEGER32",
            Unsigned8 => "UNSIGNED8",
            Unsigned16 => "UNSIGNED16",
            Unsigned32 => "UNSIGNED32",
            Real32 => "REAL32",
            VisibleString => "VISIBLE_STRING",
            OctetString => "OCTET_STRING",
            UnicodeString => "UNICODE_STRING",
            TimeOfDay => "TIME_OF_DAY",
            TimeDifference => "TIME_DIFFERENCE",
            Domain => "DOMAIN",
            Integer24 => "INTEGER24",
            Real64 => "REAL64",
            Integer40 => "INTEGER40",
            Integer48 => "INTEGER48",
            Integer56 => "INTEGER56",
            Integer64 => "INTEGER64",
            Unsigned24 => "UNSIGNED24",
            Unsigned40 => "UNSIGNED40",
            Unsigned48 => "UNSIGNED48",
            Unsigned56 => "UNSIGNED56",
            Unsigned64 => "UNSIGNED64",
            PdoCommPar => "PDO_COMMUNICATION_PARAMETER",
            PdoMapping => "PDO_MAPPING",
            SdoParameter => "SDO_PARAMETER",
            Identity => "IDENTITY",
            Bit(n) => return format!("BIT{n}").into(),
            Profile(code) => return format!("0x{code:04X}").into(),
        };
        s.into()
    }
}

/// CiA 306 ObjectType.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize)]
#[allow(missing_docs)] // CiA 301 Table 42 names
pub enum ObjectKind {
    Null,
    Domain,
    DefType,
    DefStruct,
    Var,
    Array,
    Record,
}

impl ObjectKind {
    /// The CiA 306 name: `VAR`, `ARRAY`, `RECORD`, ...
    pub fn name(self) -> &'static str {
        match self {
            ObjectKind::Null => "NULL",
            ObjectKind::Domain => "DOMAIN",
            ObjectKind::DefType => "DEFTYPE",
            ObjectKind::DefStruct => "DEFSTRUCT",
            ObjectKind::Var => "VAR",
            ObjectKind::Array => "ARRAY",
            ObjectKind::Record => "RECORD",
        }
    }

    /// The kind for a CiA 306 `ObjectType` code, if it is one.
    pub fn from_code(code: u8) -> Option<ObjectKind> {
        Some(match code {
            0x0 => ObjectKind::Null,
            0x2 => ObjectKind::Domain,
            0x5 => ObjectKind::DefType,
            0x6 => ObjectKind::DefStruct,
            0x7 => ObjectKind::Var,
            0x8 => ObjectKind::Array,
            0x9 => ObjectKind::Record,
            _ => return None,
        })
    }

    /// The CiA 306 `ObjectType` code.
    pub fn code(self) -> u8 {
        match self {
            ObjectKind::Null => 0x0,
            ObjectKind::Domain => 0x2,
            ObjectKind::DefType => 0x5,
            ObjectKind::DefStruct => 0x6,
            ObjectKind::Var => 0x7,
            ObjectKind::Array => 0x8,
            ObjectKind::Record => 0x9,
        }
    }

    /// Whether objects of this kind hold sub-objects (ARRAY, RECORD, DEFSTRUCT).
    pub fn has_subs(self) -> bool {
        matches!(self, ObjectKind::Array | ObjectKind::Record | ObjectKind::DefStruct)
    }
}

/// CiA 306 AccessType. `rwr` and `rww` stay distinct: they say which PDO direction may map
/// the object (rwr: read-write, mapped into a TPDO as a process input; rww: mapped into an RPDO
/// as a process output).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize)]
#[serde(rename_all = "lowercase")]
#[allow(missing_docs)] // CiA 306 names
pub enum Access {
    Ro,
    Wo,
    Rw,
    Rwr,
    Rww,
    Const,
}

impl Access {
    /// Parses a CiA 306 spelling, case-insensitively.
    ///
    /// By length, then the bytes with ASCII case folded by `| 0x20` (exact for letters: only
    /// a letter's two cases fold to it): every EDS sub-object has an AccessType, and comparing
    /// against each spelling in turn cost more than the rest of reading it.
    pub fn parse(s: &str) -> Option<Access> {
        let s = crate::trim::trim(s);
        let fold = |c: &u8| c | 0x20;
        Some(match s.as_bytes() {
            [a, b] => match [fold(a), fold(b)] {
                [b'r', b'o'] => Access::Ro,
                [b'w', b'o'] => Access::Wo,
                [b'r', b'w'] => Access::Rw,
                _ => return None,
            },
            [a, b, c] => match [fold(a), fold(b), fold(c)] {
                [b'r', b'w', b'r'] => Access::Rwr,
                [b'r', b'w', b'w'] => Access::Rww,
                _ => return None,
            },
            [a, b, c, d, e] => match [fold(a), fold(b), fold(c), fold(d), fold(e)] {
                [b'c', b'o', b'n', b's', b't'] => Access::Const,
                _ => return None,
            },
            _ => return None,
        })
    }

    /// The CiA 306 spelling.
    pub fn as_str(self) -> &'static str {
        match self {
            Access::Ro => "ro",
            Access::Wo => "wo",
            Access::Rw => "rw",
            Access::Rwr => "rwr",
            Access::Rww => "rww",
            Access::Const => "const",
        }
    }

    /// Whether an SDO upload may read it.
    pub fn readable(self) -> bool {
        !matches!(self, Access::Wo)
    }

    /// Whether an SDO download may write it.
    pub fn writable(self) -> bool {
        matches!(self, Access::Wo | Access::Rw | Access::Rwr | Access::Rww)
    }
}

/// Whether, and in which direction, a sub-object may be mapped into a PDO.
///
/// An EDS says only yes or no (`PDOMapping=1`); the direction then follows from the access type
/// (see [`PdoMapping::allows`]). An ESI says it outright (`R`, `T`, `RT`).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize)]
#[serde(rename_all = "lowercase")]
pub enum PdoMapping {
    /// Not mappable.
    #[default]
    No,
    /// Mappable; the direction follows from the access type.
    Yes,
    /// Mappable into receive PDOs only (ESI `R`).
    Rx,
    /// Mappable into transmit PDOs only (ESI `T`).
    Tx,
    /// Mappable both ways (ESI `RT`/`TR`).
    Both,
}

/// The two PDO directions, seen from the device.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord, Serialize)]
#[serde(rename_all = "lowercase")]
pub enum Direction {
    /// Receive PDO: master → device (outputs of the master).
    Rx,
    /// Transmit PDO: device → master (inputs of the master).
    Tx,
}

impl PdoMapping {
    /// The PDOs a sub-object with this flag and `access` may be mapped into, by meaning (an
    /// EDS's `PDOMapping=1` on a read-only entry and an XDD's `TPDO` are both `TPDO`):
    /// `RPDO/TPDO`, `RPDO`, `TPDO`, or empty.
    pub fn directions(self, access: Access) -> &'static str {
        match (self.allows(access, Direction::Rx), self.allows(access, Direction::Tx)) {
            (true, true) => "RPDO/TPDO",
            (true, false) => "RPDO",
            (false, true) => "TPDO",
            (false, false) => "",
        }
    }

    /// Whether a sub-object with this mapping flag and `access` may go into a PDO of `dir`.
    ///
    /// For EDS `Yes`: `ro`/`const`/`rwr` map into TPDOs, `wo`/`rww` into RPDOs, `rw` into both.
    pub fn allows(self, access: Access, dir: Direction) -> bool {
        match self {
            PdoMapping::No => false,
            PdoMapping::Rx => dir == Direction::Rx,
            PdoMapping::Tx => dir == Direction::Tx,
            PdoMapping::Both => true,
            PdoMapping::Yes => match access {
                Access::Rw => true,
                Access::Ro | Access::Const | Access::Rwr => dir == Direction::Tx,
                Access::Wo | Access::Rww => dir == Direction::Rx,
            },
        }
    }

    /// Whether it is mappable at all.
    pub fn is_mappable(self) -> bool {
        self != PdoMapping::No
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn access_parse_is_trimmed_and_case_insensitive() {
        let all = [Access::Ro, Access::Wo, Access::Rw, Access::Rwr, Access::Rww, Access::Const];
        for a in all {
            let name = a.as_str();
            for s in [
                name.to_owned(),
                name.to_ascii_uppercase(),
                format!(" {name}\t"),
                format!("\u{a0}{}\u{3000}", name.to_ascii_uppercase()),
            ] {
                assert_eq!(Access::parse(&s), Some(a), "{s:?}");
            }
        }
        for s in ["", "r", "w", "rr", "ow", "r0", "rwx", "rwro", "cons", "constant", "2o", "RO!"] {
            assert_eq!(Access::parse(s), None, "{s:?}");
        }
        // `| 0x20` maps only a letter's two cases to it: `R` folds to `r`, `2` does not to `R`.
        assert_eq!(Access::parse("\u{0012}o"), None);
    }
}
