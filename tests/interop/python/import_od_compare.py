#!/usr/bin/env python3
"""odc.canopen.import_od against canopen.import_od, object by object, over corpus files.

For every EDS/DCF file (python-canopen 2.4.1 reads no XDD: `canopen.import_od` refuses the
suffix), both importers build a python-canopen ObjectDictionary with the same node-ID; every
variable python-canopen made (objects, and the members of records and arrays it made) is
compared with odc's on name, data type, access type, default, limits, the `$NODEID` flag and PDO
mapping. Every difference is put in a class (tests/interop/README.md, "python-canopen
import_od", says why each is python-canopen's or odc's reading); a difference no class explains
is `unexplained` and makes the exit status 1.

Usage: import_od_compare.py [--sample N] [--node-id ID] [--show CLASS] [--list] FILE|DIR...
Prints the counts: files read by both, by one, variables compared and equal, differences per
class.
"""

import argparse
import collections
import contextlib
import io
import logging
import math
import os
import sys

import canopen
from canopen.objectdictionary import ODArray, ODRecord, ODVariable

import odc
import odc.canopen

FIELDS = ("name", "data_type", "access_type", "default", "min", "max", "relative",
          "pdo_mappable")


def files_of(paths):
    out = []
    for p in paths:
        if os.path.isdir(p):
            for n in sorted(os.listdir(p)):
                if n.lower().endswith((".eds", ".dcf")):
                    out.append(os.path.join(p, n))
        else:
            out.append(p)
    return out


def variables(entry):
    """The variables python-canopen made for an object: itself, or its members."""
    if isinstance(entry, ODVariable):
        return {0: entry}
    return {s: entry.subindices[s] for s in entry.subindices}


def same(a, b):
    if isinstance(a, float) or isinstance(b, float):
        if a is None or b is None:
            return False
        try:
            return a == b or (math.isnan(a) and math.isnan(b))
        except TypeError:
            return False
    return a == b and type(a) is not str or a == b


SIGNED_BITS = {0x02: 8, 0x03: 16, 0x04: 32, 0x10: 24, 0x12: 40, 0x13: 48, 0x14: 56, 0x15: 64}
ODD_SIGNED = (0x10, 0x12, 0x13, 0x14)
REALS = (0x08, 0x11)
BYTES = (0x0A, 0x0F)


def classify(field, pvar, ovar, pentry):
    """The class of a difference: a name from tests/interop/README.md."""
    a, b = getattr(pvar, field, None), getattr(ovar, field, None)
    raw = getattr(ovar, "default_raw", None)
    dt = ovar.data_type
    if isinstance(pentry, ODArray) and pvar.subindex == 0 and pvar.name == "Number of entries":
        return "compact-sub0"
    if (field == "name" and isinstance(pentry, ODArray) and pvar.subindex == 1
            and a == pentry.name and b == f"{pentry.name}1"):
        return "compact-member-names"
    if pvar.data_type == 0x0F and dt > 0x1B:
        return "profile-type-as-domain"
    if field == "access_type" and a not in ("ro", "wo", "rw", "rwr", "rww", "const"):
        return "access-spelling"
    if field in ("min", "max") and a is None and b is not None:
        if dt in ODD_SIGNED:
            return "limits-of-odd-signed-types"
        if dt in REALS:
            return "real-limits"
    if field == "default" and a is None and b is not None and raw is not None:
        text = raw.strip().upper()
        if text == "$NODEID":
            return "nodeid-alone"
        if dt in BYTES and len(text.replace(" ", "")) % 2 == 1:
            return "odd-hex-digits"
        if dt in REALS and text.startswith("0X"):
            return "real-hex-pattern"
        if len(text) > 1 and text.startswith("0") and text.isdigit():
            return "octal"
        if text.rstrip("FUL") != text:
            return "c-suffix"
    if field == "relative" and b and raw is not None and "$NODEID" not in raw:
        return "nodeid-case"
    if field == "pdo_mappable" and b and not a:
        return "key-case"
    if field in ("min", "max") and a is None and isinstance(b, str):
        return "string-limits"
    if field == "default" and dt == 0x01 and isinstance(a, int) and b is None:
        return "boolean-not-0-or-1"
    if field in ("default", "min", "max") and isinstance(a, int) and b is None:
        return "does-not-fit-type"
    if field in ("default", "min", "max") and isinstance(a, int) and isinstance(b, int):
        bits = SIGNED_BITS.get(dt)
        if bits and a - b == (1 << bits):
            return "signed-hex-default"
    return "unexplained"


def compare_file(path, node_id, show, stats, shown):
    pod = None
    with contextlib.redirect_stderr(io.StringIO()):
        try:
            pod = canopen.import_od(path, node_id)
        except Exception as e:  # noqa: BLE001 - python-canopen raises anything on a bad file
            stats["files python-canopen fails"] += 1
            stats[f"python-canopen fails: {type(e).__name__}"] += 1
    try:
        ood = odc.canopen.import_od(path, node_id)
    except odc.Refused as e:
        stats["files odc refuses"] += 1
        codes = sorted({d["code"] for d in e.diagnostics})
        stats[f"odc refuses: {','.join(codes)}"] += 1
        if pod is not None:
            stats["files python-canopen reads, odc refuses"] += 1
        return
    if pod is None:
        stats["files odc reads, python-canopen fails"] += 1
        return
    stats["files read by both"] += 1
    file_differs = False
    for index in pod.indices:
        pentry = pod.indices[index]
        oentry = ood.indices.get(index)
        if oentry is None:
            stats["objects python-canopen has, odc has not"] += 1
            stats["class objects-missing"] += 1
            file_differs = True
            continue
        stats["objects compared"] += 1
        if type(pentry) is not type(oentry):
            stats["class object-kind"] += 1
            file_differs = True
            continue
        obj_equal = True
        for s, pvar in variables(pentry).items():
            ovar = variables(oentry).get(s)
            stats["variables compared"] += 1
            if ovar is None:
                stats["class member-missing"] += 1
                obj_equal = False
                continue
            var_equal = True
            for field in FIELDS:
                a, b = getattr(pvar, field, None), getattr(ovar, field, None)
                if same(a, b):
                    continue
                var_equal = False
                cls = classify(field, pvar, ovar, pentry)
                stats[f"class {cls}"] += 1
                stats[f"field {field}"] += 1
                stats[f"class {cls} / {field}"] += 1
                if show and (show == cls or show == "all") and shown[cls] < 30:
                    shown[cls] += 1
                    print(f"  {cls}: {os.path.basename(path)} 0x{index:04X}sub{s} {field}: "
                          f"python-canopen {a!r} odc {b!r} (raw {getattr(ovar, 'default_raw', None)!r})")
            if var_equal:
                stats["variables equal"] += 1
            else:
                obj_equal = False
        if obj_equal:
            stats["objects equal"] += 1
        else:
            file_differs = True
    extra = set(ood.indices) - set(pod.indices)
    stats["objects only odc has"] += len(extra)
    if not file_differs:
        stats["files equal object by object"] += 1


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("paths", nargs="+")
    ap.add_argument("--sample", type=int, default=0, help="every k-th file, to about N files")
    ap.add_argument("--node-id", type=int, default=5)
    ap.add_argument("--show", help="print the differences of a class (or 'all')")
    args = ap.parse_args()
    logging.disable(logging.CRITICAL)
    files = files_of(args.paths)
    if args.sample and len(files) > args.sample:
        step = len(files) / args.sample
        files = [files[int(i * step)] for i in range(args.sample)]
    stats = collections.Counter()
    shown = collections.Counter()
    for path in files:
        stats["files"] += 1
        compare_file(path, args.node_id, args.show, stats, shown)
    width = max(len(k) for k in stats)
    order = ["files", "files read by both", "files equal object by object",
             "files python-canopen fails", "files odc refuses",
             "files odc reads, python-canopen fails", "files python-canopen reads, odc refuses",
             "objects compared", "objects equal", "objects only odc has", "variables compared",
             "variables equal"]
    for k in order + sorted(k for k in stats if k not in order):
        print(f"{k:<{width}}  {stats[k]}")
    bad = stats["class unexplained"] + stats["files python-canopen reads, odc refuses"]
    sys.exit(1 if bad else 0)


if __name__ == "__main__":
    main()
