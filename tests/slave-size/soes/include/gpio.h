/* rt-kernel's GPIO header, included by SOES's LAN9252 HAL: of rt-kernel's headers it needs
   only BIT(). */
#ifndef GPIO_H
#define GPIO_H
#ifndef BIT
#define BIT(n) (1U << (n))
#endif
#endif
