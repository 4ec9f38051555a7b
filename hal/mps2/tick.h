/* tick.h - the millisecond tick (prefix tick_): SysTick on the processor clock.
 *
 * SysTick counts the 25 MHz system clock (CLKSOURCE = 1) and interrupts every
 * 25,000 cycles; the handler adds one to a 32-bit millisecond count.
 *
 * What a "ms" is under QEMU: QEMU drives SysTick from its virtual clock, not
 * from executed instructions. Without -icount the virtual clock follows the
 * host's real time while the guest runs, so a tick is one millisecond of wall
 * time, however many guest instructions fit in it (that depends on the host).
 * With -icount shift=N every instruction advances the virtual clock by 2^N ns,
 * and a tick is 10^6 / 2^N instructions (shift=0: 1,000,000; the clock is then
 * deterministic). The firmware's frame timing therefore never comes from this
 * tick: the camera path advances by a fixed 1000/35 ms per frame (campath.h),
 * so every run renders the same frames.
 */
#ifndef MPS2_TICK_H
#define MPS2_TICK_H

#include <stdint.h>

void tick_init(void);
void tick_stop(void); /* no more tick interrupts; the count stays where it is */
uint32_t tick_ms(void);

void systick_irq(void); /* vector table (startup.c) */

#endif
