//! The LSS master (CiA 305): switch a device into configuration state (all, or one by its LSS
//! address), give it a node-ID and a bit rate, store them, ask it who it is, and find an
//! unconfigured device by fastscan.
//!
//! Requests go on 0x7E5 and answers come on 0x7E4 ([`crate::lss`]'s codec). A service that
//! expects an answer waits for it ([`LssMaster::with_timeout`]); fastscan reads silence as
//! "no", so its timeout sets how long a scan takes (about 130 requests).

use core::fmt;

use super::{Error, Master};
use crate::can::CanFrame;
use crate::cob::NodeId;
use crate::lss::frame::Part;
use crate::lss::{Identity, REQUEST_ID, RESPONSE_ID, Request, Response};
use crate::time::Duration;
use crate::transport::Bus;

/// Default wait for an LSS answer (fastscan waits this long for each silent step).
pub const DEFAULT_LSS_TIMEOUT: Duration = Duration::from_millis(50);

/// Why an LSS service failed.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum LssError {
    /// The device refused the node-ID (error code 1: out of range; 255: manufacturer's
    /// `specific` reason).
    NodeId {
        /// CiA 305 error code.
        error: u8,
        /// Manufacturer-specific error.
        specific: u8,
    },
    /// The device refused the bit timing (1: not supported).
    BitTiming {
        /// CiA 305 error code.
        error: u8,
        /// Manufacturer-specific error.
        specific: u8,
    },
    /// The device could not store (1: not supported, 2: storage media access error).
    Store {
        /// CiA 305 error code.
        error: u8,
        /// Manufacturer-specific error.
        specific: u8,
    },
    /// No device answered.
    NoAnswer(&'static str),
}

impl fmt::Display for LssError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match *self {
            Self::NodeId { error, specific } => {
                let why = match error {
                    1 => "node-ID out of range",
                    255 => "manufacturer-specific error",
                    _ => "reserved error code",
                };
                write!(f, "node-ID refused: {why} (error {error}, specific {specific})")
            }
            Self::BitTiming { error, specific } => {
                let why = if error == 1 { "bit timing not supported" } else { "error" };
                write!(f, "bit timing refused: {why} (error {error}, specific {specific})")
            }
            Self::Store { error, specific } => {
                let why = match error {
                    1 => "store configuration not supported",
                    2 => "storage media access error",
                    _ => "error",
                };
                write!(f, "store refused: {why} (error {error}, specific {specific})")
            }
            Self::NoAnswer(what) => write!(f, "no answer to {what}"),
        }
    }
}

/// LSS services on a [`Master`]'s bus.
pub struct LssMaster<'m, B: Bus> {
    master: &'m mut Master<B>,
    timeout: Duration,
}

impl<'m, B: Bus> LssMaster<'m, B> {
    pub(super) fn new(master: &'m mut Master<B>) -> Self {
        LssMaster { master, timeout: DEFAULT_LSS_TIMEOUT }
    }

    /// The same services with another answer timeout.
    pub fn with_timeout(mut self, timeout: Duration) -> Self {
        self.timeout = timeout;
        self
    }

    fn send(&mut self, r: Request) -> Result<(), Error<B::Error>> {
        self.master.send(&CanFrame::standard(REQUEST_ID, r.encode()))
    }

    /// The next LSS answer, or `None` after the timeout (other frames are kept).
    fn answer(&mut self) -> Result<Option<Response>, Error<B::Error>> {
        let deadline = self.master.now() + self.timeout;
        let f = self
            .master
            .link
            .take(deadline, |f| f.is_data(RESPONSE_ID.raw()))
            .map_err(Error::Bus)?;
        Ok(f.and_then(|f| Response::decode(f.bytes())))
    }

    fn ask(&mut self, r: Request, what: &'static str) -> Result<Response, Error<B::Error>> {
        self.send(r)?;
        self.answer()?.ok_or(Error::Lss(LssError::NoAnswer(what)))
    }

    /// Switch state global: every device into configuration state (`true`) or back to
    /// waiting. No answer is defined.
    ///
    /// # Errors
    ///
    /// The bus error.
    pub fn switch_global(&mut self, configuration: bool) -> Result<(), Error<B::Error>> {
        self.send(Request::SwitchStateGlobal { configuration })
    }

    /// Switch state selective: the device with this LSS address into configuration state.
    ///
    /// # Errors
    ///
    /// [`LssError::NoAnswer`] when no device has the address, or the bus error.
    pub fn switch_selective(&mut self, id: Identity) -> Result<(), Error<B::Error>> {
        for (part, n) in
            [(Part::Vendor, id.vendor), (Part::Product, id.product), (Part::Revision, id.revision)]
        {
            self.send(Request::SwitchStateSelective(part, n))?;
        }
        match self
            .ask(Request::SwitchStateSelective(Part::Serial, id.serial), "switch selective")?
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
    /// [`LssError::NodeId`] when refused, [`LssError::NoAnswer`], or the bus error.
    pub fn configure_node_id(&mut self, id: Option<NodeId>) -> Result<(), Error<B::Error>> {
        match self.ask(Request::ConfigureNodeId(NodeId::to_lss(id)), "configure node-ID")? {
            Response::ConfigureNodeId { error: 0, .. } => Ok(()),
            Response::ConfigureNodeId { error, specific } => {
                Err(Error::Lss(LssError::NodeId { error, specific }))
            }
            _ => Err(Error::Lss(LssError::NoAnswer("configure node-ID"))),
        }
    }

    /// Configure bit timing: `index` of CiA 305 table 1 (table 0: 0 = 1000 kbit/s, 1 = 800,
    /// 2 = 500, 3 = 250, 4 = 125, 6 = 50, 7 = 20, 8 = 10, 9 = auto).
    ///
    /// # Errors
    ///
    /// [`LssError::BitTiming`] when refused, [`LssError::NoAnswer`], or the bus error.
    pub fn configure_bit_timing(&mut self, table: u8, index: u8) -> Result<(), Error<B::Error>> {
        match self.ask(Request::ConfigureBitTiming { table, index }, "configure bit timing")? {
            Response::ConfigureBitTiming { error: 0, .. } => Ok(()),
            Response::ConfigureBitTiming { error, specific } => {
                Err(Error::Lss(LssError::BitTiming { error, specific }))
            }
            _ => Err(Error::Lss(LssError::NoAnswer("configure bit timing"))),
        }
    }

    /// Activate bit timing: every device in configuration state switches after `delay_ms`,
    /// twice (before and after the switch, the bus stays silent). No answer is defined.
    ///
    /// `delay_ms` stays a bare `u16`: it is CiA 305's 16-bit switch delay, in ms, sent as is
    /// (the master does not wait it out), so a [`crate::time::Duration`] would only add a
    /// conversion that can fail.
    ///
    /// # Errors
    ///
    /// The bus error.
    pub fn activate_bit_timing(&mut self, delay_ms: u16) -> Result<(), Error<B::Error>> {
        self.send(Request::ActivateBitTiming { delay_ms })
    }

    /// Store configuration: the device keeps its node-ID and bit timing over power cycles.
    ///
    /// # Errors
    ///
    /// [`LssError::Store`] when refused, [`LssError::NoAnswer`], or the bus error.
    pub fn store(&mut self) -> Result<(), Error<B::Error>> {
        match self.ask(Request::StoreConfiguration, "store configuration")? {
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
    /// [`LssError::NoAnswer`], or the bus error.
    pub fn inquire_identity(&mut self) -> Result<Identity, Error<B::Error>> {
        let mut parts = [0u32; 4];
        for (k, part) in
            [Part::Vendor, Part::Product, Part::Revision, Part::Serial].into_iter().enumerate()
        {
            match self.ask(Request::Inquire(part), "inquire identity")? {
                Response::Inquire(p, n) if p == part => {
                    if let Some(slot) = parts.get_mut(k) {
                        *slot = n;
                    }
                }
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
    /// [`LssError::NoAnswer`], [`Error::Invalid`] for an answer that is no node-ID (0,
    /// 128–254), or the bus error.
    pub fn inquire_node_id(&mut self) -> Result<Option<NodeId>, Error<B::Error>> {
        match self.ask(Request::InquireNodeId, "inquire node-ID")? {
            Response::InquireNodeId(id) => NodeId::from_lss(id)
                .ok_or(Error::Invalid("LSS answered a node-ID outside 1..=127 and 255")),
            _ => Err(Error::Lss(LssError::NoAnswer("inquire node-ID"))),
        }
    }

    /// Whether a device without node-ID is on the bus (identify non-configured remote slave).
    ///
    /// # Errors
    ///
    /// The bus error.
    pub fn any_unconfigured(&mut self) -> Result<bool, Error<B::Error>> {
        self.send(Request::IdentifyNonConfigured)?;
        Ok(matches!(self.answer()?, Some(Response::IdentifyNonConfigured)))
    }

    /// Fastscan (CiA 305): finds one device without node-ID and leaves it in configuration
    /// state, ready for [`LssMaster::configure_node_id`]. For each of the four parts of the
    /// LSS address, bit 31 down to 0: a request with the bit clear, and silence means the
    /// device's bit is set. `None` when no unconfigured device answers.
    ///
    /// # Errors
    ///
    /// The bus error; a device that stops answering midway is [`LssError::NoAnswer`].
    pub fn fastscan(&mut self) -> Result<Option<Identity>, Error<B::Error>> {
        let ask = |this: &mut Self, id_number: u32, bit_checked: u8, sub: u8, next: u8| {
            this.send(Request::Fastscan { id_number, bit_checked, sub, next })?;
            Ok::<bool, Error<B::Error>>(matches!(this.answer()?, Some(Response::IdentifySlave)))
        };
        if !ask(self, 0, 0x80, 0, 0)? {
            return Ok(None);
        }
        let mut id = [0u32; 4];
        for sub in 0..4u8 {
            let mut n = 0u32;
            for bit in (0..32u8).rev() {
                if !ask(self, n, bit, sub, sub)? {
                    n |= 1 << bit;
                }
            }
            // The whole part, confirmed; the last part's `next` (0) ends the scan.
            if !ask(self, n, 0, sub, (sub + 1) & 3)? {
                return Err(Error::Lss(LssError::NoAnswer("fastscan confirmation")));
            }
            if let Some(slot) = id.get_mut(usize::from(sub)) {
                *slot = n;
            }
        }
        let [vendor, product, revision, serial] = id;
        Ok(Some(Identity { vendor, product, revision, serial }))
    }
}
