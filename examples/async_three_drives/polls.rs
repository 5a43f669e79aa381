//! What the cycle thread ran between a grid point and the cycle's wake: every poll of its
//! futures (the cycle, the master's bus task) timed on the wall clock and on the thread's CPU
//! clock, with the frames the bus task received and sent in it, so that a late wake can be put
//! on the program (a poll that was running at the grid point, or ran before the cycle) or on
//! the machine (the thread outside every poll: asleep in the runtime past its timer, or
//! waiting for a CPU).
//!
//! Counts (polls, frames) are what load does not distort; a poll's CPU time is what its thread
//! ran, but on a virtual machine that does not report steal time it also holds the time the
//! hypervisor ran something else while the thread was on the CPU: a poll whose CPU time is far
//! above its frames' share is that, not the program.

use std::cell::{Cell, RefCell};
use std::future::{Future, poll_fn};
use std::pin::pin;

/// The futures the cycle thread polls.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Branch {
    /// The SYNC cycle (its timer, the axes' RPDOs, the SYNC, its own records).
    Cycle,
    /// The master's bus task (`Master::run`: received frames dispatched, queued frames sent).
    Bus,
    /// The drives' work, where it shares the thread (`ODC_ONE_THREAD=1`).
    Work,
}

/// One poll.
#[derive(Clone, Copy, Debug)]
pub struct Poll {
    pub branch: Branch,
    /// `CLOCK_MONOTONIC`, ns.
    pub start: u64,
    pub end: u64,
    /// The thread's CPU clock at its start and its end, ns.
    pub cpu_start: u64,
    pub cpu_end: u64,
    /// Frames the bus task received and sent in it.
    pub frames_in: u32,
    pub frames_out: u32,
}

/// Polls kept: a late wake looks back over the polls since its grid point (a few per period).
const RING: usize = 4096;

thread_local! {
    static RECEIVED: Cell<u32> = const { Cell::new(0) };
    static SENT: Cell<u32> = const { Cell::new(0) };
    static LOG: RefCell<Log> = RefCell::new(Log::default());
    /// The poll in progress: its start on the monotonic and the thread's CPU clock.
    static CURRENT: Cell<(u64, u64)> = const { Cell::new((0, 0)) };
}

/// The polls of this thread, the latest [`RING`], and the longest bus poll of the run.
#[derive(Debug, Default)]
struct Log {
    ring: Vec<Poll>,
    next: usize,
    polls: u64,
    longest_bus: Option<Poll>,
    bus_slow: u64,
    /// Wall time in polls the thread spent off its CPU (blocked on a lock, or preempted), ns.
    off_cpu: u64,
    off_cpu_max: u64,
}

impl Poll {
    /// The thread's CPU time in it, ns.
    pub fn cpu(&self) -> u64 {
        self.cpu_end.saturating_sub(self.cpu_start)
    }
}

impl Log {
    fn push(&mut self, p: Poll) {
        self.polls += 1;
        let off = (p.end - p.start).saturating_sub(p.cpu());
        self.off_cpu += off;
        self.off_cpu_max = self.off_cpu_max.max(off);
        if p.branch == Branch::Bus {
            self.bus_slow += u64::from(p.end - p.start > 200_000);
            if self.longest_bus.is_none_or(|l| p.end - p.start > l.end - l.start) {
                self.longest_bus = Some(p);
            }
        }
        if self.ring.len() < RING {
            // Sized once, before the cycle starts ([`reserve`]): no allocation while it runs.
            self.ring.push(p);
        } else if let Some(slot) = self.ring.get_mut(self.next) {
            *slot = p;
        }
        self.next = (self.next + 1) % RING;
    }
}

/// Room for the ring on this thread, before the cycle starts.
pub fn reserve() {
    LOG.with_borrow_mut(|l| l.ring.reserve_exact(RING));
}

/// A frame received (the bus task's `recv` returned one).
pub fn received() {
    RECEIVED.set(RECEIVED.get().wrapping_add(1));
}

/// A frame sent.
pub fn sent() {
    SENT.set(SENT.get().wrapping_add(1));
}

fn ns(t: rustix::time::Timespec) -> u64 {
    u64::try_from(t.tv_sec).unwrap_or(0) * 1_000_000_000 + u64::try_from(t.tv_nsec).unwrap_or(0)
}

fn mono_ns() -> u64 {
    ns(rustix::time::clock_gettime(rustix::time::ClockId::Monotonic))
}

fn cpu_ns() -> u64 {
    ns(rustix::time::clock_gettime(rustix::time::ClockId::ThreadCPUTime))
}

/// `f`, each of its polls logged as `branch`.
pub async fn metered<F: Future>(branch: Branch, f: F) -> F::Output {
    let mut f = pin!(f);
    poll_fn(|cx| {
        let (start, cpu_start, rx, tx) = (mono_ns(), cpu_ns(), RECEIVED.get(), SENT.get());
        let outer = CURRENT.replace((start, cpu_start));
        let r = f.as_mut().poll(cx);
        CURRENT.set(outer);
        let p = Poll {
            branch,
            start,
            end: mono_ns(),
            cpu_start,
            cpu_end: cpu_ns(),
            frames_in: RECEIVED.get().wrapping_sub(rx),
            frames_out: SENT.get().wrapping_sub(tx),
        };
        LOG.with_borrow_mut(|l| l.push(p));
        r
    })
    .await
}

/// Where one wake's lateness went: from the grid point to the cycle's wake, µs.
#[derive(Clone, Copy, Debug, Default)]
pub struct Account {
    /// The poll running at the grid point, if one was: its branch, wall and CPU µs, frames.
    pub at_due: Option<(Branch, u64, u64, u32, u32)>,
    /// In the bus task's polls (after the grid point), wall and CPU µs, frames received and
    /// sent, polls.
    pub bus_us: u64,
    pub bus_cpu_us: u64,
    pub bus_in: u32,
    pub bus_out: u32,
    pub bus_polls: u32,
    /// In other polls (the cycle's own, the work's).
    pub other_us: u64,
    /// Outside every poll: the thread in its runtime (asleep in `epoll_wait`, or waiting for a
    /// CPU to run on).
    pub outside_us: u64,
    /// The stretch outside polls the grid point fell in (from the end of a poll, before the
    /// thread slept, to the next poll after it woke), wall and the thread's CPU clock, µs:
    /// the runtime's way to sleep and back, or time the thread was charged with while its
    /// code did not run; 0 when a poll ran at the grid point.
    pub gap_us: u64,
    pub gap_cpu_us: u64,
}

/// The account of a wake at `woke_ns` (`CLOCK_MONOTONIC`) for the grid point `lateness` before
/// it, from this thread's polls; call it from inside the cycle's poll, right after its timer
/// returned.
pub fn account(woke_ns: u64, lateness: odc::time::Duration) -> Account {
    let due = woke_ns.saturating_sub(lateness.as_micros() * 1000);
    let mut a = Account::default();
    // The poll in progress (the cycle's) ends the last gap.
    let (now_start, now_cpu) = CURRENT.get();
    let mut inside = 0;
    // The part of [from, to) after the grid point and before the wake.
    let clip = |from: u64, to: u64| to.min(woke_ns).saturating_sub(from.max(due));
    LOG.with_borrow(|l| {
        // The ring's polls, oldest first.
        let (newer, older) = l.ring.split_at(l.next.min(l.ring.len()));
        let mut previous: Option<&Poll> = None;
        let mut gap = |from: &Poll, to: u64, to_cpu: u64| {
            if from.end <= due && due < to {
                a.gap_us = (to - from.end) / 1000;
                a.gap_cpu_us = to_cpu.saturating_sub(from.cpu_end) / 1000;
            }
        };
        for p in older.iter().chain(newer) {
            if let Some(q) = previous {
                gap(q, p.start, p.cpu_start);
            }
            previous = Some(p);
            if p.end <= due || p.start >= woke_ns {
                continue;
            }
            let wall = clip(p.start, p.end);
            inside += wall;
            // The CPU time of a poll that began before the grid point, in proportion.
            let cpu = p.cpu() * wall / (p.end - p.start).max(1);
            if p.start <= due {
                let full = (p.end - p.start) / 1000;
                a.at_due = Some((p.branch, full, p.cpu() / 1000, p.frames_in, p.frames_out));
            }
            match p.branch {
                Branch::Bus => {
                    a.bus_us += wall / 1000;
                    a.bus_cpu_us += cpu / 1000;
                    a.bus_in += p.frames_in;
                    a.bus_out += p.frames_out;
                    a.bus_polls += 1;
                }
                _ => a.other_us += wall / 1000,
            }
        }
        if let Some(q) = previous {
            gap(q, now_start, now_cpu);
        }
    });
    a.outside_us = (woke_ns - due).saturating_sub(inside) / 1000;
    a
}

/// The run's totals: polls, the longest bus poll, bus polls over 200 µs, µs off the CPU inside
/// polls (all, and the most in one).
pub struct Totals {
    pub polls: u64,
    pub longest_bus: Option<Poll>,
    pub bus_slow: u64,
    pub off_cpu_us: u64,
    pub off_cpu_max_us: u64,
}

/// This thread's totals.
pub fn totals() -> Totals {
    LOG.with_borrow(|l| Totals {
        polls: l.polls,
        longest_bus: l.longest_bus,
        bus_slow: l.bus_slow,
        off_cpu_us: l.off_cpu / 1000,
        off_cpu_max_us: l.off_cpu_max / 1000,
    })
}

/// `CLOCK_MONOTONIC` now, ns (the clock of [`account`]).
pub fn now_ns() -> u64 {
    mono_ns()
}
