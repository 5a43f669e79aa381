#!/usr/bin/env bash
# Fills fuzz/corpus/<target>/ with seed inputs: the device files under eds/ and esi/, the
# front-ends' test fixtures and the malformed suite. With --corpus, also the files of
# $ODC_CORPUS (default ../shared/corpus) smaller than 64 KiB. The corpora are not committed.
# The bus targets take real frames: the candump logs of tests/devices/logs (the frames the five
# device manuals print) seed `candump`, and their payloads become corpus/frames.dict, the
# libFuzzer dictionary of `node`, `sdo_server` and `lss_slave` (their inputs are structured,
# so a frame goes in as a dictionary word, not as a file).
set -euo pipefail
cd "$(dirname "$0")"
root=..
mkdir -p corpus/eds_parse corpus/eds_roundtrip corpus/esi_parse corpus/xdd_parse corpus/pdo_pack \
  corpus/node corpus/sdo_server corpus/lss_slave corpus/candump
eds_seeds=(
  "$root"/eds/*.eds
  "$root"/crates/odc-eds/tests/fixtures/*
  "$root"/crates/odc-eds/tests/invalid/*
  "$root"/crates/odc-cli/tests/fixtures/*.eds
)
esi_seeds=("$root"/esi/*.xml "$root"/crates/odc-esi/tests/fixtures/*.xml)
if [ -d "$root/tests/malformed/files" ]; then
  eds_seeds+=("$root"/tests/malformed/files/eds/*)
  esi_seeds+=("$root"/tests/malformed/files/esi/*)
fi
xdd_seeds=("$root"/tests/malformed/files/xdd/*)
if [ "${1:-}" = "--corpus" ]; then
  corpus="${ODC_CORPUS:-$root/../shared/corpus}"
  while IFS= read -r f; do eds_seeds+=("$f"); done \
    < <(find "$corpus/eds" -type f \( -iname '*.eds' -o -iname '*.dcf' \) -size -64k)
  while IFS= read -r f; do esi_seeds+=("$f"); done \
    < <(find "$corpus/esi" -type f -iname '*.xml' -size -64k)
  while IFS= read -r f; do xdd_seeds+=("$f"); done \
    < <(find "$corpus/eds" -type f \( -iname '*.xdd' -o -iname '*.xdc' \) -size -64k)
fi
for f in "${eds_seeds[@]}"; do
  [ -f "$f" ] || continue
  cp "$f" corpus/eds_parse/ && cp "$f" corpus/eds_roundtrip/
done
for f in "${esi_seeds[@]}"; do
  [ -f "$f" ] && cp "$f" corpus/esi_parse/
done
for f in "${xdd_seeds[@]}"; do
  [ -f "$f" ] && cp "$f" corpus/xdd_parse/
done
printf '\x00\x00\x00\x00\x00\x00\x00\x00\x00\x00' > corpus/pdo_pack/zeros
printf '\x01\xff\xff\xff\xff\xff\xff\xff\xff\xff\xff\xff\xff\xff\xff\xff\xff\xff\xff\xff\xff\xff\xff\xff\xff\xff\xff\xff\xff\xff\xff\xff\xff\xff\xff\xff\xff\xff\xff\xff\xff\xff' > corpus/pdo_pack/ones
logs=("$root"/tests/devices/logs/*.log)
cp "${logs[@]}" corpus/candump/
# Every distinct payload of the logs, as libFuzzer dictionary words ("\x43\x00...").
cat "${logs[@]}" | sed -n 's/^([0-9.]*) [^ ]* [0-9A-Fa-f]*#\([0-9A-Fa-f]\{2,16\}\)$/\1/p' | sort -u |
  sed 's/\(..\)/\\x\1/g; s/^/"/; s/$/"/' > corpus/frames.dict
echo "corpus/frames.dict: $(wc -l < corpus/frames.dict) words"
for t in corpus/*/; do echo "$t: $(ls "$t" | wc -l) files"; done
