#!/usr/bin/env bash
# Measures the memory the generated slave dictionary of a device takes in a firmware image:
# builds a `#![no_std]` program for a 32-bit bare-metal target that holds the dictionary in a
# static and answers SDO reads and writes, links it (rust-lld, --gc-sections), and prints
# .text/.rodata/.data/.bss against the same program without a dictionary. See README.md.
# With --node, four lines per file: the dictionary alone, and the dictionary in an
# odc::node::Node (NMT, heartbeat producer and consumer, SYNC consumer, 4+4 PDOs, EMCY, SDO
# server with a 32-byte buffer) built with three sets of odc's features:
#   node         none of the optional services;
#   canopennode  the services of CANopenNode's measured build (canopen-tools.md §5): LSS
#                slave and SYNC producer (odc features lss-slave, sync-producer);
#   all          every service: also SDO block transfer and node guarding (sdo-block,
#                guarding).
# Each image is kept as target/slave-size/images/FILE.MODE.elf (for no-fmt.sh).
#
#   tests/slave-size/run.sh [--target TRIPLE] [--odc PATH] [--node] FILE...
set -euo pipefail

ROOT=$(cd "$(dirname "${BASH_SOURCE[0]}")/../.." && pwd)
TARGET=thumbv7em-none-eabihf
FILES=()
NODE=0
ODC=
while [ $# -gt 0 ]; do
    case $1 in
        --target) TARGET=$2; shift 2 ;;
        --node) NODE=1; shift ;;
        --odc) ODC=$2; shift 2 ;;
        -h|--help) sed -n 2,17p "$0"; exit 0 ;;
        *) FILES+=("$1"); shift ;;
    esac
done
[ ${#FILES[@]} -gt 0 ] || { echo "usage: $0 [--target TRIPLE] [--odc PATH] [--node] FILE..." >&2; exit 2; }
rustup target list --installed 2>/dev/null | grep -qx "$TARGET" ||
    { echo "target $TARGET is not installed (rustup target add $TARGET)" >&2; exit 2; }

WORK=$ROOT/target/slave-size
if [ -z "$ODC" ]; then
    ODC=${CARGO_TARGET_DIR:-$ROOT/target}/release/odc
    (cd "$ROOT" && cargo build -q --release -p odc-cli) || { echo "cannot build odc-cli" >&2; exit 2; }
fi
mkdir -p "$WORK/src" "$WORK/images"
cat >"$WORK/Cargo.toml" <<TOML
[package]
name = "slave-size"
version = "0.0.0"
edition = "2024"
publish = false

[dependencies]
odc = { path = "$ROOT/crates/odc", default-features = false, features = ["derive"] }

[features]
## Without it the program is the baseline: the same SDO entry points, no dictionary.
device = []
## The dictionary in a node (NMT, heartbeat, SYNC consumer, PDOs, EMCY, SDO server).
node = ["device"]
## The node with its LSS slave.
lss = ["node", "odc/lss-slave"]
## The services of CANopenNode's measured build: LSS slave, SYNC producer.
canopennode = ["lss", "odc/sync-producer"]
## Every service odc has: also SDO block transfer and node guarding.
all = ["canopennode", "odc/sdo-block", "odc/guarding"]

[profile.release]
opt-level = "s"
codegen-units = 1
panic = "abort"
debug = false

[workspace]
TOML
cat >"$WORK/src/main.rs" <<'RS'
//! A firmware image that holds one generated slave dictionary and answers SDO transfers.
#![no_std]
#![no_main]

use core::mem::MaybeUninit;
use core::panic::PanicInfo;

#[cfg(feature = "device")]
#[allow(missing_docs, dead_code)]
mod dev {
    include!("dev.rs");
}

#[cfg(feature = "device")]
type Dict = dev::slave::Dictionary;

/// Stand-in for a device without dictionary: answers every request with an abort.
#[cfg(not(feature = "device"))]
struct Dict;
#[cfg(not(feature = "device"))]
impl Dict {
    fn new(_: Option<odc::cob::NodeId>) -> Self {
        Dict
    }
    fn read(&self, _: u16, _: u8, _: &mut [u8]) -> Result<usize, odc::SdoAbort> {
        Err(odc::SdoAbort::NoSuchObject)
    }
    fn write(&mut self, _: u16, _: u8, _: &[u8]) -> Result<(), odc::SdoAbort> {
        Err(odc::SdoAbort::NoSuchObject)
    }
}

/// The dictionary's storage, where firmware keeps it: a static.
#[unsafe(no_mangle)]
static mut OD_STORAGE: MaybeUninit<Dict> = MaybeUninit::uninit();

/// Initialises the dictionary for `node_id`.
#[unsafe(no_mangle)]
pub extern "C" fn od_init(node_id: u8) {
    // SAFETY: single-threaded test image; nothing else holds a reference.
    unsafe { (*(&raw mut OD_STORAGE)).write(Dict::new(odc::cob::NodeId::new(node_id))) };
}

/// SDO upload; returns the length, or the abort code negated.
#[unsafe(no_mangle)]
pub extern "C" fn od_read(index: u16, sub: u8, buf: *mut u8, len: usize) -> i64 {
    // SAFETY: the caller passes a valid buffer; od_init ran before.
    let (d, b) = unsafe { ((*(&raw const OD_STORAGE)).assume_init_ref(), core::slice::from_raw_parts_mut(buf, len)) };
    match d.read(index, sub, b) {
        Ok(n) => n as i64,
        Err(e) => -i64::from(e.to_u32()),
    }
}

/// SDO download; returns 0 or the abort code.
#[unsafe(no_mangle)]
pub extern "C" fn od_write(index: u16, sub: u8, data: *const u8, len: usize) -> u32 {
    // SAFETY: as for od_read.
    let (d, b) = unsafe { ((*(&raw mut OD_STORAGE)).assume_init_mut(), core::slice::from_raw_parts(data, len)) };
    match d.write(index, sub, b) {
        Ok(()) => 0,
        Err(e) => e.to_u32(),
    }
}

/// The node: SDO buffer 32 bytes (CANopenNode's default `CO_CONFIG_SDO_SRV_BUFFER_SIZE`),
/// 4 RPDOs and 4 TPDOs (those of the DS301 profile).
#[cfg(feature = "node")]
type TheNode = odc::node::Node<32, 4, 4>;

#[cfg(feature = "node")]
#[unsafe(no_mangle)]
static mut NODE_STORAGE: MaybeUninit<TheNode> = MaybeUninit::uninit();

/// Where the node's frames go: the transmit mailbox of a CAN peripheral.
#[cfg(feature = "node")]
#[unsafe(no_mangle)]
static mut TX_MAILBOX: [u32; 3] = [0; 3];

#[cfg(feature = "node")]
fn tx(f: odc::can::CanFrame) {
    let [a, b, c, d, e, g, h, i] = f.data();
    let words = [f.id() | u32::from(f.is_extended()) << 31 | u32::from(f.is_remote()) << 30, u32::from_le_bytes([a, b, c, d]), u32::from_le_bytes([e, g, h, i])];
    // SAFETY: a static of this single-threaded image; volatile as a peripheral register is.
    unsafe { core::ptr::write_volatile(&raw mut TX_MAILBOX, words) };
}

/// Starts the node (and its dictionary) for `node_id`: boot-up.
#[cfg(feature = "node")]
#[unsafe(no_mangle)]
pub extern "C" fn node_init(node_id: u8) {
    od_init(node_id);
    let node = match odc::cob::NodeId::new(node_id) {
        Some(id) => TheNode::new(id),
        None => TheNode::unconfigured(),
    };
    #[cfg(feature = "lss")]
    let node = node.with_lss(None, 0).with_lss_storage();
    // SAFETY: as for od_read; od_init ran.
    let (n, d) = unsafe { ((*(&raw mut NODE_STORAGE)).write(node), (*(&raw mut OD_STORAGE)).assume_init_mut()) };
    n.start(d, odc::time::Instant::ZERO, &mut tx);
}

/// One received frame; returns whether the node reported anything.
#[cfg(feature = "node")]
#[unsafe(no_mangle)]
pub extern "C" fn node_rx(id: u32, len: u8, data: *const u8, now_us: u64) -> bool {
    let now = odc::time::Instant::from_micros(now_us);
    // SAFETY: as for od_read; node_init ran.
    let (n, d, b) = unsafe { ((*(&raw mut NODE_STORAGE)).assume_init_mut(), (*(&raw mut OD_STORAGE)).assume_init_mut(), core::slice::from_raw_parts(data, usize::from(len.min(8)))) };
    let Some(f) = odc::can::CanFrame::from_slice(id & 0x7FF, b) else { return false };
    n.handle(d, &f, now, &mut tx) != odc::node::Events::default()
}

/// The node's timers.
#[cfg(feature = "node")]
#[unsafe(no_mangle)]
pub extern "C" fn node_poll(now_us: u64) -> bool {
    // SAFETY: as for node_rx.
    let (n, d) = unsafe { ((*(&raw mut NODE_STORAGE)).assume_init_mut(), (*(&raw mut OD_STORAGE)).assume_init_mut()) };
    n.poll(d, odc::time::Instant::from_micros(now_us), &mut tx) != odc::node::Events::default()
}

#[unsafe(no_mangle)]
pub extern "C" fn _start() -> ! {
    od_init(5);
    let mut buf = [0u8; 64];
    let n = od_read(0x1000, 0, buf.as_mut_ptr(), buf.len());
    let _ = od_write(0x1017, 0, buf.as_ptr(), n as usize);
    #[cfg(feature = "node")]
    {
        node_init(5);
        let mut t = 0u64;
        loop {
            t += 1000;
            // SAFETY: reads the mailbox back as a receive FIFO would deliver a frame.
            let [id, lo, hi] = unsafe { core::ptr::read_volatile(&raw const TX_MAILBOX) };
            let ([a, b, c, d], [e, g, h, i]) = (lo.to_le_bytes(), hi.to_le_bytes());
            let data = [a, b, c, d, e, g, h, i];
            node_rx(id, 8, data.as_ptr(), t);
            node_poll(t);
        }
    }
    #[allow(unreachable_code)]
    loop {}
}

#[panic_handler]
fn panic(_: &PanicInfo) -> ! {
    loop {}
}
RS

# `size -A` of the linked image: "section bytes" for the sections that matter.
sections() {
    size -A "$1" | awk '$1 ~ /^\.(text|rodata|data|bss)/ { split($1, p, "."); s[p[2]] += $2 }
        END { printf "%d %d %d %d\n", s["text"], s["rodata"], s["data"], s["bss"] }'
}
build() {  # $1: features ("" or "device"); prints the image path
    local f=()
    [ -n "$1" ] && f=(--features "$1")
    (cd "$WORK" && CARGO_TARGET_DIR=$WORK/target RUSTFLAGS="-C link-arg=--entry=_start" \
        cargo build -q --release --target "$TARGET" "${f[@]}") >&2
    echo "$WORK/target/$TARGET/release/slave-size"
}
printf '%s' "" >"$WORK/src/dev.rs"
read -r bt br bd bb < <(sections "$(build "")")
echo "target $TARGET, opt-level s. Baseline image without dictionary: text $bt, rodata $br, data $bd, bss $bb bytes."
echo "Sections: bytes beyond the baseline. Symbols: the table of rows and the storage."
echo "flash = text + rodata + data, RAM = data + bss."
printf '%-44s %7s | %7s %7s %7s %7s | %7s %7s | %7s %7s' device entries text rodata data bss flash RAM TABLE storage
[ "$NODE" = 1 ] && printf ' %7s' node
printf '\n'
MODES=(device)
[ "$NODE" = 1 ] && MODES=(device node canopennode all)
for file in "${FILES[@]}"; do
    "$ODC" generate "$file" --role slave -o "$WORK/src/dev.rs"
    for mode in "${MODES[@]}"; do
        img=$(build "$mode")
        cp "$img" "$WORK/images/$(basename "$file").$mode.elf"
        read -r t r d b < <(sections "$img")
        sym() {  # the size of the first symbol matching $1, in decimal
            local hex
            hex=$(nm -S "$img" | awk -v re="$1" '$4 ~ re && !n++ { print $2 }')
            echo $((16#${hex:-0}))
        }
        n=$(grep -m1 -oE 'pub static TABLE: [:a-z_]*Table<[0-9]+>' "$WORK/src/dev.rs" | grep -oE '[0-9]+>' | tr -d '>')
        name=$(basename "$file")
        [ "$NODE" = 1 ] && name="$name ($mode)"
        printf '%-44s %7s | %7d %7d %7d %7d | %7d %7d | %7d %7d' "$name" "${n:-0}" \
            $((t - bt)) $((r - br)) $((d - bd)) $((b - bb)) \
            $((t - bt + r - br + d - bd)) $((d - bd + b - bb)) \
            "$(sym 'slave5TABLE')" "$(sym '^OD_STORAGE$')"
        [ "$NODE" = 1 ] && printf ' %7d' "$(sym '^NODE_STORAGE$')"
        printf '\n'
    done
done
