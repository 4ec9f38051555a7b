/* hal_mps2.h - the Cortex-M3 target's half of hal.h (prefix mps2_): VRAM pages,
 * palette and display start at fixed PSRAM addresses (mps2.h), the system-memory
 * back buffer in RAM, input from a scripted camera path, the SysTick clock.
 *
 * Input: hal_input() returns the keys the path holds at the current frame;
 * hal_frame_done() moves to the next frame. With no path (a fixed view), input
 * is 0. Time: hal_ticks_ms() is the SysTick millisecond count (tick.h says what
 * that is under QEMU); the firmware's frames never depend on it.
 */
#ifndef HAL_MPS2_H
#define HAL_MPS2_H

#include <stdint.h>
#include "campath.h"

/* UART, SysTick, display memory cleared, display start 0, frame 0. */
void mps2_board_init(void);

void mps2_set_path(const campath *p); /* NULL: no input */
uint32_t mps2_frames_done(void);      /* hal_frame_done calls since init */

#endif
