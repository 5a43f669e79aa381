//! CiA 402 drive profile: controlword (0x6040), statusword (0x6041), the state machine, modes of
//! operation (0x6060/0x6061) and supported modes (0x6502).
//!
//! A master walks a drive to "operation enabled" by reading the state from the statusword and
//! sending the controlword that leads on; [`State::after`] is the drive's side of the same
//! state machine (what a simulated or slave-side drive does with a controlword). The drive's
//! side as a whole, the objects it reads and sets, the state machine with its fault and quick
//! stop reactions, and a simple axis, is [`Drive`] over [`DriveObjects`]:
//!
//! ```
//! use odc::cia402::{Controlword, ModeOfOperation, State, Statusword, SupportedModes};
//!
//! let mut drive = State::SwitchOnDisabled;
//! let mut sent = Vec::new();
//! // Master: from the statusword, the next controlword, until the drive is enabled.
//! while drive.statusword().state() != Some(State::OperationEnabled) {
//!     let state = drive.statusword().state().ok_or("not a state")?;
//!     let cw = state.next_command_towards_enabled().ok_or("wait for the drive")?;
//!     sent.push(cw);
//!     drive = drive.after(cw, false); // the drive's transition
//! }
//! assert_eq!(drive, State::OperationEnabled);
//! use Controlword as Cw;
//! assert_eq!(sent, [Cw::SHUTDOWN, Cw::SWITCH_ON, Cw::ENABLE_OPERATION]);
//!
//! // A profile-position set-point: enable operation with "new set-point".
//! let cw = Controlword::ENABLE_OPERATION.with_new_setpoint(true);
//! assert_eq!(cw.bits(), 0x001F);
//! let sw = Statusword(0x1637); // as read from 0x6041
//! assert_eq!(sw.state(), Some(State::OperationEnabled));
//! assert!(sw.target_reached() && sw.setpoint_ack());
//!
//! // 0x6502: which modes the drive supports.
//! let modes = SupportedModes(0x0000_0025); // pp, pv, hm
//! assert!(modes.supports(ModeOfOperation::ProfilePosition));
//! assert!(!modes.supports(ModeOfOperation::CyclicSyncPosition));
//! assert_eq!(ModeOfOperation::from_i8(8), ModeOfOperation::CyclicSyncPosition);
//! # Ok::<(), &str>(())
//! ```

mod device;
mod driver;
#[cfg(feature = "cia402")]
mod homing;
mod modes;
mod state;
mod values;
mod words;

pub use device::DriveObjects;
#[cfg(feature = "cia402")]
pub use device::{Axis, DeviceControl, Drive, HOME_SWITCH, transition};
#[cfg(feature = "cia402")]
pub use driver::{DEFAULT_TIMEOUT, Driver, DriverError, DriverStatus};
pub use driver::{DrivePdos, Inputs, Outputs};
pub use modes::{ModeOfOperation, SupportedModes};
pub use state::State;
pub use words::{Command, Controlword, Statusword};

#[cfg(all(test, feature = "cia402"))]
mod tests;
