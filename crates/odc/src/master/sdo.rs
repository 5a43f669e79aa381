//! SDO transfers of the master: one client per node, typed by generated descriptors, and
//! the execution of configuration plans.

use std::boxed::Box;
use std::vec::Vec;

use super::Waited;
use super::{Error, Master, SDO_BUFFER, link::Link};
use crate::SdoAbort;
use crate::cob::NodeId;
use crate::plan::SdoWrite;
use crate::sdo::{Client, SdoError};
use crate::transport::Bus;
use crate::{Entry, ObjValue};

impl<B: Bus> Master<B> {
    // ---- SDO -----------------------------------------------------------------------------

    /// Reads a generated descriptor's entry of `node`.
    ///
    /// # Errors
    ///
    /// [`Error::Sdo`] with the abort, or the bus error.
    pub fn read<T: ObjValue>(
        &mut self,
        node: NodeId,
        entry: &Entry<T>,
    ) -> Result<T, Error<B::Error>> {
        let (index, sub) = (entry.addr.index, entry.addr.sub);
        self.transfer(node, index, sub, |c, link| c.read(link, entry))
    }

    /// Writes `value` into a generated descriptor's entry of `node`.
    ///
    /// # Errors
    ///
    /// [`Error::Sdo`] with the abort, or the bus error.
    pub fn write<T: ObjValue>(
        &mut self,
        node: NodeId,
        entry: &Entry<T>,
        value: T,
    ) -> Result<(), Error<B::Error>> {
        let (index, sub) = (entry.addr.index, entry.addr.sub);
        self.transfer(node, index, sub, |c, link| c.write(link, entry, value))
    }

    /// Uploads `index:sub` of `node` (any size up to [`SDO_BUFFER`]).
    ///
    /// # Errors
    ///
    /// [`Error::Sdo`] with the abort, or the bus error.
    pub fn upload(
        &mut self,
        node: NodeId,
        index: u16,
        sub: u8,
    ) -> Result<Vec<u8>, Error<B::Error>> {
        self.transfer(node, index, sub, |c, link| c.upload(link, index, sub).map(<[u8]>::to_vec))
    }

    /// Downloads `data` into `index:sub` of `node`.
    ///
    /// # Errors
    ///
    /// [`Error::Sdo`] with the abort, or the bus error.
    pub fn download(
        &mut self,
        node: NodeId,
        index: u16,
        sub: u8,
        data: &[u8],
    ) -> Result<(), Error<B::Error>> {
        self.transfer(node, index, sub, |c, link| c.download(link, index, sub, data))
    }

    /// Block-uploads `index:sub` of `node` (CiA 301 block transfer with CRC: for large
    /// values, where the server supports it).
    ///
    /// # Errors
    ///
    /// [`Error::Sdo`] with the abort (a server without block transfer aborts), or the bus
    /// error.
    pub fn upload_block(
        &mut self,
        node: NodeId,
        index: u16,
        sub: u8,
    ) -> Result<Vec<u8>, Error<B::Error>> {
        self.transfer(node, index, sub, |c, link| {
            c.upload_block(link, index, sub).map(<[u8]>::to_vec)
        })
    }

    /// Block-downloads `data` into `index:sub` of `node`.
    ///
    /// # Errors
    ///
    /// As [`Master::upload_block`].
    pub fn download_block(
        &mut self,
        node: NodeId,
        index: u16,
        sub: u8,
        data: &[u8],
    ) -> Result<(), Error<B::Error>> {
        self.transfer(node, index, sub, |c, link| c.download_block(link, index, sub, data))
    }

    /// Executes a configuration plan (a generated `master::plan(node)`) on `node`, write by
    /// write, stopping at the first failure.
    ///
    /// # Errors
    ///
    /// [`Error::Plan`]: which write failed, and why; [`Error::Timeout`] when a response did
    /// not come.
    pub fn execute(&mut self, node: NodeId, plan: &[SdoWrite]) -> Result<(), Error<B::Error>> {
        let mut client = self.take_client(node)?;
        let r = client.execute(&mut self.link, plan);
        self.clients.insert(node, client);
        let Err((step, error)) = r else { return Ok(()) };
        let write = plan.get(step).copied().unwrap_or(SdoWrite::u8(0, 0, 0));
        if matches!(error, SdoError::Local(SdoAbort::Timeout)) {
            let what = Waited::Sdo { index: write.index, sub: write.sub };
            return Err(self.sdo_timeout(node, what));
        }
        Err(Error::Plan { node, step, write, error })
    }

    /// Runs one transfer with `node`'s client; its error names the node and the object.
    fn transfer<T>(
        &mut self,
        node: NodeId,
        index: u16,
        sub: u8,
        run: impl FnOnce(&mut Client<SDO_BUFFER>, &mut Link<B>) -> Result<T, SdoError<B::Error>>,
    ) -> Result<T, Error<B::Error>> {
        let mut client = self.take_client(node)?;
        let r = run(&mut client, &mut self.link);
        self.clients.insert(node, client);
        match r {
            Ok(v) => Ok(v),
            // The client waited for a response in vain (and sent the abort 0x05040000): say
            // whether the node is there at all.
            Err(SdoError::Local(SdoAbort::Timeout)) => {
                Err(self.sdo_timeout(node, Waited::Sdo { index, sub }))
            }
            Err(error) => Err(Error::Sdo { node, index, sub, error }),
        }
    }

    /// The timeout of an SDO transfer with `node`: heard or not during the last response wait
    /// (earlier responses of the same transfer do not make a silent node alive).
    fn sdo_timeout(&mut self, node: NodeId, what: Waited) -> Error<B::Error> {
        let since = self.now().saturating_sub(self.timeout);
        self.timeout_error(Some(node), what, since)
    }

    /// The node's client, out of the map while it runs (it borrows the link mutably); the
    /// link then lets its responses through.
    fn take_client(&mut self, node: NodeId) -> Result<Box<Client<SDO_BUFFER>>, Error<B::Error>> {
        self.link.sdo_response = Some(node.sdo_response().raw());
        let timeout = self.timeout;
        Ok(self
            .clients
            .remove(&node)
            .unwrap_or_else(|| Box::new(Client::new(node).with_timeout(timeout))))
    }
}
