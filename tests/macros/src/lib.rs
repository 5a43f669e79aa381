//! The code `include_device!` generates for `eds/lxm23a.eds` (role both), compiled as a
//! library: if this crate builds without warnings, the expansion does.

/// Schneider Electric Lexium 23A (`eds/lxm23a.eds`).
pub mod lxm23a {
    odc_macros::include_device!("../../eds/lxm23a.eds");
}

/// LTi ServoOne, EtherCAT (`esi/servoone.xml`), slave side.
pub mod servoone {
    odc_macros::include_device!("../../esi/servoone.xml", device = 0, role = "slave");
}
