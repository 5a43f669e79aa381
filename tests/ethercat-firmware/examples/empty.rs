//! The baseline of the firmware's size (tests/slave-size/README.md, "EtherCAT"): the same
//! board (vector table, runtime, SysTick, the SPI driver, panic handler) and a loop that
//! uses them, without odc. `firmware.rs` minus this is what odc costs.
#![no_std]
#![no_main]

#[path = "common/board.rs"]
mod board;

use embedded_hal::spi::{Operation, SpiDevice};

#[cortex_m_rt::entry]
fn main() -> ! {
    board::init();
    board::start_systick();
    let mut spi = board::Spi1;
    let mut word = [0u8; 4];
    loop {
        // As the firmware's first access (BYTE_TEST): the driver and the clock stay linked.
        let [hi, lo] = u16::try_from(board::now_ms() & 0xFFFF).unwrap_or(0).to_be_bytes();
        let Ok(()) = spi
            .transaction(&mut [Operation::Write(&[0x0B, hi, lo, 0]), Operation::Read(&mut word)]);
        core::hint::black_box(word);
    }
}
