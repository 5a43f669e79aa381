#!/usr/bin/env bash
# Generates the code of every device of the corpus with `odc generate` and compiles it with
# `cargo check` and `cargo clippy -- -D warnings` (RUSTFLAGS=-Dwarnings). See README.md.
#
#   tests/corpus-codegen/run.sh [--sample N] [--batch M] [--role both|slave|master]
#                               [--compile-only | --resume] [--odc PATH]
set -uo pipefail

ROOT=$(cd "$(dirname "${BASH_SOURCE[0]}")/../.." && pwd)
CORPUS=${ODC_CORPUS:-$ROOT/../shared/corpus}
SAMPLE=0
BATCH=100
ROLE=both
COMPILE_ONLY=0
RESUME=0
ODC=
while [ $# -gt 0 ]; do
    case $1 in
        --sample) SAMPLE=$2; shift 2 ;;
        --batch) BATCH=$2; shift 2 ;;
        --role) ROLE=$2; shift 2 ;;
        --compile-only) COMPILE_ONLY=1; shift ;;
        --resume) COMPILE_ONLY=1; RESUME=1; shift ;;
        --odc) ODC=$2; shift 2 ;;
        -h|--help) sed -n 2,5p "$0"; exit 0 ;;
        *) echo "unknown argument: $1" >&2; exit 2 ;;
    esac
done
CORPUS=$(cd "$CORPUS" 2>/dev/null && pwd) || { echo "no corpus at ${ODC_CORPUS:-$ROOT/../shared/corpus}" >&2; exit 2; }
[ -f "$CORPUS/MANIFEST.tsv" ] || { echo "no $CORPUS/MANIFEST.tsv" >&2; exit 2; }

WORK=$ROOT/target/corpus-codegen
if [ -z "$ODC" ]; then
    ODC=${CARGO_TARGET_DIR:-$ROOT/target}/release/odc
    (cd "$ROOT" && cargo build -q --release -p odc-cli) || { echo "cannot build odc-cli" >&2; exit 2; }
fi
ODC=$(cd "$(dirname "$ODC")" && pwd)/$(basename "$ODC")
[ -x "$ODC" ] || { echo "no odc binary at $ODC" >&2; exit 2; }
n_files=0 n_devices=0 n_lowerable=0 n_generated=0 n_unlowerable_files=0
LOG=$WORK/failures.tsv          # module, file, device, stage, first error
ORIGINS=$WORK/batches/origins.tsv  # module, file, device
declare -A ORIGIN                # module -> "file#device"
if [ "$COMPILE_ONLY" = 1 ]; then
    [ -f "$ORIGINS" ] || { echo "nothing generated yet under $WORK/batches" >&2; exit 2; }
    # Keep the generation failures of the last run, forget its compile failures.
    awk -F'\t' '$4 == "generate"' "$LOG" >"$LOG.tmp" 2>/dev/null; mv "$LOG.tmp" "$LOG"
    while IFS=$'\t' read -r m f d; do ORIGIN[$m]="$f#$d"; done <"$ORIGINS"
    read -r n_files n_unlowerable_files n_devices n_lowerable n_generated <"$WORK/batches/counts"
else
rm -rf "$WORK/batches"
mkdir -p "$WORK/batches"
: >"$LOG"
: >"$ORIGINS"

mapfile -t FILES < <(awk -F'\t' 'NR > 1 && ($2 == "eds" || $2 == "dcf" || $2 == "esi") { print $2 "\t" $1 }' "$CORPUS/MANIFEST.tsv")
STEP=1
if [ "$SAMPLE" -gt 0 ]; then
    # About 5 devices per ESI file, 1 per EDS/DCF: every k-th file gives about N devices.
    est=0
    for row in "${FILES[@]}"; do case ${row%%$'\t'*} in esi) est=$((est + 5)) ;; *) est=$((est + 1)) ;; esac; done
    STEP=$(( est / SAMPLE )); [ "$STEP" -lt 1 ] && STEP=1
fi

batch=-1 in_batch=$BATCH
new_batch() {
    batch=$((batch + 1)); in_batch=0
    local dir; dir=$(printf '%s/batches/b%03d' "$WORK" "$batch")
    mkdir -p "$dir/src"
    cat >"$dir/Cargo.toml" <<EOF
[package]
name = "corpus-codegen-b$(printf %03d "$batch")"
version = "0.0.0"
edition = "2024"
publish = false

[dependencies]
odc = { path = "$ROOT/crates/odc" }

[features]
# The generated pdi and startup modules of ESI devices implement the ethercrab traits with it.
ethercrab = ["odc/ethercrab"]

[lints.rust]
missing_docs = "warn"

[lints.clippy]
unwrap_used = "warn"
expect_used = "warn"
panic = "warn"
dbg_macro = "warn"

[workspace]
EOF
    printf '//! Generated code of corpus devices, batch %d.\n#![no_std]\n' "$batch" >"$dir/src/lib.rs"
    BATCH_DIR=$dir
}

# Prints the --device selectors of a file's devices, one a line; fails on front-end errors.
# The CLI takes either an index (from 0) or `PRODUCT[:REVISION]`/a name, by version.
if "$ODC" generate --help | grep -q 'PRODUCT\[:REVISION\]'; then BY_INDEX=0; else BY_INDEX=1; fi
# The checker's findings are not this run's business (the compile of what the front-end can
# read is): where `generate` applies the checker's error gate, its groups are allowed.
ALLOW=()
if "$ODC" generate --help | grep -q -- '--allow'; then ALLOW=(--allow cia301 --allow cia402 --allow etg); fi
PROBE=$WORK/probe.rs
devices_of() {
    local msg
    if [ "$BY_INDEX" = 1 ]; then
        msg=$("$ODC" generate "$1" --device 999999 -o "$PROBE" 2>&1 >/dev/null)
        [[ $msg =~ the\ file\ describes\ ([0-9]+) ]] || return 1
        seq 0 $((BASH_REMATCH[1] - 1))
        return 0
    fi
    msg=$("$ODC" generate "$1" "${ALLOW[@]}" -o "$PROBE" 2>&1 >/dev/null) && { echo ""; return 0; }
    [[ $msg == *"choose one with --device"* ]] || return 1
    # `  0x044C2C52:0x00010000  EK1100 EtherCAT Coupler (2A E-Bus)  (0 PDOs)`
    sed -nE 's/^  (0x[0-9A-F]{8}|-):(0x[0-9A-F]{8}|-)  (.*)  \([0-9]+ PDOs\)$/\1\t\2\t\3/p' <<<"$msg" |
        while IFS=$'\t' read -r product revision name; do
            if [ "$product" = - ]; then echo "$name"
            elif [ "$revision" = - ]; then echo "$product"
            else echo "$product:$revision"; fi
        done
}

i=0
for row in "${FILES[@]}"; do
    i=$((i + 1))
    [ $(( (i - 1) % STEP )) -eq 0 ] || continue
    [ "$SAMPLE" -gt 0 ] && [ "$n_devices" -ge "$SAMPLE" ] && break
    kind=${row%%$'\t'*} file=${row#*$'\t'}
    path=$CORPUS/$file
    n_files=$((n_files + 1))
    # The devices: one selector per line ("" for the only one), or none on front-end errors.
    if ! selectors=$(devices_of "$path"); then
        n_unlowerable_files=$((n_unlowerable_files + 1))
        count=1
        if [ "$kind" = esi ]; then
            # The front-end gave up: count the <Device> elements instead; none is lowerable.
            count=$(grep -o '<Device[ >]' "$path" | wc -l); [ "$count" -lt 1 ] && count=1
        fi
        n_devices=$((n_devices + count))
        continue
    fi
    while IFS= read -r sel; do
        n_devices=$((n_devices + 1)); n_lowerable=$((n_lowerable + 1))
        [ "$in_batch" -ge "$BATCH" ] && new_batch
        module=$(printf 'd%04d' "$n_devices")
        out=$BATCH_DIR/src/$module.rs
        args=(generate "$path" "${ALLOW[@]}" --role "$ROLE" -o "$out")
        [ -n "$sel" ] && args+=(--device "$sel")
        err=$("$ODC" "${args[@]}" 2>&1 >/dev/null)
        if [ $? -eq 0 ] && [ -s "$out" ]; then
            n_generated=$((n_generated + 1)); in_batch=$((in_batch + 1))
            printf '/// %s, device %s.\npub mod %s;\n' "$file" "${sel:-0}" "$module" >>"$BATCH_DIR/src/lib.rs"
            ORIGIN[$module]="$file#${sel:-0}"
            printf '%s\t%s\t%s\n' "$module" "$file" "${sel:-0}" >>"$ORIGINS"
        else
            rm -f "$out"
            first=$(grep -m1 -E '^(error|warning)' <<<"$err")
            printf '%s\t%s\t%s\tgenerate\t%s\n' "$module" "$file" "${sel:-0}" "${first:-$err}" >>"$LOG"
        fi
    done <<<"$selectors"
done
echo "$n_files $n_unlowerable_files $n_devices $n_lowerable $n_generated" >"$WORK/batches/counts"
echo "generated $n_generated modules in $((batch + 1)) crate(s) under $WORK/batches" >&2
fi

# Compile: one shared target directory for every batch, apart from the workspace's (other
# RUSTFLAGS would rebuild the workspace's dependencies there).
# No incremental cache: every crate is compiled once, and the caches of a full run take
# gigabytes.
export CARGO_TARGET_DIR=$WORK/target RUSTFLAGS=-Dwarnings CARGO_INCREMENTAL=0
declare -A BAD
# Compiles batch $1 at stage $2 (check, clippy, or ethercrab: clippy with the runtime's feature
# `ethercrab`) and prints the messages; with --resume, the
# log of an earlier run instead when there is one.
compile_stage() {
    local dir=$1 stage=$2 out cmd
    if [ "$RESUME" = 1 ] && [ -f "$dir/$stage.log" ]; then
        cat "$dir/$stage.log"
        return
    fi
    case $stage in
        check) cmd=(cargo check -q --message-format short) ;;
        clippy) cmd=(cargo clippy -q --message-format short -- -D warnings) ;;
        *) cmd=(cargo clippy -q --message-format short --features ethercrab -- -D warnings) ;;
    esac
    # cargo sometimes fails to start rustc when the machine is loaded: try again.
    for attempt in 1 2 3; do
        out=$(cd "$dir" && "${cmd[@]}" 2>&1)
        grep -q 'failed to run `rustc`' <<<"$out" || break
        sleep 10
    done
    printf '%s\n' "$out" | tee "$dir/$stage.log"
}
for dir in "$WORK"/batches/b*/; do
    for stage in check clippy ethercrab; do
        out=$(compile_stage "$dir" "$stage")
        # `src/d0001.rs:12:5: error: ...`: the first error of each module not already failed.
        while IFS= read -r line; do
            [[ $line =~ ^src/(d[0-9]+)\.rs:[0-9]+:[0-9]+:\ error ]] || continue
            m=${BASH_REMATCH[1]}
            [ -n "${BAD[$m]:-}" ] && continue
            BAD[$m]=$stage
            o=${ORIGIN[$m]:-?#?}
            printf '%s\t%s\t%s\t%s\t%s\n' "$m" "${o%#*}" "${o##*#}" "$stage" "${line#src/}" >>"$LOG"
        done <<<"$out"
        # An error outside any module (the crate itself): record it against the batch.
        if ! grep -qE '^src/d[0-9]+\.rs:' <<<"$out" && grep -q '^error' <<<"$out"; then
            printf '%s\t-\t-\t%s\t%s\n' "$(basename "$dir")" "$stage" "$(grep -m1 '^error' <<<"$out")" >>"$LOG"
            # rustc crashed or gave up on the crate: none of its modules is known to be clean.
            for f in "$dir"src/d*.rs; do
                m=$(basename "$f" .rs)
                [ -n "${BAD[$m]:-}" ] || BAD[$m]=$stage
            done
        fi
    done
done
n_check_bad=0 n_clippy_bad=0 n_ethercrab_bad=0
for m in "${!BAD[@]}"; do
    case ${BAD[$m]} in
        check) n_check_bad=$((n_check_bad + 1)) ;;
        clippy) n_clippy_bad=$((n_clippy_bad + 1)) ;;
        ethercrab) n_ethercrab_bad=$((n_ethercrab_bad + 1)) ;;
    esac
done
n_gen_bad=$(awk -F'\t' '$4 == "generate"' "$LOG" | wc -l)

sampled=""; [ "$SAMPLE" -gt 0 ] && sampled=", 1 file in $STEP"
echo "corpus:                  $CORPUS (role $ROLE$sampled)"
echo "files:                   $n_files ($n_unlowerable_files with front-end errors)"
echo "devices:                 $n_devices"
echo "lowerable devices:       $n_lowerable"
echo "generated:               $n_generated ($n_gen_bad codegen failures)"
echo "cargo check clean:       $((n_generated - n_check_bad))"
echo "clippy -D warnings clean: $((n_generated - n_check_bad - n_clippy_bad))"
echo "  and with ethercrab:    $((n_generated - n_check_bad - n_clippy_bad - n_ethercrab_bad))"
if [ -s "$LOG" ]; then
    echo "failures ($LOG):"
    sort -t$'\t' -k4,4 -k5,5 "$LOG" | awk -F'\t' '{ printf "  %-8s %-9s %s#%s: %s\n", $1, $4, $2, $3, $5 }'
    exit 1
fi
