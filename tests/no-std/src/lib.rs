//! The slave dictionary of `eds/lxm23a.eds`, generated with role `Slave`, in a `#![no_std]`
//! crate: if this builds, the generated slave code needs neither `std` nor `alloc`.

#![no_std]

/// Schneider Electric Lexium 23A (`eds/lxm23a.eds`), slave side.
pub mod lxm23a {
    odc::include_od!("lxm23a");
}

/// Reads the device type (0x1000:0) of a fresh dictionary for `node_id` into `buf`; returns
/// the number of bytes written.
///
/// # Errors
///
/// The SDO abort of the read (e.g. when `buf` is too small).
pub fn device_type(node_id: odc::cob::NodeId, buf: &mut [u8]) -> Result<usize, odc::SdoAbort> {
    let dictionary = lxm23a::slave::Dictionary::new(node_id);
    dictionary.read(0x1000, 0, buf)
}
