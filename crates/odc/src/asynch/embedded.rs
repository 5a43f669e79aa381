//! The `embedded-can`-style async interface: what an embassy HAL's CAN driver offers
//! (`embassy_stm32::can::CanTx::write(&mut self, &Frame).await`,
//! `CanRx::read(&mut self).await`), as two traits over `embedded_can::Frame`, and the
//! adapter [`Hal`] that makes such halves the master's [`CanTx`]/[`CanRx`].
//!
//! `embedded-can` 0.4 has blocking and `nb` traits only; these follow their shape (frame type
//! and error as associated types) with `async fn`, so a HAL crate implements them in a few
//! lines (feature `embedded-can`).
//!
//! ```
//! use odc::asynch::embedded::{Hal, Receive, Transmit};
//! use odc::can::CanFrame;
//!
//! /// A HAL's transmit half (here a vector standing in for the TX mailboxes).
//! struct Mailboxes(Vec<CanFrame>);
//! impl Transmit for Mailboxes {
//!     type Frame = CanFrame; // any `embedded_can::Frame`: the HAL's own frame type
//!     type Error = core::convert::Infallible;
//!     async fn transmit(&mut self, frame: &CanFrame) -> Result<(), Self::Error> {
//!         self.0.push(*frame);
//!         Ok(())
//!     }
//! }
//! let mut tx = Hal(Mailboxes(Vec::new()));
//! let sync = CanFrame::from_slice(0x080, &[]).unwrap();
//! # let poll = |f: core::pin::Pin<&mut dyn core::future::Future<Output = _>>| {
//! #     f.poll(&mut core::task::Context::from_waker(core::task::Waker::noop()))
//! # };
//! use odc::asynch::CanTx;
//! assert!(poll(core::pin::pin!(tx.send(&sync))).is_ready());
//! assert_eq!(tx.0.0, [sync]);
//! ```

use super::{CanRx, CanTx};
use crate::can::CanFrame;

/// The transmit half of an async CAN driver.
#[allow(async_fn_in_trait)]
pub trait Transmit {
    /// The driver's frame type.
    type Frame: embedded_can::Frame;
    /// The driver's error.
    type Error;

    /// Puts `frame` in a transmit mailbox, waiting for a free one.
    ///
    /// # Errors
    ///
    /// The driver's.
    async fn transmit(&mut self, frame: &Self::Frame) -> Result<(), Self::Error>;
}

/// The receive half of an async CAN driver.
#[allow(async_fn_in_trait)]
pub trait Receive {
    /// The driver's frame type.
    type Frame: embedded_can::Frame;
    /// The driver's error.
    type Error;

    /// The next received frame.
    ///
    /// # Errors
    ///
    /// The driver's (a bus-off, an overrun).
    async fn receive(&mut self) -> Result<Self::Frame, Self::Error>;
}

/// An async HAL half as the master's [`CanTx`] or [`CanRx`].
#[derive(Debug)]
pub struct Hal<T>(pub T);

/// Why a HAL half failed: its error, or a frame its frame type cannot carry.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum HalError<E> {
    /// The driver's error.
    Driver(E),
    /// A frame the driver's frame type did not take (an identifier too wide).
    Frame,
}

impl<T: Transmit> CanTx for Hal<T> {
    type Error = HalError<T::Error>;

    async fn send(&mut self, frame: &CanFrame) -> Result<(), Self::Error> {
        let f: T::Frame = frame.to_frame().ok_or(HalError::Frame)?;
        self.0.transmit(&f).await.map_err(HalError::Driver)
    }
}

impl<T: Receive> CanRx for Hal<T> {
    type Error = HalError<T::Error>;

    async fn recv(&mut self) -> Result<CanFrame, Self::Error> {
        let f = self.0.receive().await.map_err(HalError::Driver)?;
        Ok(CanFrame::from_frame(&f))
    }
}
