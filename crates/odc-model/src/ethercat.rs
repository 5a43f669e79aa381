//! EtherCAT-only parts of a device (ETG.2000): sync managers, FMMUs, mailbox, distributed clocks.
//!
//! The object dictionary and the PDOs of an ESI device live in the common model
//! ([`crate::Device::objects`], [`crate::Device::pdos`]); this holds what only EtherCAT has.

use serde::Serialize;

/// The EtherCAT description of one device (revision) of an ESI file.
#[derive(Clone, Debug, Default, PartialEq, Serialize)]
pub struct EtherCat {
    /// Vendor `Id`.
    pub vendor_id: Option<u32>,
    /// `Type ProductCode`.
    pub product_code: Option<u32>,
    /// `Type RevisionNo`.
    pub revision: Option<u32>,
}
