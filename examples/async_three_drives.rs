//! The async master on tokio: three drives of three different device files on one bus, a
//! 1 kHz SYNC with RPDO/TPDO exchange running while each drive is configured over SDO and
//! makes profile-position moves; at the end, the SYNC period's statistics.
//!
//! `cargo run --example async_three_drives [-- SECONDS [HOST:PORT]]` (10 s by default).
//!
//! The drives are `odc simulate`'s devices (odc-sim's `SimDevice`, loaded from
//! `eds/lxm23a.eds` at node 1, `eds/lexium-mdrive.eds` at node 2, `eds/servoone.eds` at node 3),
//! each in a thread of its own on odc-sim's TCP `VirtualBus` in this process (the bus of
//! `odc simulate --tcp`), ticking every millisecond. With `HOST:PORT` the program connects to
//! a bus that already has the three drives on it instead (`odc simulate` with several
//! devices) and starts none.
//!
//! The master side is the code generated from the same files (plans, PDO structs, the CiA 402
//! process data); the master itself runs on one tokio thread. The SYNC times are taken where
//! the master hands each SYNC to the TCP socket.

use std::path::Path;
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::{Arc, Mutex, OnceLock};
use std::thread;

use odc::asynch::axis::Axis;
use odc::asynch::tokio::{TokioClock, tcp};
use odc::asynch::{CanTx, Clock, Master};
use odc::can::CanFrame;
use odc::cia402::{DrivePdos, Driver, ModeOfOperation, SupportedModes};
use odc::cob::NodeId;
use odc::nmt::NmtCommand;
use odc::time::{Duration, Instant};

mod lxm23a {
    odc::include_od!("lxm23a");
}
mod lexium_mdrive {
    odc::include_od!("lexium_mdrive");
}
mod servoone {
    odc::include_od!("servoone");
}

type Error = Box<dyn std::error::Error + Send + Sync>;

/// The SYNC period.
const PERIOD: Duration = Duration::from_millis(1);

/// The drives: file, node-ID.
const DRIVES: [(&str, NodeId); 3] = [
    ("eds/lxm23a.eds", odc::node_id!(1)),
    ("eds/lexium-mdrive.eds", odc::node_id!(2)),
    ("eds/servoone.eds", odc::node_id!(3)),
];

/// The master's transmit half, noting when each SYNC goes out.
struct Recording<T, C> {
    inner: T,
    clock: C,
    syncs: Arc<Mutex<Vec<Instant>>>,
}

impl<T: CanTx, C: Clock> CanTx for Recording<T, C> {
    type Error = T::Error;

    async fn send(&mut self, frame: &CanFrame) -> Result<(), T::Error> {
        if frame.id() == 0x080 && !frame.is_extended() {
            self.syncs
                .lock()
                .unwrap_or_else(std::sync::PoisonError::into_inner)
                .push(self.clock.now());
        }
        self.inner.send(frame).await
    }
}

/// What one drive did.
#[derive(Debug, Default)]
pub struct Report {
    /// Profile-position moves made.
    pub moves: u32,
    /// SDO reads of 0x6064 between the moves.
    pub sdo: u32,
    /// 0x6064 read over SDO after the last move.
    pub position: i32,
    /// The position the last TPDO carried.
    pub tpdo_position: Option<i32>,
}

/// Runs the simulated drive of `file` at `node` on the bus at `addr` until `stop`.
fn simulate(
    addr: std::net::SocketAddr,
    file: &'static str,
    node: NodeId,
    stop: Arc<AtomicBool>,
) -> thread::JoinHandle<Result<(), Error>> {
    thread::spawn(move || {
        let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("..");
        let loaded = odc_pipeline::load(&root.join(file), &odc_pipeline::Options::new())?;
        let mut device = odc_sim::SimDevice::new(loaded.device()?, node);
        let mut bus = odc::transport::tcp::TcpCan::connect(addr)?;
        odc_sim::run_on_bus(&mut bus, &mut device, 1, || stop.load(Ordering::Relaxed))?;
        Ok(())
    })
}

/// 0x6502 of `node`.
async fn supported_modes<C: Clock>(m: &Master<C>, node: NodeId) -> Result<SupportedModes, Error> {
    let v = m.upload(node, 0x6502, 0).await?;
    let bytes: [u8; 4] = v.as_slice().try_into().map_err(|_| "0x6502 is not 4 bytes")?;
    Ok(SupportedModes(u32::from_le_bytes(bytes)))
}

/// One drive's life: its configuration (`configure`, then NMT start), its axis handed to the
/// cycle through `slot`, enable, profile position, and moves between 0 and `span` until `end`,
/// each checked by an SDO read of 0x6064 against the TPDO's position.
async fn drive<C: Clock, P: DrivePdos>(
    m: &Master<C>,
    node: NodeId,
    slot: &OnceLock<Axis<P::Command, P::Status>>,
    configure: impl std::future::Future<Output = Result<(), odc::asynch::Error>>,
    span: i32,
    end: Instant,
) -> Result<Report, Error> {
    let mut report = Report::default();
    configure.await?;
    let supported = supported_modes(m, node).await?;
    m.nmt(NmtCommand::Start, node)?;
    let axis = Axis::with_pdos::<C, P>(m, node, Driver::new(supported)).await?;
    // From now on the cycle runs it.
    let axis = slot.get_or_init(|| axis);
    axis.enable().await?;
    axis.set_mode(m, ModeOfOperation::ProfilePosition).await?;
    let mut target = span;
    while m.now() < end {
        axis.move_to(target).await?;
        report.moves += 1;
        let p = m.upload(node, 0x6064, 0).await?;
        report.sdo += 1;
        report.position =
            i32::from_le_bytes(p.as_slice().try_into().map_err(|_| "0x6064 is not 4 bytes")?);
        target = if target == 0 { span } else { 0 };
    }
    report.tpdo_position = axis.inputs().position;
    Ok(report)
}

/// min, mean, max and 99th percentile of `v` (sorted in place).
fn stats(v: &mut [u64]) -> Option<(u64, f64, u64, u64)> {
    v.sort_unstable();
    let (min, max) = (*v.first()?, *v.last()?);
    let mean = v.iter().sum::<u64>() as f64 / v.len() as f64;
    // Nearest rank: the smallest value with at least 99 % of the intervals at or below it.
    let p99 = v[(v.len() * 99).div_ceil(100).saturating_sub(1)];
    Some((min, mean, max, p99))
}

/// `[SECONDS [HOST:PORT]]`; `ODC_TOKIO_TIMER=1` runs the cycle on tokio's own timer (whole
/// milliseconds, rounded up) instead of a timerfd, for comparison.
pub fn main() -> Result<(), Error> {
    let mut args = std::env::args().skip(1);
    let seconds: u64 = args.next().map(|s| s.parse()).transpose()?.unwrap_or(10);
    let external = args.next();
    program(seconds, external, std::env::var_os("ODC_TOKIO_TIMER").is_some())?;
    Ok(())
}

/// The program for `seconds` of moves, on the in-process bus or the one at `external`; what
/// each drive did.
///
/// # Errors
///
/// A device file that does not load, a bus that fails, an SDO or drive error.
#[tokio::main(flavor = "current_thread")]
pub async fn program(
    seconds: u64,
    external: Option<String>,
    tokio_timer: bool,
) -> Result<Vec<Report>, Error> {
    if tokio_timer {
        println!("clock: tokio's timer (ODC_TOKIO_TIMER)");
        return run(TokioClock::new(), seconds, external).await;
    }
    println!("clock: timerfd (TimerfdClock)");
    run(odc::asynch::tokio::TimerfdClock::new(), seconds, external).await
}

/// The program on `clock`.
async fn run<C: Clock + Copy>(
    clock: C,
    seconds: u64,
    external: Option<String>,
) -> Result<Vec<Report>, Error> {
    // The bus and its three drives, unless one was given.
    let stop = Arc::new(AtomicBool::new(false));
    let (addr, hub, devices) = match &external {
        Some(a) => (a.parse()?, None, Vec::new()),
        None => {
            let hub = odc_sim::VirtualBus::bind("127.0.0.1:0")?;
            let addr = hub.local_addr();
            let handle = hub.stop_handle();
            thread::spawn(move || hub.run_hub(&mut |_| {}));
            let devices: Vec<_> = DRIVES
                .iter()
                .map(|(file, node)| simulate(addr, file, *node, stop.clone()))
                .collect();
            (addr, Some(handle), devices)
        }
    };
    // Let the devices connect and boot before the master listens.
    tokio::time::sleep(std::time::Duration::from_millis(200)).await;

    let (tx, rx) = tcp::connect(addr).await?;
    let syncs = Arc::new(Mutex::new(Vec::new()));
    let tx = Recording { inner: tx, clock, syncs: syncs.clone() };
    let master = Master::new(clock).with_timeout(Duration::from_secs(1));
    let m = &master;

    let [(_, n1), (_, n2), (_, n3)] = DRIVES;
    type AxisOf<P> = Axis<<P as DrivePdos>::Command, <P as DrivePdos>::Status>;
    let a1: OnceLock<AxisOf<lxm23a::cia402::Pdos>> = OnceLock::new();
    let a2: OnceLock<AxisOf<lexium_mdrive::cia402::Pdos>> = OnceLock::new();
    let a3: OnceLock<AxisOf<servoone::cia402::Pdos>> = OnceLock::new();
    let finished = AtomicBool::new(false);
    let start = m.now();
    let end = start + Duration::from_secs(seconds);

    // The cycle: each configured axis's RPDO, then the SYNC, every millisecond.
    let cycle = async {
        let mut cycle = m.cycle(PERIOD);
        while !finished.load(Ordering::Relaxed) {
            cycle.tick().await;
            if let Some(a) = a1.get() {
                a.cycle(m)?;
            }
            if let Some(a) = a2.get() {
                a.cycle(m)?;
            }
            if let Some(a) = a3.get() {
                a.cycle(m)?;
            }
            m.sync()?;
        }
        Ok::<_, Error>((cycle.ticks(), cycle.missed()))
    };
    let drives = async {
        let r = tokio::join!(
            drive::<_, lxm23a::cia402::Pdos>(
                m,
                n1,
                &a1,
                async {
                    m.execute(n1, &lxm23a::master::rpdo2(n1)).await?;
                    m.execute(n1, &lxm23a::master::tpdo2(n1)).await?;
                    m.write(n1, &lxm23a::od::PROFILE_VELOCITY, 1_000_000).await
                },
                100_000,
                end
            ),
            drive::<_, lexium_mdrive::cia402::Pdos>(
                m,
                n2,
                &a2,
                async {
                    m.execute(n2, &lexium_mdrive::master::plan(n2)).await?;
                    m.write(n2, &lexium_mdrive::od::PROFILE_VELOCITY, 512_000).await
                },
                51_200,
                end
            ),
            drive::<_, servoone::cia402::Pdos>(
                m,
                n3,
                &a3,
                async {
                    m.execute(n3, &servoone::master::plan(n3)).await?;
                    m.execute(n3, &servoone::cia402::plan(n3)).await?;
                    m.write(n3, &servoone::od::PROFILE_VELOCITY, 100_000).await
                },
                10_000,
                end
            ),
        );
        finished.store(true, Ordering::Relaxed);
        r
    };
    let ran = tokio::select! {
        r = async { tokio::join!(cycle, drives) } => Ok(r),
        r = m.run(tx, rx) => Err(r.map_or_else(Error::from, |()| "the bus task ended".into())),
    };
    let elapsed = m.now() - start;
    stop.store(true, Ordering::Relaxed);
    let (cycle, drives) = ran?;
    let (ticks, missed) = cycle?;
    for d in devices {
        d.join().map_err(|_| "a device thread panicked")??;
    }
    if let Some(h) = hub {
        h.stop();
    }

    println!(
        "three drives on one bus ({}), {elapsed} of a {PERIOD} SYNC cycle:",
        if external.is_some() { "external" } else { "odc-sim VirtualBus in process, TCP" }
    );
    let mut reports = Vec::new();
    for ((file, node), r) in DRIVES.iter().zip([drives.0, drives.1, drives.2]) {
        let r = r?;
        println!(
            "  node {node} {file}: {} profile-position moves, {} SDO reads between them; last position {} (SDO), {:?} (TPDO)",
            r.moves, r.sdo, r.position, r.tpdo_position
        );
        reports.push(r);
    }
    let syncs = syncs.lock().unwrap_or_else(std::sync::PoisonError::into_inner);
    let mut intervals: Vec<u64> = syncs.windows(2).map(|w| (w[1] - w[0]).as_micros()).collect();
    let late = intervals.iter().filter(|i| **i * 2 >= PERIOD.as_micros() * 3).count();
    let (min, mean, max, p99) = stats(&mut intervals).ok_or("no SYNC went out")?;
    println!(
        "SYNC: {} sent, {ticks} cycles; interval min {min} µs, mean {mean:.1} µs, max {max} µs, p99 {p99} µs",
        syncs.len()
    );
    println!(
        "missed cycles: {missed} (grid points the cycle woke too late for); intervals of 1.5 periods or more: {late}"
    );
    Ok(reports)
}
