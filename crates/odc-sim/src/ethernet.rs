//! Simulated EtherCAT devices on a network interface: whatever master runs on the other end of
//! the wire (a veth pair's peer, a real NIC's cable) sees devices.
//!
//! An EtherCAT segment is a line of devices whose last one closes its open port: a frame goes
//! out, each device works on it as it passes, and it comes back on the wire it left by. This
//! endpoint is that line: it takes each EtherCAT frame (EtherType 0x88A4) that arrives on the
//! interface, hands it to the simulated devices, and sends it back out of the same interface.
//!
//! A device that has worked on a frame sets bit 1 of the first byte of its source MAC address
//! ("The source MAC address is changed for every frame passing the EtherCAT Processing Unit
//! (SOURCE_MAC[1] is set to 1 – locally administered address)", Beckhoff, EtherCAT Slave
//! Controller, Technology, section I, 3: so a master tells the frames it sent from those that
//! come back). The endpoint uses the same mark to ignore the
//! frames it sent itself, which a packet socket also receives.
//!
//! The socket is `pnet_datalink`'s (AF_PACKET on Linux; root or `CAP_NET_RAW`).

use std::io;
use std::time::Duration;

use pnet_datalink::{Channel, Config, DataLinkReceiver, DataLinkSender, NetworkInterface};

/// The EtherType of EtherCAT (ETG.1000.4, IEEE assignment).
pub const ETHERTYPE_ETHERCAT: u16 = 0x88A4;
/// Bit 1 of source MAC byte 0: the frame has been through a device.
const PROCESSED: u8 = 0x02;
/// How long a receive waits before the stop condition is looked at again.
const POLL: Duration = Duration::from_millis(50);

/// One network interface serving simulated devices.
pub struct EthernetEndpoint {
    name: String,
    tx: Box<dyn DataLinkSender>,
    rx: Box<dyn DataLinkReceiver>,
}

/// What [`EthernetEndpoint::serve`] did.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct Served {
    /// EtherCAT frames worked on and sent back.
    pub frames: u64,
    /// Frames of other EtherTypes, too short, or refused by the devices, left alone.
    pub ignored: u64,
}

impl EthernetEndpoint {
    /// Opens `iface` (such as one end of a veth pair) for raw Ethernet frames.
    ///
    /// # Errors
    ///
    /// No interface of that name, or the socket is refused (root or `CAP_NET_RAW` needed).
    pub fn open(iface: &str) -> io::Result<Self> {
        let interface = pnet_datalink::interfaces()
            .into_iter()
            .find(|i: &NetworkInterface| i.name == iface)
            .ok_or_else(|| {
                io::Error::new(io::ErrorKind::NotFound, format!("no interface {iface}"))
            })?;
        let config = Config { read_timeout: Some(POLL), ..Config::default() };
        match pnet_datalink::channel(&interface, config)? {
            Channel::Ethernet(tx, rx) => Ok(Self { name: iface.to_owned(), tx, rx }),
            _ => Err(io::Error::other(format!("{iface}: not an Ethernet channel"))),
        }
    }

    /// The interface's name.
    #[must_use]
    pub fn name(&self) -> &str {
        &self.name
    }

    /// Serves until `stop` says so (looked at every 50 ms at least): each EtherCAT frame a
    /// master sends is given whole (Ethernet header included) to `process`, which works on it
    /// in place as the devices of the segment do and is sent back marked as processed; or,
    /// when `process` returns false (a malformed frame), is dropped.
    ///
    /// # Errors
    ///
    /// The socket's errors, but for the receive timeouts that let `stop` be looked at.
    pub fn serve(
        &mut self,
        mut process: impl FnMut(&mut [u8]) -> bool,
        stop: impl Fn() -> bool,
    ) -> io::Result<Served> {
        let mut served = Served::default();
        let mut frame = Vec::with_capacity(1514);
        while !stop() {
            match self.rx.next() {
                Ok(bytes) => {
                    if !is_from_master(bytes) {
                        served.ignored += u64::from(!is_ethercat(bytes));
                        continue;
                    }
                    frame.clear();
                    frame.extend_from_slice(bytes);
                    if !process(&mut frame) {
                        served.ignored += 1;
                        continue;
                    }
                    frame[6] |= PROCESSED;
                    if let Some(sent) = self.tx.send_to(&frame, None) {
                        sent?;
                    }
                    served.frames += 1;
                }
                Err(e)
                    if matches!(e.kind(), io::ErrorKind::TimedOut | io::ErrorKind::WouldBlock) => {}
                Err(e) => return Err(e),
            }
        }
        Ok(served)
    }
}

/// An Ethernet frame carrying EtherCAT (no VLAN tag: masters send none).
fn is_ethercat(frame: &[u8]) -> bool {
    frame.len() >= 16 && u16::from_be_bytes([frame[12], frame[13]]) == ETHERTYPE_ETHERCAT
}

/// An EtherCAT frame no device has worked on yet: one a master sent.
fn is_from_master(frame: &[u8]) -> bool {
    is_ethercat(frame) && frame[6] & PROCESSED == 0
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A frame as SOEM sends it: broadcast destination, source 01:01:01:01:01:01, EtherType
    /// 0x88A4, an EtherCAT header (length 12, type 1) and a BRD of register 0x0000.
    fn soem_brd() -> Vec<u8> {
        let mut f = vec![0xFF; 6];
        f.extend([1, 1, 1, 1, 1, 1, 0x88, 0xA4, 0x0C, 0x10]);
        f.extend([0x07, 0x00, 0, 0, 0, 0, 0x02, 0x00, 0, 0, 0, 0, 0, 0]);
        f
    }

    #[test]
    fn frames_from_a_master_are_told_from_those_that_came_back() {
        let sent = soem_brd();
        assert!(is_from_master(&sent));
        let mut back = sent.clone();
        back[6] |= PROCESSED;
        assert_eq!(back[6], 0x03, "01 becomes 03 (locally administered)");
        assert!(is_ethercat(&back) && !is_from_master(&back));
        let mut ip = sent;
        ip[12..14].copy_from_slice(&[0x08, 0x00]);
        assert!(!is_ethercat(&ip));
        assert!(!is_ethercat(&[0; 15]), "too short for a header");
    }
}
