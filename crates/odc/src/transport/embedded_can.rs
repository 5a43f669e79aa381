//! The `embedded_can` traits: any MCU HAL (bxCAN, FDCAN, MCP2515 drivers...) that implements
//! them carries odc's frames. [`CanFrame`] is itself an [`embedded_can::Frame`], and converts
//! from and to any other implementation ([`CanFrame::from_frame`], [`CanFrame::to_frame`]).
//!
//! [`NbBus`] and [`BlockingBus`] make a [`Bus`] of a driver and a clock the user
//! supplies (a timer, a tick counter): the `embedded_can` traits have no notion of time.
//!
//! ```
//! use embedded_can::{Frame, Id, StandardId};
//! use odc::can::CanFrame;
//!
//! let f = CanFrame::from_slice(0x605, &[0x40, 0x00, 0x10, 0x00]).unwrap();
//! assert_eq!(Frame::id(&f), Id::Standard(StandardId::new(0x605).unwrap()));
//! let back: CanFrame = CanFrame::from_frame(&f);
//! assert_eq!(back, f);
//! ```

use embedded_can::{ExtendedId, Frame, Id, StandardId};

use super::Bus;
use crate::can::CanFrame;
use crate::time::Instant;

impl Frame for CanFrame {
    fn new(id: impl Into<Id>, data: &[u8]) -> Option<Self> {
        match id.into() {
            Id::Standard(s) => CanFrame::from_slice(u32::from(s.as_raw()), data),
            Id::Extended(e) => CanFrame::extended(e.as_raw(), data),
        }
    }

    fn new_remote(id: impl Into<Id>, dlc: usize) -> Option<Self> {
        let len = u8::try_from(dlc).ok().filter(|&l| l <= 8)?;
        match id.into() {
            Id::Standard(s) => CanFrame::remote(u32::from(s.as_raw()), len),
            Id::Extended(e) => CanFrame::remote_extended(e.as_raw(), len),
        }
    }

    fn is_extended(&self) -> bool {
        self.extended
    }

    fn is_remote_frame(&self) -> bool {
        self.remote
    }

    fn id(&self) -> Id {
        // A frame's id fits its width (the constructors check it); the mask keeps this total.
        let standard = StandardId::new((self.id & 0x7FF) as u16).unwrap_or(StandardId::ZERO);
        if self.extended {
            ExtendedId::new(self.id & 0x1FFF_FFFF).map_or(Id::Standard(standard), Id::Extended)
        } else {
            Id::Standard(standard)
        }
    }

    fn dlc(&self) -> usize {
        usize::from(self.len.min(8))
    }

    fn data(&self) -> &[u8] {
        self.bytes()
    }
}

impl CanFrame {
    /// The frame of any `embedded_can` frame (a HAL's received frame). Data past 8 bytes (a
    /// CAN FD frame) is cut to 8.
    pub fn from_frame<F: Frame>(f: &F) -> Self {
        let (id, extended) = match f.id() {
            Id::Standard(s) => (u32::from(s.as_raw()), false),
            Id::Extended(e) => (e.as_raw(), true),
        };
        let mut data = [0u8; 8];
        let bytes = f.data();
        let n = bytes.len().min(8);
        if let (Some(d), Some(s)) = (data.get_mut(..n), bytes.get(..n)) {
            d.copy_from_slice(s);
        }
        let len = if f.is_remote_frame() { f.dlc().min(8) } else { n };
        CanFrame { id, extended, remote: f.is_remote_frame(), len: len as u8, data }
    }

    /// This frame as another `embedded_can` frame type (a HAL's frame to transmit); `None`
    /// when that type refuses it.
    pub fn to_frame<F: Frame>(&self) -> Option<F> {
        let id: Id = if self.extended {
            ExtendedId::new(self.id)?.into()
        } else {
            StandardId::new(u16::try_from(self.id).ok()?)?.into()
        };
        if self.remote {
            F::new_remote(id, usize::from(self.len))
        } else {
            F::new(id, self.bytes())
        }
    }
}

/// Why an adapter could not move a frame.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Error<E> {
    /// The driver failed.
    Driver(E),
    /// The driver's frame type refused this frame (its `Frame::new` gave `None`).
    Unrepresentable(CanFrame),
}

impl<E: core::fmt::Debug> core::fmt::Display for Error<E> {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        match self {
            Self::Driver(e) => write!(f, "CAN driver error: {e:?}"),
            Self::Unrepresentable(fr) => write!(f, "frame 0x{:X} not representable", fr.id),
        }
    }
}

/// A [`Bus`] over a non-blocking (`embedded_can::nb::Can`) driver and a clock.
///
/// `send` waits while the transmit buffers are full (and sends again a lower-priority frame
/// the driver replaced); `recv` polls the driver until a frame arrives or the clock reaches
/// the deadline.
pub struct NbBus<C, T> {
    can: C,
    clock: T,
}

impl<C: embedded_can::nb::Can, T: FnMut() -> Instant> NbBus<C, T> {
    /// The bus of driver `can`; `clock` tells the time (a monotonic timer's [`Instant`]).
    pub fn new(can: C, clock: T) -> Self {
        Self { can, clock }
    }

    /// The driver back.
    pub fn into_inner(self) -> C {
        self.can
    }

    fn transmit(&mut self, frame: &C::Frame) -> Result<(), Error<C::Error>> {
        let mut replaced = None;
        loop {
            match self.can.transmit(frame) {
                Ok(r) => {
                    replaced = replaced.or(r);
                    break;
                }
                Err(nb::Error::WouldBlock) => {}
                Err(nb::Error::Other(e)) => return Err(Error::Driver(e)),
            }
        }
        // A lower-priority frame pending in the driver was pushed out: it still has to go.
        if let Some(r) = replaced {
            loop {
                match self.can.transmit(&r) {
                    Ok(None) => return Ok(()),
                    Ok(Some(again)) => return self.transmit(&again),
                    Err(nb::Error::WouldBlock) => {}
                    Err(nb::Error::Other(e)) => return Err(Error::Driver(e)),
                }
            }
        }
        Ok(())
    }
}

impl<C: embedded_can::nb::Can, T: FnMut() -> Instant> Bus for NbBus<C, T> {
    type Error = Error<C::Error>;

    fn send(&mut self, frame: &CanFrame) -> Result<(), Self::Error> {
        let f: C::Frame = frame.to_frame().ok_or(Error::Unrepresentable(*frame))?;
        self.transmit(&f)
    }

    fn recv(&mut self, deadline: Instant) -> Result<Option<CanFrame>, Self::Error> {
        loop {
            match self.can.receive() {
                Ok(f) => return Ok(Some(CanFrame::from_frame(&f))),
                Err(nb::Error::WouldBlock) if (self.clock)() >= deadline => return Ok(None),
                Err(nb::Error::WouldBlock) => {}
                Err(nb::Error::Other(e)) => return Err(Error::Driver(e)),
            }
        }
    }

    fn now(&mut self) -> Instant {
        (self.clock)()
    }
}

/// A [`Bus`] over a blocking (`embedded_can::blocking::Can`) driver and a clock.
///
/// The blocking trait has no timeout: `recv` returns when the driver has a frame, whatever the
/// deadline. Use [`NbBus`] where the deadline matters (an SDO client's timeout).
pub struct BlockingBus<C, T> {
    can: C,
    clock: T,
}

impl<C: embedded_can::blocking::Can, T: FnMut() -> Instant> BlockingBus<C, T> {
    /// The bus of driver `can`; `clock` tells the time (a monotonic timer's [`Instant`]).
    pub fn new(can: C, clock: T) -> Self {
        Self { can, clock }
    }

    /// The driver back.
    pub fn into_inner(self) -> C {
        self.can
    }
}

impl<C: embedded_can::blocking::Can, T: FnMut() -> Instant> Bus for BlockingBus<C, T> {
    type Error = Error<C::Error>;

    fn send(&mut self, frame: &CanFrame) -> Result<(), Self::Error> {
        let f: C::Frame = frame.to_frame().ok_or(Error::Unrepresentable(*frame))?;
        self.can.transmit(&f).map_err(Error::Driver)
    }

    fn recv(&mut self, _deadline: Instant) -> Result<Option<CanFrame>, Self::Error> {
        self.can.receive().map(|f| Some(CanFrame::from_frame(&f))).map_err(Error::Driver)
    }

    fn now(&mut self) -> Instant {
        (self.clock)()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A driver with one transmit slot that is full every other call, and a receive queue.
    struct Fake {
        sent: [Option<CanFrame>; 4],
        n: usize,
        busy: bool,
        rx: Option<CanFrame>,
    }

    #[derive(Debug, PartialEq)]
    struct Never;
    impl embedded_can::Error for Never {
        fn kind(&self) -> embedded_can::ErrorKind {
            embedded_can::ErrorKind::Other
        }
    }

    impl embedded_can::nb::Can for Fake {
        type Frame = CanFrame;
        type Error = Never;
        fn transmit(&mut self, f: &CanFrame) -> nb::Result<Option<CanFrame>, Never> {
            self.busy = !self.busy;
            if !self.busy {
                return Err(nb::Error::WouldBlock);
            }
            self.sent[self.n] = Some(*f);
            self.n += 1;
            Ok(None)
        }
        fn receive(&mut self) -> nb::Result<CanFrame, Never> {
            self.rx.take().ok_or(nb::Error::WouldBlock)
        }
    }

    #[test]
    fn nb_adapter_sends_receives_and_times_out() {
        let mut t = 0u64;
        let fake = Fake { sent: [None; 4], n: 0, busy: true, rx: None };
        let mut bus = NbBus::new(fake, move || {
            t += 1;
            Instant::from_millis(t)
        });
        let a = CanFrame::from_slice(0x181, &[1]).unwrap();
        let b = CanFrame::remote(0x705, 1).unwrap();
        bus.send(&a).unwrap();
        bus.send(&b).unwrap();
        assert_eq!(bus.recv(Instant::from_millis(10)).unwrap(), None);
        assert!(bus.now() > Instant::from_millis(10));
        let mut fake = bus.into_inner();
        assert_eq!(&fake.sent[..2], &[Some(a), Some(b)]);
        fake.rx = Some(CanFrame::extended(0x1234_5678, &[9]).unwrap());
        let mut bus = NbBus::new(fake, || Instant::ZERO);
        let got = bus.recv(Instant::ZERO).unwrap().unwrap();
        assert!(got.extended && got.id == 0x1234_5678 && got.bytes() == [9]);
    }

    #[test]
    fn frame_trait_round_trips() {
        let e: CanFrame = Frame::new(ExtendedId::new(0x1ABC_DEF0).unwrap(), &[1, 2]).unwrap();
        assert!(e.extended && Frame::is_extended(&e) && Frame::dlc(&e) == 2);
        let r: CanFrame = Frame::new_remote(StandardId::new(0x705).unwrap(), 1).unwrap();
        assert_eq!(r, CanFrame::remote(0x705, 1).unwrap());
        assert!(<CanFrame as Frame>::new_remote(StandardId::ZERO, 9).is_none());
        assert_eq!(r.to_frame::<CanFrame>(), Some(r));
        assert_eq!(CanFrame::from_frame(&e), e);
    }
}
