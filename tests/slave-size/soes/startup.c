/* The runtime both C images share, as cortex-m-rt gives the Rust ones: a vector table of
   16 + 240 entries (1,024 bytes, the size of cortex-m-rt's for thumbv7em), a reset handler
   that copies .data and zeroes .bss, default handlers that spin.

   The reset handler's loops stay loops, as cortex-m-rt's are: at -Os gcc would turn them into
   calls of newlib's memcpy and memset, which would then sit in the empty image and be free to
   SOES, while the Rust images pay for compiler_builtins' (tests/slave-size/README.md). */
#include <stdint.h>

extern uint32_t _stack_start, _sidata, _sdata, _edata, _sbss, _ebss;
int main(void);
void SysTick_Handler(void);

__attribute__((optimize("no-tree-loop-distribute-patterns")))
void Reset_Handler(void)
{
   uint32_t *src = &_sidata;
   for (uint32_t *dst = &_sdata; dst < &_edata;) *dst++ = *src++;
   for (uint32_t *dst = &_sbss; dst < &_ebss;) *dst++ = 0;
   main();
   for (;;) {}
}

static void Default_Handler(void) { for (;;) {} }

__attribute__((section(".vector_table"), used))
static void (*const vectors[256])(void) = {
   [0] = (void (*)(void))&_stack_start,
   [1] = Reset_Handler,
   [2 ... 14] = Default_Handler,
   [15] = SysTick_Handler,
   [16 ... 255] = Default_Handler,
};
