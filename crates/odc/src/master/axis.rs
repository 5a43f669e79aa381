//! A CiA 402 drive on the CANopen master: the [`Driver`]'s cycles run on SYNC, its outputs go
//! out in the device's RPDO and its inputs come from the device's TPDO, both the generated
//! structs of the device.
//!
//! ```no_run
//! # use odc::master::{Master, axis::{Axis, ProcessData}};
//! # use odc::cob::CobId;
//! # use odc::cia402::{Controlword, Driver, Inputs, ModeOfOperation, Outputs, Statusword, SupportedModes};
//! # #[derive(odc::Pdo)] struct Rpdo2 { #[pdo(index = 0x6040)] controlword: u16, #[pdo(index = 0x607A)] target_position: i32 }
//! # #[derive(odc::Pdo)] struct Tpdo2 { #[pdo(index = 0x6041)] statusword: u16, #[pdo(index = 0x6064)] position: i32 }
//! # fn run(bus: odc::transport::mem::MemPort) -> Result<(), Box<dyn std::error::Error>> {
//! let mut master = Master::new(bus);
//! let pdos = ProcessData {
//!     rpdo: CobId::new(0x301),
//!     tpdo: CobId::new(0x281),
//!     command: |o: &Outputs| Rpdo2 { controlword: o.controlword.bits(), target_position: o.target_position.unwrap_or(0) },
//!     status: |t: &Tpdo2| Inputs::new(Statusword(t.statusword)).with_position(t.position),
//! };
//! let mut axis = Axis::new(&mut master, odc::node_id!(1), Driver::new(SupportedModes(0x1)), pdos)?;
//! axis.enable()?;
//! axis.set_mode(ModeOfOperation::ProfilePosition)?;
//! axis.move_to(100_000)?;
//! # Ok(()) }
//! ```

use super::{Error, Master};
use crate::Pdo;
use crate::cia402::{Driver, DriverStatus, Inputs, ModeOfOperation, Statusword};
use crate::cob::{CobId, NodeId};
use crate::time::Duration;
use crate::transport::Bus;

/// The device's process data for its 402 objects: the RPDO that carries the controlword
/// (and targets), the TPDO that carries the statusword (and actual values), and how the
/// driver's outputs and inputs map onto their generated structs.
pub struct ProcessData<R, T> {
    /// COB-ID of the RPDO.
    pub rpdo: CobId,
    /// COB-ID of the TPDO.
    pub tpdo: CobId,
    /// The RPDO struct for the driver's outputs.
    pub command: fn(&crate::cia402::Outputs) -> R,
    /// The driver's inputs from the TPDO struct.
    pub status: fn(&T) -> Inputs,
}

/// How long a cycle waits for the TPDO after its SYNC; without one (an event-driven TPDO
/// whose data did not change) the last inputs stand.
pub const CYCLE_WAIT: Duration = Duration::from_millis(20);

/// A CiA 402 drive driven over PDOs and SYNC.
pub struct Axis<'m, B: Bus, R, T> {
    master: &'m mut Master<B>,
    node: NodeId,
    pdos: ProcessData<R, T>,
    /// The driver (its status says how the last job ended).
    pub driver: Driver,
    inputs: Inputs,
    /// Cycles run so far.
    pub cycles: u64,
}

impl<'m, B: Bus, R: Pdo, T: Pdo> Axis<'m, B, R, T> {
    /// The drive at `node`, its first inputs read over SDO (0x6041, and 0x6064 when it has one).
    ///
    /// # Errors
    ///
    /// The SDO error reading the statusword.
    pub fn new(
        master: &'m mut Master<B>,
        node: NodeId,
        driver: Driver,
        pdos: ProcessData<R, T>,
    ) -> Result<Self, Error<B::Error>> {
        let sw = master.upload(node, 0x6041, 0)?;
        let sw = Statusword(u16::from_le_bytes([
            sw.first().copied().unwrap_or(0),
            sw.get(1).copied().unwrap_or(0),
        ]));
        let mut inputs = Inputs::new(sw);
        if let Ok(p) = master.upload(node, 0x6064, 0)
            && let Ok(b) = <[u8; 4]>::try_from(p.as_slice())
        {
            inputs = inputs.with_position(i32::from_le_bytes(b));
        }
        Ok(Axis { master, node, pdos, driver, inputs, cycles: 0 })
    }

    /// The drive at `node` with the process data of its generated code
    /// (`<device>::cia402::Pdos`).
    ///
    /// # Errors
    ///
    /// As [`Axis::new`].
    pub fn with_pdos<P: crate::cia402::DrivePdos<Command = R, Status = T>>(
        master: &'m mut Master<B>,
        node: NodeId,
        driver: Driver,
    ) -> Result<Self, Error<B::Error>> {
        let pdos = ProcessData {
            rpdo: P::command_cob_id(node),
            tpdo: P::status_cob_id(node),
            command: P::command,
            status: P::status,
        };
        Self::new(master, node, driver, pdos)
    }

    /// The inputs of the last cycle.
    pub fn inputs(&self) -> Inputs {
        self.inputs
    }

    /// One cycle: the driver's outputs in the RPDO, a SYNC, the TPDO (if it comes) into the
    /// driver.
    ///
    /// # Errors
    ///
    /// A struct that does not pack or unpack, or the bus error.
    pub fn cycle(&mut self) -> Result<Inputs, Error<B::Error>> {
        let now = self.master.now();
        let out = self.driver.cycle(&self.inputs, now);
        self.master.send_pdo(self.pdos.rpdo, &(self.pdos.command)(&out))?;
        self.master.sync()?;
        let tpdo = self.pdos.tpdo;
        let deadline = self.master.now() + CYCLE_WAIT;
        let mut latest =
            self.master.link.take(deadline, |f| tpdo.matches(f)).map_err(Error::Bus)?;
        // An event-driven TPDO may have come more than once: the newest is the drive's state.
        if latest.is_some() {
            let now = self.master.now();
            while let Some(f) =
                self.master.link.take(now, |f| tpdo.matches(f)).map_err(Error::Bus)?
            {
                latest = Some(f);
            }
        }
        if let Some(f) = latest {
            let t =
                T::unpack(f.bytes()).map_err(|reason| Error::Unpack { cob_id: tpdo, reason })?;
            self.inputs = (self.pdos.status)(&t);
        }
        self.cycles += 1;
        Ok(self.inputs)
    }

    /// Cycles until the driver's job is done.
    ///
    /// # Errors
    ///
    /// [`Error::Drive`] when the job fails (fault, timeout, …), or a cycle's error.
    pub fn run(&mut self) -> Result<(), Error<B::Error>> {
        loop {
            match self.driver.status() {
                DriverStatus::Busy => {
                    self.cycle()?;
                }
                DriverStatus::Failed(error) => return Err(Error::Drive { node: self.node, error }),
                DriverStatus::Done | DriverStatus::Idle => return Ok(()),
            }
        }
    }

    /// To "operation enabled".
    ///
    /// # Errors
    ///
    /// As [`Axis::run`].
    pub fn enable(&mut self) -> Result<(), Error<B::Error>> {
        self.driver.enable();
        self.run()
    }

    /// Fault reset.
    ///
    /// # Errors
    ///
    /// As [`Axis::run`].
    pub fn fault_reset(&mut self) -> Result<(), Error<B::Error>> {
        self.driver.fault_reset();
        self.run()
    }

    /// A mode of operation: written to 0x6060 over SDO (most RPDOs do not carry it) after the
    /// driver checked it against 0x6502, and confirmed by 0x6061.
    ///
    /// # Errors
    ///
    /// [`Error::Drive`] with the mode refused, the SDO error, or another mode displayed.
    pub fn set_mode(&mut self, mode: ModeOfOperation) -> Result<(), Error<B::Error>> {
        self.driver.set_mode(mode).map_err(|error| Error::Drive { node: self.node, error })?;
        let v = mode.to_i8().to_le_bytes();
        self.master.download(self.node, 0x6060, 0, &v)?;
        let shown = self.master.upload(self.node, 0x6061, 0)?;
        if shown.first().map(|b| i8::from_le_bytes([*b])) != Some(mode.to_i8()) {
            return Err(Error::Invalid("the drive displays another mode of operation (0x6061)"));
        }
        self.run()
    }

    /// A profile-position move to `target`.
    ///
    /// # Errors
    ///
    /// As [`Axis::run`].
    pub fn move_to(&mut self, target: i32) -> Result<(), Error<B::Error>> {
        self.driver
            .move_to(target, false)
            .map_err(|error| Error::Drive { node: self.node, error })?;
        self.run()
    }

    /// A profile-velocity run at `velocity`, until reached.
    ///
    /// # Errors
    ///
    /// As [`Axis::run`].
    pub fn run_at(&mut self, velocity: i32) -> Result<(), Error<B::Error>> {
        self.driver.run_at(velocity).map_err(|error| Error::Drive { node: self.node, error })?;
        self.run()
    }

    /// Quick stop.
    ///
    /// # Errors
    ///
    /// As [`Axis::run`].
    pub fn quick_stop(&mut self) -> Result<(), Error<B::Error>> {
        self.driver.quick_stop();
        self.run()
    }

    /// To "switch on disabled".
    ///
    /// # Errors
    ///
    /// As [`Axis::run`].
    pub fn disable(&mut self) -> Result<(), Error<B::Error>> {
        self.driver.disable();
        self.run()
    }
}
