//! Configuration plans: SDO writes as plain data, for any SDO client to execute in order.
//!
//! Generated `master` modules build them (the CiA 301 PDO mapping procedure, the EtherCAT
//! 0x1C12/0x1C13 assignment); [`sdo::Client::execute`](crate::sdo::Client::execute) runs one
//! over a bus. A plan is data, so any client can run it, or a test can apply it to a dictionary:
//!
//! ```
//! use odc::plan::SdoWrite;
//!
//! // RPDO1 maps the controlword (CiA 301 §7.5.2.36: disable, clear, map, count, enable).
//! let plan = [
//!     SdoWrite::u32(0x1400, 1, 0x8000_0205), // COB-ID, bit 31: PDO invalid
//!     SdoWrite::u8(0x1600, 0, 0),            // no entries while mapping
//!     SdoWrite::u32(0x1600, 1, 0x6040_0010), // 0x6040:00, 16 bits
//!     SdoWrite::u8(0x1600, 0, 1),            // one entry
//!     SdoWrite::u32(0x1400, 1, 0x0000_0205), // valid again
//! ];
//! let mut frames = Vec::new();
//! for w in &plan {
//!     let (bytes, n) = w.to_le_bytes(); // the data of one expedited download
//!     frames.push((w.index, w.sub, bytes[..n].to_vec()));
//! }
//! assert_eq!(frames[2], (0x1600, 1, vec![0x10, 0x00, 0x40, 0x60]));
//! assert_eq!(frames[3], (0x1600, 0, vec![1]));
//! ```

/// One expedited SDO download: `size` bytes (1, 2 or 4) of `value`, little-endian.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct SdoWrite {
    /// Object index.
    pub index: u16,
    /// Sub-index.
    pub sub: u8,
    /// The value, zero-extended.
    pub value: u32,
    /// Size in bytes: 1, 2 or 4.
    pub size: u8,
}

impl SdoWrite {
    /// An UNSIGNED8 write.
    pub const fn u8(index: u16, sub: u8, value: u8) -> Self {
        Self { index, sub, value: value as u32, size: 1 }
    }

    /// An UNSIGNED16 write.
    pub const fn u16(index: u16, sub: u8, value: u16) -> Self {
        Self { index, sub, value: value as u32, size: 2 }
    }

    /// An UNSIGNED32 write.
    pub const fn u32(index: u16, sub: u8, value: u32) -> Self {
        Self { index, sub, value, size: 4 }
    }

    /// The little-endian bytes of the value and how many of them to send.
    pub const fn to_le_bytes(self) -> ([u8; 4], usize) {
        (self.value.to_le_bytes(), self.size as usize)
    }
}
