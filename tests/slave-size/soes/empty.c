/* The baseline of the C images: the same runtime and board, the loop of
   tests/ethercat-firmware/examples/empty.rs (one FAST READ of BYTE_TEST with the clock in
   its address, so the driver and the clock stay linked), without SOES. */
#include <stdint.h>
#include "spi/spi.h"

void board_init(void);
extern volatile uint32_t board_ms;

int main(void)
{
   board_init();
   for (;;)
   {
      uint8_t cmd[4] = {0x0B, (uint8_t)(board_ms >> 8), (uint8_t)board_ms, 0};
      uint8_t word[4];
      spi_select(1);
      write(1, cmd, sizeof cmd);
      read(1, word, sizeof word);
      spi_unselect(1);
      __asm__ volatile("" : : "r"(word) : "memory");
   }
}
