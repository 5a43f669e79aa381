//! The async master: the controller side of [`crate::master`] for programs that run several
//! things on one bus at once (a 1 kHz SYNC/PDO cycle while SDO transfers configure other
//! nodes), on `core::future` with no runtime inside.
//!
//! The bus comes as two halves, [`CanTx`] and [`CanRx`], and time as a [`Clock`]; adapters:
//! `tokio` (feature `tokio`: the TCP virtual bus of `odc simulate --tcp`, SocketCAN, a
//! timerfd clock) and `embedded` (feature `embedded-can`: an `embedded-can`-style async
//! interface an embassy HAL implements). One [`Master`] is shared by reference between the tasks that use it; it owns
//! no thread and no timer. Its [`Master::run`] future carries the frames (received frames to
//! the tasks waiting for them, queued frames to the bus, SYNC and PDOs before SDO, NMT and
//! LSS) and must be polled alongside the rest (`tokio::join!`, `tokio::spawn`, an embassy
//! task).
//!
//! - SDO ([`Master::upload`], [`Master::download`], typed [`Master::read`] and
//!   [`Master::write`], block transfer, plans): the same [`crate::sdo::Client`] state machine
//!   as the blocking master, one per node, so transfers to different nodes run concurrently;
//! - NMT, the heartbeat consumer and the other events ([`Master::next_event`]);
//! - the SYNC producer and the cycle ([`Master::cycle`]): one SYNC per period on the clock's
//!   grid, the RPDOs of the cycle queued before it;
//! - PDO exchange with the generated structs ([`Master::send_pdo`], [`Master::latest_pdo`]);
//! - LSS ([`lss`]) and the CiA 402 [`Axis`](axis::Axis).
//!
//! ```no_run
//! use odc::asynch::{Master, tokio::{TimerfdClock, tcp}};
//! use odc::nmt::NmtCommand;
//! use odc::time::Duration;
//!
//! # async fn program() -> Result<(), Box<dyn std::error::Error>> {
//! // `odc simulate eds/lxm23a.eds --node-id 1 --tcp 127.0.0.1:5000` on the other end.
//! let (tx, rx) = tcp::connect("127.0.0.1:5000").await?;
//! let master = Master::new(TimerfdClock::new());
//! let node = odc::node_id!(1);
//! let work = async {
//!     let device_type = master.upload(node, 0x1000, 0).await?;
//!     master.nmt(NmtCommand::Start, node)?;
//!     // A 1 kHz SYNC while the SDO transfers of other tasks go on.
//!     let mut cycle = master.cycle(Duration::from_millis(1));
//!     for _ in 0..1000 {
//!         cycle.tick().await;
//!         master.sync()?;
//!     }
//!     Ok::<_, odc::asynch::Error>(device_type)
//! };
//! tokio::select! {
//!     r = master.run(tx, rx) => r?,
//!     r = work => println!("device type {:02X?}", r?),
//! }
//! # Ok(()) }
//! ```
//!
//! Errors are the blocking master's [`Error`](crate::master::Error); the bus error itself is
//! what [`Master::run`] returns, and every operation waiting when it ends fails with
//! [`Stopped`].

pub mod axis;
#[cfg(feature = "embedded-can")]
pub mod embedded;
pub mod lss;
mod master;
mod sdo;
#[cfg(feature = "tokio")]
pub mod tokio;
mod wait;

use core::future::Future;

use crate::can::CanFrame;
use crate::time::Instant;

pub use master::{Cycle, EVENT_QUEUE, Master, Priority, RECEIVED_PER_POLL};

/// The error of an operation whose frames can no longer go out or come in: [`Master::run`]
/// ended (the bus failed, or it was dropped).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Stopped;

impl core::fmt::Display for Stopped {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        f.write_str("the master's bus task stopped")
    }
}

impl core::error::Error for Stopped {}

/// The async master's error: the blocking master's, with [`Stopped`] for the bus.
pub type Error = crate::master::Error<Stopped>;

/// The sending half of a CAN interface.
///
/// `send` completes when the interface took the frame (a TX mailbox, a socket); the master
/// sends one frame at a time, so a frame queued with a higher [`Priority`] waits for at most
/// the one in progress.
// The futures are not required to be `Send`: an embassy HAL's seldom are, and a tokio program
// runs the master's futures on one task (`join!`) or its `Send` adapters.
#[allow(async_fn_in_trait)]
pub trait CanTx {
    /// The interface's error.
    type Error;

    /// Sends a frame.
    ///
    /// # Errors
    ///
    /// When the interface fails.
    async fn send(&mut self, frame: &CanFrame) -> Result<(), Self::Error>;
}

/// The receiving half of a CAN interface.
#[allow(async_fn_in_trait)]
pub trait CanRx {
    /// The interface's error.
    type Error;

    /// The next received frame.
    ///
    /// # Errors
    ///
    /// When the interface fails (the master's [`Master::run`] then ends).
    async fn recv(&mut self) -> Result<CanFrame, Self::Error>;
}

/// A monotonic clock and a timer: the time base of every timeout and of the SYNC period.
pub trait Clock {
    /// Now.
    fn now(&self) -> Instant;

    /// Completes when [`Clock::now`] reaches `deadline` (at once when it has); a timer of
    /// coarse [`Clock::resolution`] may complete up to one step later.
    fn sleep_until(&self, deadline: Instant) -> impl Future<Output = ()>;

    /// The step of the timer behind [`Clock::sleep_until`]: it wakes on multiples of it
    /// (tokio: 1 ms). A [`Cycle`] asks to wake that much early, so it lands on
    /// the timer step nearest its grid point rather than the one after.
    fn resolution(&self) -> crate::time::Duration {
        crate::time::Duration::MICROSECOND
    }
}

impl<C: Clock + ?Sized> Clock for &C {
    fn now(&self) -> Instant {
        (**self).now()
    }

    fn sleep_until(&self, deadline: Instant) -> impl Future<Output = ()> {
        (**self).sleep_until(deadline)
    }

    fn resolution(&self) -> crate::time::Duration {
        (**self).resolution()
    }
}
