//! LSS frames (CiA 305 §4): 8 bytes, byte 0 the command specifier, the rest its parameters
//! (numbers little-endian, unused bytes reserved and sent as 0).
//!
//! | cs | master → slave | slave → master |
//! |---|---|---|
//! | 0x04 | switch state global (mode: 0 waiting, 1 configuration) | — |
//! | 0x40–0x43 | switch state selective: vendor, product, revision, serial | — |
//! | 0x44 | — | switch state selective response |
//! | 0x11 | configure node-ID | error code, specific error |
//! | 0x13 | configure bit timing (table selector, index) | error code, specific error |
//! | 0x15 | activate bit timing (switch delay, ms) | — |
//! | 0x17 | store configuration | error code, specific error |
//! | 0x46–0x4B | identify remote slave: vendor, product, revision low/high, serial low/high | — |
//! | 0x4C | identify non-configured remote slave | — |
//! | 0x4F | — | identify slave |
//! | 0x50 | — | identify non-configured slave |
//! | 0x51 | fastscan (IDNumber, BitChecked, LSSSub, LSSNext) | — |
//! | 0x5A–0x5D | inquire vendor, product, revision, serial | the number |
//! | 0x5E | inquire node-ID | the node-ID |

/// Which of the four numbers of an LSS address (0x1018 sub 1–4).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum Part {
    /// Vendor-ID.
    Vendor = 0,
    /// Product code.
    Product = 1,
    /// Revision number.
    Revision = 2,
    /// Serial number.
    Serial = 3,
}

impl Part {
    /// The part numbered `n` (0–3, as fastscan's LSSSub counts them).
    pub const fn from_index(n: u8) -> Option<Self> {
        match n {
            0 => Some(Self::Vendor),
            1 => Some(Self::Product),
            2 => Some(Self::Revision),
            3 => Some(Self::Serial),
            _ => None,
        }
    }
}

/// Which bound of a range in "identify remote slave".
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum Bound {
    /// The lowest value that matches.
    Low,
    /// The highest value that matches.
    High,
}

/// A request, LSS master → slaves (CAN-ID 0x7E5).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum Request {
    /// 0x04: every slave to waiting (`false`) or configuration (`true`) state.
    SwitchStateGlobal {
        /// Configuration state (mode 1) or waiting state (mode 0).
        configuration: bool,
    },
    /// 0x40–0x43: one part of the address of the one slave to put in configuration state.
    SwitchStateSelective(Part, u32),
    /// 0x11: configure node-ID (1–127, or 0xFF for unconfigured). The byte as on the wire,
    /// not a [`NodeId`](crate::cob::NodeId): a slave must answer any byte a master sends
    /// (with error 1 for one that is no node-ID); [`NodeId::from_lss`](crate::cob::NodeId::from_lss)
    /// reads it.
    ConfigureNodeId(u8),
    /// 0x13: configure bit timing: table selector (0 = CiA 301's table), table index.
    ConfigureBitTiming {
        /// 0: the standard table; 1–127 reserved; 128–255 manufacturer tables.
        table: u8,
        /// The entry in the table.
        index: u8,
    },
    /// 0x15: switch to the configured bit timing after `delay_ms`, and send nothing for
    /// another `delay_ms` after that.
    ActivateBitTiming {
        /// The switch delay in milliseconds.
        delay_ms: u16,
    },
    /// 0x17: store the configured node-ID and bit timing.
    StoreConfiguration,
    /// 0x46–0x4B: identify remote slave, one part of the range: vendor and product exact
    /// (given as `Bound::Low`), revision and serial low and high.
    IdentifyRemoteSlave(Part, Bound, u32),
    /// 0x4C: identify the slaves whose node-ID is unconfigured.
    IdentifyNonConfigured,
    /// 0x51: fastscan.
    Fastscan {
        /// The bits of the part under test.
        id_number: u32,
        /// Bits below this one are not compared (0–31); 0x80 starts a new scan.
        bit_checked: u8,
        /// The part under test (0–3).
        sub: u8,
        /// The part the slave tests next once this one matches with `bit_checked` 0.
        next: u8,
    },
    /// 0x5A–0x5D: inquire one part of the address.
    Inquire(Part),
    /// 0x5E: inquire the node-ID.
    InquireNodeId,
}

/// A response, LSS slave → master (CAN-ID 0x7E4).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum Response {
    /// 0x44: the slave is in configuration state after a switch state selective.
    SwitchStateSelective,
    /// 0x11: configure node-ID: error 0 success, 1 node-ID out of range, 0xFF specific.
    ConfigureNodeId {
        /// The error code.
        error: u8,
        /// The manufacturer's error when `error` is 0xFF.
        specific: u8,
    },
    /// 0x13: configure bit timing: error 0 success, 1 not supported, 0xFF specific.
    ConfigureBitTiming {
        /// The error code.
        error: u8,
        /// The manufacturer's error when `error` is 0xFF.
        specific: u8,
    },
    /// 0x17: store configuration: error 0 success, 1 not supported, 2 storage access error,
    /// 0xFF specific.
    StoreConfiguration {
        /// The error code.
        error: u8,
        /// The manufacturer's error when `error` is 0xFF.
        specific: u8,
    },
    /// 0x4F: a slave matches (identify remote slave, fastscan).
    IdentifySlave,
    /// 0x50: a slave with an unconfigured node-ID is there.
    IdentifyNonConfigured,
    /// 0x5A–0x5D: one part of the slave's address.
    Inquire(Part, u32),
    /// 0x5E: the slave's active node-ID (0xFF: unconfigured), the byte as on the wire.
    InquireNodeId(u8),
}

fn number(b: &[u8; 8]) -> u32 {
    u32::from_le_bytes([b[1], b[2], b[3], b[4]])
}

const fn with_number(cs: u8, n: u32) -> [u8; 8] {
    let n = n.to_le_bytes();
    [cs, n[0], n[1], n[2], n[3], 0, 0, 0]
}

/// The 8 bytes of a frame, or `None` if it has fewer (CiA 305: LSS frames have 8).
fn full(bytes: &[u8]) -> Option<[u8; 8]> {
    bytes.try_into().ok()
}

impl Request {
    /// The 8 bytes on the wire.
    pub const fn encode(&self) -> [u8; 8] {
        match *self {
            Self::SwitchStateGlobal { configuration } => {
                [0x04, configuration as u8, 0, 0, 0, 0, 0, 0]
            }
            Self::SwitchStateSelective(p, n) => with_number(0x40 + p as u8, n),
            Self::ConfigureNodeId(id) => [0x11, id, 0, 0, 0, 0, 0, 0],
            Self::ConfigureBitTiming { table, index } => [0x13, table, index, 0, 0, 0, 0, 0],
            Self::ActivateBitTiming { delay_ms } => {
                let d = delay_ms.to_le_bytes();
                [0x15, d[0], d[1], 0, 0, 0, 0, 0]
            }
            Self::StoreConfiguration => [0x17, 0, 0, 0, 0, 0, 0, 0],
            Self::IdentifyRemoteSlave(p, b, n) => {
                let cs = match (p, b) {
                    (Part::Vendor, _) => 0x46,
                    (Part::Product, _) => 0x47,
                    (Part::Revision, Bound::Low) => 0x48,
                    (Part::Revision, Bound::High) => 0x49,
                    (Part::Serial, Bound::Low) => 0x4A,
                    (Part::Serial, Bound::High) => 0x4B,
                };
                with_number(cs, n)
            }
            Self::IdentifyNonConfigured => [0x4C, 0, 0, 0, 0, 0, 0, 0],
            Self::Fastscan { id_number, bit_checked, sub, next } => {
                let n = id_number.to_le_bytes();
                [0x51, n[0], n[1], n[2], n[3], bit_checked, sub, next]
            }
            Self::Inquire(p) => [0x5A + p as u8, 0, 0, 0, 0, 0, 0, 0],
            Self::InquireNodeId => [0x5E, 0, 0, 0, 0, 0, 0, 0],
        }
    }

    /// Decodes a request; `None` for a frame shorter than 8 bytes or a command specifier that
    /// is no request (a slave ignores those, CiA 305).
    pub fn decode(bytes: &[u8]) -> Option<Self> {
        let b = full(bytes)?;
        Some(match b[0] {
            0x04 => match b[1] {
                0 => Self::SwitchStateGlobal { configuration: false },
                1 => Self::SwitchStateGlobal { configuration: true },
                _ => return None,
            },
            cs @ 0x40..=0x43 => {
                Self::SwitchStateSelective(Part::from_index(cs - 0x40)?, number(&b))
            }
            0x11 => Self::ConfigureNodeId(b[1]),
            0x13 => Self::ConfigureBitTiming { table: b[1], index: b[2] },
            0x15 => Self::ActivateBitTiming { delay_ms: u16::from_le_bytes([b[1], b[2]]) },
            0x17 => Self::StoreConfiguration,
            0x46 => Self::IdentifyRemoteSlave(Part::Vendor, Bound::Low, number(&b)),
            0x47 => Self::IdentifyRemoteSlave(Part::Product, Bound::Low, number(&b)),
            0x48 => Self::IdentifyRemoteSlave(Part::Revision, Bound::Low, number(&b)),
            0x49 => Self::IdentifyRemoteSlave(Part::Revision, Bound::High, number(&b)),
            0x4A => Self::IdentifyRemoteSlave(Part::Serial, Bound::Low, number(&b)),
            0x4B => Self::IdentifyRemoteSlave(Part::Serial, Bound::High, number(&b)),
            0x4C => Self::IdentifyNonConfigured,
            0x51 => {
                Self::Fastscan { id_number: number(&b), bit_checked: b[5], sub: b[6], next: b[7] }
            }
            cs @ 0x5A..=0x5D => Self::Inquire(Part::from_index(cs - 0x5A)?),
            0x5E => Self::InquireNodeId,
            _ => return None,
        })
    }
}

impl Response {
    /// The 8 bytes on the wire.
    pub const fn encode(&self) -> [u8; 8] {
        match *self {
            Self::SwitchStateSelective => [0x44, 0, 0, 0, 0, 0, 0, 0],
            Self::ConfigureNodeId { error, specific } => [0x11, error, specific, 0, 0, 0, 0, 0],
            Self::ConfigureBitTiming { error, specific } => [0x13, error, specific, 0, 0, 0, 0, 0],
            Self::StoreConfiguration { error, specific } => [0x17, error, specific, 0, 0, 0, 0, 0],
            Self::IdentifySlave => [0x4F, 0, 0, 0, 0, 0, 0, 0],
            Self::IdentifyNonConfigured => [0x50, 0, 0, 0, 0, 0, 0, 0],
            Self::Inquire(p, n) => with_number(0x5A + p as u8, n),
            Self::InquireNodeId(id) => [0x5E, id, 0, 0, 0, 0, 0, 0],
        }
    }

    /// Decodes a response; `None` for a frame shorter than 8 bytes or a command specifier
    /// that is no response.
    pub fn decode(bytes: &[u8]) -> Option<Self> {
        let b = full(bytes)?;
        Some(match b[0] {
            0x44 => Self::SwitchStateSelective,
            0x11 => Self::ConfigureNodeId { error: b[1], specific: b[2] },
            0x13 => Self::ConfigureBitTiming { error: b[1], specific: b[2] },
            0x17 => Self::StoreConfiguration { error: b[1], specific: b[2] },
            0x4F => Self::IdentifySlave,
            0x50 => Self::IdentifyNonConfigured,
            cs @ 0x5A..=0x5D => Self::Inquire(Part::from_index(cs - 0x5A)?, number(&b)),
            0x5E => Self::InquireNodeId(b[1]),
            _ => return None,
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn requests_round_trip() {
        let all = [
            Request::SwitchStateGlobal { configuration: true },
            Request::SwitchStateGlobal { configuration: false },
            Request::SwitchStateSelective(Part::Serial, 0x1454_523E),
            Request::ConfigureNodeId(0x42),
            Request::ConfigureBitTiming { table: 0, index: 6 },
            Request::ActivateBitTiming { delay_ms: 500 },
            Request::StoreConfiguration,
            Request::IdentifyRemoteSlave(Part::Revision, Bound::High, 7),
            Request::IdentifyNonConfigured,
            Request::Fastscan { id_number: 0x0800_005A, bit_checked: 0x80, sub: 0, next: 0 },
            Request::Inquire(Part::Product),
            Request::InquireNodeId,
        ];
        for r in all {
            assert_eq!(Request::decode(&r.encode()), Some(r), "{r:?}");
        }
        // CiA 305 layouts: cs, then numbers LE in bytes 1-4; fastscan's three bytes 5-7.
        assert_eq!(
            Request::SwitchStateSelective(Part::Vendor, 0x0800_005A).encode(),
            [0x40, 0x5A, 0x00, 0x00, 0x08, 0, 0, 0]
        );
        assert_eq!(
            Request::Fastscan { id_number: 0x1234_5678, bit_checked: 31, sub: 2, next: 3 }.encode(),
            [0x51, 0x78, 0x56, 0x34, 0x12, 31, 2, 3]
        );
        assert_eq!(
            Request::ActivateBitTiming { delay_ms: 0x0102 }.encode()[..3],
            [0x15, 0x02, 0x01]
        );
        assert_eq!(Request::Inquire(Part::Serial).encode()[0], 0x5D);
        // Short frames and responses are no requests.
        assert_eq!(Request::decode(&[0x04, 0x01]), None);
        assert_eq!(Request::decode(&[0x44, 0, 0, 0, 0, 0, 0, 0]), None);
        assert_eq!(Request::decode(&[0x04, 2, 0, 0, 0, 0, 0, 0]), None);
    }

    #[test]
    fn responses_round_trip() {
        let all = [
            Response::SwitchStateSelective,
            Response::ConfigureNodeId { error: 1, specific: 0 },
            Response::ConfigureBitTiming { error: 0, specific: 0 },
            Response::StoreConfiguration { error: 0xFF, specific: 9 },
            Response::IdentifySlave,
            Response::IdentifyNonConfigured,
            Response::Inquire(Part::Revision, 0x0507),
            Response::InquireNodeId(0xFF),
        ];
        for r in all {
            assert_eq!(Response::decode(&r.encode()), Some(r), "{r:?}");
        }
        assert_eq!(
            Response::Inquire(Part::Vendor, 0x0800_005A).encode(),
            [0x5A, 0x5A, 0x00, 0x00, 0x08, 0, 0, 0]
        );
        assert_eq!(Response::decode(&[0x51, 0, 0, 0, 0, 0, 0, 0]), None);
    }
}
