//! ethercrab (crates.io), an EtherCAT master nobody here wrote, against simulated devices
//! built from ESI files, in one process: ethercrab's frames go through
//! `PduStorage::try_split`'s `PduTx`, through the simulated chain, and back through `PduRx`
//! (no network). What ethercrab finds (identities read from the SII, names, states, process
//! image sizes) is compared with what the ESI says.
#![allow(clippy::unwrap_used, clippy::expect_used, clippy::panic)]

use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::{Arc, Mutex, OnceLock};
use std::task::{Wake, Waker};
use std::thread::{self, JoinHandle, Thread};
use std::time::{Duration, Instant};

use ethercrab::{MainDevice, MainDeviceConfig, PduRx, PduStorage, PduTx, Timeouts};
use odc_sim::ethercat::{Chain, SubDevice};

const MAX_FRAMES: usize = 16;
const MAX_PDU_DATA: usize = PduStorage::element_size(1100);

/// The clock both sides use (ethercrab's DC set-up and the chain's): ns since the first use.
fn now() -> u64 {
    static START: OnceLock<Instant> = OnceLock::new();
    START.get_or_init(Instant::now).elapsed().as_nanos() as u64
}

struct Unpark(Thread);

impl Wake for Unpark {
    fn wake(self: Arc<Self>) {
        self.0.unpark();
    }
}

/// The in-process link: a thread that takes each frame ethercrab has to send, runs it
/// through the chain and hands the answer to ethercrab's receiver.
struct Link {
    chain: Arc<Mutex<Chain>>,
    stop: Arc<AtomicBool>,
    thread: Option<JoinHandle<u64>>,
}

impl Link {
    fn start(mut tx: PduTx<'static>, mut rx: PduRx<'static>, chain: Chain) -> Self {
        let chain = Arc::new(Mutex::new(chain));
        let stop = Arc::new(AtomicBool::new(false));
        let (c, s) = (chain.clone(), stop.clone());
        let thread = thread::spawn(move || {
            let waker = Waker::from(Arc::new(Unpark(thread::current())));
            let mut frames = 0u64;
            while !s.load(Ordering::Relaxed) {
                tx.replace_waker(&waker);
                let mut any = false;
                while let Some(frame) = tx.next_sendable_frame() {
                    let mut buf = Vec::new();
                    frame
                        .send_blocking(|bytes| {
                            buf.extend_from_slice(bytes);
                            Ok(bytes.len())
                        })
                        .unwrap();
                    c.lock().unwrap().process(&mut buf, now()).unwrap();
                    rx.receive_frame(&buf).unwrap();
                    frames += 1;
                    any = true;
                }
                if !any {
                    thread::park_timeout(Duration::from_millis(1));
                }
            }
            frames
        });
        Self { chain, stop, thread: Some(thread) }
    }

    /// Stops the thread: the frames it carried.
    fn stop(mut self) -> u64 {
        self.stop.store(true, Ordering::Relaxed);
        self.thread.take().map(|t| t.join().unwrap()).unwrap_or(0)
    }
}

fn load(path: &str) -> odc_model::Device {
    let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../..").join(path);
    let loaded = odc_pipeline::load(&path, &odc_pipeline::Options::new()).unwrap();
    loaded.device().unwrap().clone()
}

/// A master on its own PDU storage (each test has one: `try_split` works once per storage).
fn master(chain: Chain) -> (MainDevice<'static>, Link) {
    let storage: &'static PduStorage<MAX_FRAMES, MAX_PDU_DATA> =
        Box::leak(Box::new(PduStorage::new()));
    let (tx, rx, pdu_loop) = storage.try_split().unwrap();
    let link = Link::start(tx, rx, chain);
    let config = MainDeviceConfig { dc_static_sync_iterations: 100, ..Default::default() };
    (MainDevice::new(pdu_loop, Timeouts::default(), config), link)
}

#[test]
fn ethercrab_finds_the_servoone_and_reaches_pre_op() {
    let servoone = load("esi/servoone.xml");
    let chain = Chain::new(vec![SubDevice::new(&servoone).unwrap()]);
    let (maindevice, link) = master(chain);
    let group = smol::block_on(maindevice.init_single_group::<4, 64>(now)).unwrap();
    assert_eq!(group.len(), 1);
    let sd = group.iter(&maindevice).next().unwrap();
    let id = sd.identity();
    // esi/servoone.xml: Vendor/Id #x00000000, ProductCode #x00000000, RevisionNo #x00000000.
    assert_eq!((id.vendor_id, id.product_id, id.revision), (0, 0, 0));
    // ethercrab's name is the SII General category's order string (ETG.2010 Table 7,
    // OrderIdx: the ESI's `Type` text), its description the name string (`Name`, LcId 1033).
    assert_eq!(sd.name(), "ServoOne");
    let description = smol::block_on(sd.description()).unwrap().unwrap();
    assert_eq!(description.as_str(), "ServoOne EtherCAT (S0xx.xxx.xx3x.xxxx.x), CiA 402");
    assert_eq!(sd.configured_address(), 0x1000);
    let status = smol::block_on(sd.status()).unwrap();
    assert_eq!(format!("{:?}", status.0), "PreOp");
    // Distributed clocks: ethercrab wrote the offset that makes the device's system time
    // its own clock (`now`), then synchronised it with FRMW.
    let system_time: u64 = smol::block_on(sd.register_read(0x0910u16)).unwrap();
    let master_time = now();
    assert!(master_time.abs_diff(system_time) < 50_000_000, "{system_time} vs {master_time}");
    let (state, datagrams) = {
        let chain = link.chain.lock().unwrap();
        (chain.devices()[0].al_state(), chain.datagrams())
    };
    assert_eq!(state, 2, "the simulated device is in PRE-OP");
    let frames = link.stop();
    eprintln!("servoone to PRE-OP: {frames} frames, {datagrams} datagrams");
    assert!(frames > 10, "{frames} frames");
}
