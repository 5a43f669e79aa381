//! A CiA 402 drive on the async master: the runtime's [`Driver`] runs one step per SYNC cycle
//! ([`Axis::cycle`], called by the program's cycle task for every axis), its outputs go out in
//! the device's RPDO and its inputs come from the last TPDO; the jobs ([`Axis::enable`],
//! [`Axis::move_to`], …) are futures that complete when the driver says the job is done, so
//! several axes move at once on one cycle.
//!
//! The process data is the blocking axis's [`ProcessData`] (or the generated
//! `<device>::cia402::Pdos` through [`Axis::with_pdos`]).

use core::future::poll_fn;
use core::task::Poll;
use std::sync::{Mutex, MutexGuard, PoisonError};

use super::wait::Waiters;
use super::{Clock, Error, Master};
use crate::Pdo;
use crate::cia402::{Driver, DriverStatus, Inputs, ModeOfOperation, Statusword};
use crate::cob::NodeId;
pub use crate::master::axis::ProcessData;

#[derive(Debug)]
struct State {
    driver: Driver,
    inputs: Inputs,
    /// TPDOs received so far when the last cycle looked (a new one replaces the inputs).
    seen: u64,
    cycles: u64,
    waiters: Waiters,
}

/// A CiA 402 drive driven over PDOs on the async master's SYNC cycle.
pub struct Axis<R, T> {
    node: NodeId,
    pdos: ProcessData<R, T>,
    state: Mutex<State>,
}

impl<R, T> core::fmt::Debug for Axis<R, T> {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        f.debug_struct("Axis").field("node", &self.node).finish_non_exhaustive()
    }
}

impl<R: Pdo, T: Pdo> Axis<R, T> {
    /// The drive at `node`, its first inputs read over SDO (0x6041, and 0x6064 when it has
    /// one).
    ///
    /// # Errors
    ///
    /// The SDO error reading the statusword.
    pub async fn new<C: Clock>(
        master: &Master<C>,
        node: NodeId,
        driver: Driver,
        pdos: ProcessData<R, T>,
    ) -> Result<Self, Error> {
        let sw = master.upload(node, 0x6041, 0).await?;
        let sw = Statusword(u16::from_le_bytes([
            sw.first().copied().unwrap_or(0),
            sw.get(1).copied().unwrap_or(0),
        ]));
        let mut inputs = Inputs::new(sw);
        if let Ok(p) = master.upload(node, 0x6064, 0).await
            && let Ok(b) = <[u8; 4]>::try_from(p.as_slice())
        {
            inputs = inputs.with_position(i32::from_le_bytes(b));
        }
        let seen = master.latest_frame(pdos.tpdo).1;
        let state = State { driver, inputs, seen, cycles: 0, waiters: Waiters::default() };
        Ok(Self { node, pdos, state: Mutex::new(state) })
    }

    /// The drive at `node` with the process data of its generated code.
    ///
    /// # Errors
    ///
    /// As [`Axis::new`].
    pub async fn with_pdos<C: Clock, P: crate::cia402::DrivePdos<Command = R, Status = T>>(
        master: &Master<C>,
        node: NodeId,
        driver: Driver,
    ) -> Result<Self, Error> {
        let pdos = ProcessData {
            rpdo: P::command_cob_id(node),
            tpdo: P::status_cob_id(node),
            command: P::command,
            status: P::status,
        };
        Self::new(master, node, driver, pdos).await
    }

    fn lock(&self) -> MutexGuard<'_, State> {
        // Every change under the lock is whole before it is released: a poisoned lock is
        // consistent.
        self.state.lock().unwrap_or_else(PoisonError::into_inner)
    }

    /// The node.
    pub fn node(&self) -> NodeId {
        self.node
    }

    /// The inputs of the last cycle.
    pub fn inputs(&self) -> Inputs {
        self.lock().inputs
    }

    /// Cycles run so far.
    pub fn cycles(&self) -> u64 {
        self.lock().cycles
    }

    /// The driver's status (how the last job ended).
    pub fn status(&self) -> DriverStatus {
        self.lock().driver.status()
    }

    /// One cycle, before the cycle's SYNC: the last TPDO (if a new one came) into the
    /// driver, the driver's outputs queued in the RPDO. Completes the job futures whose job
    /// ended.
    ///
    /// # Errors
    ///
    /// A struct that does not pack or unpack, or [`Stopped`](super::Stopped).
    pub fn cycle<C: Clock>(&self, master: &Master<C>) -> Result<Inputs, Error> {
        let (frame, count) = master.latest_frame(self.pdos.tpdo);
        let now = master.now();
        let mut s = self.lock();
        if count != s.seen
            && let Some(f) = frame
        {
            let t = T::unpack(f.bytes())
                .map_err(|reason| Error::Unpack { cob_id: self.pdos.tpdo, reason })?;
            s.inputs = (self.pdos.status)(&t);
            s.seen = count;
        }
        let inputs = s.inputs;
        let out = s.driver.cycle(&inputs, now);
        s.cycles += 1;
        // Job futures check the driver's status, cycle waiters the count: wake both.
        s.waiters.wake();
        drop(s);
        master.send_pdo(self.pdos.rpdo, &(self.pdos.command)(&out))?;
        Ok(inputs)
    }

    /// Waits for the driver's job to end (the cycle task runs it).
    ///
    /// # Errors
    ///
    /// [`Error::Drive`] when the job fails (fault, timeout, …).
    pub async fn done(&self) -> Result<(), Error> {
        poll_fn(|cx| {
            let mut s = self.lock();
            match s.driver.status() {
                DriverStatus::Busy => {
                    s.waiters.register(cx.waker());
                    Poll::Pending
                }
                DriverStatus::Failed(error) => {
                    Poll::Ready(Err(Error::Drive { node: self.node, error }))
                }
                DriverStatus::Done | DriverStatus::Idle => Poll::Ready(Ok(())),
            }
        })
        .await
    }

    /// Waits until the cycle task has run one more cycle (its RPDO is queued).
    ///
    /// # Errors
    ///
    /// None yet: a `Result` so that a stopped cycle can say so later without an API change.
    pub async fn next_cycle(&self) -> Result<(), Error> {
        let after = self.lock().cycles;
        poll_fn(|cx| {
            let mut s = self.lock();
            if s.cycles > after {
                return Poll::Ready(Ok(()));
            }
            s.waiters.register(cx.waker());
            Poll::Pending
        })
        .await
    }

    /// Homing in mode hm (method and speeds as the drive's 0x6098/0x6099 say), until
    /// "homing attained".
    ///
    /// # Errors
    ///
    /// [`Error::Drive`] when hm is not the mode set, or the job fails.
    pub async fn home(&self) -> Result<(), Error> {
        self.lock().driver.home().map_err(|error| Error::Drive { node: self.node, error })?;
        self.done().await
    }

    /// The next cyclic synchronous position set-point (mode csp): completes once the cycle
    /// has sent it.
    ///
    /// # Errors
    ///
    /// [`Error::Drive`] when csp is not the mode set, or the drive faulted.
    pub async fn stream_position(&self, position: i32) -> Result<(), Error> {
        self.lock()
            .driver
            .stream_position(position)
            .map_err(|error| Error::Drive { node: self.node, error })?;
        self.next_cycle().await?;
        match self.status() {
            DriverStatus::Failed(error) => Err(Error::Drive { node: self.node, error }),
            _ => Ok(()),
        }
    }

    /// To "operation enabled".
    ///
    /// # Errors
    ///
    /// As [`Axis::done`].
    pub async fn enable(&self) -> Result<(), Error> {
        self.lock().driver.enable();
        self.done().await
    }

    /// Fault reset.
    ///
    /// # Errors
    ///
    /// As [`Axis::done`].
    pub async fn fault_reset(&self) -> Result<(), Error> {
        self.lock().driver.fault_reset();
        self.done().await
    }

    /// A mode of operation: written to 0x6060 over SDO after the driver checked it against
    /// 0x6502, and confirmed by 0x6061.
    ///
    /// # Errors
    ///
    /// [`Error::Drive`] with the mode refused, the SDO error, or another mode displayed.
    pub async fn set_mode<C: Clock>(
        &self,
        master: &Master<C>,
        mode: ModeOfOperation,
    ) -> Result<(), Error> {
        self.lock()
            .driver
            .set_mode(mode)
            .map_err(|error| Error::Drive { node: self.node, error })?;
        master.download(self.node, 0x6060, 0, &mode.to_i8().to_le_bytes()).await?;
        let shown = master.upload(self.node, 0x6061, 0).await?;
        if shown.first().map(|b| i8::from_le_bytes([*b])) != Some(mode.to_i8()) {
            return Err(Error::Invalid("the drive displays another mode of operation (0x6061)"));
        }
        self.done().await
    }

    /// A profile-position move to `target`.
    ///
    /// # Errors
    ///
    /// As [`Axis::done`].
    pub async fn move_to(&self, target: i32) -> Result<(), Error> {
        self.lock()
            .driver
            .move_to(target, false)
            .map_err(|error| Error::Drive { node: self.node, error })?;
        self.done().await
    }

    /// A profile-velocity run at `velocity`, until reached.
    ///
    /// # Errors
    ///
    /// As [`Axis::done`].
    pub async fn run_at(&self, velocity: i32) -> Result<(), Error> {
        self.lock()
            .driver
            .run_at(velocity)
            .map_err(|error| Error::Drive { node: self.node, error })?;
        self.done().await
    }

    /// Quick stop.
    ///
    /// # Errors
    ///
    /// As [`Axis::done`].
    pub async fn quick_stop(&self) -> Result<(), Error> {
        self.lock().driver.quick_stop();
        self.done().await
    }

    /// To "switch on disabled".
    ///
    /// # Errors
    ///
    /// As [`Axis::done`].
    pub async fn disable(&self) -> Result<(), Error> {
        self.lock().driver.disable();
        self.done().await
    }
}
