#!/usr/bin/env python3
"""SOEM's default bring-up of every corpus ESI device that has a mailbox or process data,
each device an `odc simulate FILE@DEVICE --interface` on a veth wire whose master end is in a
network namespace of its own (root and iproute2 needed; pysoem in the interop venv).

    cargo build -p odc-cli
    sudo python3 tests/ethercat-sweep/soem.py --jobs 2              # every device
    sudo python3 tests/ethercat-sweep/soem.py --sample 24 --jobs 2  # CI's fixed sample

Per device (tests/ethercat-sweep/README.md): config_init finds it with its ESI identity,
config_map maps it and requests SAFE-OP, SAFE-OP is reached, OP is reached with process data
running, then 1,000 cycles each come back with the working counter SOEM expects. Devices of
one file share a line (--line of them, in the file's order); a line where anything fails is
run again one device a line, so that every verdict is one device's. Writes --out/results.tsv
(one row per device), --out/results.json (the same with SOEM's reports) and
--out/summary.json, and prints the summary. Exit status 1 when a device could not be run at
all (the tester's fault: no wire, no report), 0 otherwise: a failing device is a finding.
"""

import argparse
import collections
import json
import os
import re
import subprocess
import sys
import threading
import time
from concurrent.futures import ThreadPoolExecutor
from pathlib import Path

ROOT = Path(__file__).resolve().parents[2]
HERE = Path(__file__).resolve().parent
CYCLES = 1000
CACHE_VERSION = 2
AL_STATES = {1: "INIT", 2: "PRE-OP", 3: "BOOT", 4: "SAFE-OP", 8: "OP"}


def enumerate_devices(odc, corpus, out):
    """Every device of every ESI file of the manifest, from `odc dump --format json` (cached
    in OUT/devices.json by the file's sha256): spec, identity, name, mailbox, process data."""
    cache_path = out / "devices.json"
    cache = json.loads(cache_path.read_text()) if cache_path.exists() else {}
    files = []
    with open(corpus / "MANIFEST.tsv") as f:
        head = f.readline().rstrip("\n").split("\t")
        for line in f:
            row = dict(zip(head, line.rstrip("\n").split("\t")))
            if row["kind"] == "esi":
                files.append((row["file"], row["sha256"]))
    devices = []
    for name, sha in sorted(files):
        path = corpus / name
        # Keyed by the file's content and by what dump() keeps of it.
        key = f"{sha} {CACHE_VERSION}"
        if cache.get(name, {}).get("sha256") != key:
            cache[name] = {"sha256": key, "devices": dump(odc, path)}
        listed = cache[name]["devices"]
        if isinstance(listed, str):
            devices.append({"file": name, "index": 0, "spec": str(path), "load_error": listed})
            continue
        specs = collections.Counter(d["select"] for d in listed)
        seen = collections.Counter()
        for k, d in enumerate(listed):
            seen[d["select"]] += 1
            dev = dict(d, file=name, index=k, spec=f"{path}@{d['select']}")
            # odc's `FILE@PRODUCT:REVISION` takes the last of equal matches: the earlier
            # ones cannot be picked on a command line.
            if seen[d["select"]] < specs[d["select"]]:
                dev["duplicate"] = True
            devices.append(dev)
    cache_path.write_text(json.dumps(cache))
    return devices


def dump(odc, path):
    """The devices of one file, or the reason odc cannot read it."""
    run = subprocess.run(
        [odc, "dump", "--format", "json", "-A", "all", str(path)],
        capture_output=True, text=True,
    )
    if run.returncode != 0:
        lines = [l for l in run.stderr.splitlines() if l.startswith("error")]
        return (lines or run.stderr.strip().splitlines() or [f"exit {run.returncode}"])[0]
    model = json.loads(run.stdout)
    models = model if isinstance(model, list) else [model]
    listed = []
    for m in models:
        info, ecat = m["device_info"], m.get("ethercat") or {}
        product, revision = info.get("product_number"), info.get("revision_number")
        select = (
            f"{product}:{revision}" if product and revision
            else product or info.get("order_code") or info.get("product_name")
        )
        sms = ecat.get("sync_managers") or []
        mailbox = ecat.get("mailbox") or {}
        try:
            config = bytes.fromhex(((ecat.get("eeprom") or {}).get("config_data") or "").strip())
        except ValueError:
            config = b""
        listed.append({
            "soe": mailbox.get("soe") is not None,
            # ConfigData word 0 is the PDI control register (0x0140); its bit 8, device
            # emulation, makes the ESC answer AL control itself: a device without a
            # microcontroller (ET1100 datasheet, register 0x0140).
            "device_emulation": len(config) >= 2 and config[1] & 1 == 1,
            "select": select,
            "name": m["device_info"].get("order_code") or m["device_info"].get("product_name"),
            "identity": [int(ecat.get(k) or 0) for k in ("vendor_id", "product_code", "revision")],
            "mailbox": ecat.get("mailbox") is not None,
            "process_data": bool(m.get("pdos"))
            or any(s.get("usage") in ("Outputs", "Inputs") for s in sms),
        })
    return listed


class Wire:
    """A veth pair, the master's end in a network namespace; removed by close()."""

    def __init__(self, tag):
        self.netns = f"odcsw{tag}"
        self.dev = f"odcsw{tag}d"
        self.master = f"odcsw{tag}m"
        self.close()
        for cmd in (
            ["netns", "add", self.netns],
            ["link", "add", self.dev, "type", "veth", "peer", "name", self.master],
            ["link", "set", self.master, "netns", self.netns],
            ["link", "set", self.dev, "up"],
            ["netns", "exec", self.netns, "ip", "link", "set", self.master, "up"],
        ):
            subprocess.run(["ip", *cmd], check=True, capture_output=True)

    def close(self):
        subprocess.run(["ip", "link", "del", self.dev], capture_output=True)
        subprocess.run(["ip", "netns", "del", self.netns], capture_output=True)


def realtime():
    """`chrt -f 10` where allowed: SOEM gives a datagram 2 ms (EC_TIMEOUTRET)."""
    ok = subprocess.run(["chrt", "-f", "10", "true"], capture_output=True).returncode == 0
    return ["chrt", "-f", "10"] if ok else []


def run_line(args, wire, devices):
    """One line: `odc simulate` of `devices` and soem_line.py; (report, simulate's stderr)."""
    specs = [d["spec"] for d in devices]
    log = Path(args.out) / f"simulate-{wire.netns}.log"
    with open(log, "w") as err:
        sim = subprocess.Popen(
            [*args.rt, args.odc, "simulate", *specs, "--interface", wire.dev, "--stop-on-eof"],
            stdin=subprocess.PIPE, stdout=subprocess.PIPE, stderr=err, text=True,
        )
    try:
        first = sim.stdout.readline()
        if not first.startswith("serving"):
            sim.wait(timeout=60)
            return {"refused": True}, log.read_text(errors="replace")
        plan = {"iface": wire.master, "count": len(devices), "cycles": CYCLES}
        try:
            run = subprocess.run(
                ["ip", "netns", "exec", wire.netns, *args.rt, args.python,
                 str(HERE / "soem_line.py")],
                input=json.dumps(plan), capture_output=True, text=True, timeout=args.limit,
            )
        except subprocess.TimeoutExpired:
            return {"timeout": True}, ""
        lines = run.stdout.strip().splitlines()
        try:
            report = json.loads(lines[-1])
        except (IndexError, json.JSONDecodeError):
            report = {"no_report": run.stderr.strip()[-300:]}
    finally:
        if sim.poll() is None:
            try:
                sim.stdin.close()
                sim.wait(timeout=20)
            except (subprocess.TimeoutExpired, BrokenPipeError):
                sim.kill()
                sim.wait()
    return report, log.read_text(errors="replace")


def verdicts(devices, report, sim_err):
    """Per device: (passed, stage, AL status code, detail)."""
    if report.get("refused"):
        codes = sorted(set(re.findall(r"^error\[(\w+)\]", sim_err, re.M)))
        errs = [l for l in sim_err.splitlines() if l.startswith("error")]
        what = " ".join(codes) if codes else (errs or sim_err.strip().splitlines() or ["?"])[-1]
        return [(False, "load", None, what) for _ in devices]
    for key in ("timeout", "no_report"):
        if key in report:
            return [(False, "tester", None, f"{key}: {report[key]}") for _ in devices]
    found = report.get("found", 0)
    errors = "; ".join(report.get("errors", []))
    # odc simulate names at load a mapped object the dictionary lacks (the checker's T601).
    t601 = {
        d["spec"] for d in devices for line in sim_err.splitlines()
        if line.startswith(f"{d['spec']}: ") and "SAFE-OP is refused" in line
    }
    out = []
    for k, d in enumerate(devices):
        dev = report["devices"][k] if k < len(report.get("devices", [])) else {}
        if found != len(devices) or dev.get("identity") != d["identity"]:
            out.append((False, "config_init", None,
                        f"found {found} of {len(devices)}: {dev.get('identity')} {errors}"))
            continue
        stage = report.get("stage")
        if stage == "config_map":
            # SOEM's ConfigMapError lists its errors as `KindError(SLAVE, ...)`, SLAVE from 1:
            # a device it does not name failed with the others, not by itself (None).
            mine = sorted({e for s, e in re.findall(r"(\d+), ([^)]*)\)", errors)
                           if int(s) == k + 1})
            out.append((False, "config_map", None, "; ".join(mine)) if mine else None)
            continue
        for key, name in (("after_safe_op", "safe_op"), ("after_op", "op")):
            st = dev.get(key)
            want = 4 if name == "safe_op" else 8
            if st is not None and (st[0] & 0x0F) != want:
                out.append((False, name, st[1],
                            f"AL state {AL_STATES.get(st[0] & 0x0F, st[0])}"
                            f"{' +error' if st[0] & 0x10 else ''}"
                            f"{'; T601 named at load' if d['spec'] in t601 else ''}"))
                break
        else:
            if stage == "done" and report["cycles_with_expected_wkc"] == CYCLES:
                out.append((True, "done", None, f"lost {report['frames_lost']}"))
            elif stage == "done":
                out.append((False, "cycles", None,
                            f"{report['cycles_with_expected_wkc']} of {CYCLES} at WKC "
                            f"{report['expected_wkc']}, other {report['other_wkc']}, "
                            f"lost {report['frames_lost']}, ETG.1000.4 count "
                            f"{report.get('etg_wkc')}, io map {report.get('io_map_size')}"))
            else:
                out.append((False, stage or "?", None, errors or "stopped"))
    return out


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--corpus", default=os.environ.get("ODC_CORPUS", str(ROOT.parent / "shared/corpus")))
    ap.add_argument("--odc", default=str(ROOT / "target/debug/odc"))
    ap.add_argument("--python", default=os.environ.get(
        "ODC_INTEROP_PYTHON", str(ROOT / "target/interop-venv/bin/python")))
    ap.add_argument("--sample", type=int, default=0, help="this many devices, spread evenly")
    ap.add_argument("--only", default="", help="devices whose spec contains this text")
    ap.add_argument("--failed-in", default="",
                    help="only the devices that a previous run's OUT dir (its results.tsv) "
                    "failed with a class matching --class")
    ap.add_argument("--class", dest="cls", default="unclassified",
                    help="regular expression on the class of --failed-in's rows "
                    "(default: unclassified)")
    ap.add_argument("--jobs", type=int, default=2)
    ap.add_argument("--line", type=int, default=8, help="devices of one file per line")
    ap.add_argument("--limit", type=int, default=300, help="seconds for one line's SOEM run")
    ap.add_argument("--out", default=str(ROOT / "target/ethercat-sweep/soem"))
    ap.add_argument("--reclassify", action="store_true",
                    help="no run: classify OUT/results.json again and rewrite the summary")
    args = ap.parse_args()
    out = Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    args.rt = realtime()
    # The peers: without them every device would be a tester's failure (--reclassify runs
    # nothing and needs neither).
    if args.reclassify:
        pass
    elif subprocess.run([args.python, "-c", "import pysoem"], capture_output=True).returncode:
        sys.exit(f"soem.py: {args.python} cannot import pysoem (set ODC_INTEROP_PYTHON)")
    elif os.geteuid() != 0:
        sys.exit("soem.py: needs root (network namespaces and veth pairs)")
    corpus = Path(args.corpus)
    started = time.monotonic()
    every = enumerate_devices(args.odc, corpus, out)
    swept = [d for d in every if "load_error" in d or d["mailbox"] or d["process_data"]]
    if args.only:
        swept = [d for d in swept if args.only in d["spec"]]
    if args.failed_in:
        wanted = failed_in(Path(args.failed_in) / "results.tsv", args.cls)
        swept = [d for d in swept if (d["file"], d.get("select")) in wanted]
    if args.sample:
        step = max(1, len(swept) / args.sample)
        swept = [swept[int(k * step)] for k in range(min(args.sample, len(swept)))]
    if args.reclassify:
        saved = json.loads((out / "results.json").read_text())
        by_spec = {d["spec"]: d for d in swept}
        results = {spec: (by_spec[spec], tuple(r["verdict"]), r["report"])
                   for spec, r in saved.items() if spec in by_spec}
        swept = [d for d in swept if d["spec"] in results or "load_error" in d
                 or d.get("duplicate")]
        write(out, every, swept, results, saved.get("seconds", 0), args)
        return
    runnable = [d for d in swept if "load_error" not in d and not d.get("duplicate")]
    lines = []
    for d in runnable:
        if lines and lines[-1][0]["file"] == d["file"] and len(lines[-1]) < args.line:
            lines[-1].append(d)
        else:
            lines.append([d])
    results = {}
    free = list(range(args.jobs))
    lock = threading.Lock()
    done = [0]

    def work(line):
        with lock:
            tag = free.pop()
        wire = Wire(f"{os.getpid() % 1000}x{tag}")
        try:
            report, err = run_line(args, wire, line)
            got = verdicts(line, report, err)
            if len(line) > 1 and not all(v and v[0] for v in got):
                for d, v in zip(line, got):
                    if v and v[1] == "config_map":
                        results[d["spec"]] = (d, v, report)
                for d in [d for d, v in zip(line, got) if not (v and v[1] == "config_map")]:
                    r, e = run_line(args, wire, [d])
                    v = verdicts([d], r, e)[0]
                    if not v[0] and v[1] in ("config_init", "cycles", "tester"):
                        # Once more: a loaded machine loses frames SOEM waits 2 ms for.
                        r, e = run_line(args, wire, [d])
                        v2 = verdicts([d], r, e)[0]
                        v = v2 if v2[0] else v
                    results[d["spec"]] = (d, v, r)
            else:
                for d, v in zip(line, got):
                    results[d["spec"]] = (d, v, report)
        finally:
            wire.close()
            with lock:
                free.append(tag)
                done[0] += len(line)
                for d in line:
                    v = results.get(d["spec"], (None, (False, "tester", None, "no verdict")))[1]
                    print(f"{done[0]}/{len(runnable)}\t{d['spec']}\t{v}", file=sys.stderr,
                          flush=True)

    with ThreadPoolExecutor(max_workers=args.jobs) as pool:
        list(pool.map(work, lines))
    write(out, every, swept, results, time.monotonic() - started, args)


def failed_in(tsv, pattern):
    """(file, PRODUCT:REVISION) of the failed rows of a previous run's results.tsv whose
    class matches `pattern`."""
    with open(tsv) as f:
        head = f.readline().rstrip("\n").split("\t")
        rows = [dict(zip(head, l.rstrip("\n").split("\t"))) for l in f]
    return {(r["file"], r["device"]) for r in rows
            if r["verdict"] == "fail" and re.search(pattern, r["class"])}


def classify(d, ok, stage, code, detail, sizes=None):
    """The class of one device's verdict (tests/ethercat-sweep/README.md names each)."""
    if ok:
        return "pass"
    if stage == "load":
        return f"ESI: refused at load ({detail})"
    if stage == "tester":
        return "tester"
    if stage in ("safe_op", "op"):
        # Before the SoE rule: a device that also lists SoE (kickcat's test file lists every
        # protocol) is refused for its missing objects, not for its IDNs.
        if "T601" in detail:
            return f"ESI: T601, a mapped object the dictionary lacks (AL 0x{code:04X})"
        if d.get("soe"):
            return "odc: SoE drive, its process data are IDNs (SoE not served)"
        if d.get("device_emulation") and not d["mailbox"] and code in (0x001D, 0x001E):
            return f"odc: ESC device emulation not emulated (AL 0x{code:04X})"
        # SOEM mapped nothing in the direction the device refuses (0x001D outputs, 0x001E
        # inputs) but programmed that sync manager with the SII's size.
        if sizes and ((code == 0x001D and sizes[0] == 0) or (code == 0x001E and sizes[1] == 0)):
            return f"no default PDO (modules), a process data SM with a size (AL 0x{code:04X})"
        return f"unclassified: {stage} AL 0x{code or 0:04X}"
    if stage == "config_map" and "does not exist in the object directory" in detail:
        return "ESI: an assigned PDO the dictionary lacks (SDO abort 0x06020000)"
    if stage == "cycles":
        m = re.search(r"(\d+) of \d+ at WKC (-?\d+), other \[([\d, ]*)\].*count (\d+), io map (\d+)",
                      detail)
        if m and m.group(5) == "0":
            return "no process data: SOEM mapped 0 bytes"
        if m and m.group(1) == "0" and m.group(3) == m.group(4):
            return "SOEM: expected WKC differs from the ETG.1000.4 count"
    return f"unclassified: {stage}"


def classify_by_check(cls, code, codes, detail=""):
    """A failure classify() did not name, by what `odc check` (and `odc sii`, S7xx) says of
    the ESI."""
    if code == 0x0016 and "T624" in codes:
        return "ESI: T624, mailbox sync managers declared disabled (AL 0x0016)"
    # Every frame at working counter 0: no process data SM was ever activated. With T624 the
    # firmware refused PRE-OP (0x0016), but the ESC's device emulation (register 0x0141 bit 0,
    # from ConfigData) copied each requested state into AL status, so SOEM saw OP.
    if cls == "unclassified: cycles" and "T624" in codes and re.match(r"0 of .*other \[0\]",
                                                                       detail):
        return ("ESI: T624, mailbox sync managers declared disabled (AL 0x0016), "
                "hidden by device emulation")
    if code in (0x001D, 0x001E) and "S702-info-only" in codes:
        return f"ESI: Eeprom/ByteSize holds the SII info area only (S702) (AL 0x{code:04X})"
    if code == 0x0016 and "SII-cat41-not-8-byte-records" in codes:
        return "ESI: its own SyncManager category (CatNo 41) not in 8-byte records (AL 0x0016)"
    if code in (0x0024, 0x0025) and "T622" in codes:
        return f"ESI: T622, a mapping object's default differs from its PDO (AL 0x{code:04X})"
    if code in (0x0024, 0x0025) and "T608" in codes:
        return f"ESI: T608, an assignment default counting PDO 0x0000 (AL 0x{code:04X})"
    return cls


def check_codes(odc, d):
    """The codes `odc check` gives the device (warnings and errors), and those of `odc sii`
    (S7xx: what its EEPROM image leaves out), for a failure no rule of classify() names.
    `S702-info-only`: `Eeprom/ByteSize` holds the 64-word info area and no category."""
    path, _, select = d["spec"].rpartition("@")
    run = subprocess.run([odc, "check", path, "--device", select], capture_output=True, text=True)
    codes = set(re.findall(r"^(?:warning|error)\[(\w+)\]", run.stderr, re.M))
    sii = subprocess.run([odc, "sii", path, "--device", select, "-o", os.devnull],
                         capture_output=True, text=True)
    for code, rest in re.findall(r"^(?:warning|error)\[(S7\d\d)\]: (.*)$", sii.stderr, re.M):
        codes.add(code)
        if code == "S702" and rest.endswith("`Eeprom/ByteSize` 128: optional parts left out"):
            codes.add("S702-info-only")
    # The ESI's own SyncManager category (`Eeprom/Category`, CatNo 41), written into the SII as
    # given: ETG.2010 gives each sync manager 8 bytes.
    dump = subprocess.run([odc, "dump", "--format", "json", "-A", "all", path, "--device", select],
                          capture_output=True, text=True)
    try:
        model = json.loads(dump.stdout)
    except json.JSONDecodeError:
        model = {}
    for m in model if isinstance(model, list) else [model]:
        for c in (((m.get("ethercat") or {}).get("eeprom") or {}).get("categories") or []):
            if c.get("cat_no") == 41 and len(c.get("data") or "") % 16:
                codes.add("SII-cat41-not-8-byte-records")
    return " ".join(sorted(codes))


def write(out, every, swept, results, seconds, args):
    rows, counts = [], collections.Counter()
    per_stage = collections.Counter()
    per_code = collections.Counter()
    classes = collections.Counter()
    for d in swept:
        if "load_error" in d:
            row = [d["file"], "-", "-", "-", "-", "fail", "file", "", d["load_error"],
                   "ESI: file not read"]
        elif d.get("duplicate"):
            row = [d["file"], d["select"], d["name"], d["mailbox"], d["process_data"],
                   "skip", "duplicate", "", "same PRODUCT:REVISION as a later device of the file",
                   "skipped: not selectable"]
        else:
            _, (ok, stage, code, detail), report = results.get(
                d["spec"], (d, (False, "tester", None, "no verdict"), None))
            # A failing device's report is its own line's (one device) but for config_map.
            devs = (report or {}).get("devices", [])
            sizes = devs[0].get("sizes") if len(devs) == 1 else None
            cls = classify(d, ok, stage, code, detail, sizes)
            if cls.startswith("unclassified"):
                codes = check_codes(args.odc, d)
                detail = f"{detail}; odc check: {codes}"
                cls = classify_by_check(cls, code, codes.split(), detail)
            row = [d["file"], d["select"], d["name"], d["mailbox"], d["process_data"],
                   "pass" if ok else "fail", stage,
                   "" if code is None else f"0x{code:04X}", detail, cls]
        rows.append(row)
        counts[row[5]] += 1
        classes[row[9]] += 1
        if row[5] == "fail":
            per_stage[row[6]] += 1
            if row[7]:
                per_code[f"{row[6]} {row[7]}"] += 1
    with open(out / "results.tsv", "w") as f:
        f.write("file\tdevice\tname\tmailbox\tprocess_data\tverdict\tstage\tal_status\tdetail"
                "\tclass\n")
        for r in rows:
            f.write("\t".join(str(c).replace("\t", " ").replace("\n", " ") for c in r) + "\n")
    if not args.reclassify:
        (out / "results.json").write_text(json.dumps(
            {spec: {"verdict": v, "report": r} for spec, (_, v, r) in results.items()}))
    else:
        seconds = json.loads((out / "summary.json").read_text()).get("seconds", 0)
    summary = {
        "devices_in_corpus": len(every),
        "with_mailbox_or_process_data": sum(
            1 for d in every if "load_error" not in d and (d["mailbox"] or d["process_data"])),
        "files_not_read": sum(1 for d in every if "load_error" in d),
        "swept": len(swept),
        "sample": args.sample,
        "reached_op": sum(1 for r in rows if r[5] == "pass" or r[6] == "cycles"),
        "passed": counts["pass"],
        "failed": counts["fail"],
        "skipped_duplicates": counts["skip"],
        "failed_per_stage": dict(sorted(per_stage.items())),
        "failed_per_al_status": dict(sorted(per_code.items())),
        "per_class": dict(sorted(classes.items(), key=lambda kv: (-kv[1], kv[0]))),
        "seconds": round(seconds),
    }
    (out / "summary.json").write_text(json.dumps(summary, indent=1) + "\n")
    print(json.dumps(summary, indent=1))
    tester = sum(1 for r in rows if r[6] == "tester")
    sys.exit(1 if tester else 0)


if __name__ == "__main__":
    main()
