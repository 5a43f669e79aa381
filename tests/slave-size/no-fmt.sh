#!/usr/bin/env bash
# Fails when a firmware image links any of `core::fmt`: the node, the SDO server and the
# dictionary have no reachable panic (a bounds check, unwrap or formatting would pull in
# core::fmt, about 3 KB of flash), so an image built from them has no such symbol.
#
#   tests/slave-size/no-fmt.sh IMAGE...
#
# .ci/run passes the release build of tests/no-std/examples/firmware.rs and the node images
# tests/slave-size/run.sh keeps in target/slave-size/images/. Symbols are read with `nm` of
# the host's binutils (it reads the thumbv7em ELF) or, when set, $NM (llvm-nm,
# arm-none-eabi-nm).
set -euo pipefail
[ $# -gt 0 ] || { echo "usage: $0 IMAGE..." >&2; exit 2; }
NM=${NM:-nm}
command -v "$NM" >/dev/null || { echo "no $NM (binutils or llvm-tools)" >&2; exit 2; }
status=0
for img in "$@"; do
    [ -f "$img" ] || { echo "$img: no such image" >&2; exit 2; }
    total=$("$NM" "$img" | wc -l)
    [ "$total" -gt 0 ] || { echo "$img: no symbols (stripped?)" >&2; exit 2; }
    # Legacy and v0 mangling both spell the path as length-prefixed parts: 4core3fmt.
    fmt=$("$NM" "$img" | grep -E '4core3fmt|core::fmt' || true)
    if [ -n "$fmt" ]; then
        echo "FAIL $img: $(grep -c . <<<"$fmt") core::fmt symbols of $total, e.g.:"
        "$NM" -C "$img" | grep -E 'core::fmt' | head -5 | sed 's/^/    /'
        status=1
    else
        echo "ok   $img: no core::fmt symbol ($total symbols)"
    fi
done
exit $status
