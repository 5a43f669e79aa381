#!/usr/bin/env python3
"""Bytes of a firmware image by part, from its symbols (`nm -S`): where the flash goes.

    tests/slave-size/symbols.py IMAGE [NM]

NM defaults to arm-none-eabi-nm (the host's `nm` reads the thumbv7em ELF too). A function
that LTO inlined counts where it landed (in `firmware::run`, the example's loop, for
what is inlined there); read-only data without a symbol (string literals, promoted
constants) is in no part: `size -A` gives the whole `.rodata`.
"""

import re
import subprocess
import sys
from collections import Counter

# (part, pattern on the demangled name), first match wins.
PARTS = [
    ("LAN9252 adapter (esc_spi)", r"esc_spi|Lan9252"),
    ("SDO Information (subdevice::info, slave::describe)", r"subdevice::info|slave::describe"),
    ("CoE SDO server (subdevice::coe)", r"subdevice::coe"),
    ("FoE (subdevice::foe)", r"subdevice::foe"),
    ("process data (subdevice::pdo)", r"subdevice::pdo"),
    ("AL states, mailbox (subdevice)", r"subdevice"),
    ("dictionary (slave, value, the generated Dictionary)", r"slave|Slot|Dictionary|value::|search"),
    ("compiler_builtins (memcpy, memclr)", r"compiler_builtins|^mem|__aeabi"),
    ("the example's loop, with what LTO inlined (firmware::run)", r"firmware::run"),
    ("core", r"core::"),
]


def main():
    image = sys.argv[1]
    nm = sys.argv[2] if len(sys.argv) > 2 else "arm-none-eabi-nm"
    out = subprocess.run([nm, "-S", "-C", image], capture_output=True, text=True, check=True)
    text, data = Counter(), Counter()
    for line in out.stdout.splitlines():
        fields = line.split(None, 3)
        if len(fields) < 4 or fields[2] not in "tTrR":
            continue
        size, name = int(fields[1], 16), fields[3]
        part = next((p for p, pat in PARTS if re.search(pat, name)), "other (board, runtime, vectors)")
        (text if fields[2] in "tT" else data)[part] += size
    print("| part | code | read-only data |")
    print("|---|---:|---:|")
    for part in sorted(set(text) | set(data), key=lambda p: -(text[p] + data[p])):
        print(f"| {part} | {text[part]:,} | {data[part]:,} |")


if __name__ == "__main__":
    main()
