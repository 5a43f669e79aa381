#!/usr/bin/env python3
"""Import time in Python: odc.canopen.import_od against canopen.import_od, one run.

    python import_od_python.py [--passes N] DIR|LIST...

Over the corpus files python-canopen reads (EDS and DCF; a file either importer refuses is
left out of both sums, and counted), each pass imports every file with each importer in turn
(python-canopen, odc.canopen, odc.load alone), in the same process; the figure per importer is
the CPU time of its fastest pass (process time, not wall time: the shared machine's other work
then costs less of the figure; odc's parser runs on the calling thread, so its CPU time is
all of it). Prints the sums and the
ratios of the same run. Needs the odc wheel built in release (`maturin build --release`): a
debug build measures the debug build.
"""

import argparse
import logging
import os
import sys
import time
import warnings

import canopen

import odc
import odc.canopen


def files_of(paths):
    out = []
    for p in paths:
        if os.path.isdir(p):
            out += [os.path.join(p, n) for n in sorted(os.listdir(p))
                    if n.lower().endswith((".eds", ".dcf"))]
        elif p.endswith(".list") or p.endswith(".txt"):
            out += [line.strip() for line in open(p) if line.strip()]
        else:
            out.append(p)
    return out


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("paths", nargs="+")
    ap.add_argument("--passes", type=int, default=5)
    args = ap.parse_args()
    logging.disable(logging.CRITICAL)
    warnings.simplefilter("ignore")
    files, refused = [], 0
    for path in files_of(args.paths):
        try:
            canopen.import_od(path)
            odc.canopen.import_od(path)
        except Exception:  # noqa: BLE001 - a file one of them does not read is left out
            refused += 1
            continue
        files.append(path)
    size = sum(os.path.getsize(p) for p in files)
    importers = {
        "python-canopen (canopen.import_od)": canopen.import_od,
        "odc (odc.canopen.import_od)": odc.canopen.import_od,
        "odc model only (odc.load)": lambda p: odc.load(p, warn=["cia301", "cia402", "etg",
                                                                 "F107", "F108", "F115"]),
    }
    best = {name: float("inf") for name in importers}
    for _ in range(args.passes):
        for name, fn in importers.items():
            t = time.process_time()
            for path in files:
                fn(path)
            best[name] = min(best[name], time.process_time() - t)
    print(f"files: {len(files)} read by both ({size} bytes); {refused} left out; "
          f"CPU time, fastest of {args.passes} passes; Python {sys.version.split()[0]}, "
          f"canopen {canopen.__version__}, odc {odc.__version__}")
    base = best["python-canopen (canopen.import_od)"]
    for name, t in best.items():
        print(f"{name:<36} {t * 1000:10.1f} ms   {base / t:7.2f}x")


if __name__ == "__main__":
    main()
