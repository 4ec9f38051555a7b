/* io.h - the x86 port instructions (prefix io_), for the PC's devices: the VGA's
 * registers, the DAC, COM1, the PIC and PIT, and QEMU's isa-debug-exit. */
#ifndef PCVGA_IO_H
#define PCVGA_IO_H

#include <stdint.h>

static inline void io_out8(uint16_t port, uint8_t v)
{
    __asm__ volatile("outb %0, %1" : : "a"(v), "Nd"(port));
}

static inline void io_out16(uint16_t port, uint16_t v)
{
    __asm__ volatile("outw %0, %1" : : "a"(v), "Nd"(port));
}

static inline uint8_t io_in8(uint16_t port)
{
    uint8_t v;
    __asm__ volatile("inb %1, %0" : "=a"(v) : "Nd"(port));
    return v;
}

#endif
