#!/usr/bin/env bash
# The EtherCAT firmware's flash and RAM against SOES's for the same device on the same core
# (tests/slave-size/README.md, "EtherCAT"). Run by hand, not by CI:
#
#   tests/slave-size/soes.sh [--odc PATH] [--soes-repo URL|DIR] [--opt-level s|z]
#
# --opt-level: the Rust images' (default s, as gcc's -Os; z for LLVM's smallest, README).
#
# Needs arm-none-eabi-gcc with newlib (Debian: gcc-arm-none-eabi libnewlib-arm-none-eabi),
# git, python3, the thumbv7em-none-eabihf Rust target. Writes under target/slave-size/
# only: SOES's sources (cloned at the commit below), its object list, the images.
#
# Both sides are built the same way: -Os / opt-level "s", sections garbage-collected, the
# same memory map, a 1,024-byte vector table, the same board (an STM32F4's SPI1 by its
# registers, PA4 as chip select, SysTick), measured above an empty image of the same board
# built the same way (tests/ethercat-firmware/examples/empty.rs, soes/empty.c).
set -euo pipefail
cd "$(dirname "$0")/../.."
odc=target/debug/odc
SOES_REPO=https://github.com/OpenEtherCATsociety/SOES
opt=s
while [ $# -gt 0 ]; do
  case "$1" in
    --odc) odc=$2; shift 2 ;;
    --soes-repo) SOES_REPO=$2; shift 2 ;;
    --opt-level) opt=$2; shift 2 ;;
    *) echo "usage: $0 [--odc PATH] [--soes-repo URL|DIR] [--opt-level s|z]" >&2; exit 2 ;;
  esac
done
SOES_REV=6ef7b9415e936c061ad30626ca00004bdde2ac62
out=target/slave-size/soes
src=tests/slave-size/soes
soes=$out/SOES
mkdir -p "$out/gen"
[ -d "$soes/.git" ] || git clone --quiet "$SOES_REPO" "$soes"
git -C "$soes" checkout --quiet "$SOES_REV"
[ -x "$odc" ] || cargo build --quiet -p odc-cli
demo=$soes/applications/linux_lan9252demo
# SOES's object lists written from odc's model: the ServoOne's, with names and without; the
# demo device's without names.
"$odc" dump --format json esi/servoone.xml 2>/dev/null >"$out/servoone.json"
"$odc" dump --format json "$demo/slave.xml" 2>/dev/null >"$out/demo.json"
mkdir -p "$out/gen-no-names" "$out/gen-demo-no-names"
python3 "$src/objects.py" "$out/gen" <"$out/servoone.json"
python3 "$src/objects.py" "$out/gen-no-names" --no-names <"$out/servoone.json"
python3 "$src/objects.py" "$out/gen-demo-no-names" --no-names <"$out/demo.json"

cflags=(-mcpu=cortex-m4 -mthumb -mfloat-abi=hard -mfpu=fpv4-sp-d16 -Os -std=gnu11 -DNDEBUG
  -ffunction-sections -fdata-sections -Wall -Wno-unused-function
  -I "$src/include" -I "$soes/soes" -I "$soes/soes/include/sys/gcc")
ldflags=(-nostartfiles -Wl,--gc-sections -T "$src/link.ld" --specs=nano.specs)
stack=("$soes"/soes/{esc,esc_coe,esc_foe,esc_eoe,esc_eep,ecat_slv}.c
  "$soes/soes/hal/rt-kernel-lan9252/esc_hw.c" "$src/startup.c" "$src/board.c")
arm-none-eabi-gcc "${cflags[@]}" "${ldflags[@]}" -o "$out/empty.elf" \
  "$src/startup.c" "$src/board.c" "$src/empty.c"
# soes IMAGE OBJECTLIST.c INCLUDE_DIR...: SOES with an object list, options and storage
# found in the directories (first match wins), and main.c.
soes_image() {
  local img=$1 list=$2
  shift 2
  local inc=()
  for d in "$@"; do inc+=(-I "$d"); done
  arm-none-eabi-gcc "${cflags[@]}" "${inc[@]}" "${ldflags[@]}" -o "$out/$img" \
    "${stack[@]}" "$src/main.c" "$list"
}
soes_image soes.elf "$out/gen/objectlist.c" "$out/gen" "$src"
soes_image soes-no-names.elf "$out/gen-no-names/objectlist.c" "$out/gen-no-names" "$src"
soes_image soes-demo.elf "$demo/slave_objectlist.c" "$demo"
soes_image soes-demo-no-names.elf "$out/gen-demo-no-names/objectlist.c" "$out/gen-demo-no-names" "$demo"

# odc's images: the ServoOne with and without the CiA 402 drive, the demo device's, the empty
# one.
rust=target/slave-size/ethercat
build() {
  CARGO_PROFILE_RELEASE_OPT_LEVEL=$opt CARGO_PROFILE_RELEASE_CODEGEN_UNITS=1 \
  CARGO_PROFILE_RELEASE_LTO=true CARGO_PROFILE_RELEASE_PANIC=abort CARGO_TARGET_DIR="$rust" \
    cargo build --quiet --locked -p odc-tests-ethercat-firmware --release --target thumbv7em-none-eabihf "$@"
}
bin=$rust/thumbv7em-none-eabihf/release/examples
build --example empty --features firmware
cp "$bin/empty" "$out/odc-empty.elf"
build --example firmware --features firmware
cp "$bin/firmware" "$out/odc-copy.elf"
build --example firmware --features drive
cp "$bin/firmware" "$out/odc-drive.elf"
ODC_FIRMWARE_ESI=$PWD/$demo/slave.xml build --example firmware --features firmware
cp "$bin/firmware" "$out/odc-demo.elf"

# The same two images linked with newlib-nano's mem functions, as SOES's are: the members of
# arm-none-eabi's libc_nano.a (the multilib of SOES's flags) that define memcpy, memcmp and the
# __aeabi_memcpy/memclr/memset entries, passed to the linker as objects, so their strong
# symbols take the place of compiler_builtins' weak ones (an archive would not be searched for
# a symbol already defined). Only the example's link step sees the objects (`cargo rustc`).
nano=$out/nano
mkdir -p "$nano"
nano_members=(lib_a-memcpy.o lib_a-memcmp.o lib_a-aeabi_memcpy.o lib_a-aeabi_memclr.o
  lib_a-aeabi_memset-soft.o)
(cd "$nano" && ar x "$(arm-none-eabi-gcc "${cflags[@]}" -print-file-name=libc_nano.a)" "${nano_members[@]}")
nano_args=()
for o in "${nano_members[@]}"; do nano_args+=(-C "link-arg=$PWD/$nano/$o"); done
build_nano() {
  CARGO_PROFILE_RELEASE_OPT_LEVEL=$opt CARGO_PROFILE_RELEASE_CODEGEN_UNITS=1 \
  CARGO_PROFILE_RELEASE_LTO=true CARGO_PROFILE_RELEASE_PANIC=abort CARGO_TARGET_DIR="$rust" \
    cargo rustc --quiet --locked -p odc-tests-ethercat-firmware --release --target thumbv7em-none-eabihf \
    --example firmware --features firmware -- "${nano_args[@]}"
}
build_nano
cp "$bin/firmware" "$out/odc-copy-nano.elf"
ODC_FIRMWARE_ESI=$PWD/$demo/slave.xml build_nano
cp "$bin/firmware" "$out/odc-demo-nano.elf"
for img in "$out"/odc-{copy,demo}-nano.elf; do
  if nm -C "$img" | grep -q 'compiler_builtins::mem'; then
    echo "$img: compiler_builtins' mem functions still linked" >&2; exit 1
  fi
done

# Bytes of .text, .rodata, .data, .bss (size -A: SysV format).
sections() {
  size -A "$1" | awk '
    $1 == ".text" { t = $2 } $1 == ".rodata" { r = $2 } $1 == ".data" { d = $2 } $1 == ".bss" { b = $2 }
    END { printf "%d %d %d %d\n", t, r, d, b }'
}
row() {
  local name=$1 img=$2 base=$3
  read -r t r d b < <(sections "$img")
  read -r t0 r0 d0 b0 < <(sections "$base")
  local dt=$((t - t0)) dr=$((r - r0)) dd=$((d - d0)) db=$((b - b0))
  printf '| %s | %d | %d | %d | %d | %d | %d |\n' "$name" "$dt" "$dr" "$dd" "$db" \
    $((dt + dr + dd)) $((dd + db))
}
echo "bytes above each side's empty image; flash = .text + .rodata + .data, RAM = .data + .bss"
echo "| image | .text | .rodata | .data | .bss | flash | RAM |"
echo "|---|---:|---:|---:|---:|---:|---:|"
rev=$(git -C "$soes" rev-parse --short HEAD)
row "ServoOne: odc, CiA 402 drive (\`drive\`)" "$out/odc-drive.elf" "$out/odc-empty.elf"
row "ServoOne: odc, process data copied (\`firmware\`)" "$out/odc-copy.elf" "$out/odc-empty.elf"
row "ServoOne: odc, process data copied, newlib-nano's mem functions" "$out/odc-copy-nano.elf" "$out/odc-empty.elf"
row "ServoOne: SOES $rev, process data copied" "$out/soes.elf" "$out/empty.elf"
row "ServoOne: SOES $rev, process data copied, names empty" "$out/soes-no-names.elf" "$out/empty.elf"
row "demo: odc, from the demo's slave.xml" "$out/odc-demo.elf" "$out/odc-empty.elf"
row "demo: odc, newlib-nano's mem functions" "$out/odc-demo-nano.elf" "$out/odc-empty.elf"
row "demo: SOES $rev, its own object list" "$out/soes-demo.elf" "$out/empty.elf"
row "demo: SOES $rev, names empty" "$out/soes-demo-no-names.elf" "$out/empty.elf"
echo "empty images: odc $(sections "$out/odc-empty.elf"), C $(sections "$out/empty.elf") (.text .rodata .data .bss)"
