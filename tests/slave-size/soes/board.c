/* The board of tests/ethercat-firmware/examples/common/board.rs in C: an STM32F4's SPI1 by
   its registers (RM0090) with PA4 as chip select, SysTick as the millisecond clock; and the
   four rt-kernel calls SOES's LAN9252 HAL (soes/hal/rt-kernel-lan9252/esc_hw.c) makes:
   open, spi_select, spi_unselect, read and write of one SPI device. */
#include <stdint.h>
#include <stddef.h>
#include <sys/types.h>
#include "spi/spi.h"

#define REG(a) (*(volatile uint32_t *)(a))
#define RCC_AHB1ENR 0x40023830u
#define RCC_APB2ENR 0x40023844u
#define GPIOA_MODER 0x40020000u
#define GPIOA_AFRL 0x40020020u
#define GPIOA_BSRR 0x40020018u
#define SPI1_CR1 0x40013000u
#define SPI1_SR 0x40013008u
#define SPI1_DR 0x4001300Cu
#define RXNE (1u << 0)
#define TXE (1u << 1)
#define BSY (1u << 7)
#define SYST_CSR 0xE000E010u
#define SYST_RVR 0xE000E014u
#define SYST_CVR 0xE000E018u

volatile uint32_t board_ms;

void SysTick_Handler(void) { board_ms++; }

void board_init(void)
{
   REG(RCC_AHB1ENR) |= 1u;
   REG(RCC_APB2ENR) |= 1u << 12;
   REG(GPIOA_BSRR) = 1u << 4;
   REG(GPIOA_MODER) = (REG(GPIOA_MODER) & ~(0xFFu << 8)) | 1u << 8 | 2u << 10 | 2u << 12 | 2u << 14;
   REG(GPIOA_AFRL) = (REG(GPIOA_AFRL) & ~(0xFFFu << 20)) | 5u << 20 | 5u << 24 | 5u << 28;
   REG(SPI1_CR1) = 1u << 2 | 1u << 3 | 1u << 6 | 1u << 8 | 1u << 9;
   /* SysTick: the core clock (16 MHz HSI), every millisecond. */
   REG(SYST_RVR) = 16000000u / 1000u - 1u;
   REG(SYST_CVR) = 0;
   REG(SYST_CSR) = 7u;
}

static uint8_t byte(uint8_t out)
{
   while ((REG(SPI1_SR) & TXE) == 0) {}
   REG(SPI1_DR) = out;
   while ((REG(SPI1_SR) & RXNE) == 0) {}
   return (uint8_t)REG(SPI1_DR);
}

int open(const char *name, int flags, ...) { (void)name; (void)flags; return 1; }

void spi_select(int fd) { (void)fd; REG(GPIOA_BSRR) = 1u << 20; }

void spi_unselect(int fd)
{
   (void)fd;
   while (REG(SPI1_SR) & BSY) {}
   REG(GPIOA_BSRR) = 1u << 4;
}

/* Within a selection, as rt-kernel's SPI driver: bytes out, or bytes in (0x00 out). */
ssize_t write(int fd, const void *buf, size_t n)
{
   (void)fd;
   for (size_t k = 0; k < n; k++) byte(((const uint8_t *)buf)[k]);
   return (ssize_t)n;
}

ssize_t read(int fd, void *buf, size_t n)
{
   (void)fd;
   for (size_t k = 0; k < n; k++) ((uint8_t *)buf)[k] = byte(0);
   return (ssize_t)n;
}
