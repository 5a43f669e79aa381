#!/usr/bin/env python3
"""Runs `odc conformance` against `odc simulate` for the CANopen device files of the corpus
(EDS, DCF, XDD, XDC) and prints counts: per file its pass/fail/n.a. line, per check how many
files passed, failed or found it not applicable, and the files that do not load.

    cargo build -p odc-cli
    python3 tests/conformance/sweep.py                 # every file (about 10 s each)
    python3 tests/conformance/sweep.py --sample 20     # 20 files spread over the sorted list

Each file: `odc simulate FILE --node-id 5 --tcp 127.0.0.1:0`, then `odc conformance FILE
--node-id 5 --tcp ADDR --report OUT/NAME.json`; the reports stay in --out. A file that
`odc simulate` refuses (exit 1 or 2: errors in the file, an EtherCAT file) counts as not
loaded. Bounded: each conformance run is killed after --limit seconds. Exit status 1 when a
run timed out or ended without a report (exit 2 of odc conformance): the tester's fault, not the
device's.
"""

import argparse
import collections
import json
import os
import subprocess
import sys
from concurrent.futures import ThreadPoolExecutor
from pathlib import Path

ROOT = Path(__file__).resolve().parents[2]
EXTS = {".eds", ".dcf", ".xdd", ".xdc"}


def one(odc, path, out, limit, tolerance):
    """(status, report or message) for one device file."""
    # The simulator's diagnostics and log go to a file: a pipe nobody reads fills up and
    # stops it before it listens.
    log = out / (path.name + ".simulate.log")
    with open(log, "w") as err_file:
        sim = subprocess.Popen(
            [odc, "simulate", str(path), "--node-id", "5", "--tcp", "127.0.0.1:0", "--stop-on-eof"],
            stdin=subprocess.PIPE,
            stdout=subprocess.PIPE,
            stderr=err_file,
            text=True,
        )
    try:
        first = sim.stdout.readline()
        if not first.startswith("listening on "):
            sim.wait(timeout=30)
            err = log.read_text(errors="replace").strip().splitlines()
            return "not loaded", (err[-1] if err else f"exit {sim.returncode}")
        addr = first.split()[-1]
        report = out / (path.name + ".json")
        try:
            run = subprocess.run(
                [odc, "conformance", str(path), "--node-id", "5", "--tcp", addr,
                 "--report", str(report), "--timing-tolerance", str(tolerance)],
                capture_output=True, text=True, timeout=limit,
            )
        except subprocess.TimeoutExpired:
            return "timeout", f"killed after {limit} s"
        if run.returncode not in (0, 1):
            return "error", run.stderr.strip()[-300:]
        return "run", json.loads(report.read_text())
    finally:
        if sim.poll() is None:
            try:
                sim.stdin.close()
                sim.wait(timeout=10)
            except (subprocess.TimeoutExpired, BrokenPipeError):
                sim.kill()
                sim.wait()


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--corpus", default=os.environ.get("ODC_CORPUS", str(ROOT.parent / "shared/corpus")))
    ap.add_argument("--odc", default=str(ROOT / "target/debug/odc"))
    ap.add_argument("--sample", type=int, default=0, help="this many files, spread evenly")
    ap.add_argument("--jobs", type=int, default=2)
    ap.add_argument("--limit", type=int, default=300, help="seconds per conformance run")
    ap.add_argument("--out", default=str(ROOT / "target/conformance-sweep"))
    # The simulator ticks every 10 ms; on a loaded shared machine its heartbeat is late by
    # more than the 20 ms odc conformance allows a real device by default.
    ap.add_argument("--timing-tolerance", type=int, default=40)
    args = ap.parse_args()
    files = sorted(p for p in Path(args.corpus).rglob("*") if p.suffix.lower() in EXTS)
    if args.sample and args.sample < len(files):
        step = len(files) / args.sample
        files = [files[int(i * step)] for i in range(args.sample)]
    out = Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    with ThreadPoolExecutor(args.jobs) as pool:
        results = list(pool.map(lambda p: (p, *one(args.odc, p, out, args.limit, args.timing_tolerance)), files))

    per_check = collections.defaultdict(collections.Counter)
    status = collections.Counter()
    for path, st, r in results:
        status[st] += 1
        name = path.relative_to(args.corpus)
        if st != "run":
            print(f"{st:<10} {name}: {r}")
            continue
        c = r["counts"]
        failed = [x["id"] for x in r["checks"] if x["result"] == "fail"]
        print(f"run        {name}: {c['pass']} pass, {c['fail']} fail, {c['not_applicable']} n/a"
              + (f"  FAIL {' '.join(failed)}" if failed else ""))
        for x in r["checks"]:
            per_check[x["id"]][x["result"]] += 1
    print()
    print(f"{'check':<30} {'pass':>5} {'fail':>5} {'n/a':>5}")
    for check, n in per_check.items():
        print(f"{check:<30} {n['pass']:>5} {n['fail']:>5} {n['not_applicable']:>5}")
    print()
    clean = sum(1 for _, st, r in results if st == "run" and r["counts"]["fail"] == 0)
    print(f"{len(files)} files: {status['run']} run ({clean} without a failure), "
          f"{status['not loaded']} not loaded, {status['timeout']} timed out, {status['error']} errors")
    # A failed check is the device's (or its file's) business; a run that did not end with a
    # report is the tester's.
    return 1 if status["timeout"] or status["error"] else 0


if __name__ == "__main__":
    sys.exit(main())
