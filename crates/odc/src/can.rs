//! CAN frames as plain data, so protocol code (SDO) is independent of any CAN driver.

/// One classic CAN frame: an 11- or 29-bit identifier, data or remote, up to 8 data bytes.
///
/// Only the fields protocol code needs; the driver decides how it reaches the wire (SocketCAN,
/// a serial adapter, the loopback socket of the interop tests). CANopen uses 11-bit
/// identifiers and remote frames only for node guarding and RTR-triggered PDOs; code that
/// expects a CANopen data frame ignores extended and remote frames.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct CanFrame {
    /// CAN identifier (11 bits in CANopen's predefined connection set, 29 when `extended`).
    pub id: u32,
    /// A 29-bit (CAN 2.0B) identifier.
    pub extended: bool,
    /// A remote (RTR) frame: it asks for `len` bytes and carries none.
    pub remote: bool,
    /// Number of valid bytes in `data`, 0–8 (of a remote frame: the length asked for).
    pub len: u8,
    /// Payload; bytes past `len` are zero.
    pub data: [u8; 8],
}

impl CanFrame {
    /// A frame with all 8 data bytes (every SDO frame is 8 bytes long, CiA 301 §7.2.4.3).
    pub const fn new(id: u32, data: [u8; 8]) -> Self {
        Self { id, extended: false, remote: false, len: 8, data }
    }

    /// An 11-bit data frame with the bytes of `data`, or `None` if there are more than 8.
    pub fn from_slice(id: u32, data: &[u8]) -> Option<Self> {
        let mut buf = [0u8; 8];
        buf.get_mut(..data.len())?.copy_from_slice(data);
        Some(Self { id, extended: false, remote: false, len: data.len() as u8, data: buf })
    }

    /// A 29-bit data frame, or `None` if `id` has more than 29 bits or `data` more than 8 bytes.
    pub fn extended(id: u32, data: &[u8]) -> Option<Self> {
        if id > 0x1FFF_FFFF {
            return None;
        }
        Some(Self { extended: true, ..Self::from_slice(id, data)? })
    }

    /// An 11-bit remote frame asking for `len` bytes (at most 8).
    pub const fn remote(id: u32, len: u8) -> Self {
        let len = if len > 8 { 8 } else { len };
        Self { id, extended: false, remote: true, len, data: [0; 8] }
    }

    /// Whether this is an 11-bit data frame with identifier `id`: what CANopen services
    /// receive.
    pub const fn is_data(&self, id: u32) -> bool {
        self.id == id && !self.extended && !self.remote
    }

    /// The valid bytes (none for a remote frame).
    pub fn bytes(&self) -> &[u8] {
        if self.remote {
            return &[];
        }
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
        assert!(!f.extended && !f.remote && f.is_data(0x605));
    }

    #[test]
    fn extended_and_remote() {
        let e = CanFrame::extended(0x1FFF_FFFF, &[1]).unwrap();
        assert!(e.extended && !e.remote && !e.is_data(0x1FFF_FFFF));
        assert!(CanFrame::extended(0x2000_0000, &[]).is_none());
        assert!(CanFrame::extended(0x100, &[0; 9]).is_none());
        let r = CanFrame::remote(0x705, 1);
        assert!(r.remote && !r.extended && !r.is_data(0x705));
        assert_eq!((r.len, r.bytes()), (1, &[][..]));
        assert_eq!(CanFrame::remote(0x181, 12).len, 8);
    }
}
