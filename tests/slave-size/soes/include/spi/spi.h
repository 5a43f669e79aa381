/* The part of rt-kernel's SPI API that SOES's LAN9252 HAL uses (implemented in board.c). */
#ifndef SPI_SPI_H
#define SPI_SPI_H
#include <stddef.h>
#include <sys/types.h>
#ifndef O_RDWR
#define O_RDWR 2
#endif
int open(const char *name, int flags, ...);
void spi_select(int fd);
void spi_unselect(int fd);
ssize_t read(int fd, void *buf, size_t n);
ssize_t write(int fd, const void *buf, size_t n);
#endif
