//! An EtherCAT device in firmware: a CiA 402 drive (feature `drive`) on a LAN9252 over SPI.
//! The dictionary generated from `esi/servoone.xml` (role slave, by this crate's build
//! script), `odc::ethercat::subdevice` (AL states, CoE mailbox, process data) through odc's
//! LAN9252 adapter on the board's `SpiDevice`, `odc::cia402::Drive`, a loop. `#![no_std]`,
//! `#![no_main]`, statics, no heap; `.ci/run` builds it for thumbv7em-none-eabihf:
//!
//! ```sh
//! cargo build -p odc-tests-ethercat-firmware --release --example firmware --features drive --target thumbv7em-none-eabihf
//! ```
//!
//! It is built, not run: QEMU's boards have no EtherCAT chip (the stack and adapter run
//! against the emulated ESC and LAN9252 in crates/odc-sim/tests/it/ethercat_spi.rs).
#![no_std]
#![no_main]

#[path = "common/board.rs"]
mod board;

use core::sync::atomic::{AtomicU32, Ordering};

use embedded_hal::spi::SpiDevice;
use odc::ethercat::esc_spi::lan9252::Lan9252;
use odc::ethercat::subdevice::{Application, SubDevice};
use odc::time::{Duration, Instant};
use odc_tests_ethercat_firmware::CONFIG;
use odc_tests_ethercat_firmware::device::slave::Dictionary;
use static_cell::StaticCell;

/// Mailboxes up to 128 bytes (the ESI's `DefaultSize`), SDO values up to 64 bytes in one
/// transfer, 32 mapped entries, process images up to 32 bytes (the ESI's `MaxSize`).
type Stack = SubDevice<128, 64, 32, 32>;

// The dictionary and the stack live in statics: `size` shows what they cost, and a RAM
// overflow is a link error.
static OD: StaticCell<Dictionary> = StaticCell::new();
static STACK: StaticCell<Stack> = StaticCell::new();

/// ESC accesses that failed (a LAN9252 command that stayed busy): a firmware reports them.
static ESC_ERRORS: AtomicU32 = AtomicU32::new(0);

/// What the device does beside the stack: the CiA 402 drive, stepped by the time between
/// cycles.
struct App {
    #[cfg(feature = "drive")]
    drive: odc::cia402::Drive,
    dt: Duration,
}

impl Application<Dictionary> for App {
    fn cycle(&mut self, od: &mut Dictionary, _state: u8) {
        #[cfg(feature = "drive")]
        {
            self.drive.update(od);
            self.drive.step(od, self.dt);
        }
        let _ = (od, self.dt);
    }

    fn mailbox_served(&mut self, od: &mut Dictionary) {
        // An SDO download may have written the controlword.
        #[cfg(feature = "drive")]
        self.drive.update(od);
        let _ = od;
    }
}

/// Runs the device on `spi` (the SPI device of the LAN9252) with `clock` (a monotonic
/// timer); never returns.
pub fn run<S: SpiDevice>(spi: S, mut clock: impl FnMut() -> Instant) -> ! {
    let od = OD.init_with(|| Dictionary::new(None));
    let stack = STACK.init_with(Stack::new);
    let mut esc = Lan9252::new(spi);
    // After reset the chip answers once its BYTE_TEST reads right and HW_CFG says ready.
    while !matches!(esc.ready(), Ok(true)) {}
    let mut app = App {
        #[cfg(feature = "drive")]
        drive: odc::cia402::Drive::new(),
        dt: Duration::ZERO,
    };
    #[cfg(feature = "drive")]
    app.drive.start(od);
    let mut last = clock();
    loop {
        let now = clock();
        app.dt = now - last;
        last = now;
        // AL control and the mailbox, then the process data (SAFE-OP and OP).
        let polled = stack.poll(&CONFIG, &mut esc, od, &mut app);
        let cycled = stack.cycle(&CONFIG, &mut esc, od, &mut app);
        let failed = u32::from(polled.is_err()) + u32::from(cycled.is_err());
        ESC_ERRORS.fetch_add(failed, Ordering::Relaxed);
    }
}

#[cortex_m_rt::entry]
fn main() -> ! {
    board::init();
    board::start_systick();
    run(board::Spi1, || Instant::from_millis(u64::from(board::now_ms())))
}
