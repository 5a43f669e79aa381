"""What the SOEM scripts beside it share: read the plan (JSON) on stdin, open SOEM (pysoem) on
the plan's interface, let the script's `run(master, plan, out)` fill the report, and print the
report as one JSON line, the last of stdout, with any exception in `errors`: the Rust test
decides on it."""

import json
import sys

import pysoem


def report(run, out):
    plan = json.load(sys.stdin)
    out.setdefault("errors", [])
    master = pysoem.Master()
    master.open(plan["iface"])
    try:
        run(master, plan, out)
    except Exception as e:  # the report says what failed; the Rust test fails on it
        out["errors"].append(f"{type(e).__name__}: {e}")
    finally:
        master.close()
    print(json.dumps(out))
