//! The Schneider Lexium 23A (LXM23A) servo drive on CANopen, for async Rust: its parameters
//! typed, its keypad parameters by their manual names, and a [`Lxm23a`] that enables, homes,
//! moves and streams positions.
//!
//! This crate is also the pattern a drive crate on odc follows; copy it to start one for
//! another drive:
//!
//! 1. `build.rs` generates the master side of the drive's device file with `odc-build`
//!    (descriptors for every object, PDO structs, the CiA 402 process data and its PDO plan,
//!    and the vendor's parameter scheme from the overlay beside the file);
//! 2. the crate re-exports what users need of it: [`od`] (every object, typed:
//!    `od::PROFILE_VELOCITY` is an `Entry<u32>`), [`keypad`] (the vendor's names: `P1-44` is
//!    [`keypad::P1_44`], any `Pa-bc` is [`keypad::param`]), [`pdo`] and [`cia402`];
//! 3. [`Lxm23a`] wraps the runtime's CiA 402 axis ([`odc::asynch::axis::Axis`]) in the
//!    drive's vocabulary, with async methods, on the async master ([`odc::asynch::Master`]);
//! 4. `tests/` runs it against the drive as `odc simulate eds/lxm23a.eds` serves it, in its
//!    own `cargo test`.
//!
//! # Use
//!
//! The master carries the frames ([`Master::run`](odc::asynch::Master::run)); a cycle task
//! runs every drive's [`Lxm23a::cycle`] and the SYNC; the program awaits the drive's jobs.
//!
//! ```no_run
//! use odc::asynch::Master;
//! use odc::asynch::tokio::{TimerfdClock, tcp};
//! use odc::time::Duration;
//! use odc_drive_lxm23a::{HomingMethod, Lxm23a, keypad, od};
//!
//! # async fn program() -> Result<(), Box<dyn std::error::Error>> {
//! // `odc simulate eds/lxm23a.eds --node-id 1 --tcp 127.0.0.1:5000`, or the real drive
//! // through `odc::asynch::tokio::socketcan::open("can0")`.
//! let (tx, rx) = tcp::connect("127.0.0.1:5000").await?;
//! let master = Master::new(TimerfdClock::new());
//! let work = async {
//!     let drive = Lxm23a::connect(&master, odc::node_id!(1)).await?;
//!     let cycle = async {
//!         let mut cycle = master.cycle(Duration::from_millis(2));
//!         loop {
//!             cycle.tick().await;
//!             drive.cycle(&master)?;
//!             master.sync()?;
//!         }
//!     };
//!     let moves = async {
//!         drive.set(&master, &keypad::P1_44, 1).await?; // electronic gear numerator
//!         drive.set(&master, &od::PROFILE_VELOCITY, 500_000).await?;
//!         drive.enable().await?;
//!         drive.home(&master, HomingMethod::CURRENT_POSITION).await?;
//!         drive.move_to(&master, 100_000).await?;
//!         drive.stream_positions(&master, (0..100).map(|i| 100_000 + 100 * i)).await
//!     };
//!     tokio::select! {
//!         r = cycle => r,
//!         r = moves => r,
//!     }
//! };
//! tokio::select! {
//!     r = master.run(tx, rx) => r?,
//!     r = work => r?,
//! }
//! # Ok(()) }
//! ```

use std::sync::Mutex;

use odc::asynch::axis::Axis;
use odc::asynch::{Clock, Master};
use odc::cia402::{DrivePdos, Driver, Inputs, ModeOfOperation, SupportedModes};
use odc::cob::NodeId;
use odc::nmt::NmtCommand;
use odc::{Entry, ObjValue};

/// The code generated from `eds/lxm23a.eds` (and its overlay) by `build.rs`.
mod generated {
    odc::include_od!("lxm23a");
}

pub use generated::{cia402, keypad, od, pdo};

/// Why an operation failed: the async master's error (SDO aborts, timeouts, CiA 402 job
/// failures), each naming the node and what was asked.
pub type Error = odc::asynch::Error;

/// A homing method (0x6098, CiA 402-2 §6.5): the LXM23A's file allows 0 to 35.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct HomingMethod(pub i8);

impl HomingMethod {
    /// Method 35: the current position is home.
    pub const CURRENT_POSITION: Self = Self(35);
}

type DriveAxis = Axis<<cia402::Pdos as DrivePdos>::Command, <cia402::Pdos as DrivePdos>::Status>;

/// An LXM23A on the bus: its CiA 402 axis on RPDO 2 (controlword, target position) and TPDO 2
/// (statusword, actual position), and the mode it was last put in.
#[derive(Debug)]
pub struct Lxm23a {
    axis: DriveAxis,
    mode: Mutex<Option<ModeOfOperation>>,
}

impl Lxm23a {
    /// Configures the drive at `node` over SDO (its PDOs for the axis), starts it (NMT) and
    /// reads its first state. Run [`Lxm23a::cycle`] on every cycle from then on.
    ///
    /// # Errors
    ///
    /// The SDO error of a configuration write or of the first reads.
    pub async fn connect<C: Clock>(master: &Master<C>, node: NodeId) -> Result<Self, Error> {
        master.execute(node, &cia402::plan(node)).await?;
        let modes = master.read(node, &od::SUPPORTED_DRIVE_MODES).await?;
        master.nmt(NmtCommand::Start, node)?;
        let driver = Driver::new(SupportedModes(modes));
        let axis = Axis::with_pdos::<C, cia402::Pdos>(master, node, driver).await?;
        Ok(Self { axis, mode: Mutex::new(None) })
    }

    /// The node.
    pub fn node(&self) -> NodeId {
        self.axis.node()
    }

    /// One cycle, before the cycle's SYNC: the last TPDO in, the RPDO out.
    ///
    /// # Errors
    ///
    /// A PDO that does not pack or unpack, or a stopped master.
    pub fn cycle<C: Clock>(&self, master: &Master<C>) -> Result<Inputs, Error> {
        self.axis.cycle(master)
    }

    /// The actual position the last TPDO carried (user units, 0x6064).
    pub fn position(&self) -> Option<i32> {
        self.axis.inputs().position
    }

    /// Reads a parameter: any object of [`od`] or [`keypad`], typed.
    ///
    /// # Errors
    ///
    /// The SDO error.
    pub async fn get<C: Clock, T: ObjValue>(
        &self,
        master: &Master<C>,
        p: &Entry<T>,
    ) -> Result<T, Error> {
        master.read(self.node(), p).await
    }

    /// Writes a parameter.
    ///
    /// # Errors
    ///
    /// The SDO error (the drive's abort: a value out of range, a read-only object).
    pub async fn set<C: Clock, T: ObjValue>(
        &self,
        master: &Master<C>,
        p: &Entry<T>,
        value: T,
    ) -> Result<(), Error> {
        master.write(self.node(), p, value).await
    }

    /// To "operation enabled" (fault reset first when the drive is in fault).
    ///
    /// # Errors
    ///
    /// The job's failure (a fault that does not clear, a timeout).
    pub async fn enable(&self) -> Result<(), Error> {
        if self.axis.inputs().statusword.state() == Some(odc::cia402::State::Fault) {
            self.axis.fault_reset().await?;
        }
        self.axis.enable().await
    }

    /// To "switch on disabled".
    ///
    /// # Errors
    ///
    /// The job's failure.
    pub async fn disable(&self) -> Result<(), Error> {
        self.axis.disable().await
    }

    async fn mode<C: Clock>(&self, master: &Master<C>, mode: ModeOfOperation) -> Result<(), Error> {
        let current = *self.mode.lock().unwrap_or_else(std::sync::PoisonError::into_inner);
        if current != Some(mode) {
            self.axis.set_mode(master, mode).await?;
            *self.mode.lock().unwrap_or_else(std::sync::PoisonError::into_inner) = Some(mode);
        }
        Ok(())
    }

    /// Homing by `method` (mode hm), until "homing attained".
    ///
    /// # Errors
    ///
    /// The SDO error writing the method, or the job's failure (homing error, timeout).
    pub async fn home<C: Clock>(
        &self,
        master: &Master<C>,
        method: HomingMethod,
    ) -> Result<(), Error> {
        self.mode(master, ModeOfOperation::Homing).await?;
        self.set(master, &od::HOMING_METHOD, method.0).await?;
        self.axis.home().await
    }

    /// A profile-position move to `target` (mode pp, at 0x6081's profile velocity), until
    /// "target reached".
    ///
    /// # Errors
    ///
    /// The job's failure.
    pub async fn move_to<C: Clock>(&self, master: &Master<C>, target: i32) -> Result<(), Error> {
        self.mode(master, ModeOfOperation::ProfilePosition).await?;
        self.axis.move_to(target).await
    }

    /// Streams `positions` in cyclic synchronous position mode (csp), one per cycle.
    ///
    /// # Errors
    ///
    /// The job's failure (the drive faults).
    pub async fn stream_positions<C: Clock>(
        &self,
        master: &Master<C>,
        positions: impl IntoIterator<Item = i32>,
    ) -> Result<(), Error> {
        self.mode(master, ModeOfOperation::CyclicSyncPosition).await?;
        for p in positions {
            self.axis.stream_position(p).await?;
        }
        Ok(())
    }
}
