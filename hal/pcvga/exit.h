/* exit.h - ending the kernel (prefix pcvga_): QEMU's isa-debug-exit device
 * (-device isa-debug-exit,iobase=0xf4,iosize=0x04) makes QEMU exit with status
 * 2 * code + 1 when code is written to port 0xF4. Without the device (another
 * emulator, a real PC) the write does nothing and the kernel halts instead. */
#ifndef PCVGA_EXIT_H
#define PCVGA_EXIT_H

#include <stdint.h>

/* Kernel exit statuses (QEMU's is 2 * status + 1). */
#define PCVGA_EXIT_OK 0
#define PCVGA_EXIT_SCENE 2 /* the built-in scene is invalid */
#define PCVGA_EXIT_FAULT 3 /* a processor exception */
#define PCVGA_EXIT_WORK 4  /* not enough memory for the scene's work area */
#define PCVGA_EXIT_ARGS 5  /* bad run-time options */
#define PCVGA_EXIT_BOOT 6  /* not started by a multiboot loader */

__attribute__((noreturn)) void pcvga_exit(uint8_t status);

#endif
