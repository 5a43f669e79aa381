//! CAN frames as plain data, so protocol code (SDO) is independent of any CAN driver.

/// One classic CAN data frame: an identifier and up to 8 data bytes.
///
/// Only the fields protocol code needs; the driver decides how it reaches the wire (SocketCAN,
/// a serial adapter, the loopback socket of the interop tests).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct CanFrame {
    /// CAN identifier (11 bits in CANopen's predefined connection set).
    pub id: u32,
    /// Number of valid bytes in `data`, 0–8.
    pub len: u8,
    /// Payload; bytes past `len` are zero.
    pub data: [u8; 8],
}

impl CanFrame {
    /// A frame with all 8 data bytes (every SDO frame is 8 bytes long, CiA 301 §7.2.4.3).
    pub const fn new(id: u32, data: [u8; 8]) -> Self {
        Self { id, len: 8, data }
    }

    /// A frame with the bytes of `data`, or `None` if there are more than 8.
    pub fn from_slice(id: u32, data: &[u8]) -> Option<Self> {
        let mut buf = [0u8; 8];
        buf.get_mut(..data.len())?.copy_from_slice(data);
        Some(Self { id, len: data.len() as u8, data: buf })
    }

    /// The valid bytes.
    pub fn bytes(&self) -> &[u8] {
        let n = usize::from(self.len).min(8);
        self.data.get(..n).unwrap_or(&self.data)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn slices() {
        let f = CanFrame::from_slice(0x605, &[1, 2, 3]).unwrap();
        assert_eq!(f.len, 3);
        assert_eq!(f.bytes(), &[1, 2, 3]);
        assert_eq!(f.data, [1, 2, 3, 0, 0, 0, 0, 0]);
        assert!(CanFrame::from_slice(0x605, &[0; 9]).is_none());
        assert_eq!(CanFrame::new(0x585, [7; 8]).bytes().len(), 8);
    }
}
