#!/usr/bin/env bash
# odc against the tools a user could pick instead, measured in one run on the same inputs.
# Prints one table of ratios (see BENCHMARKS.md). Sets up the other tools itself:
#   - a Python venv with python-canopen and lely's dcf-tools (PyPI);
#   - the Rust crates canopen-host, ethercat-esi, deku, packed_struct (crates.io, through
#     bench/Cargo.toml, a workspace of its own: none of them is in the product's graph).
# Usage: bench/compare.sh [--no-build-cost]     (ODC_CORPUS: the corpus, default ../shared/corpus)
set -euo pipefail
cd "$(dirname "$0")"
BENCH=$PWD
ROOT=$(cd .. && pwd)
export ODC_CORPUS="${ODC_CORPUS:-$(cd "$ROOT/.." && pwd)/shared/corpus}"
WORK="$BENCH/target/compare"
BUILD_COST=1
[ "${1:-}" = "--no-build-cost" ] && BUILD_COST=0
mkdir -p "$WORK"
export CARGO_TARGET_DIR="$BENCH/target"
export CARGO_TERM_COLOR=never
log() { echo "compare.sh: $*" >&2; }

# ---- tools -------------------------------------------------------------------------------
log "python venv (python-canopen, lely dcf-tools)"
[ -x "$WORK/venv/bin/python" ] || python3 -m venv "$WORK/venv"
PY="$WORK/venv/bin/python"
"$PY" -m pip install -q --disable-pip-version-check canopen dcf-tools >&2
# lely's C library (liblely-coapp: its C++ EDS/DCF parser) is not on PyPI nor in Debian's
# packages: only dcf-tools, lely's Python EDS/DCF tools, is installable here.
LELY_CORE=$("$PY" -m pip install -q --disable-pip-version-check lely-core >/dev/null 2>&1 \
  && echo installed || echo "not installable (no PyPI distribution)")
log "lely-core: $LELY_CORE"
log "building the harness (release)"
cargo build --release --quiet --locked --manifest-path "$BENCH/Cargo.toml"
cargo build --release --quiet --manifest-path "$ROOT/Cargo.toml" -p odc-cli
HARNESS="$CARGO_TARGET_DIR/release/odc-bench"
ODC="$CARGO_TARGET_DIR/release/odc"

# ---- inputs ------------------------------------------------------------------------------
list() { awk -F'\t' -v d="$ODC_CORPUS" -v k="$1" 'NR>1 && $2 ~ k {print d "/" $1}' "$ODC_CORPUS/MANIFEST.tsv"; }
list '^(eds|dcf)$' > "$WORK/eds.list"
list '^esi$' > "$WORK/esi.list"
largest() { xargs -d '\n' ls -S < "$1" | sed -n 1p; }
bytes() { xargs -d '\n' cat < "$1" | wc -c; }

# Which files each tool reads without an error: every ratio is taken on files both tools read.
mkdir -p "$WORK/acc-eds" "$WORK/acc-esi"
"$HARNESS" eds "$WORK/eds.list" "$WORK/acc-eds"
"$HARNESS" esi "$WORK/esi.list" "$WORK/acc-esi"
"$PY" "$BENCH/py/time_eds.py" accept "$WORK/eds.list" "$WORK/acc-eds"
all_read() { # the files every tool named reads
  local first=$1; shift
  sort "$first" > "$WORK/common"
  for t in "$@"; do sort "$t" | comm -12 "$WORK/common" - > "$WORK/common.next"; mv "$WORK/common.next" "$WORK/common"; done
  cat "$WORK/common"
}
all_read "$WORK"/acc-eds/{canopen-host,python-canopen,lely-dcf-tools} > "$WORK/eds-common.list"
largest "$WORK/eds.list" > "$WORK/eds-largest.list"
largest "$WORK/eds-common.list" > "$WORK/eds-common-largest.list"
all_read "$WORK"/acc-esi/{ethercat-esi,quick-xml} > "$WORK/esi-common.list"
largest "$WORK/esi.list" > "$WORK/esi-largest.list"
largest "$WORK/esi-common.list" > "$WORK/esi-common-largest.list"

# ---- timings -----------------------------------------------------------------------------
# glibc's malloc returns freed memory at the top of the heap to the OS once it passes a
# threshold it keeps adjusting, and takes it back with fresh page faults on the next pass.
# Whether a tool's pass crosses it depends on the heap's exact layout: the same odc binary took
# 0.44 or 0.84 ms per pass on the largest EDS depending on the length of a command-line
# argument. Fixed thresholds make every tool of a run (Rust and Python alike) reuse its memory
# from pass to pass, so the figures measure parsing, not that accident.
export MALLOC_TRIM_THRESHOLD_=268435456 MALLOC_MMAP_THRESHOLD_=268435456
# rust LIST KIND TOOL / py LIST TOOL: CPU seconds per pass of TOOL over the files of LIST.
# Each harness runs once per input list; its output is kept in $WORK/times-*.
run_rust() { local o="$WORK/times-rust-$2-$(basename "$1")"; [ -s "$o" ] || "$HARNESS" "$2" "$1" > "$o"; cat "$o"; }
run_py() { local o="$WORK/times-py-$(basename "$1")"; [ -s "$o" ] || "$PY" "$BENCH/py/time_eds.py" time "$1" > "$o"; cat "$o"; }
rust() { run_rust "$1" "$2" | awk -F'\t' -v t="$3" '$1==t {print $3}'; }
py() { run_py "$1" | awk -F'\t' -v t="$2" '$1==t {print $3}'; }
rm -f "$WORK"/times-*

ROWS="$WORK/rows.tsv"
: > "$ROWS"
# row INPUT FILES BYTES TOOL ODC OTHER [UNIT]: seconds, or with UNIT Ir instructions
row() { printf '%s\t%s\t%s\t%s\t%s\t%s\t%s\n' "$1" "$2" "$3" "$4" "$5" "$6" "${7:-s}" >> "$ROWS"; }
n() { wc -l < "$1" | tr -d ' '; }

log "EDS parse"
for set in eds eds-largest eds-common eds-common-largest; do
  L="$WORK/$set.list"
  odc=$(rust "$L" eds odc)
  row "$set" "$(n "$L")" "$(bytes "$L")" floor "$odc" "$(rust "$L" eds floor)"
done
for tool in canopen-host python-canopen lely-dcf-tools; do
  sort "$WORK/acc-eds/$tool" > "$WORK/eds-$tool.list"
  largest "$WORK/eds-$tool.list" > "$WORK/eds-$tool-largest.list"
  for L in "$WORK/eds-$tool.list" "$WORK/eds-$tool-largest.list" "$WORK/eds-common.list" "$WORK/eds-common-largest.list"; do
    set=$(basename "$L" .list)
    odc=$(rust "$L" eds odc)
    if [ "$tool" = canopen-host ]; then other=$(rust "$L" eds canopen-host); else other=$(py "$L" "$tool"); fi
    row "$set" "$(n "$L")" "$(bytes "$L")" "$tool" "$odc" "$other"
    # odc makes the sub-objects a CompactSubObj implies on first read: the same comparison
    # with odc reading every sub-object after the parse.
    row "$set" "$(n "$L")" "$(bytes "$L")" "$tool (all subs)" "$(rust "$L" eds odc-all-subs)" "$other"
  done
done

log "ESI parse"
for set in esi esi-largest; do
  L="$WORK/$set.list"
  row "$set" "$(n "$L")" "$(bytes "$L")" floor "$(rust "$L" esi odc)" "$(rust "$L" esi floor)"
done
# quick-xml stops at the first error, so it is compared on the files it reads to the end.
sort "$WORK/acc-esi/quick-xml" > "$WORK/esi-quick-xml.list"
largest "$WORK/esi-quick-xml.list" > "$WORK/esi-quick-xml-largest.list"
for set in esi-quick-xml esi-quick-xml-largest; do
  L="$WORK/$set.list"
  row "$set" "$(n "$L")" "$(bytes "$L")" quick-xml "$(rust "$L" esi odc)" "$(rust "$L" esi quick-xml)"
done
for set in esi-common esi-common-largest; do
  L="$WORK/$set.list"
  row "$set" "$(n "$L")" "$(bytes "$L")" ethercat-esi "$(rust "$L" esi odc)" "$(rust "$L" esi ethercat-esi)"
  row "$set" "$(n "$L")" "$(bytes "$L")" quick-xml "$(rust "$L" esi odc)" "$(rust "$L" esi quick-xml)"
done

log "whole process: odc check vs dcfchk, vs python-canopen over its files"
# Wall time of the whole command (interpreter start-up included), median of 5, on the
# largest EDS both read.
F=$(cat "$WORK/eds-common-largest.list")
wall() { local ts=(); for _ in 1 2 3 4 5; do local s; s=$(date +%s%N); "$@" >/dev/null 2>&1 || true; ts+=($(( $(date +%s%N) - s ))); done; printf '%s\n' "${ts[@]}" | sort -n | sed -n 3p | awk '{printf "%.9f", $1/1e9}'; }
row whole-process 1 "$(wc -c < "$F")" "dcfchk" "$(wall "$ODC" check "$F")" "$(wall "$WORK/venv/bin/dcfchk" "$F")"
# Every file python-canopen reads, one process each, best of three: `odc check` (all rules,
# human diagnostics) against `canopen.import_od` on each file.
L="$WORK/eds-python-canopen.list"
best3() { local ts=(); for _ in 1 2 3; do local s; s=$(date +%s%N); "$@" >/dev/null 2>&1 || true; ts+=($(( $(date +%s%N) - s ))); done; printf '%s\n' "${ts[@]}" | sort -n | sed -n 1p | awk '{printf "%.9f", $1/1e9}'; }
mapfile -t PYFILES < "$L"
row whole-process-many "$(n "$L")" "$(bytes "$L")" "python-canopen" \
  "$(best3 "$ODC" check "${PYFILES[@]}")" "$(best3 "$PY" "$BENCH/py/import_all.py" "$L")"

log "PDO pack/unpack (criterion, then callgrind)"
# Every loop aligned to 64 bytes, in a target directory of its own (the parse harness keeps
# its flags): each pass is a loop of about ten instructions, and where the linker happened to
# put it moved it by up to 35% (odc's and the hand-written pack loop were the same
# instructions, timed 508 and 377 ns, in one build).
PACK_ENV=(env RUSTFLAGS="-C llvm-args=-align-loops=64" CARGO_TARGET_DIR="$CARGO_TARGET_DIR/pack-aligned")
"${PACK_ENV[@]}" cargo bench --locked --manifest-path "$BENCH/Cargo.toml" --bench pack --no-run \
  > "$WORK/pack-build.txt" 2>&1
PACK_BIN=$(sed -n 's/.*Executable .*(\(.*\))$/\1/p' "$WORK/pack-build.txt" | tail -1)
[ -x "$PACK_BIN" ] || { log "no pack bench binary in $WORK/pack-build.txt"; exit 1; }
# Criterion's clock is the thread's CPU time here (benches/pack.rs), and neighbours on a shared
# machine only ever add time to a batch of passes: the bench runs PACK_RUNS times and each
# function's figure is its least time per pass over every sample of every run
# (py/criterion_least.py). criterion's own medians are kept in $WORK/pack.txt.
PACK_RUNS=${PACK_RUNS:-3}
: > "$WORK/pack.txt"
: > "$WORK/pack-least.tsv"
for _ in $(seq "$PACK_RUNS"); do
  rm -rf "$CARGO_TARGET_DIR/criterion"/{pack,unpack}_*
  (cd "$BENCH" && "$PACK_BIN" --bench --noplot) >> "$WORK/pack.txt" 2>&1
  python3 "$BENCH/py/criterion_least.py" "$CARGO_TARGET_DIR/criterion" >> "$WORK/pack-least.tsv"
done
awk -F'\t' '!($1 in m) || $2 < m[$1] {m[$1] = $2} END {for (n in m) printf "%s\t%.3f\n", n, m[n]}' \
  "$WORK/pack-least.tsv" | sort > "$WORK/pack.tsv"
pk() { awk -F'\t' -v t="$1" '$1==t {print $2/1e9}' "$WORK/pack.tsv"; }
for op in pack_rpdo2_x1024 unpack_tpdo2_x1024; do
  for other in hand deku packed_struct; do
    row "$op" 1024 "$((1024 * 6))" "$other" "$(pk "$op/odc")" "$(pk "$op/$other")"
  done
done
# Instructions a pass executes (callgrind, counting only inside the pass function): the same
# binary and code as timed above, a figure no neighbour disturbs. The passes the harness runs
# to check the tools agree are taken off by counting a run of 0 passes too.
if command -v valgrind >/dev/null 2>&1; then
  PASSES=100
  ir() { # OP TOOL PASSES: instructions executed inside pass_OP_TOOL
    local out="$WORK/callgrind.$1.$2.$3"
    ODC_PACK_COUNT="$1 $2 $3" valgrind --tool=callgrind --callgrind-out-file="$out" \
      --toggle-collect="*pass_$1_$2" "$PACK_BIN" > /dev/null 2>&1
    awk '/^summary:/ {print $2}' "$out"
  }
  irpass() { local a b; a=$(ir "$1" "$2" "$PASSES"); b=$(ir "$1" "$2" 0); echo $(( (a - b) / PASSES )); }
  for op in pack unpack; do
    set=$([ "$op" = pack ] && echo pack_rpdo2_x1024 || echo unpack_tpdo2_x1024)
    odc=$(irpass "$op" odc)
    for other in hand deku packed_struct; do
      row "$set" 1024 "$((1024 * 6))" "$other" "$odc" "$(irpass "$op" "$other")" Ir
    done
  done
else
  log "valgrind not found: no instruction counts for pack/unpack (Debian: apt-get install valgrind)"
fi

if [ "$BUILD_COST" = 1 ]; then
  log "build cost (cold builds: a few minutes)"
  DEV="$ROOT/eds/lenze-e94aycca.eds" # the largest device file of eds/
  BC="$WORK/buildcost"
  rm -rf "$BC"
  mkdir -p "$BC/with-odc/src" "$BC/checked-in/src"
  for c in with-odc checked-in; do
    cat > "$BC/$c/Cargo.toml" <<EOF
[package]
name = "device-$c"
version = "0.1.0"
edition = "2024"
[workspace]
[dependencies]
odc = { path = "$ROOT/crates/odc" }
EOF
    cp "$ROOT/Cargo.lock" "$BC/$c/Cargo.lock"
  done
  cat >> "$BC/with-odc/Cargo.toml" <<EOF
[build-dependencies]
odc-build = { path = "$ROOT/crates/odc-build" }
EOF
  cp "$DEV" "$BC/with-odc/device.eds"
  cat > "$BC/with-odc/build.rs" <<'EOF'
fn main() -> Result<(), odc_build::Error> {
    odc_build::Config::new().device("device.eds").compile()
}
EOF
  echo 'pub mod device { include!(concat!(env!("OUT_DIR"), "/device.rs")); }' > "$BC/with-odc/src/lib.rs"
  "$ODC" generate "$DEV" -o "$BC/checked-in/src/device.rs" 2>/dev/null
  echo 'pub mod device { include!("device.rs"); }' > "$BC/checked-in/src/lib.rs"
  # A build that fails stops the script: its time would mean nothing.
  secs() { local s; s=$(date +%s%N); "$@" >/dev/null 2>&1 || { log "failed: $*"; return 1; }; awk -v d=$(( $(date +%s%N) - s )) 'BEGIN {printf "%.3f", d/1e9}'; }
  b1=$(CARGO_TARGET_DIR="$BC/with-odc/target" secs cargo build --manifest-path "$BC/with-odc/Cargo.toml")
  b2=$(CARGO_TARGET_DIR="$BC/checked-in/target" secs cargo build --manifest-path "$BC/checked-in/Cargo.toml")
  touch "$BC/with-odc/device.eds"
  c1=$(CARGO_TARGET_DIR="$BC/with-odc/target" secs cargo check --manifest-path "$BC/with-odc/Cargo.toml")
  touch "$BC/checked-in/src/device.rs"
  c2=$(CARGO_TARGET_DIR="$BC/checked-in/target" secs cargo check --manifest-path "$BC/checked-in/Cargo.toml")
  row build-cold 1 "$(wc -c < "$DEV")" "checked-in file" "$b1" "$b2"
  row check-after-touch 1 "$(wc -c < "$DEV")" "checked-in file" "$c1" "$c2"
fi

# ---- the table ---------------------------------------------------------------------------
echo
echo "odc compare: $(date -u +%Y-%m-%dT%H:%MZ), $(nproc) cores, $(grep -m1 'model name' /proc/cpuinfo | cut -d: -f2 | sed 's/^ //'), load $(cut -d' ' -f1-3 /proc/loadavg)"
echo "odc $(git -C "$ROOT" rev-parse --short HEAD); python-canopen $("$PY" -c 'import canopen; print(canopen.__version__)'); dcf-tools $("$PY" -m pip show dcf-tools 2>/dev/null | awk '/^Version/ {print $2}'); lely-core: $LELY_CORE"
echo "Times: CPU time of one in-process pass (parse), thread CPU time of 1024 values (pack: least of criterion's samples over $PACK_RUNS runs; Ir: instructions of one pass under callgrind), wall time (whole process, build)."
echo "ratio = other / odc (how many times faster odc is); for floor and quick-xml (ceilings), odc / other."
echo
awk -F'\t' '
  function t(x, unit) {
    if (unit == "Ir") return sprintf("%d Ir", x)
    if (x >= 1) return sprintf("%.3f s", x)
    if (x >= 1e-3) return sprintf("%.3f ms", x * 1e3)
    if (x >= 1e-6) return sprintf("%.3f us", x * 1e6)
    return sprintf("%.1f ns", x * 1e9)
  }
  BEGIN {
    printf "| %-22s | %5s | %9s | %-16s | %12s | %12s | %9s |\n", "input", "files", "bytes", "vs", "odc", "other", "ratio"
    printf "|%s|%s|%s|%s|%s|%s|%s|\n", "------------------------", "------:", "----------:", "------------------", "-------------:", "-------------:", "----------:"
  }
  {
    ceiling = ($4 == "floor" || $4 == "quick-xml")
    r = ceiling ? (($6 > 0) ? $5 / $6 : 0) : (($5 > 0) ? $6 / $5 : 0)
    printf "| %-22s | %5s | %9s | %-16s | %12s | %12s | %8.2fx |\n", $1, $2, $3, $4, t($5, $7), t($6, $7), r
  }' "$ROWS"
