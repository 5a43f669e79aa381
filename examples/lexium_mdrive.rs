//! A Lexium MDrive on a simulated CAN bus: `cargo run --example lexium_mdrive`.
//!
//! Both ends run code generated from `eds/lexium-mdrive.eds`: the master configures every PDO
//! with the generated plan (the MDrive's PDOs are all valid by default), walks the drive to
//! "operation enabled" over R_PDO2/T_PDO2, makes one profile-position move of one revolution
//! (51200 microsteps) and reads the statusword until the target is reached; the drive is a
//! simulation around the generated slave dictionary. Every frame is printed.

use std::thread;

use odc::cia402::{Driver, ModeOfOperation};
use odc::master::axis::Axis;
use odc::nmt::NmtCommand;
use odc_examples::drive::Drive;
use odc_examples::{Error, bus, step};

/// The code generated from the device file, for both ends (a program uses part of it; the
/// generated modules allow the dead code that leaves).
mod lexium_mdrive {
    odc::include_od!("lexium_mdrive");
}
use lexium_mdrive::{od, slave};

/// The MDrive's factory node id (manual 5.2).
const NODE: odc::cob::NodeId = odc::node_id!(0x41);

/// The program: the drive in a thread, the master in this one.
pub fn main() -> Result<(), Error> {
    let (master_port, drive_port) = bus::pair();
    let drive =
        thread::spawn(move || Drive::new(slave::Dictionary::new(NODE), NODE, 10).run(&drive_port));
    let mut m = odc_examples::master(master_port);

    step("boot-up");
    m.wait_boot_up(NODE)?;
    step("PDO mapping by the generated plan: every default PDO of the file");
    m.execute(NODE, &lexium_mdrive::master::plan(NODE))?;
    // 512000 microsteps/s, 5120 per 10 ms SYNC period (the application examples' velocity).
    m.write(NODE, &od::PROFILE_VELOCITY, 512_000)?;
    let supported = odc_examples::supported_modes(&mut m, NODE)?;
    step("NMT start; the state machine to operation enabled");
    m.nmt(NmtCommand::Start, NODE)?;
    let mut axis =
        Axis::with_pdos::<lexium_mdrive::cia402::Pdos>(&mut m, NODE, Driver::new(supported))?;
    axis.enable()?;
    axis.set_mode(ModeOfOperation::ProfilePosition)?;
    step("profile position move to 51200 microsteps (one revolution), SYNC every cycle");
    let before = axis.cycles;
    axis.move_to(51_200)?;
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
