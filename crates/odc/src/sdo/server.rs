//! The SDO server: answers a client's requests from an [`ObjectDictionary`].

use super::block::MAX_BLKSIZE;
#[cfg(feature = "sdo-block")]
use super::block::{self, BlockRequest, BlockResponse, BlockSegment};
#[cfg(feature = "sdo-block")]
use super::frame::pad;
use super::frame::{Init, Request, Response, Segment};
use crate::can::{CanFrame, StdId};
use crate::cob::NodeId;
use crate::slave::ObjectDictionary;
use crate::time::{Duration, Instant};
use crate::{ObjectAddr, SdoAbort};

/// CiA 301 leaves the SDO timeout to the application; 1 s is what most stacks use.
pub const DEFAULT_TIMEOUT: Duration = Duration::from_millis(1000);

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum State {
    Idle,
    /// A segmented download: `len` bytes of the value are in the buffer.
    Download {
        addr: ObjectAddr,
        size: Option<u32>,
        len: usize,
        toggle: bool,
        deadline: Instant,
    },
    /// A segmented upload: the value's `len` bytes are in the buffer, `sent` of them are gone.
    Upload {
        addr: ObjectAddr,
        len: usize,
        sent: usize,
        toggle: bool,
        deadline: Instant,
    },
    #[cfg(feature = "sdo-block")]
    /// A block download: `received` bytes of segments are in the buffer (all 7 bytes of each,
    /// the last one's padding included), `ackseq` segments of the current sub-block of
    /// `blksize`; `last` once the final segment came in sequence (then the end frame is due).
    BlockDownload {
        addr: ObjectAddr,
        size: Option<u32>,
        crc: bool,
        received: usize,
        ackseq: u8,
        blksize: u8,
        last: bool,
        deadline: Instant,
    },
    #[cfg(feature = "sdo-block")]
    /// A block upload of the buffer's `len` bytes: `acked` segments acknowledged, `sent` of the
    /// current sub-block of `blksize` sent.
    BlockUpload {
        addr: ObjectAddr,
        len: usize,
        crc: bool,
        blksize: u8,
        acked: usize,
        sent: u8,
        phase: Phase,
        deadline: Instant,
    },
}

/// Where a block upload is.
#[cfg(feature = "sdo-block")]
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Phase {
    /// Initiate answered; the client's start is due.
    Initiated,
    /// Segments of the sub-block remain to be sent ([`Server::poll`] gives them).
    Sending,
    /// The sub-block is out; the client's acknowledgement is due.
    AwaitAck,
    /// The end frame is out; the client's end response is due.
    AwaitEnd,
}

/// The default SDO server of one node (CAN-IDs 0x600/0x580 + node id), with a transfer buffer
/// of `N` bytes: the largest value it can move in a segmented or block transfer.
///
/// Driven by the caller: [`Server::handle_into`] (or [`Server::handle`]) for each received
/// frame, [`Server::poll`] now and then for timeouts, with the time of the caller's
/// monotonic clock. Expedited, segmented and block transfers (CiA 301 §7.2.4.3), block transfers with
/// the CRC when the client asks for it.
///
/// A block upload answers one request with a sub-block of up to 127 frames: `handle_into`
/// passes all of them to its sink; `handle` returns the first and leaves the rest to `poll`,
/// one frame a call, for a caller whose transmit queue is short.
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
/// let mut server = Server::<64>::new(odc::node_id!(5));
/// let mut od = One(0x0002_0192);
/// let req = CanFrame::new(0x605, [0x40, 0x00, 0x10, 0, 0, 0, 0, 0]).unwrap();
/// let resp = server.handle(&mut od, &req, odc::time::Instant::ZERO).unwrap();
/// assert_eq!(resp, CanFrame::new(0x585, [0x43, 0x00, 0x10, 0, 0x92, 0x01, 0x02, 0x00]).unwrap());
/// ```
#[derive(Clone, Debug)]
pub struct Server<const N: usize> {
    node_id: NodeId,
    timeout: Duration,
    blksize: u8,
    state: State,
    buf: [u8; N],
}

impl<const N: usize> Server<N> {
    /// The server of node `node_id`, idle, with [`DEFAULT_TIMEOUT`] and sub-blocks of 127
    /// segments.
    pub const fn new(node_id: NodeId) -> Self {
        Self {
            node_id,
            timeout: DEFAULT_TIMEOUT,
            blksize: MAX_BLKSIZE,
            state: State::Idle,
            buf: [0; N],
        }
    }

    /// The same server with another timeout between the frames of a segmented or block
    /// transfer.
    pub const fn with_timeout(mut self, timeout: Duration) -> Self {
        self.timeout = timeout;
        self
    }

    /// The same server asking block-download clients for sub-blocks of `blksize` segments
    /// (clamped to 1–127).
    pub const fn with_blksize(mut self, blksize: u8) -> Self {
        self.blksize = if blksize == 0 {
            1
        } else if blksize > MAX_BLKSIZE {
            MAX_BLKSIZE
        } else {
            blksize
        };
        self
    }

    /// CAN-ID of the requests it serves (client → server).
    pub const fn request_id(&self) -> StdId {
        self.node_id.sdo_request()
    }

    /// CAN-ID of its responses (server → client).
    pub const fn response_id(&self) -> StdId {
        self.node_id.sdo_response()
    }

    /// Whether a segmented or block transfer is under way.
    pub const fn is_busy(&self) -> bool {
        !matches!(self.state, State::Idle)
    }

    #[inline(always)]
    fn reply(&self, r: Response) -> Option<CanFrame> {
        Some(CanFrame::standard(self.response_id(), r.encode()))
    }

    fn abort(&mut self, addr: ObjectAddr, code: SdoAbort) -> Option<CanFrame> {
        self.state = State::Idle;
        self.reply(Response::Abort(addr, code))
    }

    /// Handles one received frame and passes every frame to send to `out`: none, one, or a
    /// whole sub-block of a block upload.
    ///
    /// Frames with another CAN-ID are ignored, as are aborts from the client (which end the
    /// transfer under way without answer).
    pub fn handle_into<D: ObjectDictionary + ?Sized>(
        &mut self,
        od: &mut D,
        frame: &CanFrame,
        now: Instant,
        out: &mut impl FnMut(CanFrame),
    ) {
        if let Some(f) = self.handle(od, frame, now) {
            out(f);
        }
        while let Some(f) = self.next_segment() {
            out(f);
        }
    }

    /// Handles one received frame; returns the response to send, if any.
    ///
    /// Frames with another CAN-ID, remote and extended frames are ignored (`None`), as are aborts from the client (which
    /// end the transfer under way without answer). During a block upload the further frames
    /// of a sub-block come from [`Server::poll`]; [`Server::handle_into`] sends them at once.
    pub fn handle<D: ObjectDictionary + ?Sized>(
        &mut self,
        od: &mut D,
        frame: &CanFrame,
        now: Instant,
    ) -> Option<CanFrame> {
        // Remote and extended frames on the CAN-ID are no SDO requests (CiA 301: SDOs are
        // 11-bit data frames).
        if !frame.is_data(self.request_id().raw()) {
            return None;
        }
        let deadline = now.saturating_add(self.timeout);
        let current = self.current();
        // Sub-block segments have no command specifier: while they are due, every frame but
        // an abort (byte 0 = 0x80, which is no segment: sequence numbers start at 1) is one.
        #[cfg(feature = "sdo-block")]
        if let State::BlockDownload { last: false, .. } = self.state
            && frame.bytes().first() != Some(&0x80)
        {
            return self.block_segment(frame, deadline);
        }
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
            #[cfg(feature = "sdo-block")]
            Request::Block(BlockRequest::InitiateDownload { addr, crc, size }) => {
                self.initiate_block_download(od, addr, crc, size, deadline)
            }
            #[cfg(feature = "sdo-block")]
            Request::Block(BlockRequest::InitiateUpload { addr, crc, blksize, pst }) => {
                self.initiate_block_upload(od, addr, crc, blksize, pst, deadline)
            }
            #[cfg(feature = "sdo-block")]
            Request::Block(BlockRequest::EndDownload { unused, crc }) => {
                self.end_block_download(od, unused, crc)
            }
            #[cfg(feature = "sdo-block")]
            Request::Block(r) => self.block_upload_step(r, deadline),
            // Block transfer left out of this build: the client falls back to segmented.
            #[cfg(not(feature = "sdo-block"))]
            Request::Block(_) => self.abort(current, SdoAbort::InvalidCommand),
        }
    }

    /// Checks the timeout of a segmented or block transfer: returns the abort frame to send
    /// when it expired (CiA 301 abort 0x05040000). During a block upload sub-block, returns
    /// its next segment instead, one a call.
    pub fn poll(&mut self, now: Instant) -> Option<CanFrame> {
        if let Some(f) = self.next_segment() {
            return Some(f);
        }
        let (addr, deadline) = match self.state {
            State::Idle => return None,
            State::Download { addr, deadline, .. } | State::Upload { addr, deadline, .. } => {
                (addr, deadline)
            }
            #[cfg(feature = "sdo-block")]
            State::BlockDownload { addr, deadline, .. }
            | State::BlockUpload { addr, deadline, .. } => (addr, deadline),
        };
        if now > deadline { self.abort(addr, SdoAbort::Timeout) } else { None }
    }

    fn initiate_download<D: ObjectDictionary + ?Sized>(
        &mut self,
        od: &mut D,
        addr: ObjectAddr,
        init: Init,
        deadline: Instant,
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
        deadline: Instant,
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
            Some(dst) => crate::bits::copy_bytes(dst, bytes),
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
        deadline: Instant,
    ) -> Option<CanFrame> {
        self.state = State::Idle;
        let len = match self.read_value(od, addr) {
            Ok(n) => n,
            Err(code) => return self.abort(addr, code),
        };
        self.upload_response(addr, len, deadline)
    }

    /// Reads the value into the buffer; its length.
    fn read_value<D: ObjectDictionary + ?Sized>(
        &mut self,
        od: &D,
        addr: ObjectAddr,
    ) -> Result<usize, SdoAbort> {
        match od.read(addr.index, addr.sub, &mut self.buf) {
            Ok(n) => Ok(n.min(N)),
            // The value does not fit the transfer buffer: a resource limit of this server,
            // not a property of the request.
            Err(SdoAbort::TooShort) => Err(SdoAbort::OutOfMemory),
            Err(code) => Err(code),
        }
    }

    /// The initiate upload response for the buffer's `len` bytes: expedited, or the start of
    /// a segmented upload.
    fn upload_response(
        &mut self,
        addr: ObjectAddr,
        len: usize,
        deadline: Instant,
    ) -> Option<CanFrame> {
        let value = self.buf.get(..len).unwrap_or(&[]);
        if let Some(init) = Init::expedited(value) {
            return self.reply(Response::InitiateUpload(addr, init));
        }
        self.state = State::Upload { addr, len, sent: 0, toggle: false, deadline };
        // `len` is at most N, and a buffer over 4 GiB does not exist on an SDO server.
        let size = u32::try_from(len).unwrap_or(u32::MAX);
        self.reply(Response::InitiateUpload(addr, Init::Segmented(Some(size))))
    }

    fn upload_segment(&mut self, toggle_in: bool, deadline: Instant) -> Option<CanFrame> {
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

    #[cfg(feature = "sdo-block")]
    fn initiate_block_download<D: ObjectDictionary + ?Sized>(
        &mut self,
        od: &D,
        addr: ObjectAddr,
        crc: bool,
        size: Option<u32>,
        deadline: Instant,
    ) -> Option<CanFrame> {
        self.state = State::Idle;
        if size.is_some_and(|s| usize::try_from(s).map_or(true, |s| s > N)) {
            return self.abort(addr, SdoAbort::OutOfMemory);
        }
        if let Err(code @ (SdoAbort::NoSuchObject | SdoAbort::NoSuchSub)) =
            od.read(addr.index, addr.sub, &mut [])
        {
            return self.abort(addr, code);
        }
        let blksize = self.blksize;
        self.state = State::BlockDownload {
            addr,
            size,
            crc,
            received: 0,
            ackseq: 0,
            blksize,
            last: false,
            deadline,
        };
        self.reply(Response::Block(BlockResponse::InitiateDownload { addr, crc: true, blksize }))
    }

    #[cfg(feature = "sdo-block")]
    /// One frame while sub-block segments are due. A segment out of sequence is ignored (CiA
    /// 301: the server acknowledges the last one in sequence and the client repeats the rest);
    /// the end of the sub-block, in sequence or not, is acknowledged.
    fn block_segment(&mut self, frame: &CanFrame, deadline: Instant) -> Option<CanFrame> {
        let State::BlockDownload { addr, size, crc, mut received, mut ackseq, blksize, .. } =
            self.state
        else {
            return None;
        };
        let Some(seg) = BlockSegment::decode(&pad(frame.bytes())) else {
            return self.abort(addr, SdoAbort::InvalidSequence);
        };
        let mut last = false;
        if seg.seqno == ackseq.wrapping_add(1) {
            // Non-final segments are full: one that passes the buffer cannot succeed. The
            // final one may pass it by its padding; the end frame says by how much.
            if !seg.last && received + 7 > N {
                return self.abort(addr, SdoAbort::OutOfMemory);
            }
            let room = N.saturating_sub(received).min(7);
            if let (Some(dst), Some(src)) =
                (self.buf.get_mut(received..received + room), seg.data.get(..room))
            {
                crate::bits::copy_bytes(dst, src);
            }
            received += 7;
            ackseq = seg.seqno;
            last = seg.last;
        }
        let ack = last || seg.last || seg.seqno >= blksize;
        self.state = State::BlockDownload {
            addr,
            size,
            crc,
            received,
            ackseq: if ack { 0 } else { ackseq },
            blksize,
            last,
            deadline,
        };
        if !ack {
            return None;
        }
        self.reply(Response::Block(BlockResponse::Ack { ackseq, blksize }))
    }

    #[cfg(feature = "sdo-block")]
    fn end_block_download<D: ObjectDictionary + ?Sized>(
        &mut self,
        od: &mut D,
        unused: u8,
        client_crc: u16,
    ) -> Option<CanFrame> {
        let State::BlockDownload { addr, size, crc, received, last: true, .. } = self.state else {
            let current = self.current();
            return self.abort(current, SdoAbort::InvalidCommand);
        };
        self.state = State::Idle;
        let Some(len) = received.checked_sub(usize::from(unused)) else {
            return self.abort(addr, SdoAbort::InvalidCommand);
        };
        if len > N {
            return self.abort(addr, SdoAbort::OutOfMemory);
        }
        if size.is_some_and(|s| usize::try_from(s) != Ok(len)) {
            return self.abort(addr, SdoAbort::LengthMismatch);
        }
        let data = self.buf.get(..len).unwrap_or(&[]);
        if crc && block::crc16(data) != client_crc {
            return self.abort(addr, SdoAbort::CrcError);
        }
        match od.write(addr.index, addr.sub, data) {
            Ok(()) => self.reply(Response::Block(BlockResponse::EndDownload)),
            Err(code) => self.abort(addr, code),
        }
    }

    /// The object of the transfer under way (0000:00 when idle).
    /// Without block transfer there is no sub-block to send.
    #[cfg(not(feature = "sdo-block"))]
    #[allow(clippy::unused_self)]
    fn next_segment(&mut self) -> Option<CanFrame> {
        None
    }

    fn current(&self) -> ObjectAddr {
        match self.state {
            State::Idle => ObjectAddr::new(0, 0),
            State::Download { addr, .. } | State::Upload { addr, .. } => addr,
            #[cfg(feature = "sdo-block")]
            State::BlockDownload { addr, .. } | State::BlockUpload { addr, .. } => addr,
        }
    }

    #[cfg(feature = "sdo-block")]
    fn initiate_block_upload<D: ObjectDictionary + ?Sized>(
        &mut self,
        od: &D,
        addr: ObjectAddr,
        crc: bool,
        blksize: u8,
        pst: u8,
        deadline: Instant,
    ) -> Option<CanFrame> {
        self.state = State::Idle;
        if blksize == 0 || blksize > MAX_BLKSIZE {
            return self.abort(addr, SdoAbort::InvalidBlockSize);
        }
        let len = match self.read_value(od, addr) {
            Ok(n) => n,
            Err(code) => return self.abort(addr, code),
        };
        // The protocol switch CiA 301 offers: a value within the client's threshold goes by
        // the normal upload protocol.
        if pst != 0 && len <= usize::from(pst) {
            return self.upload_response(addr, len, deadline);
        }
        self.state = State::BlockUpload {
            addr,
            len,
            crc,
            blksize,
            acked: 0,
            sent: 0,
            phase: Phase::Initiated,
            deadline,
        };
        // `len` is at most N, and a buffer over 4 GiB does not exist on an SDO server.
        let size = Some(u32::try_from(len).unwrap_or(u32::MAX));
        self.reply(Response::Block(BlockResponse::InitiateUpload { addr, crc: true, size }))
    }

    #[cfg(feature = "sdo-block")]
    /// The client's start, acknowledgements and end response during a block upload.
    fn block_upload_step(&mut self, req: BlockRequest, deadline: Instant) -> Option<CanFrame> {
        let State::BlockUpload { addr, len, crc, blksize, acked, sent, phase, .. } = self.state
        else {
            let current = self.current();
            return self.abort(current, SdoAbort::InvalidCommand);
        };
        let at = |phase, blksize, acked, sent| State::BlockUpload {
            addr,
            len,
            crc,
            blksize,
            acked,
            sent,
            phase,
            deadline,
        };
        match (phase, req) {
            (Phase::Initiated, BlockRequest::StartUpload) => {
                self.state = at(Phase::Sending, blksize, 0, 0);
                self.next_segment()
            }
            (Phase::AwaitAck, BlockRequest::Ack { ackseq, blksize: next }) => {
                if ackseq > sent {
                    return self.abort(addr, SdoAbort::InvalidSequence);
                }
                if next == 0 || next > MAX_BLKSIZE {
                    return self.abort(addr, SdoAbort::InvalidBlockSize);
                }
                // Segments past `ackseq` are sent again in the next sub-block.
                let acked = acked + usize::from(ackseq);
                if acked >= block::segments(len) {
                    self.state = at(Phase::AwaitEnd, next, acked, 0);
                    let data = self.buf.get(..len).unwrap_or(&[]);
                    let crc = if crc { block::crc16(data) } else { 0 };
                    let unused = block::unused_in_last(len);
                    return self.reply(Response::Block(BlockResponse::EndUpload { unused, crc }));
                }
                self.state = at(Phase::Sending, next, acked, 0);
                self.next_segment()
            }
            (Phase::AwaitEnd, BlockRequest::EndUpload) => {
                self.state = State::Idle;
                None
            }
            _ => self.abort(addr, SdoAbort::InvalidCommand),
        }
    }

    #[cfg(feature = "sdo-block")]
    /// The next segment of a block upload's sub-block, if one is due.
    fn next_segment(&mut self) -> Option<CanFrame> {
        let State::BlockUpload {
            addr,
            len,
            crc,
            blksize,
            acked,
            sent,
            phase: Phase::Sending,
            deadline,
        } = self.state
        else {
            return None;
        };
        let index = acked + usize::from(sent);
        let start = index * 7;
        let end = (start + 7).min(len);
        let last = index + 1 >= block::segments(len);
        let seqno = sent + 1;
        let seg = BlockSegment::new(seqno, last, self.buf.get(start..end).unwrap_or(&[]));
        let phase = if last || seqno >= blksize { Phase::AwaitAck } else { Phase::Sending };
        self.state =
            State::BlockUpload { addr, len, crc, blksize, acked, sent: seqno, phase, deadline };
        Some(CanFrame::standard(self.response_id(), seg.encode()))
    }
}
