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

use odc::cia402::{Controlword, Driver, Inputs, ModeOfOperation, Outputs, Statusword};
use odc::cob::CobId;
use odc::master::axis::{Axis, ProcessData};
use odc::master::mapping_plan;
use odc::nmt::NmtCommand;
use odc_examples::drive::Drive;
use odc_examples::{Error, bus, step};

/// The code generated from the device file, for both ends (a program uses part of it; the
/// generated modules allow the dead code that leaves).
mod servoone {
    odc::include_od!("servoone");
}
use servoone::{od, pdo, slave};

const NODE: odc::cob::NodeId = odc::node_id!(1);

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
    let mut m = odc_examples::master(master_port);

    step("boot-up");
    m.wait_boot_up(NODE)?;
    step("the generated plan: the file's (empty) factory mapping");
    m.execute(NODE, &servoone::master::plan(NODE))?;
    step(
        "the application's mapping: R_PDO1 controlword + target position, T_PDO1 statusword + position",
    );
    let (rx, tx) = (CobId(pdo::Rpdo1::cob_id(NODE)), CobId(pdo::Tpdo1::cob_id(NODE)));
    m.execute(
        NODE,
        &mapping_plan::<Command>(pdo::Rpdo1::COMM_INDEX, pdo::Rpdo1::MAPPING_INDEX, rx, 255),
    )?;
    m.execute(
        NODE,
        &mapping_plan::<Status>(pdo::Tpdo1::COMM_INDEX, pdo::Tpdo1::MAPPING_INDEX, tx, 255),
    )?;
    m.write(NODE, &od::PROFILE_VELOCITY, 100_000)?;
    let supported = odc_examples::supported_modes(&mut m, NODE)?;
    step("NMT start; the state machine to operation enabled");
    m.nmt(NmtCommand::Start, NODE)?;
    let pdos = ProcessData {
        rpdo: rx,
        tpdo: tx,
        command: |o: &Outputs| Command {
            controlword: o.controlword,
            target_position: o.target_position.unwrap_or(0),
        },
        status: |t: &Status| Inputs::new(t.statusword).with_position(t.position_actual_value),
    };
    let mut axis = Axis::new(&mut m, NODE, Driver::new(supported), pdos)?;
    axis.enable()?;
    axis.set_mode(ModeOfOperation::ProfilePosition)?;
    step("profile position move to 10000, SYNC every cycle");
    let before = axis.cycles;
    axis.move_to(10_000)?;
    println!("-- target reached after {} SYNCs", axis.cycles - before);
    m.nmt(NmtCommand::Stop, NODE)?;
    drop(m);
    let dict = drive.join().map_err(|_| "the drive thread panicked")??;
    println!(
        "-- the drive's dictionary: position actual value {}",
        dict.get(od::POSITION_ACTUAL_VALUE)?
    );
    Ok(())
}
