/* test_hal.c - unit tests of the shared hal code (hal/fb.c, hal/perf.c) on the
 * headless target (hal/null): the chapter 62 write counts of the present paths,
 * span fills against a reference byte loop, clipping, the programmable
 * counters, the bus cost model, page flipping, the palette and the null
 * target's clock and input.
 */
#include <stdarg.h>
#include <stddef.h>
#include <setjmp.h>
#include <stdint.h>
#include <limits.h>
#include <string.h>
#include <cmocka.h>

#include "hal.h"
#include "perf_internal.h"
#include "null/hal_null.h"

static const hal_bus_model default_bus = {8, 1};

static int setup(void **state)
{
    (void)state;
    hal_null_reset();
    hal_perf_set_bus(default_bus);
    hal_perf_select(0, HAL_EV_WRITES);
    hal_perf_select(1, HAL_EV_VRAM_WRITES);
    hal_perf_reset();
    return 0;
}

static void fill_screen(const hal_surface *s, uint8_t colour)
{
    for (int y = 0; y < HAL_HEIGHT; y++) hal_fill_span(s, y, 0, HAL_WIDTH, colour);
}

/* A recognisable, non-uniform frame in the system-memory buffer (not counted). */
static void pattern_sysmem(void)
{
    uint8_t *p = hal_target_sysmem();
    for (uint32_t i = 0; i < HAL_PAGE_BYTES; i++) p[i] = (uint8_t)(i * 7u + i / 320u);
}

static void check_copy(hal_present_mode m, uint64_t writes, unsigned width)
{
    hal_surface s = hal_begin_frame(m);
    assert_non_null(s.pixels);
    assert_int_equal(s.in_vram, 0);
    assert_ptr_equal(s.pixels, hal_target_sysmem());
    pattern_sysmem();
    hal_perf_reset();
    hal_present(m);
    assert_int_equal(hal_perf_event(HAL_EV_WRITES), writes);
    assert_int_equal(hal_perf_event(HAL_EV_VRAM_WRITES), writes);
    assert_int_equal(hal_perf_event(HAL_EV_SYSMEM_WRITES), 0);
    assert_int_equal(hal_perf_event(HAL_EV_COPY_WRITES), writes);
    assert_int_equal(hal_perf_event(HAL_EV_BYTES), HAL_PAGE_BYTES);
    assert_int_equal(hal_perf_event(HAL_EV_PIXELS), 0);
    assert_int_equal(hal_perf_event(HAL_EV_WRITES8), width == 1 ? writes : 0);
    assert_int_equal(hal_perf_event(HAL_EV_WRITES16), width == 2 ? writes : 0);
    assert_int_equal(hal_perf_event(HAL_EV_WRITES32), width == 4 ? writes : 0);
    assert_int_equal(hal_perf_tsc(), writes * 8u);
    /* the copy lands in the shown page; the display start does not move */
    assert_int_equal(hal_target_display_start(), 0);
    assert_ptr_equal(hal_shown_page(), hal_target_vram(0));
    assert_memory_equal(hal_shown_page(), hal_target_sysmem(), HAL_PAGE_BYTES);
}

/* Chapter 62: 64,000 byte writes vs 16,000 dword writes. */
static void test_copy8_counts_64000(void **state)
{
    (void)state;
    check_copy(HAL_PRESENT_COPY8, 64000, 1);
}

static void test_copy16_counts_32000(void **state)
{
    (void)state;
    check_copy(HAL_PRESENT_COPY16, 32000, 2);
}

static void test_copy32_counts_16000(void **state)
{
    (void)state;
    check_copy(HAL_PRESENT_COPY32, 16000, 4);
}

static void test_flip_counts_no_copy(void **state)
{
    (void)state;
    hal_surface s = hal_begin_frame(HAL_PRESENT_FLIP);
    assert_int_equal(s.in_vram, 1);
    fill_screen(&s, 9);
    assert_int_equal(hal_perf_event(HAL_EV_VRAM_WRITES), 16000);
    assert_int_equal(hal_perf_event(HAL_EV_WRITES32), 16000);
    assert_int_equal(hal_perf_tsc(), 16000u * 8u);
    hal_perf_reset();
    hal_present(HAL_PRESENT_FLIP);
    for (int e = 0; e < HAL_EV_COUNT; e++) assert_int_equal(hal_perf_event((hal_event)e), 0);
    assert_int_equal(hal_perf_tsc(), 0);
    assert_ptr_equal(hal_shown_page(), s.pixels);
}

static void test_fullscreen_sysmem_fill(void **state)
{
    (void)state;
    hal_surface s = hal_begin_frame(HAL_PRESENT_COPY32);
    fill_screen(&s, 0xa5);
    assert_int_equal(hal_perf_event(HAL_EV_SYSMEM_WRITES), 16000);
    assert_int_equal(hal_perf_event(HAL_EV_WRITES32), 16000);
    assert_int_equal(hal_perf_event(HAL_EV_WRITES), 16000);
    assert_int_equal(hal_perf_event(HAL_EV_WRITES8), 0);
    assert_int_equal(hal_perf_event(HAL_EV_WRITES16), 0);
    assert_int_equal(hal_perf_event(HAL_EV_VRAM_WRITES), 0);
    assert_int_equal(hal_perf_event(HAL_EV_COPY_WRITES), 0);
    assert_int_equal(hal_perf_event(HAL_EV_PIXELS), 64000);
    assert_int_equal(hal_perf_event(HAL_EV_BYTES), 64000);
    assert_int_equal(hal_perf_tsc(), 16000);
    const uint8_t *p = hal_target_sysmem();
    for (uint32_t i = 0; i < HAL_PAGE_BYTES; i++) assert_int_equal(p[i], 0xa5);
    /* nothing reached VRAM */
    for (uint32_t i = 0; i < HAL_PAGE_BYTES; i++) assert_int_equal(hal_target_vram(0)[i] | hal_target_vram(1)[i], 0);
}

/* Reference: greedy naturally aligned decomposition, one address at a time. */
static void ref_counts(uintptr_t addr, int len, uint64_t *n8, uint64_t *n16, uint64_t *n32)
{
    *n8 = *n16 = *n32 = 0;
    while (len > 0) {
        if ((addr & 3u) == 0 && len >= 4) {
            (*n32)++;
            addr += 4;
            len -= 4;
        } else if ((addr & 1u) == 0 && len >= 2) {
            (*n16)++;
            addr += 2;
            len -= 2;
        } else {
            (*n8)++;
            addr += 1;
            len -= 1;
        }
    }
}

/* Reference byte loop with the documented clipping. */
static void ref_fill(uint8_t *buf, int y, int x, int len, uint8_t c)
{
    if (y < 0 || y >= HAL_HEIGHT) return;
    for (long long i = x; i < (long long)x + len; i++)
        if (i >= 0 && i < HAL_WIDTH) buf[y * HAL_WIDTH + i] = c;
}

static uint8_t ref_buf[HAL_PAGE_BYTES];

static void test_fill_span_unaligned(void **state)
{
    (void)state;
    hal_surface s = hal_begin_frame(HAL_PRESENT_COPY8);
    memset(ref_buf, 0, sizeof ref_buf);
    uint8_t colour = 1;
    int y = 0;
    static const int xs[] = {0, 1, 2, 3, 4, 5, 6, 7, 101, 157, 290, 303, 310, 315, 316, 317, 318, 319};
    for (size_t xi = 0; xi < sizeof xs / sizeof xs[0]; xi++) {
        for (int len = 1; len <= 23 && xs[xi] + len <= HAL_WIDTH; len++) {
            int x = xs[xi];
            uint64_t e8, e16, e32;
            ref_counts((uintptr_t)(s.pixels + y * HAL_WIDTH + x), len, &e8, &e16, &e32);
            hal_perf_reset();
            hal_fill_span(&s, y, x, len, colour);
            ref_fill(ref_buf, y, x, len, colour);
            assert_int_equal(hal_perf_event(HAL_EV_WRITES8), e8);
            assert_int_equal(hal_perf_event(HAL_EV_WRITES16), e16);
            assert_int_equal(hal_perf_event(HAL_EV_WRITES32), e32);
            assert_int_equal(hal_perf_event(HAL_EV_WRITES), e8 + e16 + e32);
            assert_int_equal(hal_perf_event(HAL_EV_SYSMEM_WRITES), e8 + e16 + e32);
            assert_int_equal(hal_perf_event(HAL_EV_BYTES), len);
            assert_int_equal(hal_perf_event(HAL_EV_PIXELS), len);
            assert_int_equal(hal_perf_tsc(), e8 + e16 + e32);
            /* the whole buffer matches, so nothing beyond the span changed */
            assert_memory_equal(s.pixels, ref_buf, HAL_PAGE_BYTES);
            colour = (uint8_t)(colour * 5u + 3u);
            y = (y + 7) % HAL_HEIGHT;
        }
    }
    /* Hand-checked cases: x=1,len=6 -> byte, word, word, byte; x=3,len=9 -> byte, 2 dwords */
    hal_perf_reset();
    hal_fill_span(&s, 0, 1, 6, 2);
    assert_int_equal(hal_perf_event(HAL_EV_WRITES8), 2);
    assert_int_equal(hal_perf_event(HAL_EV_WRITES16), 2);
    assert_int_equal(hal_perf_event(HAL_EV_WRITES32), 0);
    hal_perf_reset();
    hal_fill_span(&s, 0, 3, 9, 2);
    assert_int_equal(hal_perf_event(HAL_EV_WRITES8), 1);
    assert_int_equal(hal_perf_event(HAL_EV_WRITES16), 0);
    assert_int_equal(hal_perf_event(HAL_EV_WRITES32), 2);
}

/* A surface inside a guarded buffer: clipped spans never touch the guards. */
#define GUARD 256
static _Alignas(4) uint8_t guarded[GUARD + HAL_PAGE_BYTES + GUARD];

static void test_fill_span_clipping(void **state)
{
    (void)state;
    static const int cases[][3] = {
        /* y, x, len */
        {-1, 0, 320},
        {200, 0, 320},
        {INT_MIN, 0, 320},
        {INT_MAX, 0, 320},
        {5, -10, 5},
        {5, -10, 10},
        {6, -10, 11},
        {7, -10, 20},
        {8, -1000, 5000},
        {9, 315, 100},
        {10, 319, 2},
        {11, 320, 1},
        {12, 400, 10},
        {13, 0, 0},
        {14, 10, -5},
        {15, INT_MIN, INT_MAX},
        {16, INT_MAX, INT_MAX},
        {17, 0, INT_MAX},
        {18, -3, INT_MAX},
        {19, 100, INT_MIN},
        {199, 318, 7},
        {0, -2, 3},
    };
    memset(guarded, 0xee, sizeof guarded);
    memset(ref_buf, 0xee, sizeof ref_buf);
    hal_surface s = {guarded + GUARD, 0};
    uint8_t colour = 0x11;
    for (size_t i = 0; i < sizeof cases / sizeof cases[0]; i++) {
        int y = cases[i][0], x = cases[i][1], len = cases[i][2];
        long long lo = x < 0 ? 0 : x, hi = (long long)x + len;
        if (hi > HAL_WIDTH) hi = HAL_WIDTH;
        long long expect = (y >= 0 && y < HAL_HEIGHT && hi > lo) ? hi - lo : 0;
        hal_perf_reset();
        hal_fill_span(&s, y, x, len, colour);
        ref_fill(ref_buf, y, x, len, colour);
        assert_int_equal(hal_perf_event(HAL_EV_PIXELS), expect);
        assert_int_equal(hal_perf_event(HAL_EV_BYTES), expect);
        if (expect == 0) assert_int_equal(hal_perf_event(HAL_EV_WRITES), 0);
        assert_memory_equal(s.pixels, ref_buf, HAL_PAGE_BYTES);
        colour++;
    }
    for (int i = 0; i < GUARD; i++) {
        assert_int_equal(guarded[i], 0xee);
        assert_int_equal(guarded[GUARD + HAL_PAGE_BYTES + i], 0xee);
    }
    /* a NULL surface or pixel pointer is ignored */
    hal_surface none = {NULL, 1};
    hal_perf_reset();
    hal_fill_span(&none, 0, 0, 320, 1);
    hal_fill_span(NULL, 0, 0, 320, 1);
    assert_int_equal(hal_perf_event(HAL_EV_WRITES), 0);
    assert_int_equal(hal_perf_event(HAL_EV_PIXELS), 0);
}

static void test_programmable_counters(void **state)
{
    (void)state;
    hal_surface s = hal_begin_frame(HAL_PRESENT_FLIP);
    hal_fill_span(&s, 0, 0, 320, 1); /* 80 dwords before selection */
    hal_perf_select(0, HAL_EV_WRITES8);
    hal_perf_select(1, HAL_EV_PIXELS);
    assert_int_equal(hal_perf_read(0), 0);
    assert_int_equal(hal_perf_read(1), 0);
    hal_fill_span(&s, 1, 1, 3, 1); /* byte + word */
    hal_fill_span(&s, 2, 5, 1, 1); /* byte */
    assert_int_equal(hal_perf_read(0), 2);
    assert_int_equal(hal_perf_read(1), 4);
    assert_int_equal(hal_perf_event(HAL_EV_PIXELS), 324); /* totals run on */
    /* re-selecting counts from zero again */
    hal_perf_select(1, HAL_EV_WRITES32);
    assert_int_equal(hal_perf_read(1), 0);
    hal_fill_span(&s, 3, 0, 16, 1);
    assert_int_equal(hal_perf_read(1), 4);
    assert_int_equal(hal_perf_read(0), 2);
    /* reset zeroes counters but keeps the selection */
    hal_perf_reset();
    assert_int_equal(hal_perf_read(0), 0);
    assert_int_equal(hal_perf_read(1), 0);
    hal_fill_span(&s, 4, 0, 8, 1);
    assert_int_equal(hal_perf_read(0), 0);
    assert_int_equal(hal_perf_read(1), 2);
    /* present-copy writes can be selected too */
    hal_perf_select(0, HAL_EV_COPY_WRITES);
    hal_present(HAL_PRESENT_COPY32);
    assert_int_equal(hal_perf_read(0), 16000);
    /* out-of-range counters and events are ignored */
    hal_perf_select(2, HAL_EV_BYTES);
    hal_perf_select(-1, HAL_EV_BYTES);
    hal_perf_select(0, HAL_EV_COUNT);
    assert_int_equal(hal_perf_read(0), 16000);
    assert_int_equal(hal_perf_read(2), 0);
    assert_int_equal(hal_perf_read(-1), 0);
    assert_int_equal(hal_perf_event(HAL_EV_COUNT), 0);
}

static void test_bus_model_cycles(void **state)
{
    (void)state;
    hal_bus_model b = hal_perf_bus();
    assert_int_equal(b.vram_cycles, 8);
    assert_int_equal(b.sysmem_cycles, 1);
    hal_bus_model m = {13, 3};
    hal_perf_set_bus(m);
    b = hal_perf_bus();
    assert_int_equal(b.vram_cycles, 13);
    assert_int_equal(b.sysmem_cycles, 3);
    hal_surface v = hal_begin_frame(HAL_PRESENT_FLIP);
    hal_surface sm = hal_begin_frame(HAL_PRESENT_COPY16);
    hal_fill_span(&v, 0, 1, 10, 1); /* byte, word, dword, word, byte */
    hal_fill_span(&sm, 0, 3, 300, 1);
    hal_fill_span(&sm, 1, 0, 320, 1);
    uint64_t vw = hal_perf_event(HAL_EV_VRAM_WRITES);
    uint64_t sw = hal_perf_event(HAL_EV_SYSMEM_WRITES);
    assert_true(vw > 0 && sw > 0);
    assert_int_equal(vw + sw, hal_perf_event(HAL_EV_WRITES));
    assert_int_equal(hal_perf_tsc(), vw * 13u + sw * 3u);
    /* the cost is per transaction, whatever its width: copy8 costs 4x copy32 */
    hal_perf_set_bus(default_bus);
    hal_perf_reset();
    hal_present(HAL_PRESENT_COPY8);
    uint64_t c8 = hal_perf_tsc();
    hal_perf_reset();
    hal_present(HAL_PRESENT_COPY32);
    assert_int_equal(c8, 512000);
    assert_int_equal(hal_perf_tsc(), 128000);
    assert_int_equal(c8, 4 * hal_perf_tsc());
    /* a modelled frame: full-screen draw into sysmem + copy32 = 16,000*1 + 16,000*8 */
    hal_perf_reset();
    hal_surface f = hal_begin_frame(HAL_PRESENT_COPY32);
    fill_screen(&f, 3);
    hal_present(HAL_PRESENT_COPY32);
    assert_int_equal(hal_perf_tsc(), 16000u + 16000u * 8u);
    /* large totals do not wrap at 32 bits */
    hal_perf_reset();
    hal_perf_add_writes(4, HAL_DEST_VRAM, UINT32_MAX, 0);
    hal_perf_add_writes(4, HAL_DEST_VRAM, UINT32_MAX, 0);
    assert_int_equal(hal_perf_event(HAL_EV_WRITES), 2ull * UINT32_MAX);
    assert_int_equal(hal_perf_event(HAL_EV_BYTES), 8ull * UINT32_MAX);
    assert_int_equal(hal_perf_tsc(), 16ull * UINT32_MAX);
    hal_perf_add_writes(3, HAL_DEST_VRAM, 1, 0); /* bad width: ignored */
    assert_int_equal(hal_perf_event(HAL_EV_WRITES), 2ull * UINT32_MAX);
}

/* Spans are summed in 32 bits and folded into the 64-bit totals: a change of
 * bus model or counter selection between spans, and more than 2^32 pixels with
 * no read or present between, give what per-span 64-bit sums give. */
static void test_span_sums_fold(void **state)
{
    (void)state;
    hal_surface v = hal_begin_frame(HAL_PRESENT_FLIP);
    hal_fill_span(&v, 0, 1, 10, 1); /* byte, word, dword, word, byte: 5 transactions */
    hal_bus_model m = {13, 3};
    hal_perf_set_bus(m);
    hal_perf_select(0, HAL_EV_WRITES32);
    hal_fill_span(&v, 1, 0, 320, 1); /* 80 dwords */
    assert_int_equal(hal_perf_tsc(), 5u * 8u + 80u * 13u);
    assert_int_equal(hal_perf_read(0), 80);
    assert_int_equal(hal_perf_event(HAL_EV_WRITES), 85);
    assert_int_equal(hal_perf_event(HAL_EV_PIXELS), 330);
    hal_perf_set_bus(default_bus);
    hal_perf_reset();
    const uint64_t spans = 13500000; /* 320 pixels each: 4.32e9 > 2^32 */
    for (uint64_t i = 0; i < spans; i++) hal_perf_add_span(HAL_DEST_SYSMEM, 0, 0, 80, 320, 320);
    assert_int_equal(hal_perf_event(HAL_EV_PIXELS), spans * 320u);
    assert_int_equal(hal_perf_event(HAL_EV_BYTES), spans * 320u);
    assert_int_equal(hal_perf_event(HAL_EV_WRITES32), spans * 80u);
    assert_int_equal(hal_perf_event(HAL_EV_SYSMEM_WRITES), spans * 80u);
    assert_int_equal(hal_perf_tsc(), spans * 80u);
}

static void test_flip_alternates_pages(void **state)
{
    (void)state;
    uint8_t *p0 = hal_target_vram(0), *p1 = hal_target_vram(1);
    assert_ptr_not_equal(p0, p1);
    assert_int_equal((uintptr_t)p0 & 3u, 0);
    assert_int_equal((uintptr_t)p1 & 3u, 0);
    assert_int_equal((uintptr_t)hal_target_sysmem() & 3u, 0);
    assert_ptr_equal(hal_shown_page(), p0);
    for (int frame = 0; frame < 6; frame++) {
        const uint8_t *shown_before = hal_shown_page();
        hal_surface s = hal_begin_frame(HAL_PRESENT_FLIP);
        assert_int_equal(s.in_vram, 1);
        assert_ptr_not_equal(s.pixels, shown_before); /* never draw the shown page */
        assert_ptr_equal(s.pixels, (frame & 1) ? p0 : p1);
        uint8_t c = (uint8_t)(40 + frame);
        fill_screen(&s, c);
        hal_present(HAL_PRESENT_FLIP);
        hal_frame_done();
        assert_ptr_equal(hal_shown_page(), s.pixels);
        assert_int_equal(hal_target_display_start(), (frame & 1) ? 0 : 1);
        assert_int_equal(hal_shown_page()[0], c);
        assert_int_equal(hal_shown_page()[HAL_PAGE_BYTES - 1], c);
    }
    assert_int_equal(hal_null_frames(), 6);
    /* unknown modes: no surface, present does nothing */
    hal_surface bad = hal_begin_frame(HAL_PRESENT_COUNT);
    assert_null(bad.pixels);
    const uint8_t *shown = hal_shown_page();
    hal_perf_reset();
    hal_present(HAL_PRESENT_COUNT);
    assert_ptr_equal(hal_shown_page(), shown);
    assert_int_equal(hal_perf_event(HAL_EV_WRITES), 0);
}

static void test_palette_round_trip(void **state)
{
    (void)state;
    uint8_t pal[HAL_PALETTE_BYTES];
    for (int i = 0; i < HAL_PALETTE_BYTES; i++) pal[i] = (uint8_t)(255 - i * 3);
    hal_set_palette(pal);
    assert_memory_equal(hal_get_palette(), pal, HAL_PALETTE_BYTES);
    pal[0] ^= 0xff; /* a copy, not an alias */
    assert_int_not_equal(hal_get_palette()[0], pal[0]);
    hal_set_palette(NULL); /* ignored */
    assert_int_equal(hal_get_palette()[5], (uint8_t)(255 - 15));
    hal_perf_reset();
    hal_set_palette(pal);
    assert_int_equal(hal_perf_event(HAL_EV_WRITES), 0); /* not a framebuffer write */
}

static void test_names(void **state)
{
    (void)state;
    static const char *const ev[] = {"writes",      "bytes",         "writes8", "writes16",   "writes32",
                                     "vram_writes", "sysmem_writes", "pixels",  "copy_writes"};
    assert_int_equal(sizeof ev / sizeof ev[0], HAL_EV_COUNT);
    for (int e = 0; e < HAL_EV_COUNT; e++) assert_string_equal(hal_event_name((hal_event)e), ev[e]);
    assert_string_equal(hal_event_name(HAL_EV_COUNT), "unknown");
    static const char *const pm[] = {"flip", "copy8", "copy16", "copy32"};
    for (int m = 0; m < HAL_PRESENT_COUNT; m++) {
        assert_string_equal(hal_present_name((hal_present_mode)m), pm[m]);
        assert_int_equal(hal_present_parse(pm[m]), m);
    }
    assert_string_equal(hal_present_name(HAL_PRESENT_COUNT), "unknown");
    assert_int_equal(hal_present_parse("copy"), -1);
    assert_int_equal(hal_present_parse("copy320"), -1);
    assert_int_equal(hal_present_parse(""), -1);
    assert_int_equal(hal_present_parse("FLIP"), -1);
    assert_int_equal(hal_present_parse(NULL), -1);
}

static void test_null_clock_and_input(void **state)
{
    (void)state;
    assert_int_equal(hal_ticks_ms(), 0);
    hal_frame_done();
    assert_int_equal(hal_ticks_ms(), 28); /* 1000/35 = 28.57 */
    for (int i = 1; i < 35; i++) hal_frame_done();
    assert_int_equal(hal_ticks_ms(), 1000);
    for (int i = 0; i < 35 * 9; i++) hal_frame_done();
    assert_int_equal(hal_ticks_ms(), 10000);
    assert_int_equal(hal_null_frames(), 350);
    hal_null_set_ticks(12345);
    hal_frame_done();
    assert_int_equal(hal_ticks_ms(), 12345);
    hal_null_reset();
    assert_int_equal(hal_ticks_ms(), 0);
    assert_int_equal(hal_null_frames(), 0);

    uint32_t keys = HAL_KEY_FORWARD | HAL_KEY_RUN | HAL_KEY_NEXT_MODE | HAL_KEY_PRINT_COUNTERS;
    hal_null_set_input(keys);
    assert_int_equal(hal_input(), keys);
    assert_int_equal(hal_input(), HAL_KEY_FORWARD | HAL_KEY_RUN); /* edges once */
    hal_null_set_input(HAL_KEY_QUIT | HAL_KEY_NEXT_PRESENT);
    assert_int_equal(hal_input(), HAL_KEY_QUIT | HAL_KEY_NEXT_PRESENT);
    assert_int_equal(hal_input(), HAL_KEY_QUIT);
    hal_null_set_input(0);
    assert_int_equal(hal_input(), 0);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test_setup(test_copy8_counts_64000, setup),
        cmocka_unit_test_setup(test_copy16_counts_32000, setup),
        cmocka_unit_test_setup(test_copy32_counts_16000, setup),
        cmocka_unit_test_setup(test_flip_counts_no_copy, setup),
        cmocka_unit_test_setup(test_fullscreen_sysmem_fill, setup),
        cmocka_unit_test_setup(test_fill_span_unaligned, setup),
        cmocka_unit_test_setup(test_fill_span_clipping, setup),
        cmocka_unit_test_setup(test_programmable_counters, setup),
        cmocka_unit_test_setup(test_bus_model_cycles, setup),
        cmocka_unit_test_setup(test_span_sums_fold, setup),
        cmocka_unit_test_setup(test_flip_alternates_pages, setup),
        cmocka_unit_test_setup(test_palette_round_trip, setup),
        cmocka_unit_test_setup(test_names, setup),
        cmocka_unit_test_setup(test_null_clock_and_input, setup),
    };
    return cmocka_run_group_tests_name("hal", tests, NULL, NULL);
}
