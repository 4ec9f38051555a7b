/* hal_pcvga.c - hal.h's per-target functions on a PC's VGA (see hal_pcvga.h). */
#include "hal_pcvga.h"

#include "trap.h"
#include "vga.h"

static _Alignas(4) uint8_t sysmem[HAL_PAGE_BYTES];
static uint8_t palette[HAL_PALETTE_BYTES]; /* what hal_set_palette wrote */
static uint8_t dac[HAL_PALETTE_BYTES];     /* what the DAC holds */

static struct {
    int planar;        /* the VGA's layout: 1 unchained (flip), 0 mode 13h */
    int display_start; /* page shown */
    int dac_loaded;
    const campath *path;
    uint32_t frame;
} st;

uint8_t *hal_target_vram(int page)
{
    if (!st.planar) return VGA_WINDOW; /* mode 13h has room for one page only */
    return VGA_WINDOW + (page ? VGA_PLANAR_PAGE_BYTES : 0u);
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
    if (!st.planar) return;
    st.display_start = page ? 1 : 0;
    vga_set_start(st.display_start ? VGA_PLANAR_PAGE_BYTES : 0u);
}

int hal_target_display_start(void)
{
    return st.display_start;
}

int hal_target_vram_planar(void)
{
    return st.planar;
}

void hal_target_plane_mask(unsigned planes)
{
    vga_map_mask(planes);
}

void pcvga_use_present(hal_present_mode m)
{
    vga_set_mode13h();
    st.planar = m == HAL_PRESENT_FLIP;
    st.display_start = 0;
    if (st.planar) vga_set_unchained();
    st.dac_loaded = 0;
    pcvga_sync_dac();
}

void pcvga_sync_dac(void)
{
    int same = st.dac_loaded;
    for (int i = 0; same && i < HAL_PALETTE_BYTES; i++) same = dac[i] == palette[i];
    if (same) return;
    for (int i = 0; i < HAL_PALETTE_BYTES; i++) dac[i] = palette[i];
    vga_load_dac(dac);
    st.dac_loaded = 1;
}

void pcvga_read_shown(uint8_t *frame)
{
    if (st.planar) {
        vga_read_unchained(st.display_start ? VGA_PLANAR_PAGE_BYTES : 0u, frame);
        return;
    }
    const volatile uint32_t *src = (const volatile uint32_t *)(const void *)VGA_WINDOW;
    uint32_t *dst = (uint32_t *)(void *)frame;
    for (uint32_t i = 0; i < HAL_PAGE_BYTES / 4u; i++) dst[i] = src[i];
}

void pcvga_set_path(const campath *p)
{
    st.path = p;
    st.frame = 0;
}

uint32_t hal_input(void)
{
    return st.path ? campath_keys(st.path, st.frame) & ~HAL_KEY_NEXT_PRESENT : 0;
}

uint32_t hal_ticks_ms(void)
{
    return trap_ticks();
}

void hal_frame_done(void)
{
    pcvga_sync_dac();
    st.frame++;
}
