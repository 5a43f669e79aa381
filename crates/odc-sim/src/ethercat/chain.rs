//! [`Chain`]: devices in a line, as cabled port 1 to port 0. A frame passes each device in
//! order (each executes every datagram as it passes), the last one sends it back through
//! the others unchanged, and the first one returns it to the master with the source
//! address's locally administered bit set (the ESCs' port 0 does so, which is how a master
//! tells its own frames from the answers).

use super::SubDevice;
use super::esc::Passing;
use super::frame::{FrameError, ecat_payload, for_each_datagram};

/// Time a frame takes from one device to the next (cable and processing; the ESC datasheets
/// give about 500 ns through an ESC with MII ports and 5 ns a metre of cable).
pub const HOP_NS: u64 = 600;

/// Simulated devices in a line.
#[derive(Debug, Default)]
pub struct Chain {
    devices: Vec<SubDevice>,
    frames: u64,
    datagrams: u64,
}

impl Chain {
    /// A chain of `devices`, first one next to the master; all are powered on in INIT.
    pub fn new(devices: Vec<SubDevice>) -> Self {
        let n = devices.len();
        let mut devices = devices;
        for (i, d) in devices.iter_mut().enumerate() {
            d.place(i, i + 1 < n);
        }
        Self { devices, frames: 0, datagrams: 0 }
    }

    /// The devices, in line order.
    pub fn devices(&self) -> &[SubDevice] {
        &self.devices
    }

    /// The devices, to change their dictionaries.
    pub fn devices_mut(&mut self) -> &mut [SubDevice] {
        &mut self.devices
    }

    /// Frames processed so far.
    pub fn frames(&self) -> u64 {
        self.frames
    }

    /// Datagrams processed so far.
    pub fn datagrams(&self) -> u64 {
        self.datagrams
    }

    /// Runs an Ethernet frame through the chain in place at time `now_ns` (any monotonic
    /// nanosecond clock): what comes back to the master.
    ///
    /// # Errors
    ///
    /// [`FrameError`]: not an EtherCAT frame of datagrams, or malformed (ESCs forward such
    /// a frame unprocessed; the caller drops it).
    pub fn process(&mut self, frame: &mut [u8], now_ns: u64) -> Result<(), FrameError> {
        let n = self.devices.len() as u64;
        let payload = ecat_payload(frame)?;
        // A frame that does not parse is refused before any device changes state.
        let mut count = 0;
        for_each_datagram(payload, |_| count += 1)?;
        for (i, device) in (0u64..).zip(self.devices.iter_mut()) {
            let at = Passing {
                arrival_ns: now_ns + i * HOP_NS,
                port1_ns: (i + 1 < n).then(|| now_ns + (2 * (n - 1) - i) * HOP_NS),
            };
            for_each_datagram(payload, |d| device.execute(d, &at))?;
            device.after_frame(&at);
        }
        if let Some(src) = frame.get_mut(6) {
            *src |= 0x02;
        }
        self.frames += 1;
        self.datagrams += count;
        Ok(())
    }
}
