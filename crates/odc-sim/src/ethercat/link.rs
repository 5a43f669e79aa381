//! [`EthercrabLink`]: simulated devices wired to an [ethercrab] `MainDevice` in the same
//! process (feature `ethercrab`), so a master application is tested against the devices of
//! its ESI files without a network, privileges or hardware.
//!
//! ethercrab's `PduStorage::try_split` gives the frame interface a network driver uses: a
//! `PduTx` with the frames to send and a `PduRx` that takes the answers. The link is that
//! driver: a thread that takes each frame, runs it through the [`Chain`] and hands the answer
//! back, as the wire and the devices would.
//!
//! ```no_run
//! # fn ex(chain: odc_sim::ethercat::Chain) {
//! use ethercrab::{MainDevice, MainDeviceConfig, PduStorage, Timeouts};
//! static STORAGE: PduStorage<16, { PduStorage::element_size(1100) }> = PduStorage::new();
//! let (tx, rx, pdu_loop) = STORAGE.try_split().expect("split once");
//! let link = odc_sim::ethercat::EthercrabLink::start(tx, rx, chain, ethercrab::std::ethercat_now);
//! let maindevice = MainDevice::new(pdu_loop, Timeouts::default(), MainDeviceConfig::default());
//! // … maindevice.init_single_group(ethercrab::std::ethercat_now), tx_rx, SDOs …
//! let frames = link.stop();
//! # }
//! ```
//!
//! [ethercrab]: https://docs.rs/ethercrab

use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::{Arc, Mutex, MutexGuard, PoisonError};
use std::task::{Wake, Waker};
use std::thread::{self, JoinHandle, Thread};
use std::time::Duration;

use ethercrab::{PduRx, PduTx};

use super::Chain;

/// What the link did, for a test to report.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct Carried {
    /// Frames run through the chain and handed back.
    pub frames: u64,
    /// Frames the chain refused (not EtherCAT datagrams) or ethercrab did not take back:
    /// dropped, as a wire drops a damaged frame (ethercrab times out on them).
    pub dropped: u64,
}

/// A running in-process link; stopped by [`EthercrabLink::stop`] or on drop.
#[derive(Debug)]
pub struct EthercrabLink {
    chain: Arc<Mutex<Chain>>,
    stop: Arc<AtomicBool>,
    thread: Option<JoinHandle<Carried>>,
}

/// Wakes the link's thread when ethercrab has a frame to send.
struct Unpark(Thread);

impl Wake for Unpark {
    fn wake(self: Arc<Self>) {
        self.0.unpark();
    }
}

impl EthercrabLink {
    /// Starts the thread that carries ethercrab's frames through `chain`; `clock` gives the
    /// devices' time in nanoseconds (pass the clock given to ethercrab, such as
    /// `ethercrab::std::ethercat_now`, so that distributed clocks agree).
    pub fn start(tx: PduTx<'static>, rx: PduRx<'static>, chain: Chain, clock: fn() -> u64) -> Self {
        let chain = Arc::new(Mutex::new(chain));
        let stop = Arc::new(AtomicBool::new(false));
        let (devices, stopped) = (Arc::clone(&chain), Arc::clone(&stop));
        let thread = thread::spawn(move || carry(tx, rx, &devices, &stopped, clock));
        Self { chain, stop, thread: Some(thread) }
    }

    /// The devices, to look at or change between ethercrab's calls.
    pub fn chain(&self) -> MutexGuard<'_, Chain> {
        // A panic while the chain was locked leaves it as it was: still worth looking at.
        self.chain.lock().unwrap_or_else(PoisonError::into_inner)
    }

    /// Stops the thread; what it carried.
    pub fn stop(mut self) -> Carried {
        self.halt()
    }

    fn halt(&mut self) -> Carried {
        self.stop.store(true, Ordering::Relaxed);
        self.thread.take().and_then(|t| t.join().ok()).unwrap_or_default()
    }
}

impl Drop for EthercrabLink {
    fn drop(&mut self) {
        self.halt();
    }
}

/// The thread: every frame ethercrab has to send goes through the chain and back, until
/// `stop`; between frames it sleeps until ethercrab wakes it (1 ms at most).
fn carry(
    mut tx: PduTx<'static>,
    mut rx: PduRx<'static>,
    chain: &Mutex<Chain>,
    stop: &AtomicBool,
    clock: fn() -> u64,
) -> Carried {
    let waker = Waker::from(Arc::new(Unpark(thread::current())));
    let mut carried = Carried::default();
    let mut buf = Vec::with_capacity(1514);
    while !stop.load(Ordering::Relaxed) {
        tx.replace_waker(&waker);
        let mut any = false;
        while let Some(frame) = tx.next_sendable_frame() {
            any = true;
            buf.clear();
            let sent = frame.send_blocking(|bytes| {
                buf.extend_from_slice(bytes);
                Ok(bytes.len())
            });
            let processed = sent.is_ok()
                && chain
                    .lock()
                    .unwrap_or_else(PoisonError::into_inner)
                    .process(&mut buf, clock())
                    .is_ok();
            if processed && rx.receive_frame(&buf).is_ok() {
                carried.frames += 1;
            } else {
                carried.dropped += 1;
            }
        }
        if !any {
            thread::park_timeout(Duration::from_millis(1));
        }
    }
    carried
}
