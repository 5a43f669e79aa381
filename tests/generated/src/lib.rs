//! The code odc generates for the repository's device files, compiled as a library: if this
//! crate builds without warnings, the generated code does.

/// Schneider Electric Lexium 23A (`eds/lxm23a.eds`).
pub mod lxm23a {
    include!(concat!(env!("OUT_DIR"), "/lxm23a.rs"));
}

/// Schneider Electric Lexium MDrive (`eds/lexium-mdrive.eds`).
pub mod lexium_mdrive {
    include!(concat!(env!("OUT_DIR"), "/lexium_mdrive.rs"));
}

/// The small drive of the codegen snapshot tests.
pub mod mini_drive {
    odc::include_od!("mini_drive");
}

/// The small drive with two values that do not fit their types (`fixtures/bad-values.eds`),
/// generated with F108 allowed.
pub mod bad_values {
    include!(concat!(env!("OUT_DIR"), "/bad_values.rs"));
}

/// The made-up EtherCAT terminal of the process-image tests
/// (`crates/odc-codegen/tests/fixtures/pdi-terminal.xml`).
pub mod pdi_terminal {
    odc::include_od!("pdi_terminal");
}

/// A CoE terminal whose ESI dictionary leaves out the sync manager and PDO objects
/// (`crates/odc-esi/tests/fixtures/coe_implied.xml`).
pub mod coe_implied {
    odc::include_od!("coe_implied");
}

/// LTi ServoOne, EtherCAT (`esi/servoone.xml`).
pub mod servoone {
    include!(concat!(env!("OUT_DIR"), "/servoone.rs"));
}
