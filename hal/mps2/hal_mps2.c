/* hal_mps2.c - hal.h's per-target functions on the MPS2 AN385 (see hal_mps2.h). */
#include "hal_mps2.h"

#include "hal.h"
#include "mps2.h"
#include "tick.h"
#include "uart.h"

static struct {
    const campath *path;
    uint32_t frame;
} st;

uint8_t *hal_target_vram(int page)
{
    return page ? mps2_vram1 : mps2_vram0;
}

/* no buffer of its own: the copy modes draw into the hidden page (hal/fb.c) */
uint8_t *hal_target_sysmem(void)
{
    return 0;
}

uint8_t *hal_target_palette(void)
{
    return mps2_palette;
}

void hal_target_set_display_start(int page)
{
    mps2_display_start = page ? 1u : 0u;
}

int hal_target_display_start(void)
{
    return mps2_display_start ? 1 : 0;
}

/* linear pages: no planes to select */
int hal_target_vram_planar(void)
{
    return 0;
}

void hal_target_plane_mask(unsigned planes)
{
    (void)planes;
}

uint32_t hal_input(void)
{
    return st.path ? campath_keys(st.path, st.frame) : 0;
}

uint32_t hal_ticks_ms(void)
{
    return tick_ms();
}

void hal_frame_done(void)
{
    st.frame++;
}

void mps2_set_path(const campath *p)
{
    st.path = p;
}

uint32_t mps2_frames_done(void)
{
    return st.frame;
}

void mps2_board_init(void)
{
    uart_init();
    tick_init();
    uint32_t *p = (uint32_t *)(void *)mps2_vram0;
    for (uint32_t i = 0; i < 2u * HAL_PAGE_BYTES / 4u; i++) p[i] = 0; /* both pages: contiguous */
    for (int i = 0; i < HAL_PALETTE_BYTES; i++) mps2_palette[i] = 0;
    mps2_display_start = 0;
    st.path = 0;
    st.frame = 0;
}
