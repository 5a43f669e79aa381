//! CAN frames as plain data, so protocol code (SDO) is independent of any CAN driver.
//!
//! A [`CanFrame`] is checked when it is made: an 11-bit frame has an identifier of at most
//! 0x7FF, a 29-bit one at most 0x1FFF_FFFF, and at most 8 bytes; the fields are read through
//! accessors, so no code can hold an invalid frame.

/// An 11-bit CAN identifier (0..=0x7FF): what CANopen's predefined connection set uses.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct StdId(u16);

impl StdId {
    /// The largest 11-bit identifier.
    pub const MAX: u16 = 0x7FF;

    /// The identifier, or `None` above 0x7FF.
    pub const fn new(id: u16) -> Option<Self> {
        if id <= Self::MAX { Some(Self(id)) } else { None }
    }

    /// The low 11 bits of `raw` (of a COB-ID entry, whose upper bits are flags).
    pub const fn masked(raw: u32) -> Self {
        Self((raw & Self::MAX as u32) as u16)
    }

    /// The identifier.
    pub const fn get(self) -> u16 {
        self.0
    }

    /// The identifier as a frame's (32-bit) identifier.
    pub const fn raw(self) -> u32 {
        self.0 as u32
    }
}

/// One classic CAN frame: an 11- or 29-bit identifier, data or remote, up to 8 data bytes.
///
/// Only the fields protocol code needs; the driver decides how it reaches the wire (SocketCAN,
/// a serial adapter, the loopback socket of the interop tests). CANopen uses 11-bit
/// identifiers and remote frames only for node guarding and RTR-triggered PDOs; code that
/// expects a CANopen data frame ignores extended and remote frames.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
#[cfg_attr(feature = "serde", serde(try_from = "RawFrame"))]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct CanFrame {
    // The fields are the crate's, so that node code reads them directly; outside, the
    // constructors keep them valid (id within its width, len ≤ 8, bytes past len zero).
    /// CAN identifier (11 bits in CANopen's predefined connection set, 29 when `extended`).
    pub(crate) id: u32,
    /// A 29-bit (CAN 2.0B) identifier.
    pub(crate) extended: bool,
    /// A remote (RTR) frame: it asks for `len` bytes and carries none.
    pub(crate) remote: bool,
    /// Number of valid bytes in `data`, 0–8 (of a remote frame: the length asked for).
    pub(crate) len: u8,
    /// Payload; bytes past `len` are zero.
    pub(crate) data: [u8; 8],
}

/// The largest 29-bit identifier.
const EXT_MAX: u32 = 0x1FFF_FFFF;

impl CanFrame {
    /// An 11-bit data frame with all 8 data bytes (every SDO frame is 8 bytes long, CiA 301
    /// §7.2.4.3), or `None` if `id` is above 0x7FF.
    pub const fn new(id: u32, data: [u8; 8]) -> Option<Self> {
        if id > StdId::MAX as u32 {
            return None;
        }
        Some(Self { id, extended: false, remote: false, len: 8, data })
    }

    /// An 11-bit data frame of 8 bytes on an identifier known to be valid.
    pub const fn standard(id: StdId, data: [u8; 8]) -> Self {
        Self { id: id.raw(), extended: false, remote: false, len: 8, data }
    }

    /// An 11-bit data frame of the first `len` bytes of `data` (at most 8: more are cut to
    /// 8); the bytes past `len` are zeroed.
    pub const fn standard_len(id: StdId, mut data: [u8; 8], len: u8) -> Self {
        let len = if len > 8 { 8 } else { len };
        let mut i = len as usize;
        while i < 8 {
            data[i] = 0;
            i += 1;
        }
        Self { id: id.raw(), extended: false, remote: false, len, data }
    }

    /// An 11-bit data frame with the bytes of `data`, or `None` if `id` is above 0x7FF or
    /// there are more than 8 bytes.
    pub fn from_slice(id: u32, data: &[u8]) -> Option<Self> {
        if id > u32::from(StdId::MAX) {
            return None;
        }
        let mut buf = [0u8; 8];
        buf.get_mut(..data.len())?.copy_from_slice(data);
        Some(Self { id, extended: false, remote: false, len: data.len() as u8, data: buf })
    }

    /// A 29-bit data frame, or `None` if `id` has more than 29 bits or `data` more than 8 bytes.
    pub fn extended(id: u32, data: &[u8]) -> Option<Self> {
        if id > EXT_MAX {
            return None;
        }
        let mut buf = [0u8; 8];
        buf.get_mut(..data.len())?.copy_from_slice(data);
        Some(Self { id, extended: true, remote: false, len: data.len() as u8, data: buf })
    }

    /// An 11-bit remote frame asking for `len` bytes, or `None` if `id` is above 0x7FF or
    /// `len` above 8.
    pub const fn remote(id: u32, len: u8) -> Option<Self> {
        if id > StdId::MAX as u32 || len > 8 {
            return None;
        }
        Some(Self { id, extended: false, remote: true, len, data: [0; 8] })
    }

    /// A 29-bit remote frame asking for `len` bytes, or `None` if `id` has more than 29 bits
    /// or `len` is above 8.
    pub const fn remote_extended(id: u32, len: u8) -> Option<Self> {
        if id > EXT_MAX || len > 8 {
            return None;
        }
        Some(Self { id, extended: true, remote: true, len, data: [0; 8] })
    }

    /// The identifier: at most 0x7FF, or 0x1FFF_FFFF when [`CanFrame::is_extended`].
    pub const fn id(&self) -> u32 {
        self.id
    }

    /// Whether the identifier has 29 bits (CAN 2.0B).
    pub const fn is_extended(&self) -> bool {
        self.extended
    }

    /// Whether this is a remote (RTR) frame: it asks for [`CanFrame::len`] bytes and carries
    /// none.
    pub const fn is_remote(&self) -> bool {
        self.remote
    }

    /// The data length code, 0–8 (of a remote frame: the length asked for).
    pub const fn len(&self) -> u8 {
        self.len
    }

    /// Whether the frame carries no data bytes.
    pub const fn is_empty(&self) -> bool {
        self.remote || self.len == 0
    }

    /// All 8 bytes of the payload; those past [`CanFrame::len`] are zero.
    pub const fn data(&self) -> [u8; 8] {
        self.data
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

/// A frame as serialized: checked by the constructors when read back.
#[cfg(feature = "serde")]
#[derive(serde::Deserialize)]
struct RawFrame {
    id: u32,
    extended: bool,
    remote: bool,
    len: u8,
    data: [u8; 8],
}

#[cfg(feature = "serde")]
impl TryFrom<RawFrame> for CanFrame {
    type Error = &'static str;

    fn try_from(r: RawFrame) -> Result<Self, Self::Error> {
        let bytes = r.data.get(..usize::from(r.len)).ok_or("a CAN frame of more than 8 bytes")?;
        let f = match (r.extended, r.remote) {
            (false, false) => Self::from_slice(r.id, bytes),
            (true, false) => Self::extended(r.id, bytes),
            (false, true) => Self::remote(r.id, r.len),
            (true, true) => Self::remote_extended(r.id, r.len),
        };
        f.ok_or("a CAN identifier wider than its frame format")
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn slices() {
        let f = CanFrame::from_slice(0x605, &[1, 2, 3]).unwrap();
        assert_eq!(f.len(), 3);
        assert_eq!(f.bytes(), &[1, 2, 3]);
        assert_eq!(f.data(), [1, 2, 3, 0, 0, 0, 0, 0]);
        assert!(CanFrame::from_slice(0x605, &[0; 9]).is_none());
        assert_eq!(CanFrame::new(0x585, [7; 8]).unwrap().bytes().len(), 8);
        assert!(!f.is_extended() && !f.is_remote() && f.is_data(0x605));
    }

    #[test]
    fn identifiers_wider_than_the_format_are_refused() {
        assert!(CanFrame::new(0x800, [0; 8]).is_none());
        assert!(CanFrame::from_slice(0x800, &[]).is_none());
        assert!(CanFrame::remote(0x800, 0).is_none());
        assert!(CanFrame::from_slice(0x7FF, &[]).is_some());
        assert!(StdId::new(0x800).is_none());
        assert_eq!(StdId::new(0x7FF).map(StdId::get), Some(0x7FF));
        assert_eq!(StdId::masked(0x8000_0185).get(), 0x185);
        assert!(CanFrame::remote_extended(0x2000_0000, 0).is_none());
        let r = CanFrame::remote_extended(0x1FFF_FFFF, 2).unwrap();
        assert!(r.is_remote() && r.is_extended() && r.len() == 2 && r.bytes().is_empty());
    }

    #[test]
    fn typed_constructors() {
        let id = StdId::new(0x705).unwrap();
        let f = CanFrame::standard_len(id, [5, 9, 9, 9, 9, 9, 9, 9], 1);
        assert_eq!(f, CanFrame::from_slice(0x705, &[5]).unwrap());
        assert_eq!(CanFrame::standard_len(id, [1; 8], 12).len(), 8);
        assert_eq!(CanFrame::standard(id, [3; 8]), CanFrame::new(0x705, [3; 8]).unwrap());
    }

    #[test]
    fn extended_and_remote() {
        let e = CanFrame::extended(0x1FFF_FFFF, &[1]).unwrap();
        assert!(e.is_extended() && !e.is_remote() && !e.is_data(0x1FFF_FFFF));
        assert!(CanFrame::extended(0x2000_0000, &[]).is_none());
        assert!(CanFrame::extended(0x100, &[0; 9]).is_none());
        let r = CanFrame::remote(0x705, 1).unwrap();
        assert!(r.is_remote() && !r.is_extended() && !r.is_data(0x705));
        assert_eq!((r.len(), r.bytes()), (1, &[][..]));
        assert!(CanFrame::remote(0x181, 12).is_none());
    }
}
