/* fb.c - the counted framebuffer write primitives and the two present modes
 * (prefix hal_), shared by every target. Freestanding C11: no libc, no
 * floating point, no malloc, and no state of its own - the page being drawn
 * in flip mode is always the one the display start does not select, so the
 * target's display-start register is the only state, and a target reset
 * resets everything.
 *
 * Every framebuffer store goes through a volatile pointer of the width that
 * is counted: the compiler may neither merge, split, vectorise nor turn the
 * loops into memset/memcpy calls, so the counters describe the stores the
 * machine code really makes (and memory-mapped VRAM on a real target sees
 * exactly those bus transactions).
 */
#include <stddef.h>
#include "hal.h"
#include "perf_internal.h"

static const char *const present_names[HAL_PRESENT_COUNT] = {
    [HAL_PRESENT_FLIP] = "flip",
    [HAL_PRESENT_COPY8] = "copy8",
    [HAL_PRESENT_COPY16] = "copy16",
    [HAL_PRESENT_COPY32] = "copy32",
};

const char *hal_present_name(hal_present_mode m)
{
    if ((unsigned)m >= (unsigned)HAL_PRESENT_COUNT) return "unknown";
    return present_names[m];
}

static int str_eq(const char *a, const char *b)
{
    while (*a && *a == *b) {
        a++;
        b++;
    }
    return *a == *b;
}

int hal_present_parse(const char *name)
{
    if (name == NULL) return -1;
    for (int m = 0; m < HAL_PRESENT_COUNT; m++)
        if (str_eq(name, present_names[m])) return m;
    return -1;
}

/* Page the display shows now, normalised to 0 or 1. */
static int shown_index(void)
{
    return hal_target_display_start() ? 1 : 0;
}

/* Where the copy modes draw: the target's own system-memory buffer, or, on a
 * target that keeps none (hal/mps2, whose RAM holds the two pages and little
 * more), the page the display does not show. That page is free in the copy
 * modes: the present copies into the shown one and never moves the display
 * start. Its writes still count as system-memory writes, so the counters of a
 * frame do not depend on where the buffer lives. */
static uint8_t *copy_buffer(void)
{
    uint8_t *own = hal_target_sysmem();
    return own ? own : hal_target_vram(1 - shown_index());
}

hal_surface hal_begin_frame(hal_present_mode m)
{
    hal_surface s = {NULL, 0, 0};
    if (m == HAL_PRESENT_FLIP) {
        s.pixels = hal_target_vram(1 - shown_index());
        s.in_vram = 1;
        s.planar = hal_target_vram_planar() ? 1 : 0;
    } else if (m == HAL_PRESENT_COPY8 || m == HAL_PRESENT_COPY16 || m == HAL_PRESENT_COPY32) {
        s.pixels = copy_buffer();
        s.in_vram = 0;
    }
    return s; /* unknown mode: pixels NULL, hal_fill_span ignores it */
}

/* Pixels [x, x + len) of a planar row: 4-pixel groups, one byte each. A group
 * the span only partly covers is written alone with its pixels' planes; the
 * whole groups between are one run with every plane enabled. Kept out of
 * hal_fill_span (noinline): its calls to the target would otherwise make the
 * linear path save and restore registers on every span. */
static __attribute__((noinline)) void fill_planar(uint8_t *row, uint32_t x, uint32_t len, uint8_t colour)
{
    uint32_t w[3] = {0, 0, 0};                      /* transactions of 1, 2 and 4 bytes */
    uint32_t g0 = x >> 2, g1 = (x + len - 1u) >> 2; /* first and last group, inclusive */
    unsigned first = (0xFu << (x & 3u)) & 0xFu;
    unsigned last = 0xFu >> (3u - ((x + len - 1u) & 3u));
    if (g0 == g1) {
        hal_target_plane_mask(first & last);
        *(volatile uint8_t *)(row + g0) = colour;
        hal_perf_add_span(HAL_DEST_VRAM, 1, 0, 0, len, 1);
        return;
    }
    if (first != 0xFu) {
        hal_target_plane_mask(first);
        *(volatile uint8_t *)(row + g0) = colour;
        w[0]++;
        g0++;
    }
    if (last != 0xFu) {
        hal_target_plane_mask(last);
        *(volatile uint8_t *)(row + g1) = colour;
        w[0]++;
        g1--;
    }
    if (g0 <= g1) {
        hal_target_plane_mask(0xFu);
        hal_fill_run(row + g0, g1 - g0 + 1u, colour, w);
    }
    hal_perf_add_span(HAL_DEST_VRAM, w[0], w[1], w[2], len, w[0] + 2u * w[1] + 4u * w[2]);
}

void hal_fill_span(const hal_surface *s, int y, int x, int len, uint8_t colour)
{
    if (s == NULL || s->pixels == NULL) return;
    if (y < 0 || y >= HAL_HEIGHT || len <= 0 || x >= HAL_WIDTH) return;
    if (x < 0) {
        len += x; /* len > 0 and x < 0: cannot overflow */
        x = 0;
        if (len <= 0) return;
    }
    if (len > HAL_WIDTH - x) len = HAL_WIDTH - x;

    if (s->planar) { /* planar pages are VRAM */
        fill_planar(s->pixels + (uint32_t)y * (HAL_WIDTH / 4), (uint32_t)x, (uint32_t)len, colour);
        return;
    }
    uint32_t w[3] = {0, 0, 0}; /* transactions of 1, 2 and 4 bytes */
    hal_fill_run(s->pixels + (uint32_t)y * HAL_WIDTH + (uint32_t)x, (uint32_t)len, colour, w);
    hal_perf_add_span(s->in_vram ? HAL_DEST_VRAM : HAL_DEST_SYSMEM, w[0], w[1], w[2], (uint32_t)len, (uint32_t)len);
}

/* Planar: pixel x is byte x / 4 of plane x % 4. Four passes, one plane each,
 * so the mask is set four times a span, not once a pixel. */
static __attribute__((noinline)) void put_planar(uint8_t *prow, uint32_t x, uint32_t len, const uint8_t *row)
{
    uint32_t writes = 0;
    for (uint32_t plane = 0; plane < 4u; plane++) {
        uint32_t first = x + ((plane - x) & 3u); /* the span's first pixel in this plane */
        if (first >= x + len) continue;
        hal_target_plane_mask(1u << plane);
        for (uint32_t px = first; px < x + len; px += 4u) {
            *(volatile uint8_t *)(prow + (px >> 2)) = row[px];
            writes++;
        }
    }
    hal_perf_add_span(HAL_DEST_VRAM, writes, 0, 0, len, writes);
}

void hal_put_span(const hal_surface *s, int y, int x, int len, const uint8_t *row)
{
    if (s == NULL || s->pixels == NULL || row == NULL) return;
    if (y < 0 || y >= HAL_HEIGHT || len <= 0 || x < 0 || x >= HAL_WIDTH || len > HAL_WIDTH - x) return;
    if (s->planar) {
        put_planar(s->pixels + (uint32_t)y * (HAL_WIDTH / 4), (uint32_t)x, (uint32_t)len, row);
        return;
    }
    uint32_t w[3] = {0, 0, 0};
    hal_copy_run(s->pixels + (uint32_t)y * HAL_WIDTH + (uint32_t)x, row, (uint32_t)x, (uint32_t)len, w);
    hal_perf_add_span(s->in_vram ? HAL_DEST_VRAM : HAL_DEST_SYSMEM, w[0], w[1], w[2], (uint32_t)len, (uint32_t)len);
}

void hal_add_tally(const hal_surface *s, hal_tally *t)
{
    if (t->pixels)
        hal_perf_add_span(s->in_vram ? HAL_DEST_VRAM : HAL_DEST_SYSMEM, t->w[0], t->w[1], t->w[2], t->pixels,
                          t->pixels);
    *t = (hal_tally){{0, 0, 0}, 0};
}

/* The copies: the system-memory buffer and the pages are 4-aligned and
 * HAL_PAGE_BYTES is a multiple of 4, so every access is naturally aligned. */
static void copy8(uint8_t *dst, const uint8_t *src)
{
    volatile uint8_t *d = dst;
    for (uint32_t i = 0; i < HAL_PAGE_BYTES; i++) d[i] = src[i];
    hal_perf_add_writes(1, HAL_DEST_VRAM, HAL_PAGE_BYTES, 1);
}

static void copy16(uint8_t *dst, const uint8_t *src)
{
    volatile uint16_t *d = (volatile uint16_t *)(void *)dst;
    const uint16_t *s = (const uint16_t *)(const void *)src;
    for (uint32_t i = 0; i < HAL_PAGE_BYTES / 2; i++) d[i] = s[i];
    hal_perf_add_writes(2, HAL_DEST_VRAM, HAL_PAGE_BYTES / 2, 1);
}

static void copy32(uint8_t *dst, const uint8_t *src)
{
    volatile uint32_t *d = (volatile uint32_t *)(void *)dst;
    const uint32_t *s = (const uint32_t *)(const void *)src;
    for (uint32_t i = 0; i < HAL_PAGE_BYTES / 4; i++) d[i] = s[i];
    hal_perf_add_writes(4, HAL_DEST_VRAM, HAL_PAGE_BYTES / 4, 1);
}

void hal_present(hal_present_mode m)
{
    uint8_t *shown;
    const uint8_t *src;
    hal_perf_fold(); /* the frame's span sums into the 64-bit totals */
    switch (m) {
    case HAL_PRESENT_FLIP:
        /* the page just drawn is the hidden one; show it. The next
         * hal_begin_frame draws into the other. No writes are counted. */
        hal_target_set_display_start(1 - shown_index());
        return;
    case HAL_PRESENT_COPY8:
    case HAL_PRESENT_COPY16:
    case HAL_PRESENT_COPY32: break;
    default: return;
    }
    shown = hal_target_vram(shown_index());
    src = copy_buffer();
    if (shown == NULL || src == NULL) return;
    if (m == HAL_PRESENT_COPY8)
        copy8(shown, src);
    else if (m == HAL_PRESENT_COPY16)
        copy16(shown, src);
    else
        copy32(shown, src);
}

const uint8_t *hal_shown_page(void)
{
    if (hal_target_vram_planar()) return NULL;
    return hal_target_vram(shown_index());
}

void hal_set_palette(const uint8_t *rgb)
{
    uint8_t *pal = hal_target_palette();
    if (rgb == NULL || pal == NULL) return;
    for (uint32_t i = 0; i < HAL_PALETTE_BYTES; i++) pal[i] = rgb[i];
}

const uint8_t *hal_get_palette(void)
{
    return hal_target_palette();
}
