/* boot_vectors.h - whether the bootloader may start an application (hal/board):
 * its vector table, read from the start of the slot, must hold an initial stack
 * pointer inside the board's RAM and a reset handler inside the application's
 * own bytes, in Thumb state. A CRC that matches only says the bytes are the ones
 * downloaded, not that they are a program for this board: jumping into anything
 * else faults, or worse, runs data. Pure C: the host's unit tests run it. */
#ifndef BOOT_VECTORS_H
#define BOOT_VECTORS_H

#include <stdint.h>

/* NULL when the application at app_addr (app_len bytes, its first two words sp
 * and reset) may be started; else why not, for the log. */
const char *boot_vectors_refusal(uint32_t sp, uint32_t reset, uint32_t app_addr, uint32_t app_len);

#endif
