#!/usr/bin/env bash
# Runs one fuzz target for a time: ./run.sh TARGET [SECONDS] [extra libFuzzer flags...]
# Stable Rust is enough: RUSTC_BOOTSTRAP=1 lets cargo-fuzz pass its -Z flags (sanitizer,
# coverage) to the stable compiler. Crashes go to artifacts/TARGET/; with -fork=1
# -ignore_crashes=1 (default here) the run goes on after one and keeps them all.
# The last line printed is libFuzzer's summary: "Done N runs in S second(s)" or the stats line.
set -euo pipefail
cd "$(dirname "$0")"
target=${1:?usage: ./run.sh TARGET [SECONDS] [libFuzzer flags...]}
secs=${2:-300}
shift $(( $# >= 2 ? 2 : 1 ))
max_len=65536
case $target in
  eds_*) dict=(-dict=dict/eds.dict) ;;
  esi_*|xdd_*) dict=(-dict=dict/xml.dict) ;;
  # Bus targets: an input is a sequence of steps; 4 KiB is hundreds of frames.
  node|sdo_server|lss_slave) dict=(-dict=corpus/frames.dict); max_len=4096 ;;
  candump) max_len=4096 ;;
  *) dict=() ;;
esac
[ -d "corpus/$target" ] && [ -f corpus/frames.dict ] || ./seed.sh >/dev/null
unset CARGO_TARGET_DIR
export RUSTC_BOOTSTRAP=1
cargo fuzz build "$target"
cargo fuzz run "$target" -- -max_total_time="$secs" -max_len="$max_len" -timeout=10 \
  -rss_limit_mb=2048 -fork=1 -ignore_crashes=1 ${dict[@]+"${dict[@]}"} "$@"
