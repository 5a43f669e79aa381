//! The LSS master (CiA 305) on the async master: the blocking [`LssMaster`]'s services, with
//! its codec and errors. One LSS master at a time ([`Master::lss`]): the answers of every
//! service share one CAN-ID.
//!
//! [`LssMaster`]: crate::master::lss::LssMaster

use core::future::poll_fn;
use core::task::Poll;

use super::master::Priority;
use super::wait::{Either, first};
use super::{Clock, Error, Master};
use crate::can::CanFrame;
use crate::cob::NodeId;
use crate::lss::frame::Part;
use crate::lss::{Identity, REQUEST_ID, Request, Response};
pub use crate::master::lss::{DEFAULT_LSS_TIMEOUT, LssError};
use crate::time::Duration;

/// LSS services on an async [`Master`]'s bus.
#[derive(Debug)]
pub struct LssMaster<'m, C: Clock> {
    master: &'m Master<C>,
    timeout: Duration,
}

impl<C: Clock> Master<C> {
    /// The LSS master (CiA 305) on this master's bus, waiting [`DEFAULT_LSS_TIMEOUT`] for
    /// answers.
    ///
    /// # Errors
    ///
    /// [`Error::Invalid`] while another one is in use.
    pub fn lss(&self) -> Result<LssMaster<'_, C>, Error> {
        let mut g = self.lock();
        if g.lss_active {
            return Err(Error::Invalid("another LSS master is in use on this bus"));
        }
        g.lss_active = true;
        Ok(LssMaster { master: self, timeout: DEFAULT_LSS_TIMEOUT })
    }
}

impl<C: Clock> Drop for LssMaster<'_, C> {
    fn drop(&mut self) {
        self.master.lock().lss_active = false;
    }
}

impl<C: Clock> LssMaster<'_, C> {
    /// The same services with another answer timeout.
    pub fn with_timeout(mut self, timeout: Duration) -> Self {
        self.timeout = timeout;
        self
    }

    /// Queues a request; answers to earlier ones still waiting are dropped.
    fn send(&self, r: Request) -> Result<(), Error> {
        let mut g = self.master.lock();
        g.lss.clear();
        g.queue(Priority::Low, CanFrame::standard(REQUEST_ID, r.encode())).map_err(Error::Bus)
    }

    /// The next LSS answer, or `None` after the timeout.
    async fn answer(&self) -> Result<Option<Response>, Error> {
        let deadline = self.master.now() + self.timeout;
        let next = poll_fn(|cx| {
            let mut g = self.master.lock();
            g.check().map_err(Error::Bus)?;
            match g.lss.pop_front() {
                Some(f) => Poll::Ready(Ok(f)),
                None => {
                    g.lss_waiters.register(cx.waker());
                    Poll::Pending
                }
            }
        });
        match first(next, self.master.clock.sleep_until(deadline)).await {
            Either::Left(f) => Ok(Response::decode(f?.bytes())),
            Either::Right(()) => Ok(None),
        }
    }

    async fn ask(&self, r: Request, what: &'static str) -> Result<Response, Error> {
        self.send(r)?;
        self.answer().await?.ok_or(Error::Lss(LssError::NoAnswer(what)))
    }

    /// Switch state global: every device into configuration state (`true`) or back to
    /// waiting. No answer is defined.
    ///
    /// # Errors
    ///
    /// [`Stopped`](super::Stopped).
    pub fn switch_global(&self, configuration: bool) -> Result<(), Error> {
        self.send(Request::SwitchStateGlobal { configuration })
    }

    /// Switch state selective: the device with this LSS address into configuration state.
    ///
    /// # Errors
    ///
    /// [`LssError::NoAnswer`] when no device has the address.
    pub async fn switch_selective(&self, id: Identity) -> Result<(), Error> {
        for (part, n) in
            [(Part::Vendor, id.vendor), (Part::Product, id.product), (Part::Revision, id.revision)]
        {
            self.send(Request::SwitchStateSelective(part, n))?;
        }
        match self
            .ask(Request::SwitchStateSelective(Part::Serial, id.serial), "switch selective")
            .await?
        {
            Response::SwitchStateSelective => Ok(()),
            _ => Err(Error::Lss(LssError::NoAnswer("switch selective"))),
        }
    }

    /// Configure node-ID (`None`: "unconfigured", 0xFF) of the device in configuration
    /// state; it takes effect at its next reset communication.
    ///
    /// # Errors
    ///
    /// [`LssError::NodeId`] when refused, [`LssError::NoAnswer`].
    pub async fn configure_node_id(&self, id: Option<NodeId>) -> Result<(), Error> {
        match self.ask(Request::ConfigureNodeId(NodeId::to_lss(id)), "configure node-ID").await? {
            Response::ConfigureNodeId { error: 0, .. } => Ok(()),
            Response::ConfigureNodeId { error, specific } => {
                Err(Error::Lss(LssError::NodeId { error, specific }))
            }
            _ => Err(Error::Lss(LssError::NoAnswer("configure node-ID"))),
        }
    }

    /// Configure bit timing: `index` of CiA 305 table `table`.
    ///
    /// # Errors
    ///
    /// [`LssError::BitTiming`] when refused, [`LssError::NoAnswer`].
    pub async fn configure_bit_timing(&self, table: u8, index: u8) -> Result<(), Error> {
        match self.ask(Request::ConfigureBitTiming { table, index }, "configure bit timing").await?
        {
            Response::ConfigureBitTiming { error: 0, .. } => Ok(()),
            Response::ConfigureBitTiming { error, specific } => {
                Err(Error::Lss(LssError::BitTiming { error, specific }))
            }
            _ => Err(Error::Lss(LssError::NoAnswer("configure bit timing"))),
        }
    }

    /// Activate bit timing after `delay_ms` (CiA 305's 16-bit delay, sent as is). No answer
    /// is defined.
    ///
    /// # Errors
    ///
    /// [`Stopped`](super::Stopped).
    pub fn activate_bit_timing(&self, delay_ms: u16) -> Result<(), Error> {
        self.send(Request::ActivateBitTiming { delay_ms })
    }

    /// Store configuration.
    ///
    /// # Errors
    ///
    /// [`LssError::Store`] when refused, [`LssError::NoAnswer`].
    pub async fn store(&self) -> Result<(), Error> {
        match self.ask(Request::StoreConfiguration, "store configuration").await? {
            Response::StoreConfiguration { error: 0, .. } => Ok(()),
            Response::StoreConfiguration { error, specific } => {
                Err(Error::Lss(LssError::Store { error, specific }))
            }
            _ => Err(Error::Lss(LssError::NoAnswer("store configuration"))),
        }
    }

    /// Inquire the LSS address of the device in configuration state.
    ///
    /// # Errors
    ///
    /// [`LssError::NoAnswer`].
    pub async fn inquire_identity(&self) -> Result<Identity, Error> {
        let mut parts = [0u32; 4];
        for (slot, part) in
            parts.iter_mut().zip([Part::Vendor, Part::Product, Part::Revision, Part::Serial])
        {
            match self.ask(Request::Inquire(part), "inquire identity").await? {
                Response::Inquire(p, n) if p == part => *slot = n,
                _ => return Err(Error::Lss(LssError::NoAnswer("inquire identity"))),
            }
        }
        let [vendor, product, revision, serial] = parts;
        Ok(Identity { vendor, product, revision, serial })
    }

    /// Inquire the node-ID of the device in configuration state (`None`: unconfigured).
    ///
    /// # Errors
    ///
    /// [`LssError::NoAnswer`], [`Error::Invalid`] for an answer that is no node-ID.
    pub async fn inquire_node_id(&self) -> Result<Option<NodeId>, Error> {
        match self.ask(Request::InquireNodeId, "inquire node-ID").await? {
            Response::InquireNodeId(id) => NodeId::from_lss(id)
                .ok_or(Error::Invalid("LSS answered a node-ID outside 1..=127 and 255")),
            _ => Err(Error::Lss(LssError::NoAnswer("inquire node-ID"))),
        }
    }

    /// Whether a device without node-ID is on the bus.
    ///
    /// # Errors
    ///
    /// [`Stopped`](super::Stopped).
    pub async fn any_unconfigured(&self) -> Result<bool, Error> {
        self.send(Request::IdentifyNonConfigured)?;
        Ok(matches!(self.answer().await?, Some(Response::IdentifyNonConfigured)))
    }

    async fn fastscan_step(
        &self,
        id_number: u32,
        bit_checked: u8,
        sub: u8,
        next: u8,
    ) -> Result<bool, Error> {
        self.send(Request::Fastscan { id_number, bit_checked, sub, next })?;
        Ok(matches!(self.answer().await?, Some(Response::IdentifySlave)))
    }

    /// Fastscan (CiA 305): finds one device without node-ID and leaves it in configuration
    /// state. `None` when no unconfigured device answers.
    ///
    /// # Errors
    ///
    /// A device that stops answering midway is [`LssError::NoAnswer`].
    pub async fn fastscan(&self) -> Result<Option<Identity>, Error> {
        if !self.fastscan_step(0, 0x80, 0, 0).await? {
            return Ok(None);
        }
        let mut id = [0u32; 4];
        for (sub, slot) in (0..4u8).zip(id.iter_mut()) {
            let mut n = 0u32;
            for bit in (0..32u8).rev() {
                if !self.fastscan_step(n, bit, sub, sub).await? {
                    n |= 1 << bit;
                }
            }
            // The whole part, confirmed; the last part's `next` (0) ends the scan.
            if !self.fastscan_step(n, 0, sub, (sub + 1) & 3).await? {
                return Err(Error::Lss(LssError::NoAnswer("fastscan confirmation")));
            }
            *slot = n;
        }
        let [vendor, product, revision, serial] = id;
        Ok(Some(Identity { vendor, product, revision, serial }))
    }
}
