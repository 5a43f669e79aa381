//! The SDO server: answers a client's requests from an [`ObjectDictionary`].

use super::frame::{Init, Request, Response, Segment};
use crate::can::CanFrame;
use crate::slave::ObjectDictionary;
use crate::{ObjectAddr, SdoAbort};

/// CiA 301 leaves the SDO timeout to the application; 1 s is what most stacks use.
pub const DEFAULT_TIMEOUT_MS: u64 = 1000;

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum State {
    Idle,
    /// A segmented download: `len` bytes of the value are in the buffer.
    Download {
        addr: ObjectAddr,
        size: Option<u32>,
        len: usize,
        toggle: bool,
        deadline: u64,
    },
    /// A segmented upload: the value's `len` bytes are in the buffer, `sent` of them are gone.
    Upload {
        addr: ObjectAddr,
        len: usize,
        sent: usize,
        toggle: bool,
        deadline: u64,
    },
}

/// The default SDO server of one node (CAN-IDs 0x600/0x580 + node id), with a transfer buffer
/// of `N` bytes: the largest value it can move in a segmented transfer.
///
/// Driven by the caller: [`Server::handle`] for each received frame, [`Server::poll`] now and
/// then for the timeout of a segmented transfer. `now_ms` is any monotonic millisecond clock.
/// Expedited and segmented transfers; block requests are refused with
/// [`SdoAbort::InvalidCommand`], which CiA 301 lets a server do.
///
/// ```
/// use odc::can::CanFrame;
/// use odc::sdo::Server;
/// use odc::slave::ObjectDictionary;
/// use odc::SdoAbort;
///
/// struct One(u32);
/// impl ObjectDictionary for One {
///     fn read(&self, index: u16, sub: u8, buf: &mut [u8]) -> Result<usize, SdoAbort> {
///         if (index, sub) != (0x1000, 0) { return Err(SdoAbort::NoSuchObject) }
///         buf.get_mut(..4).ok_or(SdoAbort::OutOfMemory)?.copy_from_slice(&self.0.to_le_bytes());
///         Ok(4)
///     }
///     fn write(&mut self, _: u16, _: u8, _: &[u8]) -> Result<(), SdoAbort> {
///         Err(SdoAbort::WriteOfReadOnly)
///     }
/// }
/// let mut server = Server::<64>::new(5);
/// let mut od = One(0x0002_0192);
/// let req = CanFrame::new(0x605, [0x40, 0x00, 0x10, 0, 0, 0, 0, 0]);
/// let resp = server.handle(&mut od, &req, 0).unwrap();
/// assert_eq!(resp, CanFrame::new(0x585, [0x43, 0x00, 0x10, 0, 0x92, 0x01, 0x02, 0x00]));
/// ```
#[derive(Clone, Debug)]
pub struct Server<const N: usize> {
    node_id: u8,
    timeout_ms: u64,
    state: State,
    buf: [u8; N],
}

impl<const N: usize> Server<N> {
    /// The server of node `node_id`, idle, with [`DEFAULT_TIMEOUT_MS`].
    pub const fn new(node_id: u8) -> Self {
        Self { node_id, timeout_ms: DEFAULT_TIMEOUT_MS, state: State::Idle, buf: [0; N] }
    }

    /// The same server with another timeout between the frames of a segmented transfer.
    pub const fn with_timeout(mut self, ms: u64) -> Self {
        self.timeout_ms = ms;
        self
    }

    /// CAN-ID of the requests it serves (client → server).
    pub const fn request_id(&self) -> u32 {
        0x600 + self.node_id as u32
    }

    /// CAN-ID of its responses (server → client).
    pub const fn response_id(&self) -> u32 {
        0x580 + self.node_id as u32
    }

    /// Whether a segmented transfer is under way.
    pub const fn is_busy(&self) -> bool {
        !matches!(self.state, State::Idle)
    }

    fn reply(&self, r: Response) -> Option<CanFrame> {
        Some(CanFrame::new(self.response_id(), r.encode()))
    }

    fn abort(&mut self, addr: ObjectAddr, code: SdoAbort) -> Option<CanFrame> {
        self.state = State::Idle;
        self.reply(Response::Abort(addr, code))
    }

    /// Handles one received frame; returns the response to send, if any.
    ///
    /// Frames with another CAN-ID are ignored (`None`), as are aborts from the client (which
    /// end the transfer under way without answer).
    pub fn handle<D: ObjectDictionary + ?Sized>(
        &mut self,
        od: &mut D,
        frame: &CanFrame,
        now_ms: u64,
    ) -> Option<CanFrame> {
        if frame.id != self.request_id() {
            return None;
        }
        let deadline = now_ms.saturating_add(self.timeout_ms);
        let current = match self.state {
            State::Idle => ObjectAddr::new(0, 0),
            State::Download { addr, .. } | State::Upload { addr, .. } => addr,
        };
        let req = match Request::decode(frame.bytes()) {
            Ok(r) => r,
            Err(code) => return self.abort(current, code),
        };
        match req {
            Request::Abort(..) => {
                self.state = State::Idle;
                None
            }
            // A new initiate ends whatever transfer was under way (the client gave up on it).
            Request::InitiateDownload(addr, init) => {
                self.initiate_download(od, addr, init, deadline)
            }
            Request::InitiateUpload(addr) => self.initiate_upload(od, addr, deadline),
            Request::DownloadSegment(seg) => self.download_segment(od, seg, deadline),
            Request::UploadSegment(toggle) => self.upload_segment(toggle, deadline),
            Request::Block(_) => self.abort(current, SdoAbort::InvalidCommand),
        }
    }

    /// Checks the timeout of a segmented transfer; returns the abort frame to send when it
    /// expired (CiA 301 abort 0x05040000).
    pub fn poll(&mut self, now_ms: u64) -> Option<CanFrame> {
        match self.state {
            State::Download { addr, deadline, .. } | State::Upload { addr, deadline, .. }
                if now_ms > deadline =>
            {
                self.abort(addr, SdoAbort::Timeout)
            }
            _ => None,
        }
    }

    fn initiate_download<D: ObjectDictionary + ?Sized>(
        &mut self,
        od: &mut D,
        addr: ObjectAddr,
        init: Init,
        deadline: u64,
    ) -> Option<CanFrame> {
        self.state = State::Idle;
        match init {
            Init::Expedited { data, len, sized } => {
                let len = if sized {
                    usize::from(len)
                } else {
                    // Size unspecified: the object's own size, learnt by reading it (CiA 301
                    // leaves it to the server); 4 bytes when it cannot be read.
                    let mut scratch = [0u8; 4];
                    od.read(addr.index, addr.sub, &mut scratch).unwrap_or(4)
                };
                match od.write(addr.index, addr.sub, data.get(..len).unwrap_or(&data)) {
                    Ok(()) => self.reply(Response::InitiateDownload(addr)),
                    Err(code) => self.abort(addr, code),
                }
            }
            Init::Segmented(size) => {
                if size.is_some_and(|s| usize::try_from(s).map_or(true, |s| s > N)) {
                    return self.abort(addr, SdoAbort::OutOfMemory);
                }
                // Refuse at once what cannot succeed: a missing object or sub-index.
                if let Err(code @ (SdoAbort::NoSuchObject | SdoAbort::NoSuchSub)) =
                    od.read(addr.index, addr.sub, &mut [])
                {
                    return self.abort(addr, code);
                }
                self.state = State::Download { addr, size, len: 0, toggle: false, deadline };
                self.reply(Response::InitiateDownload(addr))
            }
        }
    }

    fn download_segment<D: ObjectDictionary + ?Sized>(
        &mut self,
        od: &mut D,
        seg: Segment,
        deadline: u64,
    ) -> Option<CanFrame> {
        let State::Download { addr, size, len, toggle, .. } = self.state else {
            return self.abort(ObjectAddr::new(0, 0), SdoAbort::InvalidCommand);
        };
        if seg.toggle != toggle {
            return self.abort(addr, SdoAbort::ToggleBit);
        }
        let bytes = seg.bytes();
        let end = len + bytes.len();
        match self.buf.get_mut(len..end) {
            Some(dst) => dst.copy_from_slice(bytes),
            None => return self.abort(addr, SdoAbort::OutOfMemory),
        }
        if !seg.last {
            self.state = State::Download { addr, size, len: end, toggle: !toggle, deadline };
            return self.reply(Response::DownloadSegment(toggle));
        }
        self.state = State::Idle;
        if size.is_some_and(|s| usize::try_from(s) != Ok(end)) {
            return self.abort(addr, SdoAbort::LengthMismatch);
        }
        let data = self.buf.get(..end).unwrap_or(&[]);
        match od.write(addr.index, addr.sub, data) {
            Ok(()) => self.reply(Response::DownloadSegment(toggle)),
            Err(code) => self.abort(addr, code),
        }
    }

    fn initiate_upload<D: ObjectDictionary + ?Sized>(
        &mut self,
        od: &mut D,
        addr: ObjectAddr,
        deadline: u64,
    ) -> Option<CanFrame> {
        self.state = State::Idle;
        let len = match od.read(addr.index, addr.sub, &mut self.buf) {
            Ok(n) => n.min(N),
            // The value does not fit the transfer buffer: a resource limit of this server,
            // not a property of the request.
            Err(SdoAbort::TooShort) => return self.abort(addr, SdoAbort::OutOfMemory),
            Err(code) => return self.abort(addr, code),
        };
        let value = self.buf.get(..len).unwrap_or(&[]);
        if let Some(init) = Init::expedited(value) {
            return self.reply(Response::InitiateUpload(addr, init));
        }
        self.state = State::Upload { addr, len, sent: 0, toggle: false, deadline };
        // `len` is at most N, and a buffer over 4 GiB does not exist on an SDO server.
        let size = u32::try_from(len).unwrap_or(u32::MAX);
        self.reply(Response::InitiateUpload(addr, Init::Segmented(Some(size))))
    }

    fn upload_segment(&mut self, toggle_in: bool, deadline: u64) -> Option<CanFrame> {
        let State::Upload { addr, len, sent, toggle, .. } = self.state else {
            return self.abort(ObjectAddr::new(0, 0), SdoAbort::InvalidCommand);
        };
        if toggle_in != toggle {
            return self.abort(addr, SdoAbort::ToggleBit);
        }
        let end = (sent + 7).min(len);
        let last = end == len;
        let seg = Segment::new(toggle, self.buf.get(sent..end).unwrap_or(&[]), last);
        self.state = if last {
            State::Idle
        } else {
            State::Upload { addr, len, sent: end, toggle: !toggle, deadline }
        };
        self.reply(Response::UploadSegment(seg))
    }
}
