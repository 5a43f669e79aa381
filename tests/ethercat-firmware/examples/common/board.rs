//! The board both firmware images share (`firmware.rs` and its baseline `empty.rs`): an
//! STM32F4's SPI1 driven by its registers with PA4 as chip select, SysTick as the
//! millisecond clock, a panic handler. None of it is odc's: on a real part a HAL gives the
//! `SpiDevice` and the clock. Register addresses and bits from ST's RM0090 (STM32F405/407
//! reference manual): RCC 0x4002_3800, GPIOA 0x4002_0000, SPI1 0x4001_3000.

use core::convert::Infallible;
use core::sync::atomic::{AtomicU32, Ordering};

use cortex_m::peripheral::syst::SystClkSource;
use embedded_hal::spi::{ErrorType, Operation, SpiDevice};

/// The core clock after reset (the STM32F4's 16 MHz HSI), which SysTick counts.
const CORE_HZ: u32 = 16_000_000;

/// Milliseconds since reset, counted by the SysTick exception.
pub static MS: AtomicU32 = AtomicU32::new(0);

const RCC_AHB1ENR: usize = 0x4002_3830;
const RCC_APB2ENR: usize = 0x4002_3844;
const GPIOA_MODER: usize = 0x4002_0000;
const GPIOA_AFRL: usize = 0x4002_0020;
const GPIOA_BSRR: usize = 0x4002_0018;
const SPI1_CR1: usize = 0x4001_3000;
const SPI1_SR: usize = 0x4001_3008;
const SPI1_DR: usize = 0x4001_300C;
/// SPI_SR: receive buffer not empty, transmit buffer empty, busy.
const RXNE: u32 = 1 << 0;
const TXE: u32 = 1 << 1;
const BSY: u32 = 1 << 7;

fn read(addr: usize) -> u32 {
    #[allow(unsafe_code)]
    // SAFETY: a peripheral register of the STM32F4's memory map, read as 32 bits.
    unsafe {
        (addr as *const u32).read_volatile()
    }
}

fn write(addr: usize, value: u32) {
    #[allow(unsafe_code)]
    // SAFETY: a peripheral register of the STM32F4's memory map, written as 32 bits.
    unsafe {
        (addr as *mut u32).write_volatile(value);
    }
}

/// Clocks on, PA5/PA6/PA7 as SPI1 (alternate function 5), PA4 an output (chip select,
/// high), SPI1 master, mode 0, f_PCLK / 4, software slave management.
pub fn init() {
    write(RCC_AHB1ENR, read(RCC_AHB1ENR) | 1);
    write(RCC_APB2ENR, read(RCC_APB2ENR) | 1 << 12);
    write(GPIOA_BSRR, 1 << 4);
    let moder = read(GPIOA_MODER) & !(0xFF << 8);
    write(GPIOA_MODER, moder | 0b01 << 8 | 0b10 << 10 | 0b10 << 12 | 0b10 << 14);
    let afrl = read(GPIOA_AFRL) & !(0xFFF << 20);
    write(GPIOA_AFRL, afrl | 5 << 20 | 5 << 24 | 5 << 28);
    // MSTR (bit 2), BR = 0b001 (bits 3-5), SPE (bit 6), SSI (bit 8), SSM (bit 9).
    write(SPI1_CR1, 1 << 2 | 0b001 << 3 | 1 << 6 | 1 << 8 | 1 << 9);
}

/// SysTick from the core clock, an exception every millisecond (called once: a second call
/// finds the core peripherals taken and leaves SysTick as it is).
pub fn start_systick() {
    let Some(mut p) = cortex_m::Peripherals::take() else { return };
    p.SYST.set_clock_source(SystClkSource::Core);
    p.SYST.set_reload(CORE_HZ / 1000 - 1);
    p.SYST.clear_current();
    p.SYST.enable_interrupt();
    p.SYST.enable_counter();
}

/// Milliseconds since reset.
pub fn now_ms() -> u32 {
    MS.load(Ordering::Relaxed)
}

/// SysTick, every millisecond.
#[cortex_m_rt::exception]
fn SysTick() {
    MS.fetch_add(1, Ordering::Relaxed);
}

#[panic_handler]
fn panic(_: &core::panic::PanicInfo) -> ! {
    loop {
        cortex_m::asm::wfi();
    }
}

/// SPI1 with PA4 as its chip select: one transaction is one chip-select frame.
pub struct Spi1;

impl Spi1 {
    /// One byte out, one in.
    fn byte(out: u8) -> u8 {
        while read(SPI1_SR) & TXE == 0 {}
        write(SPI1_DR, u32::from(out));
        while read(SPI1_SR) & RXNE == 0 {}
        read(SPI1_DR).to_le_bytes()[0]
    }
}

impl ErrorType for Spi1 {
    type Error = Infallible;
}

impl SpiDevice for Spi1 {
    fn transaction(&mut self, operations: &mut [Operation<'_, u8>]) -> Result<(), Infallible> {
        write(GPIOA_BSRR, 1 << 20);
        for op in operations {
            match op {
                Operation::Read(buf) => buf.iter_mut().for_each(|b| *b = Self::byte(0)),
                Operation::Write(data) => data.iter().for_each(|&b| {
                    Self::byte(b);
                }),
                Operation::Transfer(read, data) => {
                    for k in 0..read.len().max(data.len()) {
                        let b = Self::byte(data.get(k).copied().unwrap_or(0));
                        if let Some(r) = read.get_mut(k) {
                            *r = b;
                        }
                    }
                }
                Operation::TransferInPlace(buf) => buf.iter_mut().for_each(|b| *b = Self::byte(*b)),
                Operation::DelayNs(_) => {}
            }
        }
        while read(SPI1_SR) & BSY != 0 {}
        write(GPIOA_BSRR, 1 << 4);
        Ok(())
    }
}
