/* ram_target.c - VRAM pages, system-memory buffer, palette and display-start
 * register as static, 4-aligned arrays, for targets with no memory-mapped
 * display of their own. */
#include "ram_target.h"

#include "hal.h"

static _Alignas(4) uint8_t vram[2][HAL_PAGE_BYTES];
static _Alignas(4) uint8_t sysmem[HAL_PAGE_BYTES];
static _Alignas(4) uint8_t palette[HAL_PALETTE_BYTES];
static int display_start;

uint8_t *hal_target_vram(int page)
{
    return vram[page ? 1 : 0];
}

uint8_t *hal_target_sysmem(void)
{
    return sysmem;
}

uint8_t *hal_target_palette(void)
{
    return palette;
}

void hal_target_set_display_start(int page)
{
    display_start = page ? 1 : 0;
}

int hal_target_display_start(void)
{
    return display_start;
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

void hal_ram_target_reset(void)
{
    for (int p = 0; p < 2; p++)
        for (int i = 0; i < HAL_PAGE_BYTES; i++) vram[p][i] = 0;
    for (int i = 0; i < HAL_PAGE_BYTES; i++) sysmem[i] = 0;
    for (int i = 0; i < HAL_PALETTE_BYTES; i++) palette[i] = 0;
    display_start = 0;
}
