"""In-process EDS/DCF parse timings of the Python tools of the comparison.

    python time_eds.py accept LIST DIR   # writes DIR/<tool>: the files each tool reads
    python time_eds.py time LIST         # prints tool<TAB>files read<TAB>CPU s per pass

Tools: python-canopen (`canopen.import_od`, what its users call) and lely's dcf-tools
(`dcf.parse.parse_file` then `dcf.device.Device`, the model `dcfchk` and `dcfgen` build;
`dcfchk` also lints, which is not part of a parse). Times are the CPU time of this thread
(`time.thread_time`), so interpreter start-up is not in them; a pass is repeated until it
has run for a second and at least three times (median), as the Rust harness does.
"""

import sys
import time
import warnings

import canopen
from dcf.device import Device
from dcf.parse import parse_file

warnings.simplefilter("ignore")


def canopen_parse(path):
    canopen.import_od(path)


def lely_parse(path):
    Device(parse_file(path), {})


TOOLS = [("python-canopen", canopen_parse), ("lely-dcf-tools", lely_parse)]


def reads(f, path):
    try:
        f(path)
        return True
    except Exception:  # any failure: the tool does not read the file
        return False


def main():
    mode, listfile = sys.argv[1], sys.argv[2]
    files = [l for l in open(listfile).read().splitlines() if l]
    if mode == "accept":
        out = sys.argv[3]
        for name, f in TOOLS:
            with open(f"{out}/{name}", "w") as o:
                o.writelines(p + "\n" for p in files if reads(f, p))
        return
    for name, f in TOOLS:
        passes = []
        ok = 0
        start = time.thread_time()
        while len(passes) < 3 or time.thread_time() - start < 1.0:
            t = time.thread_time()
            ok = sum(reads(f, p) for p in files)
            passes.append(time.thread_time() - t)
            if time.thread_time() - start > 20.0:
                break  # slow tools: enough
        passes.sort()
        print(f"{name}\t{ok}\t{passes[len(passes) // 2]:.9f}")


if __name__ == "__main__":
    main()
