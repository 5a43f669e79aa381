#!/usr/bin/env bash
# Instructions odc's ESI reader executes on the same files at several revisions: callgrind's
# count of one `odc_esi::parse` pass over LIST, which machine load does not disturb (the
# compare.sh ratios are CPU times, which it does). For the question "did odc's reader get
# slower, or was the machine busier?" between two runs of compare.sh.
# Usage: bench/esi-ir.sh LIST REV...   (LIST: one path a line, e.g. target/compare/esi-common.list)
# Each revision is checked out in a worktree under bench/target/esi-ir (removed once built) and
# built in release.
set -euo pipefail
[ $# -ge 2 ] || { echo "usage: bench/esi-ir.sh LIST REV..." >&2; exit 2; }
LIST=$(realpath "$1"); shift
cd "$(dirname "$0")"
command -v valgrind >/dev/null || { echo "esi-ir.sh: valgrind is needed" >&2; exit 2; }
WORK=$PWD/target/esi-ir
mkdir -p "$WORK"
for rev in "$@"; do
  sha=$(git rev-parse --short "$rev^{commit}")
  tree="$WORK/tree-$sha" crate="$WORK/crate-$sha"
  git worktree add -q --force --detach "$tree" "$sha"
  mkdir -p "$crate/src"
  cat > "$crate/Cargo.toml" <<EOF
[package]
name = "esi-ir"
version = "0.0.0"
edition = "2024"
publish = false
[dependencies]
odc-esi = { path = "$tree/crates/odc-esi" }
odc-model = { path = "$tree/crates/odc-model" }
[workspace]
EOF
  cat > "$crate/src/main.rs" <<'EOF'
//! One `odc_esi::parse` pass over the files LIST names (read into memory first).
fn main() {
    let list = std::env::args().nth(1).expect("usage: esi-ir LIST");
    let list = std::fs::read_to_string(list).expect("LIST is readable");
    let files: Vec<(&str, Vec<u8>)> = list
        .lines()
        .filter(|l| !l.is_empty())
        .map(|p| (p, std::fs::read(p).expect("every listed file is readable")))
        .collect();
    for (name, bytes) in &files {
        let mut sources = odc_model::Sources::new();
        std::hint::black_box(odc_esi::parse(&mut sources, name, bytes));
    }
}
EOF
  CARGO_TARGET_DIR="$crate/target" cargo build --release --quiet --manifest-path "$crate/Cargo.toml"
  git worktree remove --force "$tree"
  out="$WORK/callgrind.$sha"
  valgrind --tool=callgrind --callgrind-out-file="$out" "$crate/target/release/esi-ir" "$LIST" \
    2>"$out.log"
  printf '%s\t%s Ir\n' "$sha" "$(grep -oP 'Collected : \K[0-9]+' "$out.log")"
done
