#!/usr/bin/env bash
# The figures of README's "Several drives at once" table: async_three_drives in its layouts,
# RUNS runs of SECONDS each, and the machine's own wake-up latency (cyclictest, rt-tests) for
# comparison. Run as root (real-time priorities) from the repository root:
#   bash examples/async_three_drives/measure.sh [RUNS [SECONDS]]
# Prints, per run, the load average and the figure lines the example prints (with the steal
# time /proc/stat counted and the cycle thread's page faults, and the account of its late
# wakes from its own polls: how much of their lateness it spent in the bus task, in the
# cycle, or outside every poll, and its CPU clock meanwhile). As root, each program runs under
# vmpause.py (a kernel trace): it adds the stretches in which a busy virtual CPU ran nothing
# (the hypervisor's pauses) and which late wakes fell in one. ODC_NO_VMPAUSE=1: without it.
set -euo pipefail
runs=${1:-3}
seconds=${2:-10}
cargo build --release -p odc-examples --example async_three_drives
cargo build -p odc-cli
example=target/release/examples/async_three_drives
odc=target/debug/odc
port=47390

figures() {
  grep -E '^(Error|layout|  node|SYNC|missed|  SYNC intervals|  cycles whose|timer wake|wakes over|late wakes|cycle thread.s polls|no real-time|memory not|latest wakes|  [0-9]+\.[0-9]{6}: |steal time|vmpause|  cpu[0-9]|  on every|  steal time|  the program|    [0-9])' || true
}
# COMMAND under vmpause.py where the kernel trace is writable, else as it is; a run that fails
# (its error is among the lines printed) does not end the others.
traced() {
  if [ -z "${ODC_NO_VMPAUSE:-}" ] && [ -w /sys/kernel/tracing ]; then
    python3 examples/async_three_drives/vmpause.py -- "$@" 2>&1 || true
  else
    "$@" 2>&1 || true
  fi
}

for i in $(seq "$runs"); do
  echo "### run $i"
  echo "## one tokio thread for everything, drives in process"
  ODC_ONE_THREAD=1 traced "$example" "$seconds" | figures
  echo "## cycle thread (FIFO 40) + work thread (FIFO 20), drives in process"
  traced "$example" "$seconds" | figures
  echo "## cycle thread (FIFO 40) + work thread (FIFO 20), drives in odc simulate (FIFO 30)"
  chrt -f 30 "$odc" simulate eds/lxm23a.eds@1 eds/lexium-mdrive.eds@2 eds/servoone.eds@3 \
    --tcp "127.0.0.1:$port" </dev/null >/dev/null 2>&1 &
  sim=$!
  sleep 2
  traced "$example" "$seconds" "127.0.0.1:$port" | figures
  kill "$sim" 2>/dev/null || true  # SIGTERM ends odc simulate
  wait "$sim" 2>/dev/null || true
  port=$((port + 1))
  if command -v cyclictest >/dev/null; then
    echo "## the machine: cyclictest -p 40 -i 1000 -l $((seconds * 1000)) (one thread, nothing else)"
    echo "load average $(cut -d' ' -f1 /proc/loadavg)"
    traced bash -c "cyclictest -m -p 40 -i 1000 -l $((seconds * 1000)) -h 5000 -q |
      awk '/^# Max Latencies/ {print \"max wake latency\", \$4+0, \"µs\"}
           !/^#/ && \$1 >= 1000 {n += \$2} END {print \"wakes 1 ms or more late:\", n + 0}'" |
      grep -vE '^    [0-9]'
  fi
done
