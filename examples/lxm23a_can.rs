//! README's program: an LXM23A on a real bus (`cargo run --example lxm23a_can`, SocketCAN
//! interface `can0`, the drive at node 1). The simulated `lxm23a` example runs the same steps.

use odc::cia402::{Driver, ModeOfOperation, SupportedModes};
use odc::master::{Master, axis::Axis};
use odc::nmt::NmtCommand;
use odc::transport::socketcan::SocketCan;
mod lxm23a {
    odc::include_od!("lxm23a");
}
use lxm23a::od;

fn main() -> Result<(), Box<dyn std::error::Error>> {
    const NODE: odc::cob::NodeId = odc::node_id!(1);
    let mut m = Master::new(SocketCan::open("can0")?);
    m.nmt(NmtCommand::ResetNode, NODE)?;
    m.wait_boot_up(NODE)?;
    m.execute(NODE, &lxm23a::cia402::plan(NODE))?; // the PDOs cia402::Pdos names
    m.write(NODE, &od::PROFILE_VELOCITY, 1_000_000)?;
    m.nmt(NmtCommand::Start, NODE)?;
    let modes = SupportedModes(u32::from_le_bytes(
        m.upload(NODE, 0x6502, 0)?.try_into().map_err(|_| "0x6502")?,
    ));
    let mut axis = Axis::with_pdos::<lxm23a::cia402::Pdos>(&mut m, NODE, Driver::new(modes))?;
    axis.enable()?;
    axis.set_mode(ModeOfOperation::ProfilePosition)?;
    axis.move_to(100_000)?;
    Ok(())
}
