#!/usr/bin/env python3
"""python-canopen's own test suite with its EDS importer replaced by odc's.

Fetches the canopen sdist of the installed version with pip (`pip download --no-binary`; its
tests are not in the wheel, and are not copied into this repository), writes a conftest.py
into its `test/` that replaces `canopen.import_od` (and the names `canopen.objectdictionary`
and `canopen.node.base` import it under) with `odc.canopen.import_od`, and runs the suite under
pytest. Prints pytest's summary and the failing tests; `--expect-fail FILE` names the tests
expected to fail (one node ID a line, `#` comments: tests/interop/README.md says why each
does), and the exit status is 0 when exactly those fail.

Usage: canopen_suite.py [--work DIR] [--expect-fail FILE] [pytest args...]
"""

import argparse
import glob
import os
import subprocess
import sys
import tarfile

import canopen

CONFTEST = '''\
# Written by odc's tests/interop/python/canopen_suite.py: every import_od is odc's.
import canopen
import canopen.node.base
import canopen.objectdictionary

import odc.canopen

calls = {"odc": 0}


def import_od(*args, **kwargs):
    calls["odc"] += 1
    return odc.canopen.import_od(*args, **kwargs)


canopen.import_od = import_od
canopen.objectdictionary.import_od = import_od
canopen.node.base.import_od = import_od


def pytest_terminal_summary(terminalreporter):
    terminalreporter.write_line(f"odc.canopen.import_od calls: {calls['odc']}")
'''


def fetch(work):
    version = canopen.__version__
    root = os.path.join(work, f"canopen-{version}")
    if not os.path.isdir(os.path.join(root, "test")):
        os.makedirs(work, exist_ok=True)
        subprocess.run([sys.executable, "-m", "pip", "download", "--quiet",
                        "--disable-pip-version-check", "--no-binary", ":all:", "--no-deps",
                        f"canopen=={version}", "-d", work], check=True)
        (sdist,) = glob.glob(os.path.join(work, f"canopen-{version}.tar.gz"))
        with tarfile.open(sdist) as tar:
            members = [m for m in tar.getmembers()
                       if m.name.startswith(f"canopen-{version}/test/")]
            tar.extractall(work, members=members)  # noqa: S202 - PyPI sdist, test files only
    with open(os.path.join(root, "test", "conftest.py"), "w") as f:
        f.write(CONFTEST)
    return os.path.join(root, "test")


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--work", default=os.path.join("target", "canopen-suite"))
    ap.add_argument("--expect-fail", help="file of the test IDs expected to fail")
    args, pytest_args = ap.parse_known_args()
    tests = fetch(os.path.abspath(args.work))
    # The package's own directory first, so that `from .util import ...` and `test.*` resolve
    # as they do in its repository; `canopen` itself is the installed one.
    report = os.path.join(os.path.abspath(args.work), "failed.txt")
    cmd = [sys.executable, "-m", "pytest", "-q", "-p", "no:cacheprovider", "-rf",
           "--rootdir", os.path.dirname(tests), tests] + pytest_args
    run = subprocess.run(cmd, capture_output=True, text=True, cwd=os.path.dirname(tests))
    print(run.stdout[-6000:])
    failed = sorted({line.split()[1].split(" - ")[0] for line in run.stdout.splitlines()
                     if line.startswith("FAILED ")})
    with open(report, "w") as f:
        f.write("\n".join(failed) + "\n")
    if args.expect_fail is None:
        sys.exit(run.returncode)
    with open(args.expect_fail) as f:
        expected = sorted({line.split("#")[0].strip() for line in f} - {""})
    unexpected = [t for t in failed if t not in expected]
    now_pass = [t for t in expected if t not in failed]
    for t in unexpected:
        print(f"unexpected failure: {t}")
    for t in now_pass:
        print(f"expected to fail, passes: {t} (remove it from {args.expect_fail})")
    if run.returncode not in (0, 1):
        sys.exit(run.returncode)
    sys.exit(1 if unexpected or now_pass else 0)


if __name__ == "__main__":
    main()
