"""python-canopen as a user runs it on many files: one process that imports each.

    python import_all.py LIST

The whole process is what `bench/compare.sh` times (interpreter start-up included), against
`odc check` over the same files in one process. A file python-canopen refuses is skipped, as a
user's script would report and go on.
"""

import sys
import warnings

import canopen

warnings.simplefilter("ignore")

for path in open(sys.argv[1]).read().splitlines():
    if path:
        try:
            canopen.import_od(path)
        except Exception:  # the file is not read; the next one is
            pass
