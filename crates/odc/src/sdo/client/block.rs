//! The client's half of SDO block transfer (CiA 301 §7.2.4.3.9–16): the same [`Client`]
//! state machine, in a file of its own because block transfer is a protocol of its own.

use super::{Bus, Client, SdoError, State, Step};
use crate::can::CanFrame;
use crate::sdo::block::{self, BlockRequest, BlockResponse, BlockSegment, MAX_BLKSIZE};
use crate::sdo::frame::{Request, pad};
use crate::time::Instant;
use crate::{ObjectAddr, SdoAbort};

impl<const N: usize> Client<N> {
    /// Starts a block download of `data` into `index:sub`, with the CRC; the segments follow
    /// from [`Client::poll`] once the server has answered.
    ///
    /// # Errors
    ///
    /// [`SdoError::Busy`] during another transfer, [`SdoError::Local`] with
    /// [`SdoAbort::OutOfMemory`] when `data` is longer than the buffer.
    pub fn start_block_download(
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
        let dst = self.buf.get_mut(..data.len()).ok_or(SdoError::Local(SdoAbort::OutOfMemory))?;
        dst.copy_from_slice(data);
        self.len = data.len();
        let size = u32::try_from(data.len()).map_err(|_| SdoError::Local(SdoAbort::OutOfMemory))?;
        self.state = State::InitBlockDownload { addr, deadline: now + self.timeout };
        let req = BlockRequest::InitiateDownload { addr, crc: true, size: Some(size) };
        Ok(self.frame(Request::Block(req)))
    }

    /// Starts a block upload of `index:sub`, with the CRC, in sub-blocks of up to 127
    /// segments. A server may answer with the normal upload protocol instead (CiA 301); the
    /// transfer then goes on as [`Client::start_upload`]'s would.
    ///
    /// # Errors
    ///
    /// [`SdoError::Busy`] during another transfer.
    pub fn start_block_upload(
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
        self.state = State::InitBlockUpload { addr, deadline: now + self.timeout };
        // pst 0: this client asks for a block transfer whatever the size.
        let req = BlockRequest::InitiateUpload { addr, crc: true, blksize: MAX_BLKSIZE, pst: 0 };
        Ok(self.frame(Request::Block(req)))
    }

    /// Block-uploads `index:sub` over `bus` and returns its bytes.
    ///
    /// # Errors
    ///
    /// As for [`Client::upload`]; a CRC that does not match is a local
    /// [`SdoAbort::CrcError`] (and the abort is sent).
    pub fn upload_block<B: Bus>(
        &mut self,
        bus: &mut B,
        index: u16,
        sub: u8,
    ) -> Result<&[u8], SdoError<B::Error>> {
        let first = self.start_block_upload(index, sub, bus.now()).map_err(SdoError::widen)?;
        self.run(bus, first)?;
        Ok(self.data())
    }

    /// Block-downloads `data` into `index:sub` over `bus`.
    ///
    /// # Errors
    ///
    /// As for [`Client::download`].
    pub fn download_block<B: Bus>(
        &mut self,
        bus: &mut B,
        index: u16,
        sub: u8,
        data: &[u8],
    ) -> Result<(), SdoError<B::Error>> {
        let first =
            self.start_block_download(index, sub, data, bus.now()).map_err(SdoError::widen)?;
        self.run(bus, first)
    }

    /// The next segment of a block download's sub-block, if one is due.
    pub(super) fn next_block_segment(&mut self) -> Option<CanFrame> {
        let State::BlockDownload { addr, crc, blksize, acked, sent, sending: true, deadline } =
            self.state
        else {
            return None;
        };
        let index = acked + usize::from(sent);
        let start = index * 7;
        let end = (start + 7).min(self.len);
        let last = index + 1 >= block::segments(self.len);
        let seqno = sent + 1;
        let seg = BlockSegment::new(seqno, last, self.buf.get(start..end).unwrap_or(&[]));
        let sending = !last && seqno < blksize;
        self.state =
            State::BlockDownload { addr, crc, blksize, acked, sent: seqno, sending, deadline };
        Some(CanFrame::standard(self.request_id(), seg.encode()))
    }

    /// A block response (not a segment) in any state.
    pub(super) fn block_response(
        &mut self,
        addr: ObjectAddr,
        resp: BlockResponse,
        deadline: Instant,
    ) -> Step {
        match (self.state, resp) {
            (
                State::InitBlockDownload { .. },
                BlockResponse::InitiateDownload { addr: a, crc, blksize },
            ) => {
                if a != addr {
                    return self.fail(addr, SdoAbort::InvalidCommand);
                }
                if blksize == 0 || blksize > MAX_BLKSIZE {
                    return self.fail(addr, SdoAbort::InvalidBlockSize);
                }
                self.state = State::BlockDownload {
                    addr,
                    crc,
                    blksize,
                    acked: 0,
                    sent: 0,
                    sending: true,
                    deadline,
                };
                // `sending` is set: a segment is due (the arm is for the type, not reachable).
                match self.next_block_segment() {
                    Some(f) => Step::Send(f),
                    None => self.fail(addr, SdoAbort::General),
                }
            }
            (
                State::BlockDownload { crc, acked, sent, sending: false, .. },
                BlockResponse::Ack { ackseq, blksize },
            ) => {
                if ackseq > sent {
                    return self.fail(addr, SdoAbort::InvalidSequence);
                }
                if blksize == 0 || blksize > MAX_BLKSIZE {
                    return self.fail(addr, SdoAbort::InvalidBlockSize);
                }
                // The server's `ackseq` says where it lost the sequence; resend from there.
                let acked = acked + usize::from(ackseq);
                if acked >= block::segments(self.len) {
                    self.state = State::EndBlockDownload { addr, deadline };
                    let data = self.buf.get(..self.len).unwrap_or(&[]);
                    let crc = if crc { block::crc16(data) } else { 0 };
                    let unused = block::unused_in_last(self.len);
                    return Step::Send(
                        self.frame(Request::Block(BlockRequest::EndDownload { unused, crc })),
                    );
                }
                self.state = State::BlockDownload {
                    addr,
                    crc,
                    blksize,
                    acked,
                    sent: 0,
                    sending: true,
                    deadline,
                };
                // `sending` is set: a segment is due (the arm is for the type, not reachable).
                match self.next_block_segment() {
                    Some(f) => Step::Send(f),
                    None => self.fail(addr, SdoAbort::General),
                }
            }
            (State::EndBlockDownload { .. }, BlockResponse::EndDownload) => {
                self.state = State::Idle;
                Step::Done
            }
            (
                State::InitBlockUpload { .. },
                BlockResponse::InitiateUpload { addr: a, crc, size },
            ) => {
                if a != addr {
                    return self.fail(addr, SdoAbort::InvalidCommand);
                }
                let size = size.map(|s| usize::try_from(s).unwrap_or(usize::MAX));
                if size.is_some_and(|s| s > N) {
                    return self.fail(addr, SdoAbort::OutOfMemory);
                }
                self.state =
                    State::BlockUpload { addr, crc, size, ackseq: 0, last: false, deadline };
                Step::Send(self.frame(Request::Block(BlockRequest::StartUpload)))
            }
            (
                State::BlockUpload { crc, size, last: true, .. },
                BlockResponse::EndUpload { unused, crc: server_crc },
            ) => {
                let Some(len) = self.len.checked_sub(usize::from(unused)) else {
                    return self.fail(addr, SdoAbort::InvalidCommand);
                };
                if len > N {
                    return self.fail(addr, SdoAbort::OutOfMemory);
                }
                if size.is_some_and(|s| s != len) {
                    return self.fail(addr, SdoAbort::LengthMismatch);
                }
                self.len = len;
                if crc && block::crc16(self.data()) != server_crc {
                    return self.fail(addr, SdoAbort::CrcError);
                }
                self.state = State::Idle;
                // The end response has no answer: the transfer is complete once it is sent.
                Step::Finish(self.frame(Request::Block(BlockRequest::EndUpload)))
            }
            _ => self.fail(addr, SdoAbort::InvalidCommand),
        }
    }

    /// A frame while upload segments are due: stored if in sequence, ignored if not (CiA 301:
    /// the acknowledgement names the last one in sequence and the server repeats the rest);
    /// the end of the sub-block is acknowledged.
    pub(super) fn block_upload_segment(
        &mut self,
        addr: ObjectAddr,
        frame: &CanFrame,
        deadline: Instant,
    ) -> Option<Step> {
        let State::BlockUpload { crc, size, ackseq, .. } = self.state else {
            return Some(self.fail(addr, SdoAbort::InvalidCommand));
        };
        let Some(seg) = BlockSegment::decode(&pad(frame.bytes())) else {
            return Some(self.fail(addr, SdoAbort::InvalidSequence));
        };
        let (mut ackseq, mut last) = (ackseq, false);
        if seg.seqno == ackseq.wrapping_add(1) {
            if !seg.last && self.len + 7 > N {
                return Some(self.fail(addr, SdoAbort::OutOfMemory));
            }
            let room = N.saturating_sub(self.len).min(7);
            if let (Some(dst), Some(src)) =
                (self.buf.get_mut(self.len..self.len + room), seg.data.get(..room))
            {
                dst.copy_from_slice(src);
            }
            // Whole segments count until the end frame says how much of the last is padding.
            self.len += 7;
            ackseq = seg.seqno;
            last = seg.last;
        }
        let ack = last || seg.last || seg.seqno >= MAX_BLKSIZE;
        self.state = State::BlockUpload {
            addr,
            crc,
            size,
            ackseq: if ack { 0 } else { ackseq },
            last,
            deadline,
        };
        if !ack {
            return None;
        }
        let ack = BlockRequest::Ack { ackseq, blksize: MAX_BLKSIZE };
        Some(Step::Send(self.frame(Request::Block(ack))))
    }
}
