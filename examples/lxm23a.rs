//! A Schneider LXM23A on a simulated CAN bus: `cargo run --example lxm23a`.
//!
//! Both ends run code generated from `eds/lxm23a.eds`: the master configures the PDOs with
//! the generated plans, walks the drive to "operation enabled", makes one profile-position
//! move and reads the statusword until the target is reached; the drive is a simulation
//! around the generated slave dictionary (`odc_examples::drive`). Every frame is printed.

use std::thread;

use odc::cia402::{Driver, ModeOfOperation};
use odc::master::axis::Axis;
use odc::nmt::NmtCommand;
use odc_examples::drive::Drive;
use odc_examples::{Error, bus, step};

/// The code generated from the device file, for both ends (a program uses part of it; the
/// generated modules allow the dead code that leaves).
mod lxm23a {
    odc::include_od!("lxm23a");
}
use lxm23a::{od, slave};

const NODE: odc::cob::NodeId = odc::node_id!(1);

/// The program: the drive in a thread, the master in this one.
pub fn main() -> Result<(), Error> {
    let (master_port, drive_port) = bus::pair();
    let drive =
        thread::spawn(move || Drive::new(slave::Dictionary::new(NODE), NODE, 10).run(&drive_port));
    let mut m = odc_examples::master(master_port);

    step("boot-up");
    m.wait_boot_up(NODE)?;
    step(
        "PDO mapping by the generated plans: R_PDO2 (controlword, target position), T_PDO2 (statusword, position)",
    );
    m.execute(NODE, &lxm23a::master::rpdo2(NODE))?;
    m.execute(NODE, &lxm23a::master::tpdo2(NODE))?;
    m.write(NODE, &od::PROFILE_VELOCITY, 1_000_000)?;
    let supported = odc_examples::supported_modes(&mut m, NODE)?;
    step("NMT start; the state machine to operation enabled");
    m.nmt(NmtCommand::Start, NODE)?;
    let mut axis = Axis::with_pdos::<lxm23a::cia402::Pdos>(&mut m, NODE, Driver::new(supported))?;
    axis.enable()?;
    step("profile position mode, checked against 0x6502 and confirmed by 0x6061");
    axis.set_mode(ModeOfOperation::ProfilePosition)?;
    step("profile position move to 100000 pulses, SYNC every cycle");
    let before = axis.cycles;
    axis.move_to(100_000)?;
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
