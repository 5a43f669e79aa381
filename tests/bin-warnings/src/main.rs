//! The code generated for every device file of `eds/` and `esi/`, included in a binary crate
//! the way a user's first program includes it: no `#[allow]` of its own, nothing used. In a
//! binary, an unused `pub` item is dead code, so `cargo clippy --all-targets -- -D warnings`
//! (CI) fails here when generated code leaves a warning to its user.

mod lenze_e94aycca {
    odc::include_od!("lenze_e94aycca");
}

mod lexium_mdrive {
    odc::include_od!("lexium_mdrive");
}

mod linmot_e1200 {
    odc::include_od!("linmot_e1200");
}

mod lxm23a {
    odc::include_od!("lxm23a");
}

mod servoone {
    odc::include_od!("servoone");
}

mod servoone_ecat {
    odc::include_od!("servoone_ecat");
}

fn main() {}
