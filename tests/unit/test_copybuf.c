/* test_copybuf.c - the copy present modes on a target that keeps no
 * system-memory buffer of its own (hal_target_sysmem() NULL, as hal/mps2):
 * hal/fb.c draws into the page the display does not show and copies it into
 * the shown one. A fake linear target in this file stands in for
 * hal/ram_target.c (the link is this file, hal/fb.c and hal/perf.c; see the
 * test_copybuf rule in the Makefile).
 *
 * What it checks: with either page shown, a copy mode's surface is the other
 * page, marked as system memory; a full-screen fill and its copy count exactly
 * what hal/ram_target.c's own buffer counts (test_hal.c: 16,000 system-memory
 * dword writes, then 64,000 / 32,000 / 16,000 VRAM writes by width, bus
 * cycles 1 and 8 each); the copy lands in the shown page, the display start
 * never moves, and flip mode after a copy frame still draws the hidden page.
 */
#include <stdarg.h>
#include <stddef.h>
#include <setjmp.h>
#include <stdint.h>
#include <string.h>
#include <cmocka.h>

#include "hal.h"

static struct {
    _Alignas(4) uint8_t vram[2][HAL_PAGE_BYTES];
    _Alignas(4) uint8_t palette[HAL_PALETTE_BYTES];
    int display_start;
} fk;

uint8_t *hal_target_vram(int page)
{
    return fk.vram[page ? 1 : 0];
}

uint8_t *hal_target_sysmem(void)
{
    return NULL; /* no buffer of its own */
}

uint8_t *hal_target_palette(void)
{
    return fk.palette;
}

void hal_target_set_display_start(int page)
{
    fk.display_start = page ? 1 : 0;
}

int hal_target_display_start(void)
{
    return fk.display_start;
}

int hal_target_vram_planar(void)
{
    return 0;
}

void hal_target_plane_mask(unsigned planes)
{
    (void)planes;
}

static int setup(void **state)
{
    (void)state;
    memset(&fk, 0, sizeof fk);
    hal_perf_set_bus((hal_bus_model){8, 1});
    hal_perf_reset();
    return 0;
}

static void fill_screen(const hal_surface *s, uint8_t colour)
{
    for (int y = 0; y < HAL_HEIGHT; y++) hal_fill_span(s, y, 0, HAL_WIDTH, colour);
}

static void check_page(int page, uint8_t colour)
{
    for (uint32_t i = 0; i < HAL_PAGE_BYTES; i++)
        if (fk.vram[page][i] != colour)
            fail_msg("page %d byte %u: %u, not %u", page, (unsigned)i, fk.vram[page][i], colour);
}

/* One copy frame with page `shown` on display: draw, check the counts, present. */
static void copy_frame(int shown, hal_present_mode m, uint64_t copy_writes, unsigned width, uint8_t colour)
{
    hal_target_set_display_start(shown);
    hal_perf_reset();
    hal_surface s = hal_begin_frame(m);
    assert_ptr_equal(s.pixels, fk.vram[1 - shown]);
    assert_int_equal(s.in_vram, 0);
    assert_int_equal(s.planar, 0);
    fill_screen(&s, colour);
    assert_int_equal(hal_perf_event(HAL_EV_SYSMEM_WRITES), 16000);
    assert_int_equal(hal_perf_event(HAL_EV_VRAM_WRITES), 0);
    assert_int_equal(hal_perf_event(HAL_EV_WRITES32), 16000);
    assert_int_equal(hal_perf_event(HAL_EV_PIXELS), 64000);
    assert_int_equal(hal_perf_tsc(), 16000);
    hal_perf_reset();
    hal_present(m);
    assert_int_equal(hal_perf_event(HAL_EV_WRITES), copy_writes);
    assert_int_equal(hal_perf_event(HAL_EV_VRAM_WRITES), copy_writes);
    assert_int_equal(hal_perf_event(HAL_EV_COPY_WRITES), copy_writes);
    assert_int_equal(hal_perf_event(HAL_EV_SYSMEM_WRITES), 0);
    assert_int_equal(hal_perf_event(HAL_EV_BYTES), HAL_PAGE_BYTES);
    assert_int_equal(hal_perf_event(HAL_EV_WRITES8), width == 1 ? copy_writes : 0);
    assert_int_equal(hal_perf_event(HAL_EV_WRITES16), width == 2 ? copy_writes : 0);
    assert_int_equal(hal_perf_event(HAL_EV_WRITES32), width == 4 ? copy_writes : 0);
    assert_int_equal(hal_perf_tsc(), copy_writes * 8u);
    assert_int_equal(hal_target_display_start(), shown);
    assert_ptr_equal(hal_shown_page(), fk.vram[shown]);
    check_page(shown, colour);
    check_page(1 - shown, colour);
}

static void test_copy_modes_use_the_hidden_page(void **state)
{
    (void)state;
    copy_frame(0, HAL_PRESENT_COPY8, 64000, 1, 0x11);
    copy_frame(1, HAL_PRESENT_COPY16, 32000, 2, 0x22);
    copy_frame(0, HAL_PRESENT_COPY32, 16000, 4, 0x33);
    copy_frame(1, HAL_PRESENT_COPY32, 16000, 4, 0x44);
}

/* Frames switch between the modes: each draws where its mode says, and the
 * shown page always holds the frame just presented. */
static void test_flip_and_copy_alternate(void **state)
{
    (void)state;
    hal_surface s = hal_begin_frame(HAL_PRESENT_FLIP);
    assert_ptr_equal(s.pixels, fk.vram[1]);
    fill_screen(&s, 0x51);
    hal_present(HAL_PRESENT_FLIP);
    assert_int_equal(hal_target_display_start(), 1);
    check_page(1, 0x51);

    s = hal_begin_frame(HAL_PRESENT_COPY32);
    assert_ptr_equal(s.pixels, fk.vram[0]);
    fill_screen(&s, 0x52);
    check_page(1, 0x51); /* still showing the flip frame while drawing */
    hal_present(HAL_PRESENT_COPY32);
    assert_int_equal(hal_target_display_start(), 1);
    check_page(1, 0x52);

    s = hal_begin_frame(HAL_PRESENT_FLIP);
    assert_ptr_equal(s.pixels, fk.vram[0]);
    fill_screen(&s, 0x53);
    check_page(1, 0x52);
    hal_present(HAL_PRESENT_FLIP);
    assert_int_equal(hal_target_display_start(), 0);
    check_page(0, 0x53);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test_setup(test_copy_modes_use_the_hidden_page, setup),
        cmocka_unit_test_setup(test_flip_and_copy_alternate, setup),
    };
    return cmocka_run_group_tests_name("copybuf", tests, NULL, NULL);
}
