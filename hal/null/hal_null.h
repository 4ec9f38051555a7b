/* hal_null.h - the headless target (prefix hal_null_): VRAM, the system-memory
 * buffer and the palette are plain static arrays; nothing is shown. Used by
 * the unit tests and the headless render CLI.
 *
 * Input is a bitmask the host program scripts: hal_input() returns it, then
 * clears the edge-triggered bits (HAL_KEY_NEXT_MODE, HAL_KEY_NEXT_PRESENT,
 * HAL_KEY_PRINT_COUNTERS) so each is reported once per hal_null_set_input();
 * held bits and HAL_KEY_QUIT stay until the host changes them.
 *
 * Time: hal_ticks_ms() advances by exactly 1000/35 ms per hal_frame_done()
 * (a 35 Hz tic, the fraction carried so 35 frames are 1000 ms), starting at 0.
 * Once hal_null_set_ticks() is called the clock is the host's: it stays at the
 * value set, frames no longer move it, until the next set or hal_null_reset().
 */
#ifndef HAL_NULL_H
#define HAL_NULL_H

#include <stdint.h>

void hal_null_set_input(uint32_t keys); /* HAL_KEY_* bits */
void hal_null_set_ticks(uint32_t ms);   /* take manual control of the clock */
uint32_t hal_null_frames(void);         /* hal_frame_done calls since reset */
/* Zero both VRAM pages, the system-memory buffer and the palette; display
 * start 0; input 0; frames 0; clock back to automatic at 0. Does not touch
 * the performance counters (hal_perf_reset does). */
void hal_null_reset(void);

#endif
