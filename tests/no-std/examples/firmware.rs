//! A CANopen slave in firmware: the dictionary generated from `eds/lxm23a.eds` (role slave, by
//! this crate's build script), `odc::node::Node`, `odc::cia402::Drive`, a transport over an
//! `embedded_can::nb::Can` driver, a loop. `#![no_std]`, `#![no_main]`, no heap; built for
//! thumbv7em-none-eabihf and run in QEMU (board mps2-an386, a Cortex-M4) by
//! `tests/no-std/qemu.py`, which `.ci/run` calls:
//!
//! ```sh
//! cargo build -p odc-tests-no-std --release --example firmware --features firmware --target thumbv7em-none-eabihf
//! ```
//!
//! The part between the `slave` markers is the program README.md shows (`tests/readme.rs`
//! keeps the two equal). Below it, the board: cortex-m-rt's entry point, SysTick as the
//! millisecond clock, a panic handler, and a stand-in for the HAL's CAN peripheral that plays
//! a scripted bus from a host file through semihosting (the QEMU board has no CAN controller).
#![no_std]
#![no_main]

// slave: begin
use odc::can::CanFrame;
use odc::cia402::Drive;
use odc::cob::NodeId;
use odc::node::Node;
use odc::time::Instant;
use odc::transport::{Bus, embedded_can::NbBus};
use static_cell::StaticCell;

mod lxm23a {
    odc::include_od!("lxm23a"); // build.rs: odc_build::Config::new().device("eds/lxm23a.eds")
}
use lxm23a::slave::Dictionary;

/// The node-ID the device starts with (DIP switches or an LSS master may give another).
const NODE_ID: NodeId = odc::node_id!(5); // checked at compile time: 1..=127

// The dictionary and the node live in statics: the linker places them in .bss, so `size`
// shows what they cost and a RAM overflow is a link error, not a stack crash at run time.
static OD: StaticCell<Dictionary> = StaticCell::new();
static NODE: StaticCell<Node<64>> = StaticCell::new();

/// Runs the node on `can` (the HAL's CAN peripheral) with `clock` (a monotonic timer); never
/// returns. Called once, from the entry point (a second call panics: the statics are taken).
pub fn run<C: embedded_can::nb::Can>(can: C, clock: impl FnMut() -> Instant) -> ! {
    let od = OD.init_with(|| Dictionary::new(NODE_ID));
    let node = NODE.init_with(|| Node::new(NODE_ID));
    let mut drive = Drive::new(); // CiA 402: the power state machine, a simulated axis
    let mut bus = NbBus::new(can, clock);
    let mut bus_errors = 0u32; // what the driver refused: a firmware reports it (EMCY, LED)
    let mut last = bus.now();
    node.start(od, last, &mut |f| bus_errors += u32::from(bus.send(&f).is_err()));
    drive.start(od);
    loop {
        let now = bus.now();
        let received = bus.recv(now); // at once: Ok(None) when nothing came
        let mut out = |f: CanFrame| bus_errors += u32::from(bus.send(&f).is_err());
        let mut events = node.poll(od, now, &mut out);
        match received {
            Ok(Some(frame)) => {
                events.absorb(node.handle(od, &frame, now, &mut out));
                drive.update(od); // an SDO or RPDO may have written the controlword
            }
            Ok(None) => {}
            Err(_) => bus_errors += 1,
        }
        if now != last {
            drive.step(od, now - last);
            last = now;
        }
        if events.reset.is_some() {
            od.reset(node.next_node_id()); // defaults back, in place
            drive = Drive::new();
            drive.start(od);
        }
    }
}
// slave: end

use board::{MS, ScriptCan};
use core::sync::atomic::Ordering;
use cortex_m_rt::{entry, exception};

/// The reset entry point (cortex-m-rt calls it once .bss is zeroed and .data copied).
#[entry]
fn main() -> ! {
    board::paint_stack();
    board::start_systick();
    board::calibrate();
    run(ScriptCan::open(), || {
        odc::time::Instant::from_millis(u64::from(MS.load(Ordering::Relaxed)))
    })
}

/// SysTick, every millisecond: the clock `run` reads.
#[exception]
fn SysTick() {
    MS.fetch_add(1, Ordering::Relaxed);
}

#[panic_handler]
fn panic(_: &core::panic::PanicInfo) -> ! {
    // Under QEMU, end the run with a failure; on a part, a firmware would reset or halt.
    board::exit(cortex_m_semihosting::debug::EXIT_FAILURE)
}

/// The board under QEMU (mps2-an386): clock, stack measure and the scripted bus. None of it is
/// odc's; a HAL provides the clock and the CAN driver on a real part.
mod board {
    use core::sync::atomic::{AtomicU32, Ordering};
    use cortex_m::peripheral::SYST;
    use cortex_m::peripheral::syst::SystClkSource;
    use cortex_m_semihosting::{debug, hio, syscall};
    use embedded_can::{Frame, Id, StandardId};
    use odc::can::CanFrame;
    use static_cell::StaticCell;

    /// mps2-an386's core clock, which SysTick counts (QEMU models 25 MHz).
    const CORE_HZ: u32 = 25_000_000;
    const TICKS_PER_MS: u32 = CORE_HZ / 1000;

    /// Milliseconds since reset, counted by the SysTick exception. It wraps after 49.7 days,
    /// which a QEMU run never reaches; a product's clock must not (the node's time would go
    /// back).
    pub static MS: AtomicU32 = AtomicU32::new(0);

    /// SysTick from the core clock, an exception every millisecond.
    pub fn start_systick() {
        let Some(mut p) = cortex_m::Peripherals::take() else { fail(b"peripherals taken twice\n") };
        p.SYST.set_clock_source(SystClkSource::Core);
        p.SYST.set_reload(TICKS_PER_MS - 1);
        p.SYST.clear_current();
        p.SYST.enable_interrupt();
        p.SYST.enable_counter();
    }

    /// Times a loop of a known number of instructions (`movw`, then 10,000 × `subs`, `bne`:
    /// 20,001) and writes `calibrate TICKS`: the script checks its conversion of ticks into
    /// instructions on it.
    pub fn calibrate() {
        let start = now_ticks();
        #[allow(unsafe_code)]
        // SAFETY: a register-only loop; r0 is declared clobbered.
        unsafe {
            core::arch::asm!(
                "movw r0, #10000",
                "2:",
                "subs r0, #1",
                "bne 2b",
                out("r0") _,
                options(nomem, nostack),
            );
        }
        let ticks = now_ticks() - start;
        if let Ok(mut out) = hio::hstdout() {
            let mut line = Line::new();
            line.text(b"calibrate ");
            line.dec(ticks);
            line.push(b'\n');
            if out.write_all(line.bytes()).is_err() {
                exit(debug::EXIT_FAILURE);
            }
        }
    }

    /// Core clock ticks since reset: milliseconds and the SysTick count, read again when a
    /// millisecond passed between the two reads.
    fn now_ticks() -> u64 {
        loop {
            let ms = MS.load(Ordering::Relaxed);
            let down = SYST::get_current();
            if MS.load(Ordering::Relaxed) == ms {
                return u64::from(ms) * u64::from(TICKS_PER_MS)
                    + u64::from(TICKS_PER_MS - 1 - down);
            }
        }
    }

    /// What the stack is filled with at reset, to find later how deep it went.
    const PAINT: u32 = 0x5AC5_5AC5;

    #[allow(unsafe_code)] // declarations of two linker symbols, whose addresses only are used
    unsafe extern "C" {
        /// cortex-m-rt's linker script: the lowest address the stack may reach (end of .bss).
        static _stack_end: u32;
        /// The initial stack pointer (end of RAM); the stack grows down from it.
        static _stack_start: u32;
    }

    fn stack_bounds() -> (usize, usize) {
        // Addresses of linker symbols, never read through.
        (&raw const _stack_end as usize, &raw const _stack_start as usize)
    }

    /// Fills the free stack below the caller's frame (minus a margin) with `PAINT`.
    #[inline(never)]
    pub fn paint_stack() {
        let (bottom, _) = stack_bounds();
        let sp = cortex_m::register::msp::read() as usize;
        let mut at = bottom;
        while at + 256 < sp {
            #[allow(unsafe_code)]
            // SAFETY: `at` is word-aligned (cortex-m-rt aligns _stack_end to 4) and lies in the
            // stack region below the live frames; nothing else uses that memory yet.
            unsafe {
                (at as *mut u32).write_volatile(PAINT);
            }
            at += 4;
        }
    }

    /// The deepest the stack has been since `paint_stack`, in bytes: from its top to the
    /// lowest word that no longer holds the paint.
    fn stack_high_water() -> usize {
        let (bottom, top) = stack_bounds();
        let mut at = bottom;
        #[allow(unsafe_code)]
        // SAFETY: word-aligned addresses inside the stack region, which is RAM.
        while at < top && unsafe { (at as *const u32).read_volatile() } == PAINT {
            at += 4;
        }
        top - at
    }

    /// The state of the scripted bus, in a static (not on the stack being measured).
    struct Script {
        /// Semihosting handles of the script file and of the host's stdout.
        file: usize,
        out: hio::HostStream,
        line: [u8; 64],
        /// Frames the node sent since the last report, with the millisecond they were sent.
        sent: [Option<(u32, CanFrame)>; 8],
        n_sent: usize,
        dropped: u32,
        /// Core clock ticks at the moment the last received frame was handed to the node.
        started: Option<u64>,
        wait_until: Option<u32>,
        /// While waiting: ticks when the loop last got no frame, and the cheapest such pass.
        idle_started: Option<u64>,
        idle_min: Option<u64>,
    }

    static SCRIPT: StaticCell<Script> = StaticCell::new();

    /// STAND-IN, NOT A DRIVER: where a HAL's CAN peripheral goes. It implements
    /// `embedded_can::nb::Can` as a driver does, but its bus is a script: `bus.txt` in QEMU's
    /// working directory, read through semihosting, one line per event: `ID#HEX` delivers a
    /// frame (candump's compact form), `wait MS` lets MS milliseconds pass. It writes to the
    /// host's stdout `rx`, `wait` and `tx MS ID#HEX` lines, `cost TICKS` (core clock ticks
    /// from handing a frame over until the loop asked for the next one) and, at the end of the
    /// script, `stack BYTES`, `idle TICKS` (the cheapest pass of the loop without a frame,
    /// while waiting) and `dropped N`; then it ends QEMU.
    pub struct ScriptCan(&'static mut Script);

    /// The stand-in's error: a HAL reports bus-off, overruns and the like.
    #[derive(Debug)]
    pub struct StandInError;

    impl embedded_can::Error for StandInError {
        fn kind(&self) -> embedded_can::ErrorKind {
            embedded_can::ErrorKind::Other
        }
    }

    impl ScriptCan {
        /// Opens `bus.txt` and the host's stdout; ends QEMU when either cannot be opened.
        pub fn open() -> Self {
            let Ok(out) = hio::hstdout() else { fail(b"") };
            let name = b"bus.txt\0";
            // Mode 0 is "r"; the length excludes the terminating zero.
            #[allow(unsafe_code)]
            // SAFETY: the semihosting OPEN call with a zero-terminated name that outlives it.
            let file = unsafe { syscall!(OPEN, name.as_ptr(), 0, name.len() - 1) };
            if file == usize::MAX {
                fail(b"cannot open bus.txt\n");
            }
            let script = SCRIPT.try_init(Script {
                file,
                out,
                line: [0; 64],
                sent: [None; 8],
                n_sent: 0,
                dropped: 0,
                started: None,
                wait_until: None,
                idle_started: None,
                idle_min: None,
            });
            let Some(script) = script else { fail(b"the script is open already\n") };
            Self(script)
        }
    }

    impl embedded_can::nb::Can for ScriptCan {
        type Frame = CanFrame;
        type Error = StandInError;

        fn transmit(&mut self, frame: &CanFrame) -> nb::Result<Option<CanFrame>, StandInError> {
            let s = &mut *self.0;
            match s.sent.get_mut(s.n_sent) {
                Some(slot) => {
                    *slot = Some((MS.load(Ordering::Relaxed), *frame));
                    s.n_sent += 1;
                }
                None => s.dropped += 1,
            }
            Ok(None)
        }

        fn receive(&mut self) -> nb::Result<CanFrame, StandInError> {
            let end = now_ticks();
            let s = &mut *self.0;
            s.report(end);
            if let Some(idle) = s.idle_started.take() {
                s.idle_min = Some(s.idle_min.map_or(end - idle, |m| m.min(end - idle)));
            }
            if let Some(until) = s.wait_until {
                if MS.load(Ordering::Relaxed) < until {
                    s.idle_started = Some(now_ticks());
                    return Err(nb::Error::WouldBlock);
                }
                s.wait_until = None;
            }
            let len = s.next_line();
            let line = s.line.get(..len).unwrap_or_default();
            if let Some(ms) = line.strip_prefix(b"wait ") {
                let Some(ms) = parse_number(ms, 10) else { fail(b"bad wait line\n") };
                s.write(b"wait\n");
                s.wait_until = Some(MS.load(Ordering::Relaxed).saturating_add(ms));
                return Err(nb::Error::WouldBlock);
            }
            let Some(frame) = parse_frame(line) else { fail(b"bad frame line\n") };
            s.write(b"rx ");
            s.write_frame(&frame);
            s.started = Some(now_ticks());
            Ok(frame)
        }
    }

    impl Script {
        fn write(&mut self, bytes: &[u8]) {
            if self.out.write_all(bytes).is_err() {
                exit(debug::EXIT_FAILURE);
            }
        }

        /// `ID#HEX\n`.
        fn write_frame(&mut self, frame: &CanFrame) {
            let mut line = Line::new();
            let id = match Frame::id(frame) {
                Id::Standard(s) => u32::from(s.as_raw()),
                Id::Extended(e) => e.as_raw(),
            };
            line.hex(id, 3);
            line.push(b'#');
            for &byte in Frame::data(frame) {
                line.hex(u32::from(byte), 2);
            }
            line.push(b'\n');
            self.write(line.bytes());
        }

        /// Writes the frames sent and the cost of the frame received last.
        fn report(&mut self, end: u64) {
            let sent = core::mem::take(&mut self.sent);
            self.n_sent = 0;
            for (ms, frame) in sent.iter().flatten() {
                let mut line = Line::new();
                line.text(b"tx ");
                line.dec(u64::from(*ms));
                line.push(b' ');
                self.write(line.bytes());
                self.write_frame(frame);
            }
            if let Some(start) = self.started.take() {
                self.write_number(b"cost ", end - start);
            }
        }

        fn write_number(&mut self, label: &[u8], value: u64) {
            let mut line = Line::new();
            line.text(label);
            line.dec(value);
            line.push(b'\n');
            self.write(line.bytes());
        }

        /// The next line of the script that is neither empty nor a `#` comment, without its
        /// `\r\n`, into `self.line`; at the end of the script, reports and ends QEMU.
        fn next_line(&mut self) -> usize {
            loop {
                let mut len = 0;
                loop {
                    let mut byte = 0u8;
                    #[allow(unsafe_code)]
                    // SAFETY: semihosting READ of one byte into a live local.
                    let left = unsafe { syscall!(READ, self.file, &raw mut byte, 1) };
                    if left != 0 {
                        if len > 0 {
                            return len;
                        }
                        self.finish();
                    }
                    if byte == b'\n' {
                        break;
                    }
                    if byte != b'\r' {
                        let Some(slot) = self.line.get_mut(len) else { fail(b"line too long\n") };
                        *slot = byte;
                        len += 1;
                    }
                }
                if len > 0 && self.line.first() != Some(&b'#') {
                    return len;
                }
            }
        }

        fn finish(&mut self) -> ! {
            let stack = stack_high_water() as u64;
            self.write_number(b"stack ", stack);
            if let Some(idle) = self.idle_min {
                self.write_number(b"idle ", idle);
            }
            let dropped = u64::from(self.dropped);
            self.write_number(b"dropped ", dropped);
            exit(debug::EXIT_SUCCESS)
        }
    }

    /// A line of output being built; what does not fit is cut (no line here comes near).
    struct Line {
        buf: [u8; 48],
        len: usize,
    }

    impl Line {
        fn new() -> Self {
            Self { buf: [0; 48], len: 0 }
        }

        fn push(&mut self, byte: u8) {
            if let Some(slot) = self.buf.get_mut(self.len) {
                *slot = byte;
                self.len += 1;
            }
        }

        fn text(&mut self, text: &[u8]) {
            text.iter().for_each(|&b| self.push(b));
        }

        fn bytes(&self) -> &[u8] {
            self.buf.get(..self.len).unwrap_or_default()
        }

        /// `value` in upper-case hex, at least `digits` digits.
        fn hex(&mut self, value: u32, digits: u32) {
            let needed = (32 - value.leading_zeros()).div_ceil(4).max(digits).min(8);
            for i in (0..needed).rev() {
                self.push(b"0123456789ABCDEF"[((value >> (i * 4)) & 0xF) as usize]);
            }
        }

        /// `value` in decimal.
        fn dec(&mut self, mut value: u64) {
            let mut digits = [0u8; 20]; // u64::MAX has 20
            let mut n = 0;
            for slot in &mut digits {
                *slot = b'0' + (value % 10) as u8;
                value /= 10;
                n += 1;
                if value == 0 {
                    break;
                }
            }
            digits.iter().take(n).rev().for_each(|&d| self.push(d));
        }
    }

    fn parse_number(text: &[u8], radix: u32) -> Option<u32> {
        if text.is_empty() || text.len() > 8 {
            return None;
        }
        text.iter().try_fold(0u32, |acc, &c| Some(acc * radix + (c as char).to_digit(radix)?))
    }

    /// `ID#HEX` with an 11-bit ID and 0–8 data bytes.
    fn parse_frame(line: &[u8]) -> Option<CanFrame> {
        let mut parts = line.splitn(2, |&c| c == b'#');
        let id = StandardId::new(u16::try_from(parse_number(parts.next()?, 16)?).ok()?)?;
        let hex = parts.next()?;
        if hex.len() % 2 != 0 || hex.len() > 16 {
            return None;
        }
        let mut data = [0u8; 8];
        for (slot, pair) in data.iter_mut().zip(hex.chunks(2)) {
            *slot = u8::try_from(parse_number(pair, 16)?).ok()?;
        }
        <CanFrame as Frame>::new(id, data.get(..hex.len() / 2)?)
    }

    /// Says why on the host's stdout and ends QEMU with a failure.
    fn fail(why: &[u8]) -> ! {
        if let Ok(mut out) = hio::hstdout() {
            let _ = out.write_all(why);
        }
        exit(debug::EXIT_FAILURE)
    }

    /// Ends the QEMU run with `status` (semihosting); should that return, sleeps for good.
    pub fn exit(status: debug::ExitStatus) -> ! {
        debug::exit(status);
        loop {
            cortex_m::asm::wfi();
        }
    }
}
