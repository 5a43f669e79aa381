//! The crate against the drive as `odc simulate eds/lxm23a.eds --node-id 1 --tcp` serves it:
//! odc-sim's device for the file on its TCP virtual bus, in a thread of this process; the
//! master on tokio over TCP, a 2 ms SYNC cycle.
#![allow(clippy::unwrap_used, clippy::expect_used, clippy::panic, missing_docs)]

use std::path::Path;
use std::sync::Arc;
use std::sync::atomic::{AtomicBool, Ordering};
use std::thread;

use odc::asynch::Master;
use odc::asynch::tokio::{TokioClock, tcp};
use odc::cob::NodeId;
use odc::time::Duration;
use odc_drive_lxm23a::{HomingMethod, Lxm23a, keypad, od};

const NODE: NodeId = odc::node_id!(1);

/// How long an SDO answer or a state the test waits for may take. The simulated drive answers
/// within a millisecond or two; on a machine loaded by parallel builds its threads may wait
/// for a CPU for hundreds of milliseconds, so the deadlines are generous: they only turn a
/// drive that never answers into a failure instead of a hang.
const PATIENCE: Duration = Duration::from_secs(10);

/// The whole test's bound: a hang fails it.
const WHOLE_TEST: std::time::Duration = std::time::Duration::from_secs(120);

/// `odc simulate`'s device for eds/lxm23a.eds at node 1 on a virtual bus; its address and the
/// flag that stops it. Returns once the device is on the bus: a frame the master sends before
/// is lost (nobody is there to hear it), and its SDO request would then wait for an answer
/// that never comes, as it did under load when the device's thread started late.
fn simulated_drive() -> (std::net::SocketAddr, Arc<AtomicBool>, thread::JoinHandle<()>) {
    let file = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../eds/lxm23a.eds");
    let loaded = odc_pipeline::load(&file, &odc_pipeline::Options::new()).unwrap();
    let mut device = odc_sim::SimDevice::new(loaded.device().unwrap(), NODE);
    let hub = odc_sim::VirtualBus::bind("127.0.0.1:0").unwrap();
    let addr = hub.local_addr();
    let handle = hub.stop_handle();
    thread::spawn(move || hub.run_hub(&mut |_| {}));
    let stop = Arc::new(AtomicBool::new(false));
    let stopped = stop.clone();
    let (connected, on_bus) = std::sync::mpsc::channel();
    let device = thread::spawn(move || {
        let mut bus = odc::transport::tcp::TcpCan::connect(addr).unwrap();
        // The hub accepts connections in order: the master's comes after this one.
        connected.send(()).unwrap();
        odc_sim::run_on_bus(&mut bus, &mut device, 1, || stopped.load(Ordering::Relaxed)).unwrap();
        handle.stop();
    });
    on_bus.recv_timeout(WHOLE_TEST).expect("the device did not connect");
    (addr, stop, device)
}

#[tokio::test]
async fn enables_homes_moves_and_streams() {
    let (addr, stop, device) = simulated_drive();
    let (tx, rx) = tcp::connect(addr).await.unwrap();
    let master = Master::new(TokioClock::new()).with_timeout(PATIENCE);
    let m = &master;
    let done = AtomicBool::new(false);
    let work = async {
        let drive = Lxm23a::connect(m, NODE).await.unwrap();
        let cycle = async {
            let mut cycle = m.cycle(Duration::from_millis(2));
            while !done.load(Ordering::Relaxed) {
                cycle.tick().await;
                drive.cycle(m).unwrap();
                m.sync().unwrap();
            }
        };
        let jobs = async {
            // A vendor (keypad) parameter by its manual name, written and read back.
            drive.set(m, &keypad::P1_44, 16).await.unwrap();
            assert_eq!(drive.get(m, &keypad::P1_44).await.unwrap(), 16);
            drive.set(m, &od::PROFILE_VELOCITY, 1_000_000).await.unwrap();
            drive.enable().await.unwrap();
            drive.home(m, HomingMethod::CURRENT_POSITION).await.unwrap();
            let home = drive.position().unwrap();
            drive.move_to(m, home + 20_000).await.unwrap();
            assert_eq!(drive.position(), Some(home + 20_000));
            assert_eq!(drive.get(m, &od::POSITION_ACTUAL_VALUE).await.unwrap(), home + 20_000);
            // 50 set-points, 100 apart; csp follows each within its cycle.
            let last = home + 20_000 + 50 * 100;
            drive.stream_positions(m, (1..=50).map(|i| home + 20_000 + i * 100)).await.unwrap();
            // The last set-point went out with the last cycle; the drive reports it within a
            // cycle or two, however late those cycles run.
            let reached = async {
                while drive.position() != Some(last) {
                    tokio::time::sleep(std::time::Duration::from_millis(2)).await;
                }
            };
            let within = std::time::Duration::from_micros(PATIENCE.as_micros());
            let waited = tokio::time::timeout(within, reached).await;
            assert!(
                waited.is_ok(),
                "position {:?}, not {last}, after {PATIENCE}",
                drive.position()
            );
            drive.disable().await.unwrap();
            done.store(true, Ordering::Relaxed);
        };
        tokio::join!(cycle, jobs);
    };
    let run = async {
        tokio::select! {
            r = m.run(tx, rx) => panic!("bus ended: {r:?}"),
            () = work => {}
        }
    };
    tokio::time::timeout(WHOLE_TEST, run).await.expect("the test hung");
    stop.store(true, Ordering::Relaxed);
    device.join().unwrap();
}
