//! Code generated from the six device files of the five manuals in `../shared/seeds`, each with
//! the overlay beside it. The tests rebuild the manuals' worked examples from it.

/// Schneider Electric Lexium 23A (`eds/lxm23a.eds`).
pub mod lxm23a {
    include!(concat!(env!("OUT_DIR"), "/lxm23a.rs"));
}

/// Schneider Electric Lexium MDrive (`eds/lexium-mdrive.eds`).
pub mod lexium_mdrive {
    include!(concat!(env!("OUT_DIR"), "/lexium_mdrive.rs"));
}

/// LTI ServoOne, CANopen (`eds/servoone.eds`).
pub mod servoone {
    include!(concat!(env!("OUT_DIR"), "/servoone.rs"));
}

/// LTI ServoOne, EtherCAT (`esi/servoone.xml`).
pub mod servoone_ecat {
    include!(concat!(env!("OUT_DIR"), "/servoone_ecat.rs"));
}

/// Lenze E94AYCCA CANopen module (`eds/lenze-e94aycca.eds`).
pub mod lenze_e94aycca {
    include!(concat!(env!("OUT_DIR"), "/lenze_e94aycca.rs"));
}

/// LinMot E1200 (`eds/linmot-e1200.eds`).
pub mod linmot_e1200 {
    include!(concat!(env!("OUT_DIR"), "/linmot_e1200.rs"));
}
