//! An LTI ServoOne on a simulated CAN bus: `cargo run --example servoone`.
//!
//! Both ends run code generated from `eds/servoone.eds`. The ServoOne has no factory PDO
//! mapping ("the PDOs do not contain any mapping with the factory setting", manual 8.3), so
//! the generated plan, run first, leaves them empty; the master then maps R_PDO1 (controlword,
//! target position) and T_PDO1 (statusword, actual position) with the plan generated for the
//! CiA 402 driver (`cia402::plan`, whose PDOs `cia402::Pdos` names: the README's recipe for
//! any CiA 402 drive). Then it walks the drive to "operation enabled", makes one
//! profile-position move and reads the statusword until the target is reached. Every frame
//! is printed.

use std::thread;

use odc::cia402::{Driver, ModeOfOperation};
use odc::master::axis::Axis;
use odc::nmt::NmtCommand;
use odc_examples::drive::Drive;
use odc_examples::{Error, bus, step};

/// The code generated from the device file, for both ends (a program uses part of it; the
/// generated modules allow the dead code that leaves).
mod servoone {
    odc::include_od!("servoone");
}
use servoone::{cia402, od, slave};

const NODE: odc::cob::NodeId = odc::node_id!(1);

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
        "the driver's mapping: R_PDO1 controlword + target position, T_PDO1 statusword + position",
    );
    m.execute(NODE, &cia402::plan(NODE))?;
    m.write(NODE, &od::PROFILE_VELOCITY, 100_000)?;
    let supported = odc_examples::supported_modes(&mut m, NODE)?;
    step("NMT start; the state machine to operation enabled");
    m.nmt(NmtCommand::Start, NODE)?;
    let mut axis = Axis::with_pdos::<cia402::Pdos>(&mut m, NODE, Driver::new(supported))?;
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
