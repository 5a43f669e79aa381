//! A Schneider LXM23A on a simulated CAN bus: `cargo run --example lxm23a`.
//!
//! Both ends run code generated from `eds/lxm23a.eds`: the master configures the PDOs with
//! the generated plans, walks the drive to "operation enabled", makes one profile-position
//! move and reads the statusword until the target is reached; the drive is a simulation
//! around the generated slave dictionary (`odc_examples::drive`). Every frame is printed.

use std::thread;

use odc::cia402::Controlword;
use odc::nmt::NmtCommand;
use odc_examples::drive::Drive;
use odc_examples::master::{self, Master, PositionPdos};
use odc_examples::{Error, bus};

/// The code generated from the device file, for both ends (a program uses part of it; the
/// generated modules allow the dead code that leaves).
mod lxm23a {
    odc::include_od!("lxm23a");
}
use lxm23a::{cia402::Mode, od, pdo, slave};

const NODE: u8 = 1;

/// The program: the drive in a thread, the master in this one.
pub fn main() -> Result<(), Error> {
    let (master_port, drive_port) = bus::pair();
    let drive =
        thread::spawn(move || Drive::new(slave::Dictionary::new(NODE), NODE, 10).run(&drive_port));
    let mut m = Master::new(master_port, NODE);

    m.step("boot-up");
    m.boot_up()?;
    m.step("PDO mapping by the generated plans: R_PDO2 (controlword, target position), T_PDO2 (statusword, position)");
    m.execute(&lxm23a::master::rpdo2(NODE))?;
    m.execute(&lxm23a::master::tpdo2(NODE))?;
    m.write(&od::PROFILE_VELOCITY, 1_000_000)?;
    m.write(&od::MODES_OF_OPERATION, Mode::ProfilePosition.to_i8())?;
    let active = m.read(&od::MODES_OF_OPERATION_DISPLAY)?;
    if Mode::from_i8(active) != Some(Mode::ProfilePosition) {
        return Err(format!("mode {active} active instead of profile position").into());
    }
    let pdos = PositionPdos {
        rx: pdo::Rpdo2::cob_id(NODE),
        tx: pdo::Tpdo2::cob_id(NODE),
        command: |cw: Controlword, target| pdo::Rpdo2 { controlword: cw, target_position: target },
        status: |t: &pdo::Tpdo2| (t.statusword, t.position_actual_value),
    };
    m.step("NMT start; the state machine to operation enabled");
    m.nmt(NmtCommand::Start)?;
    master::enable(&mut m, &pdos)?;
    m.step("profile position move to 100000 pulses, SYNC every 10 ms");
    let syncs = master::move_to(&mut m, &pdos, 100_000)?;
    println!("-- target reached after {syncs} SYNCs");
    m.nmt(NmtCommand::Stop)?;
    drop(m);
    let dict = drive.join().map_err(|_| "the drive thread panicked")??;
    println!(
        "-- the drive's dictionary: position actual value {}",
        dict.get(od::POSITION_ACTUAL_VALUE)?
    );
    Ok(())
}
