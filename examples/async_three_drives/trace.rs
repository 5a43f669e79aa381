//! Per-cycle records of the SYNC cycle, and the figures drawn from them: when each cycle's
//! timer woke against its grid point, how long its thread waited for a CPU meanwhile, when its
//! SYNC went to the socket, and whether every drive's TPDO came back before the next SYNC.

use std::sync::{Arc, Mutex, PoisonError};

use odc::asynch::{CanRx, CanTx, Clock};
use odc::can::CanFrame;
use odc::time::{Duration, Instant};

use super::polls::{self, Account, Branch};

/// One cycle as its thread saw it.
#[derive(Clone, Copy, Debug)]
pub struct Tick {
    /// The grid point.
    pub due: Instant,
    /// When the timer's wait returned.
    pub woke: Instant,
    /// During the wait (from before it began until the SYNC was queued), nanoseconds this
    /// thread spent runnable but not running (other threads had the CPUs) and running (its
    /// runtime's other tasks, its own code), from `/proc/thread-self/schedstat`. The rest of
    /// a late wake it was blocked: asleep past its timer, or on a lock.
    pub queued_ns: Option<u64>,
    pub ran_ns: Option<u64>,
    /// `woke` on `CLOCK_MONOTONIC`, µs: the clock of a kernel trace taken with ftrace's
    /// `mono` clock (`vmpause.py`), so that a late wake can be found in it.
    pub mono_us: u64,
    /// Where the time from the grid point to the wake went: the thread's polls meanwhile.
    pub account: Account,
}

/// `CLOCK_MONOTONIC` now, µs.
pub fn monotonic_us() -> u64 {
    let t = rustix::time::clock_gettime(rustix::time::ClockId::Monotonic);
    let (s, ns) = (u64::try_from(t.tv_sec).unwrap_or(0), u64::try_from(t.tv_nsec).unwrap_or(0));
    s * 1_000_000 + ns / 1000
}

/// Steal time per CPU in `/proc/stat`'s text (`cpuN` lines, the eighth number), in its clock
/// ticks: the time the hypervisor says it ran something else while a virtual CPU wanted to run.
pub fn parse_steal(stat: &str) -> Vec<(u32, u64)> {
    stat.lines()
        .filter_map(|l| {
            let mut f = l.split_whitespace();
            let cpu = f.next()?.strip_prefix("cpu")?.parse().ok()?;
            Some((cpu, f.nth(7)?.parse().ok()?))
        })
        .collect()
}

/// A thread's minor and major page faults in its `/proc/…/stat` text (fields 10 and 12, counted
/// after the parenthesised name, which may hold spaces).
pub fn parse_faults(stat: &str) -> Option<(u64, u64)> {
    let mut f = stat.get(stat.rfind(')')? + 1..)?.split_whitespace();
    let minor = f.nth(7)?.parse().ok()?;
    let major = f.nth(1)?.parse().ok()?;
    Some((minor, major))
}

/// A thread's voluntary and involuntary context switches in its `/proc/…/status` text.
pub fn parse_switches(status: &str) -> Option<(u64, u64)> {
    let field =
        |name: &str| status.lines().find_map(|l| l.strip_prefix(name)?.trim().parse::<u64>().ok());
    Some((field("voluntary_ctxt_switches:")?, field("nonvoluntary_ctxt_switches:")?))
}

/// Counters read before and after the cycle, to tell the machine's delays from the program's:
/// steal time per CPU, and the cycle thread's page faults (a fault that reads a page from disk
/// blocks the thread) and context switches (a blocking call adds voluntary ones).
#[derive(Clone, Debug, Default)]
pub struct Counters {
    /// Steal time per CPU, ms.
    pub steal_ms: Vec<(u32, u64)>,
    /// Minor and major page faults of the calling thread.
    pub faults: Option<(u64, u64)>,
    /// Voluntary and involuntary context switches of the calling thread.
    pub switches: Option<(u64, u64)>,
}

impl Counters {
    /// The counters now, for the calling thread.
    pub fn read() -> Self {
        let read = |p: &str| std::fs::read_to_string(p).ok();
        let hz = rustix::param::clock_ticks_per_second().max(1);
        let steal = read("/proc/stat").map(|s| parse_steal(&s)).unwrap_or_default();
        Self {
            steal_ms: steal.into_iter().map(|(c, t)| (c, t * 1000 / hz)).collect(),
            faults: read("/proc/thread-self/stat").as_deref().and_then(parse_faults),
            switches: read("/proc/thread-self/status").as_deref().and_then(parse_switches),
        }
    }

    /// What the counters grew by since `before`.
    pub fn since(&self, before: &Self) -> Self {
        let pair = |a: Option<(u64, u64)>, b: Option<(u64, u64)>| {
            let ((a0, a1), (b0, b1)) = (a?, b?);
            Some((a0.saturating_sub(b0), a1.saturating_sub(b1)))
        };
        let steal_ms = self
            .steal_ms
            .iter()
            .filter_map(|(c, t)| {
                let (_, t0) = before.steal_ms.iter().find(|(c0, _)| c0 == c)?;
                Some((*c, t.saturating_sub(*t0)))
            })
            .collect();
        Self {
            steal_ms,
            faults: pair(self.faults, before.faults),
            switches: pair(self.switches, before.switches),
        }
    }
}

impl std::fmt::Display for Counters {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        let steal: Vec<String> =
            self.steal_ms.iter().map(|(c, ms)| format!("cpu{c} {ms} ms")).collect();
        let or_q = |v: Option<(u64, u64)>, i: usize| {
            v.map_or("?".to_owned(), |v| if i == 0 { v.0 } else { v.1 }.to_string())
        };
        write!(
            f,
            "steal time during the cycle (/proc/stat, 10 ms steps): {}; the cycle thread: {} minor / {} major page faults, {} voluntary / {} involuntary context switches",
            if steal.is_empty() { "?".to_owned() } else { steal.join(", ") },
            or_q(self.faults, 0),
            or_q(self.faults, 1),
            or_q(self.switches, 0),
            or_q(self.switches, 1),
        )
    }
}

/// This thread's scheduler statistics (`/proc/thread-self/schedstat`): nanoseconds run and
/// nanoseconds waited on a run queue; `None` where the kernel does not tell.
pub fn schedstat() -> Option<(u64, u64)> {
    let s = std::fs::read_to_string("/proc/thread-self/schedstat").ok()?;
    let mut f = s.split_whitespace().map(str::parse::<u64>);
    Some((f.next()?.ok()?, f.next()?.ok()?))
}

/// The frames the master sent and received, timed on its clock.
#[derive(Debug, Default)]
pub struct Wire {
    /// When each SYNC was handed to the socket (its `send` returned).
    pub syncs: Vec<Instant>,
    /// When each TPDO was received, and from which node.
    pub tpdos: Vec<(Instant, u8)>,
    /// From each received frame handed to the master until it asked for the next: its
    /// dispatch under the master's lock, µs (the longest and how many took over 200 µs).
    pub dispatch_max: u64,
    pub dispatch_slow: u64,
}

/// The shared [`Wire`] record.
pub type Shared = Arc<Mutex<Wire>>;

impl Wire {
    /// An empty record with room for `cycles` SYNCs and three TPDOs each.
    pub fn shared(cycles: usize) -> Shared {
        Arc::new(Mutex::new(Self {
            syncs: Vec::with_capacity(cycles),
            tpdos: Vec::with_capacity(cycles * 3),
            ..Self::default()
        }))
    }
}

fn lock(w: &Shared) -> std::sync::MutexGuard<'_, Wire> {
    w.lock().unwrap_or_else(PoisonError::into_inner)
}

/// The master's transmit half, noting when each SYNC went out.
pub struct Tx<T, C> {
    pub inner: T,
    pub clock: C,
    pub wire: Shared,
}

impl<T: CanTx, C: Clock> CanTx for Tx<T, C> {
    type Error = T::Error;

    async fn send(&mut self, frame: &CanFrame) -> Result<(), T::Error> {
        self.inner.send(frame).await?;
        polls::sent();
        if frame.id() == 0x080 && !frame.is_extended() {
            lock(&self.wire).syncs.push(self.clock.now());
        }
        Ok(())
    }
}

/// The master's receive half, noting when each TPDO came in and how long the master took
/// to dispatch each frame.
pub struct Rx<R, C> {
    pub inner: R,
    pub clock: C,
    pub wire: Shared,
    pub returned: Option<Instant>,
}

impl<R: CanRx, C: Clock> CanRx for Rx<R, C> {
    type Error = R::Error;

    async fn recv(&mut self) -> Result<CanFrame, R::Error> {
        if let Some(t) = self.returned.take() {
            let us = self.clock.now().saturating_duration_since(t).as_micros();
            let mut w = lock(&self.wire);
            w.dispatch_max = w.dispatch_max.max(us);
            w.dispatch_slow += u64::from(us > 200);
        }
        let f = self.inner.recv().await?;
        polls::received();
        self.returned = Some(self.clock.now());
        // TPDO1..4 of nodes 1..=127 (CiA 301's pre-defined connection set).
        if !f.is_extended() && matches!(f.id() & 0x780, 0x180 | 0x280 | 0x380 | 0x480) {
            lock(&self.wire).tpdos.push((self.clock.now(), (f.id() & 0x7F) as u8));
        }
        Ok(f)
    }
}

/// The load average over the last minute (`/proc/loadavg`).
pub fn load_average() -> Option<String> {
    let s = std::fs::read_to_string("/proc/loadavg").ok()?;
    s.split_whitespace().next().map(str::to_owned)
}

/// min, mean, p99 (nearest rank) and max of `v`, sorted in place.
pub fn stats(v: &mut [u64]) -> Option<(u64, f64, u64, u64)> {
    v.sort_unstable();
    let (min, max) = (*v.first()?, *v.last()?);
    let mean = v.iter().sum::<u64>() as f64 / v.len() as f64;
    // Nearest rank: the smallest value with at least 99 % of the values at or below it.
    let p99 = v[(v.len() * 99).div_ceil(100).saturating_sub(1)];
    Some((min, mean, p99, max))
}

/// The figures of one run.
#[derive(Debug)]
pub struct Figures {
    pub cycles: usize,
    pub syncs: usize,
    /// SYNC intervals: min, mean, p99, max, µs.
    pub interval: (u64, f64, u64, u64),
    /// Grid points without a SYNC: a SYNC left more than a period after its grid point, so
    /// the next one skipped (the cycle's own count).
    pub skipped: u64,
    /// SYNC intervals of 1.5 periods or more: what a SYNC consumer's timeout flags (CANopenNode
    /// raises its SYNC timeout EMCY at 1.5 periods).
    pub long_intervals: usize,
    /// Cycles (from the first in which every drive answered until the last SYNC) whose TPDOs
    /// did not all arrive before the next SYNC, and how many such cycles were counted.
    pub tpdo_late: usize,
    pub tpdo_cycles: usize,
    /// Of those, per node: the cycles in which that node's TPDO was not in.
    pub tpdo_late_by_node: Vec<(u8, usize)>,
    /// The longest dispatch of a received frame (µs) and how many took over 200 µs.
    pub dispatch: (u64, u64),
    /// Timer wake after the grid point: p50, p99, max, µs.
    pub wake: (u64, u64, u64),
    /// SYNC on the socket after the wake: p50, p99, max, µs.
    pub send: (u64, u64, u64),
    /// Wakes more than half a period late, their lateness (µs, summed), and during their waits
    /// the time the thread waited for a CPU and the time it ran.
    pub late_wakes: usize,
    pub late_us: u64,
    pub late_queued_us: u64,
    pub late_ran_us: u64,
    /// The late wakes' accounts summed: in the bus task's polls (wall, CPU, frames received
    /// and sent, polls), in other polls, outside every poll; and how many of those wakes found
    /// a bus poll running at the grid point.
    pub late_account: Account,
    pub late_bus_at_due: usize,
    /// Per wake, µs the thread's CPU clock ran in the stretch outside its polls that the grid
    /// point fell in (its runtime's way to sleep and back, or time it was charged with): p50,
    /// p99 and max, over the wakes on time and over the late ones.
    pub gap_cpu_on_time: (u64, u64, u64),
    pub gap_cpu_late: (u64, u64, u64),
    /// The latest wakes over half a period late, latest first (five at most).
    pub worst: Vec<Tick>,
}

fn percentiles(mut v: Vec<u64>) -> (u64, u64, u64) {
    v.sort_unstable();
    let at = |q: usize| v.get((v.len() * q).div_ceil(100).saturating_sub(1)).copied().unwrap_or(0);
    (at(50), at(99), v.last().copied().unwrap_or(0))
}

/// The figures of `ticks` and `wire` for `nodes` at `period`, with the cycle's own count of
/// skipped grid points.
pub fn figures(
    ticks: &[Tick],
    wire: &Wire,
    nodes: &[u8],
    period: Duration,
    skipped: u64,
) -> Option<Figures> {
    let p = period.as_micros();
    let s = &wire.syncs;
    let mut intervals: Vec<u64> = s.windows(2).map(|w| (w[1] - w[0]).as_micros()).collect();
    let long_intervals = intervals.iter().filter(|i| **i * 2 >= p * 3).count();
    let interval = stats(&mut intervals)?;

    // TPDOs: for SYNC k, did each node's TPDO arrive in (s[k], s[k+1]]? Counted from the
    // first SYNC every node answered.
    let answered = |k: usize, node: u8| {
        let (from, to) = (s[k], s[k + 1]);
        wire.tpdos.iter().any(|(t, n)| *n == node && *t > from && *t <= to)
    };
    let all = |k: usize| nodes.iter().all(|n| answered(k, *n));
    let first = (0..s.len().saturating_sub(1)).find(|k| all(*k));
    let (mut tpdo_late, mut tpdo_cycles) = (0, 0);
    let mut tpdo_late_by_node: Vec<(u8, usize)> = nodes.iter().map(|n| (*n, 0)).collect();
    if let Some(first) = first {
        for k in first..s.len() - 1 {
            tpdo_cycles += 1;
            if !all(k) {
                tpdo_late += 1;
                for (n, late) in &mut tpdo_late_by_node {
                    *late += usize::from(!answered(k, *n));
                }
            }
        }
    }

    let wake: Vec<u64> = ticks.iter().map(|t| (t.woke - t.due).as_micros()).collect();
    // Ticks and SYNCs pair in order: every tick queues one SYNC.
    let send: Vec<u64> = ticks
        .iter()
        .zip(s)
        .map(|(t, sent)| sent.saturating_duration_since(t.woke).as_micros())
        .collect();
    let late: Vec<&Tick> = ticks.iter().filter(|t| (t.woke - t.due).as_micros() * 2 > p).collect();
    Some(Figures {
        cycles: ticks.len(),
        syncs: s.len(),
        interval,
        skipped,
        long_intervals,
        tpdo_late,
        tpdo_cycles,
        tpdo_late_by_node,
        dispatch: (wire.dispatch_max, wire.dispatch_slow),
        wake: percentiles(wake),
        send: percentiles(send),
        late_wakes: late.len(),
        late_us: late.iter().map(|t| (t.woke - t.due).as_micros()).sum(),
        late_queued_us: late.iter().filter_map(|t| t.queued_ns).sum::<u64>() / 1000,
        late_ran_us: late.iter().filter_map(|t| t.ran_ns).sum::<u64>() / 1000,
        late_account: late.iter().fold(Account::default(), |s, t| {
            let a = t.account;
            Account {
                at_due: None,
                bus_us: s.bus_us + a.bus_us,
                bus_cpu_us: s.bus_cpu_us + a.bus_cpu_us,
                bus_in: s.bus_in + a.bus_in,
                bus_out: s.bus_out + a.bus_out,
                bus_polls: s.bus_polls + a.bus_polls,
                other_us: s.other_us + a.other_us,
                outside_us: s.outside_us + a.outside_us,
                gap_us: s.gap_us + a.gap_us,
                gap_cpu_us: s.gap_cpu_us + a.gap_cpu_us,
            }
        }),
        gap_cpu_on_time: percentiles(
            ticks
                .iter()
                .filter(|t| (t.woke - t.due).as_micros() * 2 <= p)
                .map(|t| t.account.gap_cpu_us)
                .collect(),
        ),
        gap_cpu_late: percentiles(late.iter().map(|t| t.account.gap_cpu_us).collect()),
        late_bus_at_due: late
            .iter()
            .filter(|t| matches!(t.account.at_due, Some((Branch::Bus, ..))))
            .count(),
        worst: {
            let mut w: Vec<Tick> = late.iter().map(|t| **t).collect();
            w.sort_by_key(|t| std::cmp::Reverse(t.woke - t.due));
            w.truncate(5);
            w
        },
    })
}

impl std::fmt::Display for Figures {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        let (min, mean, p99, max) = self.interval;
        writeln!(
            f,
            "SYNC: {} cycles, {} sent; interval min {min} / mean {mean:.1} / p99 {p99} / max {max} µs",
            self.cycles, self.syncs
        )?;
        writeln!(
            f,
            "missed cycles: {} (grid points without a SYNC: one left more than a period late)",
            self.skipped
        )?;
        writeln!(
            f,
            "  SYNC intervals of 1.5 periods or more (a consumer's SYNC timeout): {}",
            self.long_intervals
        )?;
        let nodes: Vec<String> =
            self.tpdo_late_by_node.iter().map(|(n, _)| n.to_string()).collect();
        writeln!(
            f,
            "  cycles whose synchronous TPDOs (node {}) did not arrive before the next SYNC: {} of {}",
            nodes.join(", "),
            self.tpdo_late,
            self.tpdo_cycles
        )?;
        writeln!(
            f,
            "received frames dispatched (the master's lock): longest {} µs, {} over 200 µs",
            self.dispatch.0, self.dispatch.1
        )?;
        let (w50, w99, wmax) = self.wake;
        let (s50, s99, smax) = self.send;
        writeln!(f, "timer wake after the grid point: p50 {w50} / p99 {w99} / max {wmax} µs")?;
        writeln!(f, "SYNC on the socket after the wake: p50 {s50} / p99 {s99} / max {smax} µs")?;
        write!(
            f,
            "wakes over half a period late: {}, {} µs late in all; meanwhile the cycle thread waited {} µs for a CPU and ran {} µs",
            self.late_wakes, self.late_us, self.late_queued_us, self.late_ran_us
        )?;
        let a = &self.late_account;
        write!(
            f,
            "\nlate wakes from the grid point to the wake (the cycle thread's polls): {} µs in the bus task ({} polls, {} µs CPU, {} frames received, {} sent; {} wakes found it polled at the grid point), {} µs in the cycle's and other polls, {} µs outside every poll (in the runtime: asleep past the timer, or waiting for a CPU)",
            a.bus_us,
            a.bus_polls,
            a.bus_cpu_us,
            a.bus_in,
            a.bus_out,
            self.late_bus_at_due,
            a.other_us,
            a.outside_us,
        )?;
        let ((o50, o99, omax), (l50, l99, lmax)) = (self.gap_cpu_on_time, self.gap_cpu_late);
        write!(
            f,
            "; the thread's CPU clock in the stretch outside polls the grid point fell in, per wake: on time p50 {o50} / p99 {o99} / max {omax} µs, late p50 {l50} / p99 {l99} / max {lmax} µs"
        )?;
        if !self.worst.is_empty() {
            write!(
                f,
                "\nlatest wakes (CLOCK_MONOTONIC s: µs late = waited for a CPU + ran + neither, that is asleep while its timer was due; of the lateness, in bus polls / in other polls / outside polls µs, the CPU clock in the stretch outside polls the grid point fell in; the poll running at the grid point):"
            )?;
        }
        for t in &self.worst {
            let late = (t.woke - t.due).as_micros();
            let (q, r) = (t.queued_ns.unwrap_or(0) / 1000, t.ran_ns.unwrap_or(0) / 1000);
            let a = &t.account;
            write!(
                f,
                "\n  {}.{:06}: {late} = {q} + {r} + {}; {} / {} / {}, CPU {} of {} µs",
                t.mono_us / 1_000_000,
                t.mono_us % 1_000_000,
                late.saturating_sub(q + r),
                a.bus_us,
                a.other_us,
                a.outside_us,
                a.gap_cpu_us,
                a.gap_us,
            )?;
            if let Some((b, wall, cpu, fin, fout)) = a.at_due {
                write!(f, "; {b:?} poll of {wall} µs ({cpu} µs CPU, {fin} frames in, {fout} out)")?;
            }
        }
        Ok(())
    }
}

/// The cycle thread's polls over the run, as one line.
pub struct PollTotals<'a>(pub &'a polls::Totals);

impl std::fmt::Display for PollTotals<'_> {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        let t = self.0;
        write!(
            f,
            "cycle thread's polls: {}; bus task polls over 200 µs: {}; longest bus poll: ",
            t.polls, t.bus_slow
        )?;
        match t.longest_bus {
            Some(p) => write!(
                f,
                "{} µs ({} µs CPU, {} frames in, {} out)",
                (p.end - p.start) / 1000,
                p.cpu() / 1000,
                p.frames_in,
                p.frames_out
            )?,
            None => f.write_str("none")?,
        }
        write!(
            f,
            "; off the CPU inside polls (blocked on a lock, or preempted): {} µs in all, {} µs at most in one",
            t.off_cpu_us, t.off_cpu_max_us
        )
    }
}

/// Each thread of this process: name, ms run, ms waited for a CPU (`/proc/self/task`).
pub fn threads() -> Vec<(String, u64, u64)> {
    let mut out = Vec::new();
    let Ok(dir) = std::fs::read_dir("/proc/self/task") else { return out };
    for e in dir.flatten() {
        let path = e.path();
        let name = std::fs::read_to_string(path.join("comm")).unwrap_or_default();
        let stat = std::fs::read_to_string(path.join("schedstat")).unwrap_or_default();
        let mut f = stat.split_whitespace().map(|v| v.parse::<u64>().unwrap_or(0));
        let (run, wait) = (f.next().unwrap_or(0), f.next().unwrap_or(0));
        out.push((name.trim().to_owned(), run / 1_000_000, wait / 1_000_000));
    }
    out.sort();
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn steal_is_the_eighth_number_of_each_cpu_line() {
        // This machine's /proc/stat (the total line "cpu " has no number after "cpu").
        let stat = "cpu  4473794 690389 1189761 2250844 69914 0 55727 6662 0 0\n\
                    cpu0 2213025 313193 567086 1220892 25142 0 24547 3284 0 0\n\
                    cpu1 2260769 377195 622674 1029952 44771 0 31179 3378 0 0\n\
                    intr 1 2 3\n";
        assert_eq!(parse_steal(stat), vec![(0, 3284), (1, 3378)]);
    }

    #[test]
    fn faults_are_counted_after_the_name_even_with_spaces_and_parentheses() {
        let stat = "825 (a (b) c) R 822 822 12579 0 -1 4194304 102 7 3 9 0 0 0 0 20 0";
        assert_eq!(parse_faults(stat), Some((102, 3)));
        assert_eq!(parse_faults("825 (cat"), None);
    }

    #[test]
    fn switches_come_from_both_status_lines() {
        let status =
            "Name:\tcycle\nvoluntary_ctxt_switches:\t10051\nnonvoluntary_ctxt_switches:\t2\n";
        assert_eq!(parse_switches(status), Some((10051, 2)));
        assert_eq!(parse_switches("voluntary_ctxt_switches:\t1\n"), None);
    }

    #[test]
    fn counters_since_subtract_per_cpu() {
        let before = Counters {
            steal_ms: vec![(0, 100), (1, 50)],
            faults: Some((10, 1)),
            switches: Some((5, 0)),
        };
        let after = Counters {
            steal_ms: vec![(0, 130), (1, 50)],
            faults: Some((12, 1)),
            switches: Some((9005, 3)),
        };
        let d = after.since(&before);
        assert_eq!(d.steal_ms, vec![(0, 30), (1, 0)]);
        assert_eq!((d.faults, d.switches), (Some((2, 0)), Some((9000, 3))));
    }
}
