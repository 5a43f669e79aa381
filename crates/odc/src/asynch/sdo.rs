//! SDO transfers of the async master: the blocking master's [`Client`] state machine, one per
//! node, driven by futures. A transfer holds its node's client; transfers to different nodes
//! run at once, a second one to the same node waits for the first.

use core::future::poll_fn;
use core::task::Poll;
use std::boxed::Box;
use std::vec;
use std::vec::Vec;

use super::master::{Master, Priority};
use super::wait::{Either, first};
use super::{Clock, Error, Stopped};
use crate::can::CanFrame;
use crate::cob::NodeId;
use crate::master::{SDO_BUFFER, Waited};
use crate::plan::SdoWrite;
use crate::sdo::{Client, SdoError, Step};
use crate::time::{Duration, Instant};
use crate::{Entry, ObjValue, SdoAbort};

type SdoClient = Box<Client<SDO_BUFFER>>;

/// A node's client lent to one transfer; given back (idle) when the transfer ends or its
/// future is dropped.
struct Lease<'m, C: Clock> {
    master: &'m Master<C>,
    node: NodeId,
    client: Option<SdoClient>,
}

impl<C: Clock> Drop for Lease<'_, C> {
    fn drop(&mut self) {
        let mut g = self.master.lock();
        let slot = g.sdo.entry(self.node).or_default();
        // A transfer dropped half-way leaves its client busy: the server times out on its
        // side, and the node's next transfer starts on a fresh client.
        slot.client = self.client.take().filter(|c| !c.is_busy());
        slot.active = false;
        slot.responses.clear();
        slot.waiters.wake();
    }
}

impl<C: Clock> Master<C> {
    /// `node`'s client, once no other transfer holds it.
    async fn lease(&self, node: NodeId) -> Result<Lease<'_, C>, Error> {
        let timeout = self.timeout;
        let client = poll_fn(|cx| {
            let mut g = self.lock();
            g.check()?;
            let slot = g.sdo.entry(node).or_default();
            if slot.active {
                slot.waiters.register(cx.waker());
                return Poll::Pending;
            }
            slot.active = true;
            slot.responses.clear();
            let client = slot
                .client
                .take()
                .unwrap_or_else(|| Box::new(Client::new(node).with_timeout(timeout)));
            Poll::Ready(Ok::<_, Stopped>(client))
        })
        .await
        .map_err(Error::Bus)?;
        Ok(Lease { master: self, node, client: Some(client) })
    }

    /// The next response routed to `node`'s transfer, or `None` at `deadline`.
    async fn response(&self, node: NodeId, deadline: Instant) -> Result<Option<CanFrame>, Stopped> {
        let next = poll_fn(|cx| {
            let mut g = self.lock();
            g.check()?;
            let slot = g.sdo.entry(node).or_default();
            match slot.responses.pop_front() {
                Some(f) => Poll::Ready(Ok(f)),
                None => {
                    slot.waiters.register(cx.waker());
                    Poll::Pending
                }
            }
        });
        match first(next, self.clock.sleep_until(deadline)).await {
            Either::Left(r) => r.map(Some),
            Either::Right(()) => Ok(None),
        }
    }

    /// Runs one transfer on `node`'s client: `start` gives its first frame, `end` what the
    /// finished client holds. Errors name the node and the object.
    async fn transfer<T>(
        &self,
        node: NodeId,
        (index, sub): (u16, u8),
        start: impl FnOnce(&mut Client<SDO_BUFFER>, Instant) -> Result<CanFrame, SdoError>,
        end: impl FnOnce(&Client<SDO_BUFFER>) -> Result<T, SdoError>,
    ) -> Result<T, Error> {
        let mut lease = self.lease(node).await?;
        let Some(client) = lease.client.as_deref_mut() else {
            return Err(Error::Invalid("SDO client lent twice"));
        };
        let r = match self.drive(node, client, start).await {
            Ok(()) => end(client),
            Err(e) => Err(e),
        };
        drop(lease);
        match r {
            Ok(v) => Ok(v),
            Err(SdoError::Bus(never)) => match never {},
            // The client waited in vain (and sent the abort 0x05040000): say whether the node
            // was heard during the last wait.
            Err(SdoError::Local(SdoAbort::Timeout)) => {
                let since = self.now().saturating_sub(self.timeout);
                Err(self.timeout_error(Some(node), Waited::Sdo { index, sub }, since))
            }
            Err(e) => {
                if self.lock().check().is_err() {
                    return Err(Error::Bus(Stopped));
                }
                Err(Error::Sdo { node, index, sub, error: e.widen() })
            }
        }
    }

    /// The state machine's steps until the transfer ends: frames it gives are queued, the
    /// responses routed to `node` fed back, its timeout checked at its deadline.
    async fn drive(
        &self,
        node: NodeId,
        client: &mut Client<SDO_BUFFER>,
        start: impl FnOnce(&mut Client<SDO_BUFFER>, Instant) -> Result<CanFrame, SdoError>,
    ) -> Result<(), SdoError> {
        let first_frame = start(client, self.now())?;
        self.queue_sdo(first_frame)?;
        loop {
            let Some(deadline) = client.deadline() else { return Ok(()) };
            let step = match self.response(node, deadline).await {
                Ok(Some(frame)) => client.handle(&frame, self.now()),
                // Past the deadline by construction: the timeout has passed.
                Ok(None) => client.poll(self.now().max(deadline + Duration::MICROSECOND)),
                Err(Stopped) => return Err(SdoError::Local(SdoAbort::General)),
            };
            match step {
                None => {}
                Some(Step::Send(f)) => {
                    self.queue_sdo(f)?;
                    // The rest of a block download's sub-block.
                    while let Some(f) = client.next_block_segment() {
                        self.queue_sdo(f)?;
                    }
                }
                Some(Step::Done) => return Ok(()),
                Some(Step::Finish(f)) => return self.queue_sdo(f),
                Some(Step::Failed(e, abort)) => {
                    if let Some(f) = abort {
                        self.queue_sdo(f)?;
                    }
                    return Err(e);
                }
            }
        }
    }

    fn queue_sdo(&self, frame: CanFrame) -> Result<(), SdoError> {
        // A stopped bus shows as the transfer's failure; `transfer` names it [`Stopped`].
        self.lock()
            .queue(Priority::Low, frame)
            .map_err(|Stopped| SdoError::Local(SdoAbort::General))
    }

    /// Uploads `index:sub` of `node` (expedited or segmented, up to [`SDO_BUFFER`] bytes).
    ///
    /// # Errors
    ///
    /// [`Error::Sdo`] with the abort, [`Error::Timeout`], or [`Stopped`].
    pub async fn upload(&self, node: NodeId, index: u16, sub: u8) -> Result<Vec<u8>, Error> {
        let start = |c: &mut Client<SDO_BUFFER>, now| c.start_upload(index, sub, now);
        self.transfer(node, (index, sub), start, |c| Ok(c.data().to_vec())).await
    }

    /// Downloads `data` into `index:sub` of `node`.
    ///
    /// # Errors
    ///
    /// As [`Master::upload`].
    pub async fn download(
        &self,
        node: NodeId,
        index: u16,
        sub: u8,
        data: &[u8],
    ) -> Result<(), Error> {
        let start = |c: &mut Client<SDO_BUFFER>, now| c.start_download(index, sub, data, now);
        self.transfer(node, (index, sub), start, |_| Ok(())).await
    }

    /// Block-uploads `index:sub` of `node` (CiA 301 block transfer with CRC).
    ///
    /// # Errors
    ///
    /// As [`Master::upload`]; a server without block transfer aborts.
    pub async fn upload_block(&self, node: NodeId, index: u16, sub: u8) -> Result<Vec<u8>, Error> {
        let start = |c: &mut Client<SDO_BUFFER>, now| c.start_block_upload(index, sub, now);
        self.transfer(node, (index, sub), start, |c| Ok(c.data().to_vec())).await
    }

    /// Block-downloads `data` into `index:sub` of `node`.
    ///
    /// # Errors
    ///
    /// As [`Master::upload_block`].
    pub async fn download_block(
        &self,
        node: NodeId,
        index: u16,
        sub: u8,
        data: &[u8],
    ) -> Result<(), Error> {
        let start = |c: &mut Client<SDO_BUFFER>, now| c.start_block_download(index, sub, data, now);
        self.transfer(node, (index, sub), start, |_| Ok(())).await
    }

    /// Reads a generated descriptor's entry of `node`, decoded as its type.
    ///
    /// # Errors
    ///
    /// As [`Master::upload`]; a value of the wrong length is a local abort.
    pub async fn read<T: ObjValue>(&self, node: NodeId, entry: &Entry<T>) -> Result<T, Error> {
        let (index, sub) = (entry.addr.index, entry.addr.sub);
        let start = |c: &mut Client<SDO_BUFFER>, now| c.start_upload(index, sub, now);
        self.transfer(node, (index, sub), start, Client::decode).await
    }

    /// Writes `value` into a generated descriptor's entry of `node`.
    ///
    /// # Errors
    ///
    /// As [`Master::download`]; a value that does not encode is a local abort.
    pub async fn write<T: ObjValue>(
        &self,
        node: NodeId,
        entry: &Entry<T>,
        value: T,
    ) -> Result<(), Error> {
        let (index, sub) = (entry.addr.index, entry.addr.sub);
        let mut data = vec![0u8; SDO_BUFFER];
        let n = value.encode(&mut data).map_err(|e| Error::Sdo {
            node,
            index,
            sub,
            error: SdoError::Local(e.into()),
        })?;
        data.truncate(n);
        self.download(node, index, sub, &data).await
    }

    /// Executes a configuration plan (a generated `master::plan(node)`) on `node`, write by
    /// write, stopping at the first failure.
    ///
    /// # Errors
    ///
    /// [`Error::Plan`]: which write failed and why; [`Error::Timeout`]; [`Stopped`].
    pub async fn execute(&self, node: NodeId, plan: &[SdoWrite]) -> Result<(), Error> {
        for (step, write) in plan.iter().enumerate() {
            let (bytes, n) = write.to_le_bytes();
            let data = bytes.get(..n).unwrap_or(&bytes);
            match self.download(node, write.index, write.sub, data).await {
                Ok(()) => {}
                Err(Error::Sdo { error, .. }) => {
                    return Err(Error::Plan { node, step, write: *write, error });
                }
                Err(e) => return Err(e),
            }
        }
        Ok(())
    }
}
