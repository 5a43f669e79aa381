//! A CANopen slave in firmware: the dictionary generated from `eds/lxm23a.eds` (role slave, by
//! this crate's build script), `odc::node::Node`, a transport over an `embedded_can::nb::Can`
//! driver, a loop. `#![no_std]`, `#![no_main]`, no heap; built for thumbv7em-none-eabihf by
//! `.ci/run`:
//!
//! ```sh
//! cargo build -p odc-tests-no-std --example firmware --features firmware --target thumbv7em-none-eabihf
//! ```
//!
//! The part between the `slave` markers is the program README.md shows (`tests/readme.rs`
//! keeps the two equal). Below it: a stand-in for the HAL's CAN peripheral and clock, since no
//! real HAL is a dependency here, and the entry point and panic handler a HAL's runtime crate
//! (cortex-m-rt, embassy) would provide.
#![no_std]
#![no_main]

// slave: begin
use odc::can::CanFrame;
use odc::node::Node;
use odc::time::Instant;
use odc::transport::{Bus, embedded_can::NbBus};

mod lxm23a {
    odc::include_od!("lxm23a"); // build.rs: odc_build::Config::new().device("eds/lxm23a.eds")
}

/// Runs the node on `can` (the HAL's CAN peripheral) with a millisecond clock; never returns.
pub fn run<C: embedded_can::nb::Can>(can: C, clock_ms: impl FnMut() -> u64) -> ! {
    let node_id = odc::node_id!(5);
    let mut od = lxm23a::slave::Dictionary::new(node_id);
    let mut node: Node<64> = Node::new(node_id);
    let mut bus = NbBus::new(can, clock_ms);
    let mut bus_errors = 0u32; // what the driver refused: a firmware reports it (EMCY, LED)
    let now = Instant::from_millis(bus.now_ms());
    node.start(&mut od, now, &mut |f| bus_errors += u32::from(bus.send(&f).is_err()));
    loop {
        let now_ms = bus.now_ms();
        let received = bus.recv(now_ms); // at once: Ok(None) when nothing came
        let now = Instant::from_millis(now_ms);
        let mut out = |f: CanFrame| bus_errors += u32::from(bus.send(&f).is_err());
        let mut events = node.poll(&mut od, now, &mut out);
        match received {
            Ok(Some(frame)) => events.absorb(node.handle(&mut od, &frame, now, &mut out)),
            Ok(None) => {}
            Err(_) => bus_errors += 1,
        }
        if events.reset.is_some() {
            od = lxm23a::slave::Dictionary::new(node.next_node_id()); // defaults back
        }
    }
}
// slave: end

/// STAND-IN, NOT A DRIVER: where a HAL's CAN peripheral (bxCAN, FDCAN, MCP2515...) goes. It
/// implements `embedded_can::nb::Can` as a driver does; there is no bus behind it: a frame to
/// transmit is counted (a peripheral would put it on the wire), and nothing is ever received.
struct StandInCan {
    transmitted: u32,
}

/// The stand-in's error: a HAL reports bus-off, overruns and the like.
#[derive(Debug)]
struct StandInError;

impl embedded_can::Error for StandInError {
    fn kind(&self) -> embedded_can::ErrorKind {
        embedded_can::ErrorKind::Other
    }
}

impl embedded_can::nb::Can for StandInCan {
    type Frame = CanFrame;
    type Error = StandInError;

    fn transmit(&mut self, _frame: &CanFrame) -> nb::Result<Option<CanFrame>, StandInError> {
        self.transmitted = self.transmitted.wrapping_add(1);
        Ok(None)
    }

    fn receive(&mut self) -> nb::Result<CanFrame, StandInError> {
        Err(nb::Error::WouldBlock)
    }
}

/// STAND-IN: milliseconds since reset, which a SysTick interrupt would count.
static TICKS_MS: core::sync::atomic::AtomicU32 = core::sync::atomic::AtomicU32::new(0);

/// The reset entry point (a HAL's runtime crate provides it and calls `main`).
#[allow(unsafe_code)] // the linker's entry symbol: an unmangled name, nothing else unsafe
#[unsafe(no_mangle)]
pub extern "C" fn _start() -> ! {
    let can = StandInCan { transmitted: 0 };
    run(can, || u64::from(TICKS_MS.load(core::sync::atomic::Ordering::Relaxed)))
}

#[panic_handler]
fn panic(_: &core::panic::PanicInfo) -> ! {
    loop {}
}
