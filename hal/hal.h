/* hal.h - the target contract (prefix hal_). The renderer core (firmware/) talks to
 * the machine only through this header.
 *
 * The machine is a VGA-like 320x200, 8-bit, 256-colour display:
 *   - two 64,000-byte VRAM pages (row pitch 320) and a display-start register
 *     choosing the shown page;
 *   - a 256-entry palette, 8 bits per gun (r, g, b), 768 bytes;
 *   - a millisecond tick, an input bitmask, and a frame-done hook.
 *
 * Shared by every target (hal/fb.c, hal/perf.c): the counted framebuffer write
 * primitives, the two present modes, and the performance counters that mimic
 * the Pentium's (two programmable counters with selectable events plus a
 * time-stamp-style cycle counter driven by a bus cost model).
 *
 * Per target (hal/null, hal/sdl, hal/mps2, hal/pcvga, ...): where VRAM, the system-memory
 * buffer and the palette live, what showing a page means, input and time.
 * The firmware owns no main loop: the target calls the engine step.
 */
#ifndef HAL_H
#define HAL_H

#include <stdint.h>

#define HAL_WIDTH 320
#define HAL_HEIGHT 200
#define HAL_PAGE_BYTES (HAL_WIDTH * HAL_HEIGHT)
#define HAL_PALETTE_BYTES 768

/* ---- present modes ---------------------------------------------------- */
typedef enum {
    HAL_PRESENT_FLIP,   /* draw into the hidden VRAM page, then flip the display start */
    HAL_PRESENT_COPY8,  /* draw into system memory, copy to the shown page a byte at a time */
    HAL_PRESENT_COPY16, /* ... 16 bits at a time */
    HAL_PRESENT_COPY32, /* ... 32 bits at a time */
    HAL_PRESENT_COUNT
} hal_present_mode;

/* Name for a mode ("flip", "copy8", "copy16", "copy32"); parse returns -1 if unknown. */
const char *hal_present_name(hal_present_mode m);
int hal_present_parse(const char *name);

/* ---- performance counters --------------------------------------------- */
typedef enum {
    HAL_EV_WRITES,  /* framebuffer write transactions of any width (drawing + present) */
    HAL_EV_BYTES,   /* bytes written to any framebuffer */
    HAL_EV_WRITES8, /* write transactions by width */
    HAL_EV_WRITES16,
    HAL_EV_WRITES32,
    HAL_EV_VRAM_WRITES,   /* transactions that hit VRAM */
    HAL_EV_SYSMEM_WRITES, /* transactions that hit the system-memory buffer */
    HAL_EV_PIXELS,        /* pixels drawn by the renderer (overdraw = pixels / 64,000) */
    HAL_EV_COPY_WRITES,   /* transactions made by the present copy */
    HAL_EV_COUNT
} hal_event;

const char *hal_event_name(hal_event e); /* "writes", "bytes", ... (JSON keys); "unknown" if out of range */

/* Bus cost model: modelled cycles per write transaction, whatever its width,
 * because a bus transaction costs the same for a byte or a dword - the point of
 * Abrash's chapter 62 measurement. Defaults: VRAM 8, system memory 1. */
typedef struct {
    uint32_t vram_cycles;
    uint32_t sysmem_cycles;
} hal_bus_model;

#define HAL_PERF_COUNTERS 2
/* Zero every event total, both counters and the cycle count; keeps the bus model
 * and the events the counters have selected. */
void hal_perf_reset(void);
void hal_perf_set_bus(hal_bus_model m);
hal_bus_model hal_perf_bus(void);
uint64_t hal_perf_event(hal_event e);           /* running total of one event */
void hal_perf_select(int counter, hal_event e); /* counter 0 or 1: count e from now, from zero */
uint64_t hal_perf_read(int counter);            /* counts of the selected event since selected */
uint64_t hal_perf_tsc(void);                    /* modelled bus cycles since reset */

/* ---- framebuffer writes (counted) -------------------------------------- */
typedef struct {
    uint8_t *pixels; /* linear: 320 x 200, pitch 320; planar: the page's first byte */
    uint8_t in_vram; /* 1: VRAM page, 0: system memory */
    uint8_t planar;  /* 1: a VRAM page in the VGA's unchained layout (hal_target_vram_planar) */
} hal_surface;

/* Start a frame: the surface to draw into is the hidden VRAM page (flip) or the
 * system-memory buffer (copy modes). An unknown mode gives pixels == NULL, which
 * hal_fill_span ignores. */
hal_surface hal_begin_frame(hal_present_mode m);

/* Fill pixels [x, x+len) of row y with one colour, with aligned dword writes in
 * the middle and byte/word writes at the ends, counting every transaction.
 * Out-of-range rows or columns are clipped, never written. On a planar page a
 * byte covers 4 pixels (one per plane): the partial groups at the ends are
 * written with the plane mask of their pixels, the whole groups between them
 * with every plane enabled, so a dword write fills 16 pixels; the bytes event
 * counts the bytes the processor wrote, the pixels event the pixels. */
void hal_fill_span(const hal_surface *s, int y, int x, int len, uint8_t colour);

/* Write n >= 1 bytes of one value from p: a byte to reach 2-alignment, a word
 * to reach 4-alignment, aligned dwords, then a word and a byte; adds the
 * transactions of each width to w[0..2]. Inlined into its callers, so the
 * counts stay in registers. */
static inline __attribute__((always_inline)) void hal_fill_run(uint8_t *p, uint32_t n, uint8_t colour, uint32_t w[3])
{
    uint16_t c16 = (uint16_t)(colour * 0x0101u);
    uint32_t c32 = colour * 0x01010101u;
    if (((uintptr_t)p & 1u) != 0) {
        *(volatile uint8_t *)p = colour;
        p += 1;
        n -= 1;
        w[0]++;
    }
    if (((uintptr_t)p & 2u) != 0 && n >= 2) {
        *(volatile uint16_t *)(void *)p = c16;
        p += 2;
        n -= 2;
        w[1]++;
    }
    uint32_t n32 = n >> 2;
    volatile uint32_t *d = (volatile uint32_t *)(void *)p;
    for (uint32_t i = 0; i < n32; i++) d[i] = c32;
    w[2] += n32;
    p += n32 * 4u;
    n &= 3u;
    if (n >= 2) {
        *(volatile uint16_t *)(void *)p = c16;
        p += 2;
        n -= 2;
        w[1]++;
    }
    if (n != 0) {
        *(volatile uint8_t *)p = colour;
        w[0]++;
    }
}

/* Write pixels row[x .. x + len) of one screen row to p (which is pixel x of
 * that row on a linear surface) with the transactions hal_fill_run makes for
 * the same span, adding them to w[0..2]. row is 4-aligned like the surface's
 * rows, so each dword is read aligned. */
static inline __attribute__((always_inline)) void hal_copy_run(uint8_t *p, const uint8_t *row, uint32_t x, uint32_t n,
                                                               uint32_t w[3])
{
    const uint8_t *q = row + x;
    if (((uintptr_t)p & 1u) != 0) {
        *(volatile uint8_t *)p = *q;
        p += 1;
        q += 1;
        n -= 1;
        w[0]++;
    }
    if (((uintptr_t)p & 2u) != 0 && n >= 2) {
        *(volatile uint16_t *)(void *)p = *(const uint16_t *)(const void *)q;
        p += 2;
        q += 2;
        n -= 2;
        w[1]++;
    }
    uint32_t n32 = n >> 2;
    volatile uint32_t *d = (volatile uint32_t *)(void *)p;
    const uint32_t *s = (const uint32_t *)(const void *)q;
    for (uint32_t i = 0; i < n32; i++) d[i] = s[i];
    w[2] += n32;
    p += n32 * 4u;
    q += n32 * 4u;
    n &= 3u;
    if (n >= 2) {
        *(volatile uint16_t *)(void *)p = *(const uint16_t *)(const void *)q;
        p += 2;
        q += 2;
        n -= 2;
        w[1]++;
    }
    if (n != 0) {
        *(volatile uint8_t *)p = *q;
        w[0]++;
    }
}

/* hal_fill_span for pixels of many colours: row[x .. x + len) (row indexed by
 * screen column, 4-aligned) to pixels [x, x + len) of row y, counted. On a
 * planar page each pixel is a byte written with its plane's mask. */
void hal_put_span(const hal_surface *s, int y, int x, int len, const uint8_t *row);

/* Spans filled straight into a linear surface, counted here and added to the
 * counters at once (hal_add_tally): the renderer's fill loop pays no call and
 * no 64-bit sum per span, and every counter ends as hal_fill_span would leave it. */
typedef struct {
    uint32_t w[3];   /* transactions of 1, 2 and 4 bytes */
    uint32_t pixels; /* = bytes */
} hal_tally;

/* 1 if s can be filled with hal_fill_linear: a linear page or buffer. */
static inline int hal_surface_linear(const hal_surface *s)
{
    return s->pixels != 0 && !s->planar;
}

/* Pixels [x, x + len) of row y of a linear surface, with the writes
 * hal_fill_span makes, counted into t. The caller keeps 0 <= y < 200, 0 <= x,
 * 1 <= len and x + len <= 320. */
static inline __attribute__((always_inline)) void hal_fill_linear(const hal_surface *s, int y, int x, int len,
                                                                  uint8_t colour, hal_tally *t)
{
    hal_fill_run(s->pixels + (uint32_t)y * HAL_WIDTH + (uint32_t)x, (uint32_t)len, colour, t->w);
    t->pixels += (uint32_t)len;
}

/* hal_put_span into a linear surface, counted into t (the caller keeps the
 * bounds hal_fill_linear asks for). */
static inline __attribute__((always_inline)) void hal_put_linear(const hal_surface *s, int y, int x, int len,
                                                                 const uint8_t *row, hal_tally *t)
{
    hal_copy_run(s->pixels + (uint32_t)y * HAL_WIDTH + (uint32_t)x, row, (uint32_t)x, (uint32_t)len, t->w);
    t->pixels += (uint32_t)len;
}

/* Add what t counted for spans into s to the counters, and clear it. */
void hal_add_tally(const hal_surface *s, hal_tally *t);

/* Finish a frame: flip the display start to the drawn page, or copy the
 * system-memory buffer to the shown VRAM page with the chosen width (counted). */
void hal_present(hal_present_mode m);

/* The page the display shows now (what a camera pointed at the screen sees);
 * NULL when the pages are planar (the target reads those back itself). */
const uint8_t *hal_shown_page(void);

/* Palette: 768 bytes, 8 bits per gun. */
void hal_set_palette(const uint8_t *rgb);
const uint8_t *hal_get_palette(void);

/* ---- input and time (per target) --------------------------------------- */
#define HAL_KEY_FORWARD (1u << 0)
#define HAL_KEY_BACK (1u << 1)
#define HAL_KEY_TURN_LEFT (1u << 2)
#define HAL_KEY_TURN_RIGHT (1u << 3)
#define HAL_KEY_STRAFE_LEFT (1u << 4)
#define HAL_KEY_STRAFE_RIGHT (1u << 5)
#define HAL_KEY_FLY_UP (1u << 6)
#define HAL_KEY_FLY_DOWN (1u << 7)
#define HAL_KEY_LOOK_UP (1u << 8)
#define HAL_KEY_LOOK_DOWN (1u << 9)
#define HAL_KEY_RUN (1u << 10)
/* edge-triggered: reported once per press, cleared when read */
#define HAL_KEY_NEXT_MODE (1u << 16)
#define HAL_KEY_NEXT_PRESENT (1u << 17)
#define HAL_KEY_PRINT_COUNTERS (1u << 18)
#define HAL_KEY_PRINT_VIEW (1u << 19) /* the host's emu: print the camera as build/render options */
#define HAL_KEY_SCREENSHOT (1u << 20) /* the host's emu: save the frame shown as a PNG */
#define HAL_KEY_QUIT (1u << 30)

uint32_t hal_input(void);    /* HAL_KEY_* bits held or pressed since the last call */
uint32_t hal_ticks_ms(void); /* milliseconds since the target started */
void hal_frame_done(void);   /* the engine finished a frame: show it, stream it, ... */

/* ---- what each target provides to the shared code ------------------------ */
uint8_t *hal_target_vram(int page); /* page 0 or 1, HAL_PAGE_BYTES each */
/* The system-memory back buffer of the copy modes, or NULL: the target keeps
 * none, and the copy modes draw into the VRAM page the display does not show
 * (which needs two distinct linear pages). */
uint8_t *hal_target_sysmem(void);
uint8_t *hal_target_palette(void); /* HAL_PALETTE_BYTES */
void hal_target_set_display_start(int page);
int hal_target_display_start(void);
/* How the VRAM pages are laid out: 0 linear (pitch 320, every target but
 * hal/pcvga in flip mode); 1 the VGA's unchained layout, pixel (x, y) in plane
 * x & 3 at byte y * 80 + x / 4 of the page, each write reaching the planes
 * hal_target_plane_mask last enabled (bit p: plane p). The system-memory
 * buffer is always linear. */
int hal_target_vram_planar(void);
void hal_target_plane_mask(unsigned planes);

#endif
