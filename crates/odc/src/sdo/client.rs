//! The SDO client: uploads and downloads against one node's server, frame by frame or over a
//! [`Bus`].

mod block;

use super::frame::{Init, Request, Response, Segment};
use super::server::DEFAULT_TIMEOUT;
use crate::can::{CanFrame, StdId};
use crate::cob::NodeId;
use crate::plan::SdoWrite;
use crate::time::{Duration, Instant};
use crate::transport::Bus;
use crate::{Entry, ObjValue, ObjectAddr, SdoAbort};
use core::fmt;

/// Why a transfer failed.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum SdoError<E = core::convert::Infallible> {
    /// The server aborted the transfer with this code.
    Remote(SdoAbort),
    /// This client aborted it (and sent the abort frame): timeout, toggle error, an
    /// unexpected response, a value too long for the buffer, a value of the wrong size.
    Local(SdoAbort),
    /// A transfer is already under way on this client.
    Busy,
    /// The bus failed.
    Bus(E),
}

impl<E: fmt::Display> fmt::Display for SdoError<E> {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Self::Remote(a) => write!(f, "server aborted: {a}"),
            Self::Local(a) => write!(f, "client aborted: {a}"),
            Self::Busy => f.write_str("an SDO transfer is already under way"),
            Self::Bus(e) => write!(f, "bus error: {e}"),
        }
    }
}

impl<E: fmt::Debug + fmt::Display> core::error::Error for SdoError<E> {}

impl SdoError {
    /// The same error with a bus error type.
    pub fn widen<E>(self) -> SdoError<E> {
        match self {
            Self::Remote(a) => SdoError::Remote(a),
            Self::Local(a) => SdoError::Local(a),
            Self::Busy => SdoError::Busy,
            Self::Bus(never) => match never {},
        }
    }
}

impl<E> SdoError<E> {
    /// The abort code, whoever sent it.
    pub const fn abort(&self) -> Option<SdoAbort> {
        match self {
            Self::Remote(a) | Self::Local(a) => Some(*a),
            _ => None,
        }
    }
}

/// What to do after [`Client::handle`].
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum Step {
    /// Send this frame and wait for the next response.
    Send(CanFrame),
    /// The transfer is complete (an upload's value is in [`Client::data`]).
    Done,
    /// Send this last frame; the transfer is then complete (a block upload's end response,
    /// which the server does not answer).
    Finish(CanFrame),
    /// The transfer failed; send the abort frame if there is one (none when the server
    /// aborted).
    Failed(SdoError, Option<CanFrame>),
}

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum State {
    Idle,
    InitDownload {
        addr: ObjectAddr,
        segmented: bool,
        deadline: Instant,
    },
    Download {
        addr: ObjectAddr,
        sent: usize,
        toggle: bool,
        last: bool,
        deadline: Instant,
    },
    InitUpload {
        addr: ObjectAddr,
        deadline: Instant,
    },
    Upload {
        addr: ObjectAddr,
        size: Option<usize>,
        toggle: bool,
        deadline: Instant,
    },
    InitBlockDownload {
        addr: ObjectAddr,
        deadline: Instant,
    },
    /// Block download of the buffer's `len` bytes: `acked` segments acknowledged, `sent` of
    /// the current sub-block of `blksize` sent; `sending` while more of it are due.
    BlockDownload {
        addr: ObjectAddr,
        crc: bool,
        blksize: u8,
        acked: usize,
        sent: u8,
        sending: bool,
        deadline: Instant,
    },
    EndBlockDownload {
        addr: ObjectAddr,
        deadline: Instant,
    },
    InitBlockUpload {
        addr: ObjectAddr,
        deadline: Instant,
    },
    /// Block upload: `self.len` bytes of whole segments received, `ackseq` of the current
    /// sub-block; `last` once the final segment came (then the end frame is due).
    BlockUpload {
        addr: ObjectAddr,
        crc: bool,
        size: Option<usize>,
        ackseq: u8,
        last: bool,
        deadline: Instant,
    },
}

/// The SDO client for one server (node), with an `N`-byte transfer buffer: the largest value
/// it can upload or download.
///
/// Frame level: [`Client::start_download`] / [`Client::start_upload`] give the first frame,
/// [`Client::handle`] each response, [`Client::poll`] the timeout. With a [`Bus`], the
/// blocking calls do all of that: [`Client::upload`], [`Client::download`], the typed
/// [`Client::read`] and [`Client::write`] on generated descriptors, and [`Client::execute`]
/// on generated configuration plans.
///
/// Block transfer (CiA 301, with the CRC): [`Client::upload_block`] and
/// [`Client::download_block`], or [`Client::start_block_upload`] /
/// [`Client::start_block_download`] at frame level, where [`Client::poll`] also gives the
/// segments of a sub-block, one a call.
///
/// A [`Bus`] is whatever carries frames and tells the time; here an in-memory one with a
/// device on it (an SDO [`Server`](super::Server) and a one-entry dictionary), answering each
/// request as it is sent. With a real interface, `send` writes the frame to the CAN socket and
/// `recv` waits for the next one until the deadline.
///
/// ```
/// use odc::can::CanFrame;
/// use odc::sdo::{Bus, Client, SdoError, Server};
/// use odc::slave::ObjectDictionary;
/// use odc::time::{Duration, Instant};
/// use odc::{Access, Entry, SdoAbort};
///
/// /// The device: 0x2000 holds a u32 that the client may read and write.
/// struct Device(u32);
/// impl ObjectDictionary for Device {
///     fn read(&self, index: u16, sub: u8, buf: &mut [u8]) -> Result<usize, SdoAbort> {
///         if (index, sub) != (0x2000, 0) { return Err(SdoAbort::NoSuchObject) }
///         buf.get_mut(..4).ok_or(SdoAbort::OutOfMemory)?.copy_from_slice(&self.0.to_le_bytes());
///         Ok(4)
///     }
///     fn write(&mut self, index: u16, sub: u8, data: &[u8]) -> Result<(), SdoAbort> {
///         if (index, sub) != (0x2000, 0) { return Err(SdoAbort::NoSuchObject) }
///         let bytes: [u8; 4] = data.try_into().map_err(|_| SdoAbort::LengthMismatch)?;
///         self.0 = u32::from_le_bytes(bytes);
///         Ok(())
///     }
/// }
///
/// /// The bus: frames go straight to the device's server; its answer is the next received.
/// struct InMemoryBus { device: Device, server: Server<64>, reply: Option<CanFrame>, now: Instant }
/// impl Bus for InMemoryBus {
///     type Error = core::convert::Infallible;
///     fn send(&mut self, frame: &CanFrame) -> Result<(), Self::Error> {
///         self.reply = self.server.handle(&mut self.device, frame, self.now);
///         Ok(())
///     }
///     fn recv(&mut self, _deadline: Instant) -> Result<Option<CanFrame>, Self::Error> {
///         self.now += Duration::from_millis(1); // a real bus waits; time passes either way
///         Ok(self.reply.take())
///     }
///     fn now(&mut self) -> Instant { self.now }
/// }
///
/// const COUNTER: Entry<u32> = Entry::new(0x2000, 0, "Counter", Access::Rw, false);
/// let mut bus = InMemoryBus { device: Device(7), server: Server::new(odc::node_id!(5)), reply: None, now: Instant::ZERO };
/// let mut sdo = Client::<64>::new(odc::node_id!(5));
/// assert_eq!(sdo.read(&mut bus, &COUNTER)?, 7); // typed: a u32, because COUNTER is Entry<u32>
/// sdo.write(&mut bus, &COUNTER, 1000)?;
/// assert_eq!(bus.device.0, 1000);
/// // Untyped, by address; the device's abort comes back as the error.
/// assert_eq!(sdo.upload(&mut bus, 0x2000, 0)?, &1000u32.to_le_bytes());
/// assert_eq!(sdo.upload(&mut bus, 0x2001, 0), Err(SdoError::Remote(SdoAbort::NoSuchObject)));
/// # Ok::<(), SdoError>(())
/// ```
#[derive(Clone, Debug)]
pub struct Client<const N: usize> {
    node_id: NodeId,
    timeout: Duration,
    state: State,
    buf: [u8; N],
    len: usize,
    /// Whether the last upload's size was indicated (an expedited answer without `s` has 4
    /// bytes of which the value's type decides how many count).
    sized: bool,
}

impl<const N: usize> Client<N> {
    /// The client of node `node_id`'s default SDO server, with [`DEFAULT_TIMEOUT`].
    pub const fn new(node_id: NodeId) -> Self {
        Self {
            node_id,
            timeout: DEFAULT_TIMEOUT,
            state: State::Idle,
            buf: [0; N],
            len: 0,
            sized: true,
        }
    }

    /// The same client with another response timeout.
    pub const fn with_timeout(mut self, timeout: Duration) -> Self {
        self.timeout = timeout;
        self
    }

    /// CAN-ID of its requests (client → server).
    pub const fn request_id(&self) -> StdId {
        self.node_id.sdo_request()
    }

    /// CAN-ID of the responses it listens to (server → client).
    pub const fn response_id(&self) -> StdId {
        self.node_id.sdo_response()
    }

    /// Whether a transfer is under way.
    pub const fn is_busy(&self) -> bool {
        !matches!(self.state, State::Idle)
    }

    /// The value of the last completed upload.
    pub fn data(&self) -> &[u8] {
        self.buf.get(..self.len).unwrap_or(&self.buf)
    }

    fn frame(&self, r: Request) -> CanFrame {
        CanFrame::standard(self.request_id(), r.encode())
    }

    /// Ends the transfer with a local abort.
    fn fail(&mut self, addr: ObjectAddr, code: SdoAbort) -> Step {
        self.state = State::Idle;
        Step::Failed(SdoError::Local(code), Some(self.frame(Request::Abort(addr, code))))
    }

    /// Starts downloading `data` into `index:sub`: expedited up to 4 bytes, segmented above.
    ///
    /// # Errors
    ///
    /// [`SdoError::Busy`] during another transfer, [`SdoError::Local`] with
    /// [`SdoAbort::OutOfMemory`] when `data` is longer than the buffer.
    pub fn start_download(
        &mut self,
        index: u16,
        sub: u8,
        data: &[u8],
        now: Instant,
    ) -> Result<CanFrame, SdoError> {
        if self.is_busy() {
            return Err(SdoError::Busy);
        }
        let addr = ObjectAddr::new(index, sub);
        let deadline = now + self.timeout;
        if let Some(init) = Init::expedited(data) {
            self.state = State::InitDownload { addr, segmented: false, deadline };
            return Ok(self.frame(Request::InitiateDownload(addr, init)));
        }
        let dst = self.buf.get_mut(..data.len()).ok_or(SdoError::Local(SdoAbort::OutOfMemory))?;
        dst.copy_from_slice(data);
        self.len = data.len();
        let size = u32::try_from(data.len()).map_err(|_| SdoError::Local(SdoAbort::OutOfMemory))?;
        self.state = State::InitDownload { addr, segmented: true, deadline };
        Ok(self.frame(Request::InitiateDownload(addr, Init::Segmented(Some(size)))))
    }

    /// Starts uploading `index:sub`.
    ///
    /// # Errors
    ///
    /// [`SdoError::Busy`] during another transfer.
    pub fn start_upload(
        &mut self,
        index: u16,
        sub: u8,
        now: Instant,
    ) -> Result<CanFrame, SdoError> {
        if self.is_busy() {
            return Err(SdoError::Busy);
        }
        let addr = ObjectAddr::new(index, sub);
        self.len = 0;
        self.sized = true;
        self.state = State::InitUpload { addr, deadline: now + self.timeout };
        Ok(self.frame(Request::InitiateUpload(addr)))
    }

    /// Checks the response timeout; on expiry the transfer fails with a local
    /// [`SdoAbort::Timeout`] and the abort frame to send. During a block download sub-block,
    /// gives its next segment instead ([`Step::Send`]), one a call: call again until `None`.
    pub fn poll(&mut self, now: Instant) -> Option<Step> {
        if let Some(f) = self.next_block_segment() {
            return Some(Step::Send(f));
        }
        match self.state {
            State::InitDownload { addr, deadline, .. }
            | State::Download { addr, deadline, .. }
            | State::InitUpload { addr, deadline }
            | State::Upload { addr, deadline, .. }
            | State::InitBlockDownload { addr, deadline }
            | State::BlockDownload { addr, deadline, .. }
            | State::EndBlockDownload { addr, deadline }
            | State::InitBlockUpload { addr, deadline }
            | State::BlockUpload { addr, deadline, .. }
                if now > deadline =>
            {
                Some(self.fail(addr, SdoAbort::Timeout))
            }
            _ => None,
        }
    }

    /// The deadline of the response awaited, if a transfer is under way.
    pub const fn deadline(&self) -> Option<Instant> {
        match self.state {
            State::Idle => None,
            State::InitDownload { deadline, .. }
            | State::Download { deadline, .. }
            | State::InitUpload { deadline, .. }
            | State::Upload { deadline, .. }
            | State::InitBlockDownload { deadline, .. }
            | State::BlockDownload { deadline, .. }
            | State::EndBlockDownload { deadline, .. }
            | State::InitBlockUpload { deadline, .. }
            | State::BlockUpload { deadline, .. } => Some(deadline),
        }
    }

    /// Handles a received frame; `None` when it is not a response of this client's server, no
    /// transfer is under way, or it needs no answer (a segment inside a block upload's
    /// sub-block).
    pub fn handle(&mut self, frame: &CanFrame, now: Instant) -> Option<Step> {
        // Remote and extended frames on the CAN-ID are no SDO responses.
        if !frame.is_data(self.response_id().raw()) {
            return None;
        }
        let deadline = now + self.timeout;
        let addr = match self.state {
            State::Idle => return None,
            State::InitDownload { addr, .. }
            | State::Download { addr, .. }
            | State::InitUpload { addr, .. }
            | State::Upload { addr, .. }
            | State::InitBlockDownload { addr, .. }
            | State::BlockDownload { addr, .. }
            | State::EndBlockDownload { addr, .. }
            | State::InitBlockUpload { addr, .. }
            | State::BlockUpload { addr, .. } => addr,
        };
        // Sub-block segments have no command specifier: while they are due, every frame but
        // an abort (byte 0 = 0x80; sequence numbers start at 1) is one.
        if let State::BlockUpload { last: false, .. } = self.state
            && frame.bytes().first() != Some(&0x80)
        {
            return self.block_upload_segment(addr, frame, deadline);
        }
        let resp = match Response::decode(frame.bytes()) {
            Ok(r) => r,
            Err(code) => return Some(self.fail(addr, code)),
        };
        if let Response::Abort(_, code) = resp {
            self.state = State::Idle;
            return Some(Step::Failed(SdoError::Remote(code), None));
        }
        Some(match (self.state, resp) {
            (State::InitDownload { segmented, .. }, Response::InitiateDownload(a)) => {
                if a != addr {
                    return Some(self.fail(addr, SdoAbort::InvalidCommand));
                }
                if segmented {
                    self.next_download_segment(addr, 0, false, deadline)
                } else {
                    self.state = State::Idle;
                    Step::Done
                }
            }
            (State::Download { sent, toggle, last, .. }, Response::DownloadSegment(t)) => {
                if t != toggle {
                    return Some(self.fail(addr, SdoAbort::ToggleBit));
                }
                if last {
                    self.state = State::Idle;
                    Step::Done
                } else {
                    self.next_download_segment(addr, sent, !toggle, deadline)
                }
            }
            (State::InitUpload { .. }, Response::InitiateUpload(a, init)) => {
                if a != addr {
                    return Some(self.fail(addr, SdoAbort::InvalidCommand));
                }
                match init {
                    Init::Expedited { data, len, sized } => {
                        let n = usize::from(len).min(4);
                        match (self.buf.get_mut(..n), data.get(..n)) {
                            (Some(dst), Some(src)) => dst.copy_from_slice(src),
                            _ => return Some(self.fail(addr, SdoAbort::OutOfMemory)),
                        }
                        self.len = n;
                        self.sized = sized;
                        self.state = State::Idle;
                        Step::Done
                    }
                    Init::Segmented(size) => {
                        let size = size.map(|s| usize::try_from(s).unwrap_or(usize::MAX));
                        if size.is_some_and(|s| s > N) {
                            return Some(self.fail(addr, SdoAbort::OutOfMemory));
                        }
                        self.state = State::Upload { addr, size, toggle: false, deadline };
                        Step::Send(self.frame(Request::UploadSegment(false)))
                    }
                }
            }
            (State::Upload { size, toggle, .. }, Response::UploadSegment(seg)) => {
                if seg.toggle != toggle {
                    return Some(self.fail(addr, SdoAbort::ToggleBit));
                }
                let bytes = seg.bytes();
                let end = self.len + bytes.len();
                match self.buf.get_mut(self.len..end) {
                    Some(dst) => dst.copy_from_slice(bytes),
                    None => return Some(self.fail(addr, SdoAbort::OutOfMemory)),
                }
                self.len = end;
                if size.is_some_and(|s| end > s) {
                    return Some(self.fail(addr, SdoAbort::LengthMismatch));
                }
                if !seg.last {
                    self.state = State::Upload { addr, size, toggle: !toggle, deadline };
                    return Some(Step::Send(self.frame(Request::UploadSegment(!toggle))));
                }
                if size.is_some_and(|s| end != s) {
                    return Some(self.fail(addr, SdoAbort::LengthMismatch));
                }
                self.state = State::Idle;
                Step::Done
            }
            // CiA 301 lets a server answer a block upload with the normal upload protocol
            // (python-canopen's LocalNode always does): carry on as a normal upload.
            (State::InitBlockUpload { .. }, Response::InitiateUpload(..)) => {
                self.state = State::InitUpload { addr, deadline };
                return self.handle(frame, now);
            }
            (_, Response::Block(r)) => self.block_response(addr, r, deadline),
            _ => self.fail(addr, SdoAbort::InvalidCommand),
        })
    }

    fn next_download_segment(
        &mut self,
        addr: ObjectAddr,
        sent: usize,
        toggle: bool,
        deadline: Instant,
    ) -> Step {
        let end = (sent + 7).min(self.len);
        let last = end == self.len;
        let seg = Segment::new(toggle, self.buf.get(sent..end).unwrap_or(&[]), last);
        self.state = State::Download { addr, sent: end, toggle, last, deadline };
        Step::Send(self.frame(Request::DownloadSegment(seg)))
    }

    /// Runs a started transfer to its end over `bus`.
    fn run<B: Bus>(&mut self, bus: &mut B, first: CanFrame) -> Result<(), SdoError<B::Error>> {
        bus.send(&first).map_err(SdoError::Bus)?;
        loop {
            let Some(deadline) = self.deadline() else { return Ok(()) };
            let step = match bus.recv(deadline).map_err(SdoError::Bus)? {
                Some(frame) => self.handle(&frame, bus.now()),
                // `recv` waited up to the deadline: the timeout has passed.
                None => self.poll(bus.now().max(deadline + Duration::MICROSECOND)),
            };
            match step {
                None => {}
                Some(Step::Send(f)) => {
                    bus.send(&f).map_err(SdoError::Bus)?;
                    // The rest of a block download's sub-block.
                    while let Some(f) = self.next_block_segment() {
                        bus.send(&f).map_err(SdoError::Bus)?;
                    }
                }
                Some(Step::Done) => return Ok(()),
                Some(Step::Finish(f)) => {
                    bus.send(&f).map_err(SdoError::Bus)?;
                    return Ok(());
                }
                Some(Step::Failed(e, abort)) => {
                    if let Some(f) = abort {
                        bus.send(&f).map_err(SdoError::Bus)?;
                    }
                    return Err(e.widen());
                }
            }
        }
    }

    /// Uploads `index:sub` over `bus` and returns its bytes.
    ///
    /// # Errors
    ///
    /// The server's abort, this client's abort (timeout, protocol error), or the bus error.
    pub fn upload<B: Bus>(
        &mut self,
        bus: &mut B,
        index: u16,
        sub: u8,
    ) -> Result<&[u8], SdoError<B::Error>> {
        let first = self.start_upload(index, sub, bus.now()).map_err(SdoError::widen)?;
        self.run(bus, first)?;
        Ok(self.data())
    }

    /// Downloads `data` into `index:sub` over `bus`.
    ///
    /// # Errors
    ///
    /// As for [`Client::upload`].
    pub fn download<B: Bus>(
        &mut self,
        bus: &mut B,
        index: u16,
        sub: u8,
        data: &[u8],
    ) -> Result<(), SdoError<B::Error>> {
        let first = self.start_download(index, sub, data, bus.now()).map_err(SdoError::widen)?;
        self.run(bus, first)
    }

    /// Reads a generated descriptor's entry and decodes it as its type.
    ///
    /// An expedited answer without size indication carries 4 bytes; a narrower type takes
    /// the low ones, as CiA 301 leaves the size to the object.
    ///
    /// # Errors
    ///
    /// As for [`Client::upload`]; a value of the wrong length is a local
    /// [`SdoAbort::LengthMismatch`]-family abort (not sent: the transfer is over).
    pub fn read<B: Bus, T: ObjValue>(
        &mut self,
        bus: &mut B,
        entry: &Entry<T>,
    ) -> Result<T, SdoError<B::Error>> {
        self.upload(bus, entry.addr.index, entry.addr.sub)?;
        let data = self.data();
        let data = if self.sized { data } else { data.get(..T::MAX_LEN.min(4)).unwrap_or(data) };
        T::decode(data).map_err(|e| SdoError::Local(e.into()))
    }

    /// Writes `value` into a generated descriptor's entry; the value type is checked by the
    /// compiler against the descriptor.
    ///
    /// # Errors
    ///
    /// As for [`Client::download`]; a value that does not encode is a local abort.
    pub fn write<B: Bus, T: ObjValue>(
        &mut self,
        bus: &mut B,
        entry: &Entry<T>,
        value: T,
    ) -> Result<(), SdoError<B::Error>> {
        let mut tmp = [0u8; N];
        let n = value.encode(&mut tmp).map_err(|e| SdoError::Local(e.into()))?;
        self.download(bus, entry.addr.index, entry.addr.sub, tmp.get(..n).unwrap_or(&[]))
    }

    /// Writes `value` into a generated descriptor's entry as an expedited transfer of `size`
    /// bytes, the value zero-extended (sign-extended for a signed integer type) to that size.
    /// For devices that take every parameter write at one width whatever the object's type:
    /// LinMot's UPID commands always send command 23h (4 bytes) with the value "size depends
    /// on the UPID" in the low bytes; a vendor scheme declares it as `write-size`.
    ///
    /// # Errors
    ///
    /// As for [`Client::download`]; a local [`SdoAbort::TooLong`] when `size` is not 1..=4 or
    /// the value takes more than `size` bytes.
    pub fn write_widened<B: Bus, T: ObjValue>(
        &mut self,
        bus: &mut B,
        entry: &Entry<T>,
        value: T,
        size: usize,
    ) -> Result<(), SdoError<B::Error>> {
        let mut data = [0u8; 4];
        let n = value.encode(&mut data).map_err(|e| SdoError::Local(e.into()))?;
        if !(1..=4).contains(&size) || n > size {
            return Err(SdoError::Local(SdoAbort::TooLong));
        }
        let negative = n > 0 && data[n - 1] & 0x80 != 0;
        if entry.data_type().is_signed_integer() && negative {
            data[n..].fill(0xFF);
        }
        self.download(bus, entry.addr.index, entry.addr.sub, data.get(..size).unwrap_or(&data))
    }

    /// Executes a configuration plan (say a generated `master::plan(node)`) in order, stopping
    /// at the first failure.
    ///
    /// # Errors
    ///
    /// The position of the failed write in `plan` and why it failed.
    pub fn execute<B: Bus>(
        &mut self,
        bus: &mut B,
        plan: &[SdoWrite],
    ) -> Result<(), (usize, SdoError<B::Error>)> {
        for (i, w) in plan.iter().enumerate() {
            let (bytes, n) = w.to_le_bytes();
            let data = bytes.get(..n).unwrap_or(&bytes);
            self.download(bus, w.index, w.sub, data).map_err(|e| (i, e))?;
        }
        Ok(())
    }
}
