//! An in-process CAN bus between two nodes: two channels, one per direction.

use std::fmt;
use std::sync::mpsc::{self, Receiver, RecvTimeoutError, Sender, TryRecvError};
use std::time::{Duration, Instant};

use odc::can::CanFrame;
use odc::cob::{self, Function};

/// The other end of the bus is gone.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Closed;

impl fmt::Display for Closed {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str("the bus is closed (the other node stopped)")
    }
}

impl std::error::Error for Closed {}

/// One end of the bus: what it sends, the other end receives, in order.
pub struct Port {
    tx: Sender<CanFrame>,
    rx: Receiver<CanFrame>,
    start: Instant,
}

/// A bus with two ends.
pub fn pair() -> (Port, Port) {
    let (a_tx, b_rx) = mpsc::channel();
    let (b_tx, a_rx) = mpsc::channel();
    let start = Instant::now();
    (Port { tx: a_tx, rx: a_rx, start }, Port { tx: b_tx, rx: b_rx, start })
}

impl Port {
    /// Sends a frame to the other end.
    ///
    /// # Errors
    ///
    /// [`Closed`] when the other end is gone.
    pub fn send(&self, frame: CanFrame) -> Result<(), Closed> {
        self.tx.send(frame).map_err(|_| Closed)
    }

    /// The next frame, waiting at most `timeout`; `None` if none came.
    ///
    /// # Errors
    ///
    /// [`Closed`] when the other end is gone and nothing is left to read.
    pub fn recv_timeout(&self, timeout: Duration) -> Result<Option<CanFrame>, Closed> {
        match self.rx.recv_timeout(timeout) {
            Ok(f) => Ok(Some(f)),
            Err(RecvTimeoutError::Timeout) => Ok(None),
            Err(RecvTimeoutError::Disconnected) => Err(Closed),
        }
    }

    /// A frame that has already arrived, without waiting.
    ///
    /// # Errors
    ///
    /// [`Closed`] when the other end is gone and nothing is left to read.
    pub fn try_recv(&self) -> Result<Option<CanFrame>, Closed> {
        match self.rx.try_recv() {
            Ok(f) => Ok(Some(f)),
            Err(TryRecvError::Empty) => Ok(None),
            Err(TryRecvError::Disconnected) => Err(Closed),
        }
    }
}

/// The master's side of the bus: `odc::master::Master` runs over it.
impl odc::transport::Bus for Port {
    type Error = Closed;

    fn send(&mut self, frame: &CanFrame) -> Result<(), Closed> {
        Port::send(self, *frame)
    }

    fn recv(&mut self, deadline: odc::time::Instant) -> Result<Option<CanFrame>, Closed> {
        let left = deadline - odc::time::Instant::since(self.start);
        self.recv_timeout(left.into())
    }

    fn now(&mut self) -> odc::time::Instant {
        odc::time::Instant::since(self.start)
    }
}

/// A frame as the examples print it: CAN-ID, data bytes, and its role in CiA 301's
/// predefined connection set (`601  23 01 14 01 01 03 00 04  SDO request`).
pub fn describe(frame: &CanFrame) -> String {
    let bytes: Vec<String> = frame.bytes().iter().map(|b| format!("{b:02X}")).collect();
    let role = u16::try_from(frame.id()).ok().and_then(cob::classify).map(|(f, _)| match f {
        Function::Nmt => "NMT".to_string(),
        Function::Sync => "SYNC".to_string(),
        Function::Emcy => "EMCY".to_string(),
        Function::Time => "TIME".to_string(),
        Function::Tpdo(n) => format!("TPDO{n}"),
        Function::Rpdo(n) => format!("RPDO{n}"),
        Function::SdoTx => "SDO response".to_string(),
        Function::SdoRx => "SDO request".to_string(),
        Function::Heartbeat => "NMT error control".to_string(),
    });
    format!("{:03X}  {:<23}  {}", frame.id(), bytes.join(" "), role.unwrap_or_default())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn frames_cross_and_print() {
        let (a, b) = pair();
        let f = CanFrame::new(0x601, [0x23, 0x01, 0x14, 0x01, 0x01, 0x03, 0x00, 0x04]).unwrap();
        assert_eq!(a.send(f), Ok(()));
        assert_eq!(b.recv_timeout(Duration::from_millis(10)), Ok(Some(f)));
        assert_eq!(b.try_recv(), Ok(None));
        assert_eq!(describe(&f), "601  23 01 14 01 01 03 00 04  SDO request");
        let nmt = CanFrame::from_slice(0, &[1, 0]).unwrap();
        assert!(describe(&nmt).ends_with("NMT"));
        drop(a);
        assert_eq!(b.recv_timeout(Duration::from_millis(1)), Err(Closed));
    }
}
