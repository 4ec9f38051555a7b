/* trap.h - interrupts and exceptions of the PC kernel (prefix trap_): an IDT
 * with every processor exception and the timer, the two 8259 PICs moved to
 * vectors 32..47 with every line masked but IRQ 0, and the 8254 PIT's channel
 * 0 interrupting at 1 kHz (1,193,182 Hz / 1,193: 1.000 15 ms a tick).
 *
 * An exception is reported on COM1 - its name and vector, eip, the error
 * code, cr2 for a page fault - and ends the kernel with PCVGA_EXIT_FAULT. */
#ifndef PCVGA_TRAP_H
#define PCVGA_TRAP_H

#include <stdint.h>

/* What trap_entry.S pushes: pushal's registers, then vector and error code,
 * then what the processor pushed. */
struct trap_frame {
    uint32_t edi, esi, ebp, esp_unused, ebx, edx, ecx, eax;
    uint32_t vector, error;
    uint32_t eip, cs, eflags;
};

void trap_init(void);      /* IDT, PICs, PIT; interrupts on */
uint32_t trap_ticks(void); /* PIT ticks (~ms) since trap_init */

#endif
