//! Drives on a simulated CAN bus, for the example programs beside this crate
//! (`cargo run --example lxm23a`, `lexium_mdrive`, `servoone`, `linmot`).
//!
//! Each example includes the code odc generates from one device file twice over: the master
//! side (descriptors, PDO structs, the configuration plans) drives the bus through the
//! runtime's `odc::master::Master` (and a CiA 402 drive through `odc::master::axis::Axis`),
//! and the slave side (the `no_std` object dictionary) is the heart of a simulated drive on
//! the other end. The two run in two threads and talk through [`bus`], a pair of channels
//! carrying [`odc::can::CanFrame`]s; every frame is printed.
//!
//! - [`bus`]: the channels, and how a frame is printed;
//! - [`drive`]: the simulated CiA 402 drive: the generated dictionary served by the runtime's
//!   `odc::node::Node`, with its `odc::cia402::Drive` (state machine, profile-position axis).

pub mod bus;
pub mod drive;

use odc::master::{Dir, Master};

/// What can go wrong in an example: a closed bus, an SDO failure, a missing answer.
pub type Error = Box<dyn std::error::Error + Send + Sync>;

/// How long the master waits for an answer.
pub const TIMEOUT: odc::time::Duration = odc::time::Duration::from_secs(10);

/// The runtime's master on `port`, printing every frame sent and received, numbered.
pub fn master(port: bus::Port) -> Master<bus::Port> {
    let mut m = Master::new(port).with_timeout(TIMEOUT);
    let mut n = 0u32;
    m.observe(move |dir, frame| {
        n += 1;
        let arrow = match dir {
            Dir::Sent => "master -> ",
            Dir::Received => "  drive -> ",
        };
        println!("{n:>5}  {arrow} {}", bus::describe(frame));
    });
    m
}

/// Prints a step of the example.
pub fn step(text: &str) {
    println!("-- {text}");
}

/// 0x6502 (supported drive modes) of `node`, read over SDO.
///
/// # Errors
///
/// The SDO error.
pub fn supported_modes(
    m: &mut Master<bus::Port>,
    node: odc::cob::NodeId,
) -> Result<odc::cia402::SupportedModes, Error> {
    let v = m.upload(node, 0x6502, 0)?;
    let bytes: [u8; 4] = v.as_slice().try_into().map_err(|_| "0x6502 is not 4 bytes")?;
    Ok(odc::cia402::SupportedModes(u32::from_le_bytes(bytes)))
}
