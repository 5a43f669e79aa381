#!/usr/bin/env python3
"""Runs README's firmware program (examples/firmware.rs) in QEMU and checks it on a scripted bus.

Builds the example for thumbv7em-none-eabihf (release), runs it on QEMU's mps2-an386 board (a
Cortex-M4) with `-icount shift=3`, plays the bus below through semihosting, and checks every
frame the node sends against the bytes CiA 301 prescribes (written here by hand, not taken from
a run). Then prints the figures: RAM and flash by `size`, the statics by `nm`, the stack's
high-water mark, and the instructions one frame costs. Fails when the image links
`core::fmt`: the firmware path has no reachable panic (#32).

    tests/no-std/qemu.py                 # build, run, check, print the figures
    tests/no-std/qemu.py --check-readme  # ... and fail when README.md shows other figures
    tests/no-std/qemu.py --write-readme  # ... and write them into README.md

What a "cost" is: with `-icount shift=3` QEMU advances its virtual clock by 2**3 = 8 ns per
instruction executed, whatever the instruction; SysTick counts the board's 25 MHz core clock
(40 ns) in that virtual time, so one SysTick tick is 5 instructions. The firmware reads SysTick
when it hands a frame to the loop and again when the loop asks for the next one; the script
turns the difference into instructions, having checked the conversion on a loop of a known
number of instructions the firmware times first. The count is deterministic (the run depends on
nothing but the instructions executed), resolved to 5 instructions; it is not a cycle count:
a Cortex-M4 takes one cycle or more per instruction, more with flash wait states.
"""

import argparse
import os
import re
import shutil
import subprocess
import sys
import tempfile
from pathlib import Path

HERE = Path(__file__).resolve().parent
ROOT = HERE.parent.parent
TARGET = "thumbv7em-none-eabihf"
ICOUNT_SHIFT = 3
NS_PER_INSTRUCTION = 2**ICOUNT_SHIFT
NS_PER_TICK = 40  # SysTick on the 25 MHz core clock of mps2-an386
CLOCK_READ = 30  # what the two clock reads around a measured stretch may add, in instructions
BEGIN = "<!-- tests/no-std/qemu.py: begin -->"
END = "<!-- tests/no-std/qemu.py: end -->"


def instructions(ticks):
    """SysTick ticks (25 MHz: 40 ns) to instructions (2**ICOUNT_SHIFT ns each)."""
    return ticks * NS_PER_TICK // NS_PER_INSTRUCTION


def sdo_abort(index, sub, code):
    """SDO abort transfer (CiA 301 7.2.4.3.17): 0x80, the address, the code, little-endian."""
    return "80" + le(index, 2) + le(sub, 1) + le(code, 4)


def le(value, size):
    return value.to_bytes(size, "little").hex().upper()


# The bus: (what the master sends, what the node must answer, the step's name in the figures).
# Node-ID 5: SDO requests on 0x605, responses on 0x585, TPDO1 0x185, RPDO1 0x205, NMT error
# control 0x705 (CiA 301 7.3.5, the predefined connection set). Device type 0x04020192 is the
# DefaultValue of [1000] in eds/lxm23a.eds; TPDO1 maps the statusword 0x6041 (default 0),
# RPDO1 the controlword 0x6040 ([1A00], [1600]).
SYNCS = 100
STEPS = [
    # NMT reset node 5 (CiA 301 7.2.8.3.2.1: cs 0x81); the node boots: boot-up, one byte 0.
    ("000#8105", [], "NMT reset node (the dictionary back to its defaults)"),
    ("wait 1", ["705#00"], None),
    # Expedited upload of 0x1000:00 (ccs 2: 0x40) → 0x43 (scs 2, e=1, s=1, n=0), 4 data bytes.
    ("605#4000100000000000", ["585#4300100092010204"], "SDO upload, expedited (0x1000:00)"),
    # Expedited download of 1 byte to 0x1800:02 (ccs 1, n=3, e=1, s=1: 0x2F): TPDO1 becomes
    # synchronous, sent on every SYNC (transmission type 1) → 0x60 with the address.
    ("605#2F00180201000000", ["585#6000180200000000"],
     "SDO download, expedited (0x1800:02: the node reloads TPDO1)"),
    # 2 bytes to 0x1017 (0x2B): heartbeat every 20 ms.
    ("605#2B17100014000000", ["585#6017100000000000"], "SDO download, expedited (0x1017:00)"),
    # Upload of an object the device does not have → abort 0x06020000.
    ("605#4055550000000000", ["585#" + sdo_abort(0x5555, 0, 0x06020000)],
     "SDO upload of a missing object (abort)"),
    # Download to the read-only device type → abort 0x06010002.
    ("605#2300100000000000", ["585#" + sdo_abort(0x1000, 0, 0x06010002)],
     "SDO download to a read-only object (abort)"),
    # NMT start remote node 5 (cs 0x01): operational, nothing sent.
    ("000#0105", [], "NMT start"),
    # 50 ms: heartbeats in state operational (0x05), 20 ms apart (checked below).
    ("wait 50", ["705#05", "705#05"], None),
    # Heartbeat off again (0), so that no heartbeat falls among the frames below: when one
    # would depends on how many instructions they take.
    ("605#2B17100000000000", ["585#6017100000000000"], "SDO download, expedited (0x1017:00)"),
    # SYNC (0x080, no data) → TPDO1: the statusword, 2 bytes, in CiA 402's "switch on
    # disabled" (the drive started: transition 1).
    ("080#", [("185", "switch on disabled")], "SYNC, TPDO1 sent"),
    # RPDO1: the controlword, 2 bytes. Shutdown (0x0006): transition 2.
    ("205#0600", [], "RPDO1 received (controlword), the drive's transition taken"),
    ("080#", [("185", "ready to switch on")], "SYNC, TPDO1 sent"),
    # Switch on (0x0007): transition 3.
    ("205#0700", [], "RPDO1 received (controlword), the drive's transition taken"),
    ("080#", [("185", "switched on")], "SYNC, TPDO1 sent"),
    # Enable operation (0x000F): transition 4.
    ("205#0F00", [], "RPDO1 received (controlword), the drive's transition taken"),
    # An upload of 0x6040:00 reads the controlword back (0x4B: 2 bytes).
    ("605#4040600000000000", ["585#4B4060000F000000"], "SDO upload, expedited (0x6040:00)"),
] + [
    ("080#", [("185", "operation enabled")], "SYNC, TPDO1 sent")
] * SYNCS

# CiA 402 (IEC 61800-7-201) statusword: the state is the bits under the mask.
STATES = {
    "switch on disabled": (0x4F, 0x40),
    "ready to switch on": (0x6F, 0x21),
    "switched on": (0x6F, 0x23),
    "operation enabled": (0x6F, 0x27),
}


def matches(frame, expected):
    """An exact frame, or (COB-ID, CiA 402 state) for a 2-byte statusword."""
    if isinstance(expected, str):
        return frame == expected
    cob, state = expected
    ident, _, data = frame.partition("#")
    mask, value = STATES[state]
    return ident == cob and len(data) == 4 and int.from_bytes(bytes.fromhex(data), "little") & mask == value


def run(cmd, **kw):
    print("+", " ".join(str(c) for c in cmd), file=sys.stderr, flush=True)
    return subprocess.run(cmd, check=True, text=True, **kw)


def build():
    run(
        ["cargo", "build", "--locked", "-q", "-p", "odc-tests-no-std", "--release", "--example",
         "firmware", "--features", "firmware", "--target", TARGET],
        cwd=ROOT,
    )
    target_dir = Path(os.environ.get("CARGO_TARGET_DIR", ROOT / "target"))
    return target_dir / TARGET / "release" / "examples" / "firmware"


def emulate(elf):
    """Runs the firmware on the script; returns the lines it wrote."""
    qemu = shutil.which("qemu-system-arm")
    if qemu is None:
        sys.exit("qemu-system-arm not found (Debian: apt-get install qemu-system-arm)")
    with tempfile.TemporaryDirectory() as tmp:
        (Path(tmp) / "bus.txt").write_text("".join(step + "\n" for step, _, _ in STEPS))
        cmd = [qemu, "-M", "mps2-an386", "-display", "none", "-monitor", "none", "-serial",
               "none", "-semihosting-config", "enable=on,target=native", "-icount",
               f"shift={ICOUNT_SHIFT}", "-kernel", str(elf)]
        print("+", " ".join(cmd), file=sys.stderr, flush=True)
        try:
            out = subprocess.run(cmd, cwd=tmp, stdout=subprocess.PIPE, text=True, timeout=120)
        except subprocess.TimeoutExpired as e:
            sys.exit(f"FAILED: QEMU still ran after 120 s; it wrote:\n{e.stdout or ''}")
    if out.returncode != 0:
        # The firmware ends QEMU with a failure on a panic or a script it cannot read.
        sys.exit(f"FAILED: QEMU exited with {out.returncode}; the firmware wrote:\n{out.stdout}")
    return out.stdout.splitlines()


def check(lines):
    """Checks the frames against STEPS; returns (costs by kind in ticks, stack bytes)."""
    failures = []
    costs = {}
    it = iter(lines)
    line = next(it, None)
    # The firmware times a loop of 20,001 instructions first: the conversion of SysTick ticks
    # into instructions must give that, plus the few instructions of the two clock reads.
    calibrate = int(line.split()[1]) if line and line.startswith("calibrate ") else None
    if calibrate is None or not 20_001 <= instructions(calibrate) <= 20_001 + CLOCK_READ:
        sys.exit(f"FAILED: the calibration loop of 20,001 instructions measured {line!r}")
    line = next(it, None)
    # Before the first step: the boot-up after power-on (CiA 301 7.2.8.3.1: 0x700 + id, 0).
    sent = []
    while line is not None and line.startswith("tx "):
        sent.append(line.split()[2])
        line = next(it, None)
    if sent != ["705#00"]:
        failures.append(f"power-on: sent {sent}, expected ['705#00']")
    for step, expected, kind in STEPS:
        echo = "wait" if step.startswith("wait") else "rx " + step
        if line != echo:
            failures.append(f"{step}: the firmware wrote {line!r}, expected {echo!r}")
            break
        line = next(it, None)
        sent, times, cost = [], [], None
        while line is not None and (line.startswith("tx ") or line.startswith("cost ")):
            if line.startswith("tx "):
                _, ms, frame = line.split()
                sent.append(frame)
                times.append(int(ms))
            else:
                cost = int(line.split()[1])
            line = next(it, None)
        if len(sent) != len(expected) or not all(map(matches, sent, expected)):
            failures.append(f"{step}: sent {sent}, expected {expected}")
        if step.startswith("wait 50") and [b - a for a, b in zip(times, times[1:])] != [20]:
            failures.append(f"{step}: heartbeats at {times} ms, expected 20 ms apart")
        if kind is not None and cost is not None:
            costs.setdefault(kind, []).append(cost)
    tail = [line] + list(it)
    stack = next((int(t.split()[1]) for t in tail if t and t.startswith("stack ")), None)
    dropped = next((int(t.split()[1]) for t in tail if t and t.startswith("dropped ")), None)
    idle = next((int(t.split()[1]) for t in tail if t and t.startswith("idle ")), None)
    if stack is None or idle is None or dropped != 0:
        failures.append(f"end of the script: {tail}")
    missing = [k for _, _, k in STEPS if k is not None and k not in costs]
    if missing:
        failures.append(f"no cost reported for {missing}")
    if failures:
        sys.exit("FAILED\n" + "\n".join(failures))
    costs["a pass of the loop without a frame"] = [idle]
    return costs, stack


def sizes(elf):
    """Section sizes (`size -A`) and the sizes of the dictionary and node statics (`nm -S`)."""
    sections = {}
    for row in run(["size", "-A", str(elf)], stdout=subprocess.PIPE).stdout.splitlines():
        parts = row.split()
        if len(parts) == 3 and parts[1].isdigit():
            sections[parts[0]] = int(parts[1])
    symbols = {}
    rows = run(["nm", "-S", "-C", str(elf)], stdout=subprocess.PIPE).stdout.splitlines()
    # The firmware path has no reachable panic, so nothing formats: no core::fmt is linked
    # (#32; a bounds check or an unwrap on the frame path brings it back).
    fmt = [row for row in rows if "core::fmt" in row]
    if fmt:
        sys.exit("FAILED: the firmware image links core::fmt:\n" + "\n".join(fmt))
    for row in rows:
        m = re.fullmatch(r"[0-9a-f]+ ([0-9a-f]+) [bBdD] firmware::(OD|NODE)", row)
        if m:
            symbols[m.group(2)] = int(m.group(1), 16)
    return sections, symbols


def figures(elf, costs, stack):
    sections, symbols = sizes(elf)
    rustc = run(["rustc", "--version"], stdout=subprocess.PIPE).stdout.strip()
    flash = sections[".vector_table"] + sections[".text"] + sections[".rodata"] + sections[".data"]
    ram = sections[".data"] + sections[".bss"]
    rows = [
        f"Measured by `tests/no-std/qemu.py` ({rustc}, release, QEMU `mps2-an386`, "
        f"`-icount shift={ICOUNT_SHIFT}`):",
        "",
        "| what | bytes |",
        "|---|---:|",
        f"| flash: `.vector_table` + `.text` + `.rodata` + `.data` | {flash:,} |",
        f"| RAM: `.data` + `.bss` | {ram:,} |",
        f"| of which the dictionary (`OD`) | {symbols['OD']:,} |",
        f"| of which the node (`NODE`, `Node<64>`) | {symbols['NODE']:,} |",
        f"| stack high-water mark | {stack:,} |",
        "",
        "| frame | instructions |",
        "|---|---:|",
    ]
    for name, ticks in costs.items():
        counts = sorted({instructions(t) for t in ticks})
        shown = f"{counts[0]:,}" if len(counts) == 1 else f"{counts[0]:,}–{counts[-1]:,}"
        times = f" ({len(ticks)}×)" if len(ticks) > 1 else ""
        rows.append(f"| {name}{times} | {shown} |")
    return "\n".join(rows) + "\n"


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    mode = ap.add_mutually_exclusive_group()
    mode.add_argument("--check-readme", action="store_true")
    mode.add_argument("--write-readme", action="store_true")
    args = ap.parse_args()
    elf = build()
    costs, stack = check(emulate(elf))
    block = figures(elf, costs, stack)
    print(f"ok: {len(STEPS)} steps of the scripted bus answered as CiA 301 and CiA 402 prescribe\n")
    print(block)
    if not (args.check_readme or args.write_readme):
        return
    readme_path = ROOT / "README.md"
    readme = readme_path.read_text()
    before, sep1, rest = readme.partition(BEGIN + "\n")
    shown, sep2, after = rest.partition(END)
    if not (sep1 and sep2):
        sys.exit(f"README.md has no {BEGIN} ... {END} block")
    if args.write_readme:
        readme_path.write_text(before + sep1 + block + sep2 + after)
        print("README.md written")
    elif args.check_readme and shown != block:
        # The figures follow the compiler: with another rustc they differ, and only a warning
        # says so; with the one README names, they must be equal.
        recorded = re.search(r"\((rustc [^,]*),", shown)
        rustc = re.search(r"\((rustc [^,]*),", block)
        if recorded and rustc and recorded.group(1) != rustc.group(1):
            print(f"warning: README.md's figures are for {recorded.group(1)}, not "
                  f"{rustc.group(1)}; run tests/no-std/qemu.py --write-readme", file=sys.stderr)
        else:
            sys.exit("README.md's figures differ from this run: tests/no-std/qemu.py --write-readme")


if __name__ == "__main__":
    main()
