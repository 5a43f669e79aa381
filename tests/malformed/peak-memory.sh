#!/usr/bin/env bash
# Peak resident set of the `odc check` binary (release build) on the worst hostile inputs, each
# at the largest size the limits let through. Prints one line per case: the input size, the
# peak (from /proc's VmHWM via GNU time, or bash's own measurement when that is missing) and the
# wall time. A measurement, not a test: run it after changing a front-end or a limit.
set -euo pipefail
cd "$(dirname "$0")/../.."
cargo build --release -p odc-cli --quiet
odc=${CARGO_TARGET_DIR:-target}/release/odc
dir=$(mktemp -d)
trap 'rm -rf "$dir"' EXIT
python3 - "$dir" <<'PY'
import sys
d = sys.argv[1]
mb = 1024 * 1024
head = "[FileInfo]\nFileName=x.eds\n\n[1000]\nParameterName=Device type\nDataType=0x0007\nAccessType=ro\n\n"
# EDS: just under the 32 MiB limit.
open(f"{d}/stray_lines_32m.eds", "w").write(head + "x\n" * ((32 * mb - len(head)) // 2 - 1))
open(f"{d}/one_line_32m.eds", "w").write(head + "A" * (32 * mb - len(head) - 2) + "\n")
open(f"{d}/keys_32m.eds", "w").write("[2000]\n" + "a=1\n" * ((32 * mb - 8) // 4))
open(f"{d}/compact_bomb.eds", "w").write("".join(
    "[%04X]\nParameterName=T\nObjectType=0x8\nDataType=0x0007\nAccessType=rw\nCompactSubObj=255\n" % i
    for i in range(0x2000, 0x2000 + 5000)))
# ESI: at the element limit, and just under the 64 MiB limit.
open(f"{d}/elements_2m.xml", "w").write("<EtherCATInfo>" + "<a/>" * 2_000_000 + "</EtherCATInfo>")
open(f"{d}/attributes_64m.xml", "w").write("<EtherCATInfo><a " + " ".join("b%d=\"&x;\"" % i for i in range(3_000_000)) + "/></EtherCATInfo>")
types = ("<DataType><Name>UDINT</Name><BitSize>32</BitSize></DataType><DataType><Name>ARR</Name>"
         "<BaseType>UDINT</BaseType><BitSize>8160</BitSize><ArrayInfo><LBound>1</LBound><Elements>255"
         "</Elements></ArrayInfo></DataType>")
objects = "".join("<Object><Index>#x%04X</Index><Name>A</Name><Type>ARR</Type></Object>" % (0x2000 + i) for i in range(8000))
open(f"{d}/array_type_bomb.xml", "w").write(
    "<?xml version=\"1.0\"?><EtherCATInfo><Vendor><Id>1</Id></Vendor><Descriptions><Devices><Device>"
    "<Type ProductCode=\"#x1\" RevisionNo=\"#x1\">D</Type><Name>D</Name><Profile><Dictionary><DataTypes>"
    + types + "</DataTypes><Objects>" + objects + "</Objects></Dictionary></Profile></Device></Devices>"
    "</Descriptions></EtherCATInfo>")
PY
for f in "$dir"/*; do
  size=$(stat -c %s "$f")
  if [ -x /usr/bin/time ]; then
    /usr/bin/time -f "%M %e" -o "$dir/.t" "$odc" check --format short "$f" >/dev/null 2>&1 || true
    read -r kb secs < <(tail -n 1 "$dir/.t")
  else
    start=$(date +%s.%N); "$odc" check --format short "$f" >/dev/null 2>&1 || true
    kb=?; secs=$(echo "$(date +%s.%N) - $start" | bc)
  fi
  printf '%-22s input %10d B  peak RSS %8s KiB  %6ss\n' "$(basename "$f")" "$size" "$kb" "$secs"
done
