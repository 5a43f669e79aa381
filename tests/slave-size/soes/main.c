/* SOES's device for the comparison: its stack (ecat_slv) on the LAN9252 HAL, the object
   list of objects.py, a polling loop; the application copies process data only (the Rust
   image without the `drive` feature does the same). */
#include "ecat_slv.h"
#include "utypes.h"

void board_init(void);

_Objects Obj;

void cb_get_inputs(void) {}
void cb_set_outputs(void) {}

int main(void)
{
   static esc_cfg_t config = {
      .user_arg = "spi1",
      .use_interrupt = 0,
      .watchdog_cnt = 150,
   };
   board_init();
   ecat_slv_init(&config);
   for (;;)
   {
      ecat_slv();
   }
}
