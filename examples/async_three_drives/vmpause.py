#!/usr/bin/env python3
"""Runs a command under a kernel trace and tells the machine's stalls from the program's.

    python3 examples/async_three_drives/vmpause.py [--silence-ms MS] -- COMMAND [ARGS...]

Root (ftrace, /sys/kernel/tracing). While COMMAND runs, the kernel records every context switch,
every local timer interrupt and every idle entry and exit on each CPU (a tracefs instance of
its own, the `mono` clock, so its times are CLOCK_MONOTONIC). A CPU that is busy (not idle)
takes its scheduler tick every 1/HZ s (4 ms at HZ=250) and, with other tasks, context
switches: a busy CPU with no event at all for longer than that ran no kernel code with
interrupts on in the meantime. In a virtual machine that is the hypervisor not running the
virtual CPU (or, on one CPU only, the guest kernel with interrupts off for that long).

VMPAUSE_KEEP=FILE keeps the trace in FILE. Prints COMMAND's output, then: those silences per CPU (how many, the longest, how many on
every CPU at once), the steal time /proc/stat counted over the same run (what the hypervisor
admits to), and, for the late wakes COMMAND listed as async_three_drives prints them
("  SECONDS.MICROS: LATE = ..." under "latest wakes"), whether each fell in a silence, how late
its thread's timer interrupt came and which task the interrupt found, and how long the thread
then waited for the CPU and behind which task (a kernel built with preempt=none lets a task in
a system call keep the CPU from a real-time thread until the call ends or yields).
"""

import gzip
import os
import re
import subprocess
import sys

TRACING = "/sys/kernel/tracing"
EVENTS = ["sched/sched_switch", "irq_vectors/local_timer_entry", "power/cpu_idle",
          "timer/hrtimer_start", "timer/hrtimer_expire_entry"]
# The thread whose timer wakes are followed (async_three_drives' cycle thread).
THREAD = "cycle"
LINE = re.compile(r"^\s*(.+?)-(\d+)\s+\[(\d+)\]\s+\S+\s+([\d.]+):\s+(\w+):\s*(.*)$")
WAKE = re.compile(r"^\s+(\d+)\.(\d{6}): (\d+) = ")


def write(path, text):
    with open(path, "w") as f:
        f.write(text)


def hz():
    """CONFIG_HZ from /proc/config.gz, else 250 (the common distribution choice)."""
    try:
        with gzip.open("/proc/config.gz", "rt") as f:
            for line in f:
                if line.startswith("CONFIG_HZ="):
                    return int(line.split("=")[1])
    except OSError:
        pass
    return 250


def steal_ms():
    """Steal time per CPU, ms (/proc/stat's eighth number, in USER_HZ ticks)."""
    tick = os.sysconf("SC_CLK_TCK")
    out = {}
    with open("/proc/stat") as f:
        for line in f:
            m = re.match(r"^cpu(\d+)\s+((?:\d+\s+){7}\d+)", line)
            if m:
                out[int(m.group(1))] = int(m.group(2).split()[7]) * 1000 // tick
    return out


def silences(lines, limit_us):
    """(cpu, start, end) of each busy stretch with no event longer than limit_us, and the
    traced span (first, last event)."""
    last, idle, found = {}, {}, []
    first = end = None
    for line in lines:
        m = LINE.match(line)
        if not m:
            continue
        cpu, t, name, rest = int(m.group(3)), float(m.group(4)), m.group(5), m.group(6)
        first = t if first is None else first
        end = t
        if cpu in last and not idle.get(cpu) and (t - last[cpu]) * 1e6 > limit_us:
            found.append((cpu, last[cpu], t))
        last[cpu] = t
        if name == "cpu_idle":
            # state=4294967295 (-1) is the exit from idle.
            idle[cpu] = not rest.startswith("state=4294967295")
    return found, (first, end)


def timer_wakes(lines):
    """The followed thread's timerfd wakes: (due, irq, cpu, running at the irq, on CPU, held
    the CPU meanwhile, asleep since), CLOCK_MONOTONIC s: when the timer was due, when its
    interrupt came, which task the interrupt found, when the thread ran after it and who ran
    before, and since when the thread had been asleep at the interrupt (its last switch away,
    in state S) or None when the trace had it on a CPU or runnable."""
    armed, pending, out = {}, {}, []
    # The followed thread's last switch away (time, state) and last switch to it.
    last_out, last_in = None, None
    # Task names by pid, from the switches (the trace writes "<...>" for a name it did not keep).
    names = {}
    for line in lines:
        for comm, pid in re.findall(r"(?:prev|next)_comm=(.*?) (?:prev|next)_pid=(\d+)", line):
            names[pid] = comm
    for line in lines:
        m = LINE.match(line)
        if not m:
            continue
        cpu, t, name, rest = int(m.group(3)), float(m.group(4)), m.group(5), m.group(6)
        if name == "hrtimer_start" and "function=timerfd_tmrproc" in rest:
            f = dict(kv.split("=", 1) for kv in rest.split() if "=" in kv)
            armed[f["hrtimer"]] = int(f["expires"]) / 1e9
        elif name == "hrtimer_expire_entry":
            f = dict(kv.split("=", 1) for kv in rest.split() if "=" in kv)
            due = armed.pop(f.get("hrtimer"), None)
            if due is not None:
                task = f"{names.get(m.group(2), m.group(1))}, pid {m.group(2)}"
                asleep = (last_out[0] if last_out and last_out[1] == "S"
                          and (last_in is None or last_in < last_out[0]) else None)
                pending[cpu] = [due, t, cpu, task, asleep]
        if name == "sched_switch":
            prev = re.search(r"prev_comm=(.*?) prev_pid=\d+ prev_prio=\d+ prev_state=(\S+)", rest)
            nxt = re.search(r"next_comm=(.*?) next_pid", rest)
            if prev and prev.group(1) == THREAD:
                last_out = (t, prev.group(2))
            if nxt and nxt.group(1) == THREAD:
                last_in = t
        if name == "sched_switch" and cpu in pending:
            nxt = re.search(r"next_comm=(.*?) next_pid", rest)
            if nxt and nxt.group(1) == THREAD:
                prev = re.search(r"prev_comm=(.*?) prev_pid", rest)
                p = pending.pop(cpu)
                out.append((*p[:4], t, prev.group(1) if prev else "?", p[4]))
            elif re.search(r"prev_comm=(.*?) prev_pid", rest).group(1) == THREAD:
                # The thread leaves the CPU and no switch to it was recorded (the trace keeps
                # none for some tasks): it ran by then at the latest.
                p = pending.pop(cpu)
                out.append((*p[:4], t, "at the latest; the switch to it not traced", p[4]))
    return out


def first_run(lines, cpu, irq):
    """After the interrupt at `irq` on `cpu`: the first event the followed thread itself
    recorded (it runs by then: its next timer armed, a switch away) and how many events its
    CPU recorded in between, other than the interrupt's own."""
    between = 0
    for line in lines:
        m = LINE.match(line)
        if not m or float(m.group(4)) <= irq:
            continue
        t = float(m.group(4))
        if m.group(1).strip() == THREAD:
            return t, between
        if int(m.group(3)) == cpu and m.group(5) not in ("local_timer_entry",
                                                         "hrtimer_expire_entry"):
            between += 1
    return None, between


def main():
    args = sys.argv[1:]
    tick_ms = 1000 / hz()
    limit_ms = tick_ms + 1
    if args[:1] == ["--silence-ms"]:
        limit_ms = float(args[1])
        args = args[2:]
    if args[:1] == ["--"]:
        args = args[1:]
    if not args:
        sys.exit(__doc__)
    inst = f"{TRACING}/instances/vmpause-{os.getpid()}"
    try:
        os.mkdir(inst)
    except OSError as e:
        sys.exit(f"vmpause: no kernel trace ({e}): run as root on a kernel with tracefs")
    try:
        write(f"{inst}/trace_clock", "mono")
        write(f"{inst}/buffer_size_kb", "65536")
        # Only the followed thread's timers are armed in the trace.
        write(f"{inst}/events/timer/hrtimer_start/filter", f'comm == "{THREAD}"')
        for e in EVENTS:
            if os.path.exists(f"{inst}/events/{e}"):
                write(f"{inst}/events/{e}/enable", "1")
        write(f"{inst}/tracing_on", "1")
        before = steal_ms()
        out = []
        with subprocess.Popen(args, stdout=subprocess.PIPE, text=True) as p:
            for line in p.stdout:
                sys.stdout.write(line)
                out.append(line)
        rc = p.returncode
        after = steal_ms()
        write(f"{inst}/tracing_on", "0")
        with open(f"{inst}/trace") as f:
            lines = f.readlines()
        if os.environ.get("VMPAUSE_KEEP"):
            with open(os.environ["VMPAUSE_KEEP"], "w") as f:
                f.writelines(lines)
        overrun = 0
        for cpu in sorted(os.listdir(f"{inst}/per_cpu")):
            with open(f"{inst}/per_cpu/{cpu}/stats") as f:
                overrun += sum(int(l.split()[1]) for l in f if l.startswith("overrun:"))
    finally:
        for e in EVENTS:
            if os.path.exists(f"{inst}/events/{e}"):
                write(f"{inst}/events/{e}/enable", "0")
        os.rmdir(inst)

    found, (first, end) = silences(lines, limit_ms * 1000)
    span = (end - first) if first is not None else 0
    cpus = sorted(after)
    both = [s for s in found if s[0] == cpus[0] and any(
        o[0] != s[0] and o[1] < s[2] and s[1] < o[2] for o in found)]
    print(f"vmpause: {span:.1f} s traced ({len(lines)} events, {overrun} lost); busy CPUs with "
          f"no event for over {limit_ms:g} ms (tick {tick_ms:g} ms): {len(found)}")
    for cpu in cpus:
        mine = [(e - s) * 1000 for c, s, e in found if c == cpu]
        print(f"  cpu{cpu}: {len(mine)}, {sum(mine):.1f} ms in all, longest "
              f"{max(mine, default=0):.1f} ms")
    print(f"  on every CPU at once: {len(both) if len(cpus) == 2 else '?'}")
    print("  steal time over the same run (/proc/stat): " + ", ".join(
        f"cpu{c} {after[c] - before.get(c, 0)} ms" for c in cpus))
    wakes = [m for m in map(WAKE.match, out) if m]
    timers = timer_wakes(lines)
    if wakes:
        print(f"  the program's latest wakes (due .. woke, CLOCK_MONOTONIC s), its timer "
              f"interrupt (after due, the task it found) and the thread on a CPU (after the "
              f"interrupt, the task that had the CPU until then):")
    for m in wakes:
        woke = int(m.group(1)) + int(m.group(2)) / 1e6
        due = woke - int(m.group(3)) / 1e6
        hit = [(c, s, e) for c, s, e in found if s < woke and due < e]
        where = "; ".join(f"cpu{c} silent {s:.6f} .. {e:.6f} ({(e - s) * 1000:.1f} ms)"
                          for c, s, e in hit) or "no CPU silent"
        timer = min(timers, key=lambda w: abs(w[0] - due), default=None)
        if timer and abs(timer[0] - due) < 100e-6:
            d, irq, cpu, found_task, ran, held, asleep = timer
            slept = ("asleep since " + f"{(d - asleep) * 1e6:.0f} µs before due"
                     if asleep is not None else "not asleep")
            where += (f"; {slept}; interrupt +{(irq - d) * 1e6:.0f} µs on cpu{cpu} "
                      f"({found_task}), on CPU +{(ran - irq) * 1e6:.0f} µs ({held})")
            own, between = first_run(lines, cpu, irq)
            if own is not None:
                where += (f"; its first own event +{(own - irq) * 1e6:.0f} µs after the "
                          f"interrupt, {between} events on cpu{cpu} in between")
        print(f"    {due:.6f} .. {woke:.6f}: {where}")
    sys.exit(rc)


if __name__ == "__main__":
    main()
