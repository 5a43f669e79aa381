//! The async master on tokio: three drives of three different device files on one bus, a
//! 1 kHz SYNC with RPDO/TPDO exchange running while each drive is configured over SDO and
//! makes profile-position moves; at the end, the SYNC cycle's figures.
//!
//! `cargo run --release --example async_three_drives [-- SECONDS [HOST:PORT]]` (10 s by default).
//!
//! The drives are `odc simulate`'s devices (odc-sim's `SimDevice`, loaded from
//! `eds/lxm23a.eds` at node 1, `eds/lexium-mdrive.eds` at node 2, `eds/servoone.eds` at node 3),
//! each in a thread of its own on odc-sim's TCP `VirtualBus` in this process, ticking every
//! millisecond. With `HOST:PORT` the program connects to a bus that already has the three
//! drives on it instead and starts none: `odc simulate eds/lxm23a.eds@1
//! eds/lexium-mdrive.eds@2 eds/servoone.eds@3 --tcp HOST:PORT`, the drives in a process of their
//! own as real drives are on hardware of their own.
//!
//! The pattern for a steady cycle: the SYNC cycle and the master's bus task ([`Master::run`])
//! on a thread of their own, with a current-thread tokio runtime, the timerfd clock (absolute
//! deadlines on the period's grid: no drift, microsecond wakes) and a real-time priority
//! (SCHED_FIFO 40, where allowed); the program's work (SDO configuration, the moves) on
//! another runtime and thread (SCHED_FIFO 20), sharing the one `Master` by reference; the
//! process's memory locked and faulted in before the threads start (`mlockall`, current and
//! future) and the cycle's records sized for the whole run up front, so that the cycle thread
//! takes no page fault and maps no memory while it runs. Ordinary threads then no longer delay
//! the cycle: what is left is the machine's own wake-up latency (README). The master's futures
//! are plain `core::future`s: the library has no runtime or thread of its own, the program
//! chooses.
//!
//! Environment, for comparison: `ODC_ONE_THREAD=1` runs the cycle, the bus task and the
//! drives' work on one tokio thread (the layout of the first version); `ODC_NO_RT=1` leaves the
//! cycle thread at normal priority, `ODC_RT_PRIORITY=N` gives it another; `ODC_TOKIO_TIMER=1`
//! times the cycle with tokio's own timer (whole milliseconds, rounded up) instead of a
//! timerfd; `ODC_NO_MLOCK=1` leaves memory unlocked.
//!
//! Printed: the cycles, the missed ones (grid points without a SYNC, because one left more than
//! a period late), SYNC intervals (taken where each SYNC was handed to the socket), the cycles
//! whose TPDOs did not all come back before the next SYNC, the timer's wake-up latency and how
//! much of the late wakes the cycle thread spent waiting for a CPU, the five latest wakes (with
//! their `CLOCK_MONOTONIC` time), the steal time `/proc/stat` counted on each CPU during the
//! cycle, the cycle thread's page faults and context switches, and each thread's CPU time;
//! and, from every poll of the cycle thread's futures (`polls.rs`), where the late wakes'
//! lateness went: into the bus task's polls, the cycle's, or outside every poll (asleep in
//! the runtime or waiting for a CPU), with the poll running at each grid point, if one was.
//!
//! Telling the machine from the program: a late wake in which the thread neither ran nor
//! waited for a CPU was asleep while its timer was due. Steal time says when the hypervisor
//! admits to having run something else; on the VM this was measured on, it often does not
//! (README). `python3 examples/async_three_drives/vmpause.py -- COMMAND` (root) runs a program
//! under a kernel trace and says, for each late wake printed, whether the virtual CPUs were
//! paused meanwhile. `bash examples/async_three_drives/measure.sh` runs the layouts side by
//! side, each under it, with `cyclictest` for the machine alone (README).

mod polls;
mod trace;

use std::path::Path;
use std::sync::Arc;
use std::sync::OnceLock;
use std::sync::atomic::{AtomicBool, Ordering};
use std::thread;

use odc::asynch::axis::Axis;
use odc::asynch::tokio::{TokioClock, tcp};
use odc::asynch::{Clock, Master};
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

/// The real-time priority of the cycle thread (SCHED_FIFO, 1 to 99) unless `ODC_RT_PRIORITY`
/// gives one: above every normal thread and a `chrt -f 10` neighbour, below the kernel's
/// interrupt threads (50) and watchdogs.
const RT_PRIORITY: u8 = 40;

/// The real-time priority of the thread that runs the drives' work (SDO, the moves) unless
/// `ODC_WORK_RT_PRIORITY` gives one (0: none): below the cycle's, above normal threads. It
/// shares the master's lock with the cycle thread; at normal priority, a busy machine may
/// preempt it while it holds the lock, and the cycle then waits for it (priority inversion).
const WORK_RT_PRIORITY: u8 = 20;

/// The drive whose TPDO answers every SYNC.
const SYNC_TPDO_NODE: NodeId = DRIVES[2].1;

/// How the program runs.
#[derive(Clone, Debug)]
pub struct Options {
    /// Seconds of moves.
    pub seconds: u64,
    /// A bus that already has the three drives on it (`odc simulate … --tcp`), else one in
    /// this process.
    pub external: Option<String>,
    /// tokio's own timer instead of a timerfd.
    pub tokio_timer: bool,
    /// Everything on one tokio thread instead of the cycle on a thread of its own.
    pub one_thread: bool,
    /// The cycle thread's real-time priority (SCHED_FIFO), or none.
    pub realtime: Option<u8>,
    /// The work thread's, or none.
    pub work_realtime: Option<u8>,
    /// All of the process's memory locked in RAM and faulted in, now and as it grows
    /// (`mlockall`), so that no page fault stalls the cycle thread.
    pub lock_memory: bool,
}

impl Options {
    /// `seconds` on the in-process bus, in the recommended layout (cycle thread, timerfd,
    /// real-time priority where allowed).
    pub fn new(seconds: u64) -> Self {
        Self {
            seconds,
            external: None,
            tokio_timer: false,
            one_thread: false,
            realtime: Some(RT_PRIORITY),
            work_realtime: Some(WORK_RT_PRIORITY),
            lock_memory: true,
        }
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
    connected: std::sync::mpsc::Sender<NodeId>,
) -> std::io::Result<thread::JoinHandle<Result<(), Error>>> {
    thread::Builder::new().name(format!("sim-{node}")).spawn(move || {
        let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("..");
        let loaded = odc_pipeline::load(&root.join(file), &odc_pipeline::Options::new())?;
        let mut device = odc_sim::SimDevice::new(loaded.device()?, node);
        let mut bus = odc::transport::tcp::TcpCan::connect(addr)?;
        // The hub accepts connections in order: the master's comes after this one. (A
        // receiver that gave up waiting is no reason to stop.)
        let _ = connected.send(node);
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
/// cycle through `slot`, enable, profile position, and moves between 0 and `span` until `end` (one at least),
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
    // At least one move, however long the configuration took (a loaded machine, a debug
    // build), then moves until `end`.
    loop {
        axis.move_to(target).await?;
        report.moves += 1;
        let p = m.upload(node, 0x6064, 0).await?;
        report.sdo += 1;
        report.position =
            i32::from_le_bytes(p.as_slice().try_into().map_err(|_| "0x6064 is not 4 bytes")?);
        target = if target == 0 { span } else { 0 };
        if m.now() >= end {
            break;
        }
    }
    report.tpdo_position = axis.inputs().position;
    Ok(report)
}

/// `[SECONDS [HOST:PORT]]`, and the environment of the module docs.
pub fn main() -> Result<(), Error> {
    let mut args = std::env::args().skip(1);
    let mut o = Options::new(args.next().map(|s| s.parse()).transpose()?.unwrap_or(10));
    o.external = args.next();
    let set = |v: &str| std::env::var_os(v).is_some_and(|v| v != "0");
    o.tokio_timer = set("ODC_TOKIO_TIMER");
    o.one_thread = set("ODC_ONE_THREAD");
    let priority = |v: &str| -> Result<Option<Option<u8>>, Error> {
        let Some(p) = std::env::var_os(v) else { return Ok(None) };
        let p: u8 = p.to_str().ok_or("a priority is a number")?.parse()?;
        Ok(Some((p > 0).then_some(p)))
    };
    if let Some(p) = priority("ODC_RT_PRIORITY")? {
        o.realtime = p;
    }
    if let Some(p) = priority("ODC_WORK_RT_PRIORITY")? {
        o.work_realtime = p;
    }
    o.lock_memory = !set("ODC_NO_MLOCK");
    if set("ODC_NO_RT") {
        (o.realtime, o.work_realtime) = (None, None);
    }
    program(&o)?;
    Ok(())
}

/// The three axes, each set once its drive is configured; the cycle runs those that are.
type AxisOf<P> = Axis<<P as DrivePdos>::Command, <P as DrivePdos>::Status>;
#[derive(Default)]
struct Axes {
    a1: OnceLock<AxisOf<lxm23a::cia402::Pdos>>,
    a2: OnceLock<AxisOf<lexium_mdrive::cia402::Pdos>>,
    a3: OnceLock<AxisOf<servoone::cia402::Pdos>>,
}

/// The program: the bus and its drives (unless external), the master, the moves; what each
/// drive did.
///
/// # Errors
///
/// A device file that does not load, a bus that fails, an SDO or drive error.
pub fn program(o: &Options) -> Result<Vec<Report>, Error> {
    println!(
        "layout: {}; clock: {}; load average {} at the start",
        match (o.one_thread, o.realtime) {
            (true, _) => "cycle, bus task and drives on one tokio thread".to_owned(),
            (false, p) => format!(
                "cycle and bus task on a thread of their own ({}), the drives' work on another ({})",
                p.map_or("normal priority".into(), |p| format!("SCHED_FIFO {p}")),
                o.work_realtime.map_or("normal priority".into(), |p| format!("SCHED_FIFO {p}")),
            ),
        },
        if o.tokio_timer { "tokio's timer" } else { "timerfd" },
        trace::load_average().as_deref().unwrap_or("?"),
    );
    // Locked before the threads start, so that their stacks are faulted in as they are mapped.
    let locked = o.lock_memory.then(|| {
        use rustix::mm::{MlockAllFlags, mlockall};
        mlockall(MlockAllFlags::CURRENT | MlockAllFlags::FUTURE)
    });
    if let Some(Err(e)) = locked {
        println!("memory not locked ({e}): the cycle thread may take page faults");
    }
    let r = if o.tokio_timer {
        run(TokioClock::new(), o)
    } else {
        run(odc::asynch::tokio::TimerfdClock::new(), o)
    };
    if let Some(Ok(())) = locked {
        // The process goes on (a test, say): its memory need not stay locked.
        let _ = rustix::mm::munlockall();
    }
    r
}

/// A current-thread tokio runtime with its reactor and timer.
fn runtime() -> std::io::Result<tokio::runtime::Runtime> {
    tokio::runtime::Builder::new_current_thread().enable_all().build()
}

/// SCHED_FIFO at `priority` for the calling thread.
fn realtime(priority: u8) -> Result<(), String> {
    use thread_priority::{
        RealtimeThreadSchedulePolicy, ThreadPriority, ThreadSchedulePolicy,
        set_thread_priority_and_policy, thread_native_id,
    };
    let priority = ThreadPriority::Crossplatform(priority.try_into()?);
    let policy = ThreadSchedulePolicy::Realtime(RealtimeThreadSchedulePolicy::Fifo);
    set_thread_priority_and_policy(thread_native_id(), priority, policy)
        .map_err(|e| format!("{e:?}"))
}

/// The program on `clock`.
fn run<C: Clock + Copy + Send + Sync>(clock: C, o: &Options) -> Result<Vec<Report>, Error> {
    // The bus and its three drives, unless one was given.
    let stop = Arc::new(AtomicBool::new(false));
    let (addr, hub, devices) = match &o.external {
        Some(a) => (a.parse()?, None, Vec::new()),
        None => {
            let hub = odc_sim::VirtualBus::bind("127.0.0.1:0")?;
            let addr = hub.local_addr();
            let handle = hub.stop_handle();
            thread::Builder::new().name("hub".into()).spawn(move || hub.run_hub(&mut |_| {}))?;
            let (connected, on_bus) = std::sync::mpsc::channel();
            let devices = DRIVES
                .iter()
                .map(|(file, node)| simulate(addr, file, *node, stop.clone(), connected.clone()))
                .collect::<Result<Vec<_>, _>>()?;
            // The master connects once every device is on the bus: a frame sent before would
            // reach nobody, and its SDO request wait for an answer that never comes.
            drop(connected);
            for _ in DRIVES {
                if on_bus.recv_timeout(std::time::Duration::from_secs(60)).is_err() {
                    // A device that failed to load or connect: its thread's error.
                    stop.store(true, Ordering::Relaxed);
                    for d in devices {
                        d.join().map_err(|_| "a device thread panicked")??;
                    }
                    return Err("a simulated device did not connect within 60 s".into());
                }
            }
            (addr, Some(handle), devices)
        }
    };
    // Room for every cycle's record from the start (and some for the configuration's
    // seconds): a record that grew during the cycle would map new memory on the cycle thread.
    let cycles = usize::try_from((o.seconds + 30) * 1_000_000 / PERIOD.as_micros())?;
    let wire = trace::Wire::shared(cycles);
    let master = Master::new(clock).with_timeout(Duration::from_secs(1));
    let m = &master;
    let axes = Axes::default();
    let finished = AtomicBool::new(false);
    let start = m.now();
    let end = start + Duration::from_secs(o.seconds);
    let connect = async {
        let (tx, rx) = tcp::connect(addr).await?;
        let tx = trace::Tx { inner: tx, clock, wire: wire.clone() };
        let rx = trace::Rx { inner: rx, clock, wire: wire.clone(), returned: None };
        Ok::<_, Error>((tx, rx))
    };
    let bus_ended = |r: Result<(), std::io::Error>| -> Error {
        r.map_or_else(Error::from, |()| "the bus task ended".into())
    };

    let (cycled, drives, rt, threads) = if o.one_thread {
        runtime()?.block_on(async {
            let (tx, rx) = connect.await?;
            let work = async {
                let d = drives(m, &axes, end).await;
                let t = trace::threads();
                finished.store(true, Ordering::Relaxed);
                (d, t)
            };
            let threads = async {
                let (c, (d, t)) = tokio::join!(
                    polls::metered(polls::Branch::Cycle, cycle(m, &axes, &finished, cycles)),
                    polls::metered(polls::Branch::Work, work)
                );
                ((c, d), t)
            };
            polls::reserve();
            tokio::select! {
                ((c, d), t) = threads => Ok::<_, Error>((c, d, None, t)),
                r = polls::metered(polls::Branch::Bus, m.run(tx, rx)) => Err(bus_ended(r)),
            }
        })?
    } else {
        thread::scope(|s| {
            // The cycle thread: the SYNC cycle and the bus task.
            let cycler = thread::Builder::new().name("cycle".into()).spawn_scoped(s, || {
                let rt = o.realtime.map(realtime);
                polls::reserve();
                runtime()?.block_on(async {
                    let (tx, rx) = connect.await?;
                    // The cycle first when both are ready: a SYNC due goes to the queue before
                    // the bus task routes what came in meanwhile.
                    tokio::select! {
                        biased;
                        c = polls::metered(polls::Branch::Cycle, cycle(m, &axes, &finished, cycles)) => Ok::<_, Error>((c, rt)),
                        r = polls::metered(polls::Branch::Bus, m.run(tx, rx)) => Err(bus_ended(r)),
                    }
                })
            })?;
            // The work thread: the drives' configuration and moves.
            let worker = thread::Builder::new().name("work".into()).spawn_scoped(s, || {
                let rt = o.work_realtime.map(realtime);
                let d = runtime()?.block_on(drives(m, &axes, end));
                let threads = trace::threads();
                finished.store(true, Ordering::Relaxed);
                Ok::<_, Error>((d, threads, rt))
            });
            let worked = worker
                .map_err(Error::from)
                .and_then(|w| w.join().map_err(|_| Error::from("the work thread panicked"))?);
            // Whatever the work thread did, the cycle ends.
            finished.store(true, Ordering::Relaxed);
            let (c, rt) = cycler.join().map_err(|_| "the cycle thread panicked")??;
            let (d, threads, work_rt) = worked?;
            if let Some(Err(e)) = work_rt {
                println!("no real-time priority for the work thread ({e})");
            }
            Ok::<_, Error>((c, d, rt, threads))
        })?
    };
    let elapsed = m.now() - start;
    stop.store(true, Ordering::Relaxed);
    for d in devices {
        d.join().map_err(|_| "a device thread panicked")??;
    }
    if let Some(h) = hub {
        h.stop();
    }
    if let Some(Err(e)) = &rt {
        println!("no real-time priority for the cycle thread ({e}): it ran at normal priority");
    }
    let (ticks, skipped, counters, totals) = cycled?;

    println!(
        "three drives on one bus ({}), {elapsed} of a {PERIOD} SYNC cycle; load average {} at the end:",
        if o.external.is_some() { "external" } else { "odc-sim VirtualBus in process, TCP" },
        trace::load_average().as_deref().unwrap_or("?"),
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
    let wire = wire.lock().unwrap_or_else(std::sync::PoisonError::into_inner);
    // Only servoone's TPDO is synchronous (transmission type 1, as its file maps it); the
    // lxm23a's and the Lexium's files map theirs event-driven (255): they send on change.
    let f = trace::figures(&ticks, &wire, &[SYNC_TPDO_NODE.get()], PERIOD, skipped)
        .ok_or("no SYNC went out")?;
    println!("{f}");
    println!("{counters}");
    println!("{}", trace::PollTotals(&totals));
    println!("threads (CPU ms run / ms waiting for a CPU):");
    for (name, run, wait) in threads {
        println!("  {name}: {run} / {wait}");
    }
    Ok(reports)
}

/// The cycle: each configured axis's RPDO, then the SYNC, every period until `finished`; each
/// tick's record (room for `cycles`), the grid points it skipped, and the counters' growth.
async fn cycle<C: Clock>(
    m: &Master<C>,
    axes: &Axes,
    finished: &AtomicBool,
    cycles: usize,
) -> Result<(Vec<trace::Tick>, u64, trace::Counters, polls::Totals), Error> {
    let mut ticks = Vec::with_capacity(cycles);
    let mut cycle = m.cycle(PERIOD);
    let counters = trace::Counters::read();
    while !finished.load(Ordering::Relaxed) {
        let before = trace::schedstat();
        let due = cycle.tick().await;
        let woke = m.now();
        let mono_us = trace::monotonic_us();
        // Before the cycle's own work: what the thread ran since the grid point.
        let account = polls::account(polls::now_ns(), woke.saturating_duration_since(due));
        if let Some(a) = axes.a1.get() {
            a.cycle(m)?;
        }
        if let Some(a) = axes.a2.get() {
            a.cycle(m)?;
        }
        if let Some(a) = axes.a3.get() {
            a.cycle(m)?;
        }
        m.sync()?;
        // The bus task sends the RPDOs and the SYNC now; this cycle's records after them.
        tokio::task::yield_now().await;
        let after = trace::schedstat();
        let delta = |f: fn((u64, u64)) -> u64| Some(f(after?).saturating_sub(f(before?)));
        let (ran_ns, queued_ns) = (delta(|s| s.0), delta(|s| s.1));
        ticks.push(trace::Tick { due, woke, queued_ns, ran_ns, mono_us, account });
    }
    let counters = trace::Counters::read().since(&counters);
    Ok((ticks, cycle.missed(), counters, polls::totals()))
}

/// The three drives' lives, at once.
async fn drives<C: Clock>(
    m: &Master<C>,
    axes: &Axes,
    end: Instant,
) -> (Result<Report, Error>, Result<Report, Error>, Result<Report, Error>) {
    let [(_, n1), (_, n2), (_, n3)] = DRIVES;
    tokio::join!(
        drive::<_, lxm23a::cia402::Pdos>(
            m,
            n1,
            &axes.a1,
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
            &axes.a2,
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
            &axes.a3,
            async {
                m.execute(n3, &servoone::master::plan(n3)).await?;
                m.execute(n3, &servoone::cia402::plan(n3)).await?;
                m.write(n3, &servoone::od::PROFILE_VELOCITY, 100_000).await
            },
            10_000,
            end
        ),
    )
}
