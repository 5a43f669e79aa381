//! An LTI ServoOne on a simulated CAN bus: `cargo run --example servoone`.
//!
//! Both ends run code generated from `eds/servoone.eds`. The ServoOne has no factory PDO
//! mapping ("the PDOs do not contain any mapping with the factory setting", manual 8.3), so
//! the generated plan, run first, leaves them empty; the master then maps R_PDO1 (controlword,
//! target position) and T_PDO1 (statusword, actual position) with a plan built from its own
//! PDO structs, checked against the generated descriptors. Then it walks the drive to
//! "operation enabled", makes one profile-position move and reads the statusword until the
//! target is reached. Every frame is printed.

use std::thread;

use odc::cia402::{Controlword, ModeOfOperation, Statusword};
use odc::nmt::NmtCommand;
use odc_examples::drive::Drive;
use odc_examples::master::{self, Master, PositionPdos, mapping_plan};
use odc_examples::{Error, bus};

/// The code generated from the device file, for both ends (a program uses part of it; the
/// generated modules allow the dead code that leaves).
mod servoone {
    odc::include_od!("servoone");
}
use servoone::{od, pdo, slave};

const NODE: u8 = 1;

/// R_PDO1 as this application maps it.
#[derive(Clone, Copy, Debug, PartialEq, odc::Pdo)]
struct Command {
    #[pdo(index = 0x6040, bits = 16)]
    controlword: Controlword,
    #[pdo(index = 0x607A)]
    target_position: i32,
}

/// T_PDO1 as this application maps it.
#[derive(Clone, Copy, Debug, PartialEq, odc::Pdo)]
struct Status {
    #[pdo(index = 0x6041, bits = 16)]
    statusword: Statusword,
    #[pdo(index = 0x6064)]
    position_actual_value: i32,
}

// The structs map objects the file declares mappable, with their types.
const _: () = {
    assert!(od::CONTROLWORD.addr.index == 0x6040 && od::CONTROLWORD.pdo_mappable);
    assert!(od::TARGET_POSITION.addr.index == 0x607A && od::TARGET_POSITION.pdo_mappable);
    assert!(od::STATUSWORD.addr.index == 0x6041 && od::STATUSWORD.pdo_mappable);
    assert!(
        od::POSITION_ACTUAL_VALUE.addr.index == 0x6064 && od::POSITION_ACTUAL_VALUE.pdo_mappable
    );
};

/// The program: the drive in a thread, the master in this one.
pub fn main() -> Result<(), Error> {
    let (master_port, drive_port) = bus::pair();
    let drive =
        thread::spawn(move || Drive::new(slave::Dictionary::new(NODE), NODE, 10).run(&drive_port));
    let mut m = Master::new(master_port, NODE);

    m.step("boot-up");
    m.boot_up()?;
    m.step("the generated plan: the file's (empty) factory mapping");
    m.execute(&servoone::master::plan(NODE))?;
    m.step("the application's mapping: R_PDO1 controlword + target position, T_PDO1 statusword + position");
    let (rx, tx) = (pdo::Rpdo1::cob_id(NODE), pdo::Tpdo1::cob_id(NODE));
    m.execute(&mapping_plan::<Command>(
        pdo::Rpdo1::COMM_INDEX,
        pdo::Rpdo1::MAPPING_INDEX,
        rx,
        255,
    ))?;
    m.execute(&mapping_plan::<Status>(pdo::Tpdo1::COMM_INDEX, pdo::Tpdo1::MAPPING_INDEX, tx, 255))?;
    m.write(&od::PROFILE_VELOCITY, 100_000)?;
    m.write(&od::MODES_OF_OPERATION, ModeOfOperation::ProfilePosition.to_i8())?;
    let pdos = PositionPdos {
        rx,
        tx,
        command: |cw: Controlword, target| Command { controlword: cw, target_position: target },
        status: |t: &Status| (t.statusword, t.position_actual_value),
    };
    m.step("NMT start; the state machine to operation enabled");
    m.nmt(NmtCommand::Start)?;
    master::enable(&mut m, &pdos)?;
    m.step("profile position move to 10000, SYNC every 10 ms");
    let syncs = master::move_to(&mut m, &pdos, 10_000)?;
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
