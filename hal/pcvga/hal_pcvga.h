/* hal_pcvga.h - the PC target's half of hal.h (prefix pcvga_): VRAM is the
 * VGA's own memory at 0xA0000, the palette goes to the DAC, input comes from a
 * scripted camera path, time from the PIT.
 *
 * The present mode decides the VGA's layout, once, before the first frame:
 *   copy8/16/32  mode 13h, chained: one linear page at 0xA0000, the display
 *                start always 0; the frame is drawn in system memory and copied.
 *   flip         unchained: two planar pages at 0xA0000 and 0xA0000 + 16,000,
 *                the CRTC start address showing one while the other is drawn.
 * The run's present mode is fixed: hal_input never reports HAL_KEY_NEXT_PRESENT.
 *
 * The palette: hal_set_palette writes a copy in RAM; pcvga_sync_dac loads it
 * into the DAC when it has changed (hal_frame_done does, every frame). */
#ifndef HAL_PCVGA_H
#define HAL_PCVGA_H

#include <stdint.h>

#include "campath.h"
#include "hal.h"

void pcvga_use_present(hal_present_mode m); /* sets the VGA's layout for m */
void pcvga_sync_dac(void);
void pcvga_set_path(const campath *p); /* NULL: no input */
/* The frame the display shows, read back from the VGA into frame (64,000 bytes). */
void pcvga_read_shown(uint8_t *frame);

#endif
