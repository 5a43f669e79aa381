//! The controller's side of a CiA 402 drive, sans I/O: one [`Driver::cycle`] call per
//! process-data cycle (a SYNC on CANopen, a frame on EtherCAT) turns the drive's inputs
//! (statusword, mode display, actual values) into its outputs (controlword, mode, targets).
//! The same driver runs over the CANopen master (`odc::master::axis`, with `std`), over ethercrab's
//! process image, or in a test against the device side ([`super::Drive`]).
//!
//! Each request ([`Driver::enable`], [`Driver::move_to`], …) starts a job; [`Driver::status`]
//! says whether it is under way, done or failed, and why (a fault, a timeout, a mode the
//! device does not support). Faults are reset only when asked ([`Driver::fault_reset`]).
//!
//! ```
//! use odc::cia402::{Controlword, Drive, DriveObjects, Driver, DriverStatus, Inputs};
//! use odc::cia402::{ModeOfOperation, State, Statusword, SupportedModes};
//! use odc::time::{Duration, Instant};
//!
//! /// A tiny drive's 402 objects (generated dictionaries implement the trait).
//! #[derive(Default)]
//! struct Objects { cw: Controlword, sw: Statusword, mode: Option<ModeOfOperation>, target: i32, position: i32 }
//! impl DriveObjects for Objects {
//!     fn controlword(&self) -> Controlword { self.cw }
//!     fn set_statusword(&mut self, sw: Statusword) { self.sw = sw }
//!     fn modes_of_operation(&self) -> Option<ModeOfOperation> { self.mode }
//!     fn target_position(&self) -> Option<i32> { Some(self.target) }
//!     fn profile_velocity(&self) -> Option<u32> { Some(1000) }
//!     fn set_position_actual_value(&mut self, p: i32) { self.position = p }
//! }
//!
//! let (mut od, mut drive) = (Objects::default(), Drive::new());
//! drive.start(&mut od);
//! let mut driver = Driver::new(SupportedModes(0x1)); // 0x6502: pp only
//! // One cycle: the drive's inputs in, the outputs written back, 10 ms pass.
//! let mut cycle = |driver: &mut Driver, od: &mut Objects, now: &mut Instant| {
//!     let out = driver.cycle(&Inputs::new(od.sw).with_position(od.position), *now);
//!     (od.cw, od.mode) = (out.controlword, out.mode);
//!     od.target = out.target_position.unwrap_or(od.target);
//!     drive.update(od);
//!     drive.step(od, Duration::from_millis(10));
//!     *now += Duration::from_millis(10);
//! };
//! let mut now = Instant::ZERO;
//! driver.enable();
//! while driver.status() == DriverStatus::Busy { cycle(&mut driver, &mut od, &mut now) }
//! assert_eq!(od.sw.state(), Some(State::OperationEnabled));
//! driver.set_mode(ModeOfOperation::ProfilePosition)?;
//! driver.move_to(500, false)?;
//! while driver.status() == DriverStatus::Busy { cycle(&mut driver, &mut od, &mut now) }
//! assert_eq!((driver.status(), od.position), (DriverStatus::Done, 500));
//! // 0x6502 says no csp.
//! assert!(driver.set_mode(ModeOfOperation::CyclicSyncPosition).is_err());
//! # Ok::<(), odc::cia402::DriverError>(())
//! ```

#[cfg_attr(not(feature = "cia402"), allow(unused_imports))]
use super::{Controlword, ModeOfOperation, State, Statusword, SupportedModes};
#[cfg_attr(not(feature = "cia402"), allow(unused_imports))]
use crate::time::{Duration, Instant};

/// What the driver reads from the drive each cycle (its TPDOs or input process data).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Inputs {
    /// 0x6041.
    pub statusword: Statusword,
    /// 0x6061, when the device reports it cyclically.
    pub mode_display: Option<ModeOfOperation>,
    /// 0x6064.
    pub position: Option<i32>,
    /// 0x606C.
    pub velocity: Option<i32>,
    /// 0x6077.
    pub torque: Option<i16>,
}

impl Inputs {
    /// Inputs with only a statusword.
    pub const fn new(statusword: Statusword) -> Self {
        Inputs { statusword, mode_display: None, position: None, velocity: None, torque: None }
    }

    /// With the mode display (0x6061).
    pub const fn with_mode(mut self, mode: i8) -> Self {
        self.mode_display = Some(ModeOfOperation::from_i8(mode));
        self
    }

    /// With the position actual value (0x6064).
    pub const fn with_position(mut self, p: i32) -> Self {
        self.position = Some(p);
        self
    }

    /// With the velocity actual value (0x606C).
    pub const fn with_velocity(mut self, v: i32) -> Self {
        self.velocity = Some(v);
        self
    }
}

/// What the driver writes to the drive each cycle (its RPDOs or output process data).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Outputs {
    /// 0x6040.
    pub controlword: Controlword,
    /// 0x6060, once a mode was asked for.
    pub mode: Option<ModeOfOperation>,
    /// 0x607A (pp, csp).
    pub target_position: Option<i32>,
    /// 0x60FF (pv, csv).
    pub target_velocity: Option<i32>,
    /// 0x6071 (tq, cst).
    pub target_torque: Option<i16>,
}

/// A CiA 402 device's process data as its generated code maps it: the generated
/// `cia402::Pdos` of a CANopen drive, two PDOs of its default mapping (the controlword and a
/// target out, the statusword in) or, where it has no such pair, RPDO 1 and TPDO 1 as the
/// generated `cia402::plan` maps them. The driver's [`Outputs`] become its RPDO struct, its TPDO struct becomes
/// [`Inputs`].
pub trait DrivePdos {
    /// The RPDO with the controlword.
    type Command: crate::Pdo;
    /// The TPDO with the statusword.
    type Status: crate::Pdo;
    /// The RPDO's COB-ID at `node_id`.
    fn command_cob_id(node_id: crate::cob::NodeId) -> crate::cob::CobId;
    /// The TPDO's COB-ID at `node_id`.
    fn status_cob_id(node_id: crate::cob::NodeId) -> crate::cob::CobId;
    /// The RPDO for the driver's outputs.
    fn command(outputs: &Outputs) -> Self::Command;
    /// The driver's inputs from the TPDO.
    fn status(status: &Self::Status) -> Inputs;
}

/// Why a job failed.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg(feature = "cia402")]
pub enum DriverError {
    /// The drive is in `Fault` (or went there during the job); ask for a fault reset.
    Fault,
    /// The job did not finish in time.
    Timeout {
        /// What it was waiting for.
        waiting_for: &'static str,
    },
    /// 0x6502 does not list the mode.
    ModeNotSupported(ModeOfOperation),
    /// The job needs another mode of operation active first ([`Driver::set_mode`]).
    WrongMode {
        /// The mode the job needs.
        needs: ModeOfOperation,
    },
    /// The job needs "operation enabled" ([`Driver::enable`]).
    NotEnabled,
    /// Homing error (statusword bit 13 in homing mode).
    Homing,
    /// Following error (statusword bit 13 in a position mode).
    FollowingError,
}

#[cfg(feature = "cia402")]
impl core::fmt::Display for DriverError {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        match self {
            Self::Fault => f.write_str("the drive is in fault; reset it first"),
            Self::Timeout { waiting_for } => write!(f, "timeout waiting for {waiting_for}"),
            Self::ModeNotSupported(m) => write!(f, "mode {m:?} is not in 0x6502"),
            Self::WrongMode { needs } => write!(f, "needs mode {needs:?} active"),
            Self::NotEnabled => f.write_str("needs operation enabled"),
            Self::Homing => f.write_str("homing error (statusword bit 13)"),
            Self::FollowingError => f.write_str("following error (statusword bit 13)"),
        }
    }
}

#[cfg(feature = "cia402")]
impl core::error::Error for DriverError {}

/// Where the current job is.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg(feature = "cia402")]
pub enum DriverStatus {
    /// No job asked for yet.
    Idle,
    /// Under way: call [`Driver::cycle`] again.
    Busy,
    /// Finished.
    Done,
    /// Failed.
    Failed(DriverError),
}

/// The current job.
#[derive(Clone, Copy, Debug, PartialEq)]
#[cfg(feature = "cia402")]
enum Job {
    None,
    Enable,
    Disable,
    QuickStop,
    /// Fault reset: one cycle with bit 7 clear, then the rising edge.
    FaultReset {
        edge_sent: bool,
    },
    Mode(ModeOfOperation),
    /// Profile position: set-point acknowledge clear first (`armed`), then the set-point until
    /// acknowledged, then wait for the target.
    Move {
        target: i32,
        relative: bool,
        armed: bool,
        acknowledged: bool,
        absolute: Option<i32>,
    },
    Velocity(i32),
    Home {
        started: bool,
    },
    /// Cyclic synchronous set-points: the job lasts while they come.
    Stream,
}

/// Default time a job may take (5 s; [`Driver::with_timeout`] sets another).
///
/// When a job is not done in time, [`Driver::status`] is [`DriverError::Timeout`] naming what
/// it waited for, and the drive is stopped: a drive in "operation enabled" gets the halt bit
/// (controlword bit 8, CiA 402-2 §6.3.1 / IEC 61800-7-201 "halt"), so it decelerates as its
/// halt option code 0x605D says and stays enabled for the next job; in any other state the
/// power stage does not drive a motion and the controlword stays as it was.
#[cfg(feature = "cia402")]
pub const DEFAULT_TIMEOUT: Duration = Duration::from_secs(5);

/// A CiA 402 drive's controller.
#[derive(Clone, Debug)]
#[cfg(feature = "cia402")]
pub struct Driver {
    supported: SupportedModes,
    job: Job,
    status: DriverStatus,
    out: Outputs,
    timeout: Duration,
    /// When the job started (set at its first cycle).
    started: Option<Instant>,
}

#[cfg(feature = "cia402")]
impl Driver {
    /// A driver for a drive supporting `supported` (0x6502), job timeout
    /// [`DEFAULT_TIMEOUT`].
    pub const fn new(supported: SupportedModes) -> Self {
        Driver {
            supported,
            job: Job::None,
            status: DriverStatus::Idle,
            out: Outputs {
                controlword: Controlword::DISABLE_VOLTAGE,
                mode: None,
                target_position: None,
                target_velocity: None,
                target_torque: None,
            },
            timeout: DEFAULT_TIMEOUT,
            started: None,
        }
    }

    /// The same driver with another job timeout (what happens when it fires:
    /// [`DEFAULT_TIMEOUT`]).
    pub const fn with_timeout(mut self, timeout: Duration) -> Self {
        self.timeout = timeout;
        self
    }

    /// The current job's status.
    pub const fn status(&self) -> DriverStatus {
        self.status
    }

    /// The outputs of the last cycle.
    pub const fn outputs(&self) -> Outputs {
        self.out
    }

    fn start(&mut self, job: Job) {
        self.job = job;
        self.status = DriverStatus::Busy;
        self.started = None;
    }

    fn fail(&mut self, e: DriverError) -> Result<(), DriverError> {
        self.status = DriverStatus::Failed(e);
        self.job = Job::None;
        Err(e)
    }

    /// Walks the state machine to "operation enabled".
    pub fn enable(&mut self) {
        self.start(Job::Enable);
    }

    /// Walks it to "switch on disabled" (disable voltage).
    pub fn disable(&mut self) {
        self.start(Job::Disable);
    }

    /// Quick stop: done once the drive is in "quick stop active" or has gone on to "switch on
    /// disabled" (0x605A decides which).
    pub fn quick_stop(&mut self) {
        self.start(Job::QuickStop);
    }

    /// Fault reset: a rising edge of controlword bit 7; done when the drive leaves `Fault`.
    pub fn fault_reset(&mut self) {
        self.start(Job::FaultReset { edge_sent: false });
    }

    /// Asks for a mode of operation (0x6060); done when 0x6061 shows it (at once when the
    /// device does not report 0x6061 cyclically).
    ///
    /// # Errors
    ///
    /// [`DriverError::ModeNotSupported`] when 0x6502 does not list it.
    pub fn set_mode(&mut self, mode: ModeOfOperation) -> Result<(), DriverError> {
        if !self.supported.supports(mode) {
            return self.fail(DriverError::ModeNotSupported(mode));
        }
        self.out.mode = Some(mode);
        self.start(Job::Mode(mode));
        Ok(())
    }

    fn needs(&mut self, mode: ModeOfOperation) -> Result<(), DriverError> {
        if self.out.mode == Some(mode) {
            Ok(())
        } else {
            self.fail(DriverError::WrongMode { needs: mode })
        }
    }

    /// A profile-position move (mode pp): to `target`, or by it when `relative`. Done when
    /// the drive reports "target reached" (and, when it reports its position, is there).
    ///
    /// # Errors
    ///
    /// [`DriverError::WrongMode`] when profile position is not the mode asked for.
    pub fn move_to(&mut self, target: i32, relative: bool) -> Result<(), DriverError> {
        self.needs(ModeOfOperation::ProfilePosition)?;
        let job = Job::Move { target, relative, armed: false, acknowledged: false, absolute: None };
        self.start(job);
        Ok(())
    }

    /// Profile velocity (mode pv): done when the drive reports "target reached" (velocity
    /// reached).
    ///
    /// # Errors
    ///
    /// [`DriverError::WrongMode`] when profile velocity is not the mode asked for.
    pub fn run_at(&mut self, velocity: i32) -> Result<(), DriverError> {
        self.needs(ModeOfOperation::ProfileVelocity)?;
        self.start(Job::Velocity(velocity));
        Ok(())
    }

    /// Homing (mode hm): starts with controlword bit 4, done at "homing attained" (bit 12)
    /// with "target reached" (bit 10); bit 13 is a homing error.
    ///
    /// # Errors
    ///
    /// [`DriverError::WrongMode`] when homing is not the mode asked for.
    pub fn home(&mut self) -> Result<(), DriverError> {
        self.needs(ModeOfOperation::Homing)?;
        self.start(Job::Home { started: false });
        Ok(())
    }

    /// The next cyclic synchronous position set-point (mode csp): sent at the next cycle.
    ///
    /// # Errors
    ///
    /// [`DriverError::WrongMode`] when csp is not the mode asked for.
    pub fn stream_position(&mut self, position: i32) -> Result<(), DriverError> {
        self.needs(ModeOfOperation::CyclicSyncPosition)?;
        self.out.target_position = Some(position);
        if self.job != Job::Stream {
            self.start(Job::Stream);
        }
        Ok(())
    }

    /// The next cyclic synchronous velocity set-point (mode csv).
    ///
    /// # Errors
    ///
    /// [`DriverError::WrongMode`] when csv is not the mode asked for.
    pub fn stream_velocity(&mut self, velocity: i32) -> Result<(), DriverError> {
        self.needs(ModeOfOperation::CyclicSyncVelocity)?;
        self.out.target_velocity = Some(velocity);
        if self.job != Job::Stream {
            self.start(Job::Stream);
        }
        Ok(())
    }

    /// One cycle at `now`: the drive's inputs in, its outputs out.
    pub fn cycle(&mut self, inputs: &Inputs, now: Instant) -> Outputs {
        let started = *self.started.get_or_insert(now);
        let sw = inputs.statusword;
        let state = sw.state();
        if self.status == DriverStatus::Busy {
            self.step(inputs, state);
            if self.status == DriverStatus::Busy
                && now - started > self.timeout
                && self.job != Job::Stream
            {
                let waiting_for = self.waiting_for();
                self.status = DriverStatus::Failed(DriverError::Timeout { waiting_for });
                self.job = Job::None;
                // A job that ran out of time must not leave the axis moving (see
                // DEFAULT_TIMEOUT): halt, CiA 402-2 controlword bit 8.
                if state == Some(State::OperationEnabled) {
                    self.out.controlword = Controlword::ENABLE_OPERATION.with_halt(true);
                }
            }
        }
        self.out
    }

    fn waiting_for(&self) -> &'static str {
        match self.job {
            Job::Enable => "operation enabled",
            Job::Disable => "switch on disabled",
            Job::QuickStop => "quick stop active",
            Job::FaultReset { .. } => "the fault to clear",
            Job::Mode(_) => "the mode display (0x6061)",
            Job::Move { armed: false, .. } => "the set-point acknowledge (bit 12) to clear",
            Job::Move { acknowledged: false, .. } => "the set-point acknowledge (bit 12)",
            Job::Move { .. } => "target reached (bit 10)",
            Job::Velocity(_) => "velocity reached (bit 10)",
            Job::Home { .. } => "homing attained (bit 12)",
            Job::Stream | Job::None => "nothing",
        }
    }

    fn done(&mut self) {
        self.status = DriverStatus::Done;
        if self.job != Job::Stream {
            self.job = Job::None;
        }
    }

    fn step(&mut self, inputs: &Inputs, state: Option<State>) {
        let sw = inputs.statusword;
        let fault = state == Some(State::Fault) || state == Some(State::FaultReactionActive);
        if fault && !matches!(self.job, Job::FaultReset { .. }) {
            self.status = DriverStatus::Failed(DriverError::Fault);
            self.job = Job::None;
            return;
        }
        let run = Controlword::ENABLE_OPERATION;
        match self.job {
            Job::None => self.status = DriverStatus::Done,
            Job::Enable => match state {
                Some(State::OperationEnabled) => {
                    self.out.controlword = run;
                    self.done();
                }
                Some(s) => {
                    if let Some(cw) = s.next_command_towards_enabled() {
                        self.out.controlword = cw;
                    }
                }
                None => {}
            },
            Job::Disable => {
                self.out.controlword = Controlword::DISABLE_VOLTAGE;
                if state == Some(State::SwitchOnDisabled) {
                    self.done();
                }
            }
            Job::QuickStop => {
                self.out.controlword = Controlword::QUICK_STOP;
                if matches!(state, Some(State::QuickStopActive | State::SwitchOnDisabled)) {
                    self.done();
                }
            }
            Job::FaultReset { edge_sent } => {
                if !fault && edge_sent {
                    self.out.controlword = Controlword::DISABLE_VOLTAGE;
                    self.done();
                } else if edge_sent {
                    self.out.controlword = Controlword::FAULT_RESET;
                } else {
                    // Bit 7 low for one cycle, so that the next is a rising edge.
                    self.out.controlword = Controlword::DISABLE_VOLTAGE;
                    self.job = Job::FaultReset { edge_sent: true };
                }
            }
            Job::Mode(mode) => {
                if inputs.mode_display.is_none_or(|m| m == mode) {
                    self.done();
                }
            }
            Job::Move { target, relative, armed, acknowledged, absolute } => {
                if state != Some(State::OperationEnabled) {
                    self.status = DriverStatus::Failed(DriverError::NotEnabled);
                    self.job = Job::None;
                    return;
                }
                // Where the move ends, known from the position at its start.
                let absolute = absolute.or_else(|| match relative {
                    false => Some(target),
                    true => inputs.position.map(|p| p.wrapping_add(target)),
                });
                self.out.target_position = Some(target);
                // The hand-shake (CiA 402 figure 19) starts from bit 12 clear: set, it belongs
                // to something before this move (a set-point not yet released, or "homing
                // attained" in a statusword sampled before the switch from hm), and taking it
                // for this set-point's acknowledge would clear bit 4 before the drive saw it.
                if !armed {
                    self.out.controlword = run.with_relative(relative);
                    if sw.setpoint_ack() {
                        self.job = Job::Move { target, relative, armed, acknowledged, absolute };
                        return;
                    }
                }
                let armed = true;
                if !acknowledged {
                    self.out.controlword = run.with_new_setpoint(true).with_relative(relative);
                    // This statusword was sampled before bit 4 went out when the move was
                    // armed in this very cycle: its bit 12 is clear.
                    let ack = sw.setpoint_ack();
                    self.job = Job::Move { target, relative, armed, acknowledged: ack, absolute };
                    if ack {
                        // Acknowledged: clear bit 4 (the hand-shake of CiA 402 figure 19).
                        self.out.controlword = run.with_relative(relative);
                    }
                    return;
                }
                self.out.controlword = run.with_relative(relative);
                self.job = Job::Move { target, relative, armed, acknowledged, absolute };
                let there = match (absolute, inputs.position) {
                    (Some(a), Some(p)) => a == p,
                    _ => true,
                };
                if sw.target_reached() && !sw.setpoint_ack() && there {
                    self.done();
                }
            }
            Job::Velocity(v) => {
                self.out.controlword = run;
                self.out.target_velocity = Some(v);
                if state != Some(State::OperationEnabled) {
                    self.status = DriverStatus::Failed(DriverError::NotEnabled);
                    self.job = Job::None;
                } else if sw.target_reached() {
                    self.done();
                }
            }
            Job::Home { started } => {
                if state != Some(State::OperationEnabled) {
                    self.status = DriverStatus::Failed(DriverError::NotEnabled);
                    self.job = Job::None;
                    return;
                }
                self.out.controlword = run.with_homing_start(true);
                if sw.homing_error() {
                    self.out.controlword = run;
                    self.status = DriverStatus::Failed(DriverError::Homing);
                    self.job = Job::None;
                } else if started && sw.homing_attained() && sw.target_reached() {
                    self.out.controlword = run;
                    self.done();
                } else {
                    self.job = Job::Home { started: true };
                }
            }
            Job::Stream => {
                self.out.controlword = run;
                if state != Some(State::OperationEnabled) {
                    self.status = DriverStatus::Failed(DriverError::NotEnabled);
                    self.job = Job::None;
                } else if self.out.mode == Some(ModeOfOperation::CyclicSyncPosition)
                    && sw.following_error()
                {
                    self.status = DriverStatus::Failed(DriverError::FollowingError);
                    self.job = Job::None;
                } else {
                    self.status = DriverStatus::Busy;
                }
            }
        }
    }
}

#[cfg(test)]
#[path = "driver_tests.rs"]
#[cfg(feature = "cia402")]
mod tests;
