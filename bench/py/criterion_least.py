"""criterion_least.py DIR: for each criterion benchmark under DIR (its last run's
`GROUP/FUNCTION/new/sample.json`), the least time per iteration over the run's samples, in ns:
`GROUP/FUNCTION<TAB>ns` a line.

Each sample times a batch of thousands of passes; neighbours on a shared machine only ever
add time to a batch, so the least batch is the steadiest figure of what the code costs.
"""

import json
import pathlib
import sys


def main() -> None:
    root = pathlib.Path(sys.argv[1])
    for f in sorted(root.glob("*/*/new/sample.json")):
        s = json.loads(f.read_text())
        least = min(t / n for t, n in zip(s["times"], s["iters"]) if n > 0)
        group, function = f.parts[-4], f.parts[-3]
        print(f"{group}/{function}\t{least:.3f}")


if __name__ == "__main__":
    main()
