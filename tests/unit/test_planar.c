/* test_planar.c - unit tests of hal_fill_span's planar path (hal/fb.c
 * fill_planar) and of the flip-mode surface on a planar target, against a
 * fake VGA in this file instead of hal/ram_target.c (the link is only this
 * file, hal/fb.c and hal/perf.c; see the test_planar rule in the Makefile).
 *
 * What it checks: for rows 0, 1, 100 and 199, every x in 0..319 and every len
 * in 1..320-x, one span on a background page changes exactly pixels [x, x+len)
 * of row y once the planes are decoded back to a linear frame, touches each
 * 4-pixel group's byte once, and counts pixels == len, bytes == n8 + 2 n16 +
 * 4 n32 == groups covered, writes8 <= the partial groups plus the run's odd
 * head and tail, writes16 <= 2, writes32 == every aligned dword of the
 * whole-group run, vram_writes == writes, no system-memory or copy writes;
 * a full row is 20 dword writes (80 bytes). Clipped spans (x < 0,
 * x + len > 320, len <= 0, rows and columns out of range) write nothing
 * outside the clipped row. Random overlapping spans match a linear reference.
 * hal_begin_frame(HAL_PRESENT_FLIP) gives the hidden page, planar = 1;
 * hal_shown_page() is NULL; hal_present(HAL_PRESENT_FLIP) flips the start.
 *
 * Why the fake works this way: on the VGA a CPU byte store reaches every
 * plane the map mask enables, but a C store through a pointer cannot be routed
 * by a mask. So hal_target_vram(page) returns a 4-aligned "CPU-visible" array
 * filled with a sentinel byte (never a colour the tests draw), and the fake
 * commits it: whenever hal_target_plane_mask is called, and once more after
 * each hal_fill_span (the test calls fake_commit), every CPU byte that differs
 * from the sentinel is copied into each plane the mask in force while it was
 * written enables, and reset to the sentinel. A byte written with no plane
 * enabled is counted as lost; the mask is poisoned to 0 before every span, so
 * a write relying on a mask left by an earlier span is lost too. Commits scan
 * only a window (the row being drawn, 80 bytes) to keep the exhaustive loops
 * fast; after them the whole CPU array of both pages must still be all
 * sentinel, which catches any store outside the window. Dword alignment: the
 * pages are 4-aligned and writes32 must equal the aligned dwords of the run;
 * in the sanitizer build UBSan's alignment check also traps a misaligned
 * dword store.
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

#define ROW_BYTES (HAL_WIDTH / 4)        /* 80 bytes per row in each plane */
#define PLANE_BYTES (HAL_PAGE_BYTES / 4) /* 16,000 bytes per plane per page */
#define SENTINEL 0x00u                   /* never drawn: colours are 1..255 */
#define BACKGROUND 0x5Au
#define HIDDEN 1 /* the page drawn in flip mode while the display shows page 0 */

/* ---- the fake VGA target ------------------------------------------------- */
static struct {
    _Alignas(4) uint8_t cpu[2][PLANE_BYTES]; /* what the CPU writes: hal_target_vram(page) */
    uint8_t plane[2][4][PLANE_BYTES];        /* the planes, per page */
    _Alignas(4) uint8_t sysmem[HAL_PAGE_BYTES];
    _Alignas(4) uint8_t palette[HAL_PALETTE_BYTES];
    int display_start;
    unsigned mask; /* the map mask in force */
    int win_page;  /* commit scans cpu[win_page][win_lo, win_hi); -1: both pages, whole */
    uint32_t win_lo, win_hi;
    uint32_t committed; /* CPU bytes moved into the planes */
    uint32_t lost;      /* CPU bytes written while the mask enabled no plane */
    uint32_t bad_masks; /* hal_target_plane_mask calls with bits above plane 3 */
    uint32_t mask_calls;
} fk;

static void commit_range(int page, uint32_t lo, uint32_t hi)
{
    uint8_t *cpu = fk.cpu[page];
    for (uint32_t i = lo; i < hi; i++) {
        uint8_t v = cpu[i];
        if (v == SENTINEL) continue;
        if ((fk.mask & 0xFu) == 0) fk.lost++;
        for (int p = 0; p < 4; p++)
            if (fk.mask & (1u << p)) fk.plane[page][p][i] = v;
        cpu[i] = SENTINEL;
        fk.committed++;
    }
}

/* Move what the CPU wrote since the last commit into the planes of the mask in force. */
static void fake_commit(void)
{
    if (fk.win_page < 0) {
        commit_range(0, 0, PLANE_BYTES);
        commit_range(1, 0, PLANE_BYTES);
    } else {
        commit_range(fk.win_page, fk.win_lo, fk.win_hi);
    }
}

static void fake_window_all(void)
{
    fk.win_page = -1;
}

static void fake_window_row(int page, int y)
{
    fk.win_page = page;
    fk.win_lo = (uint32_t)y * ROW_BYTES;
    fk.win_hi = fk.win_lo + ROW_BYTES;
}

static void fake_reset(void)
{
    memset(fk.cpu, SENTINEL, sizeof fk.cpu);
    memset(fk.plane, BACKGROUND, sizeof fk.plane);
    memset(fk.sysmem, 0, sizeof fk.sysmem);
    memset(fk.palette, 0, sizeof fk.palette);
    fk.display_start = 0;
    fk.mask = 0;
    fk.win_page = -1;
    fk.committed = fk.lost = fk.bad_masks = fk.mask_calls = 0;
}

uint8_t *hal_target_vram(int page)
{
    return fk.cpu[page ? 1 : 0];
}

uint8_t *hal_target_sysmem(void)
{
    return fk.sysmem;
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
    return 1;
}

void hal_target_plane_mask(unsigned planes)
{
    fake_commit(); /* the bytes written so far went to the old mask's planes */
    if (planes & ~0xFu) fk.bad_masks++;
    fk.mask = planes & 0xFu;
    fk.mask_calls++;
}

/* Pixel (x, y) of a page, decoded from the planes. */
static uint8_t pixel(int page, int x, int y)
{
    return fk.plane[page][x & 3][(uint32_t)y * ROW_BYTES + (uint32_t)x / 4u];
}

static void row_to_background(int page, int y)
{
    for (int p = 0; p < 4; p++) memset(&fk.plane[page][p][(uint32_t)y * ROW_BYTES], BACKGROUND, ROW_BYTES);
}

/* Every CPU-visible byte of both pages must be the sentinel: nothing was
 * written outside the commit window. */
static void assert_no_stray_writes(void)
{
    for (int page = 0; page < 2; page++)
        for (uint32_t i = 0; i < PLANE_BYTES; i++)
            if (fk.cpu[page][i] != SENTINEL)
                fail_msg("stray write: page %d byte %u (row %u, group %u) = 0x%02x", page, i, i / ROW_BYTES,
                         i % ROW_BYTES, fk.cpu[page][i]);
}

/* ---- expected counts -------------------------------------------------------- */
typedef struct {
    uint32_t groups; /* 4-pixel groups (bytes) the span covers */
    uint32_t max8;   /* partial groups + the run's odd head and odd tail */
    uint32_t dwords; /* aligned dwords inside the run of whole groups */
} expect_counts;

/* For an already clipped span [x, x + len), len >= 1. Rows start 4-aligned
 * (80 bytes a row, pages 4-aligned), so a group's offset in the row has the
 * alignment of its address. */
static expect_counts expected(int x, int len)
{
    expect_counts e = {0, 0, 0};
    int g0 = x / 4, g1 = (x + len - 1) / 4;
    int a = g0, b = g1; /* the run of whole groups, inclusive */
    e.groups = (uint32_t)(g1 - g0 + 1);
    if (x % 4 != 0) {
        a++;
        e.max8++;
    }
    if ((x + len) % 4 != 0 && (g1 != g0 || x % 4 == 0)) {
        b--;
        e.max8++;
    }
    if (a <= b) {
        e.max8 += (uint32_t)(a & 1) + (uint32_t)((b + 1) & 1);
        int lo = (a + 3) / 4, hi = (b + 1) / 4; /* dword k covers 4k..4k+3 */
        e.dwords = hi > lo ? (uint32_t)(hi - lo) : 0;
    }
    return e;
}

/* One span on surface s: the page's CPU memory committed before and after,
 * the mask poisoned, the counters zeroed first. */
static void draw(const hal_surface *s, int y, int x, int len, uint8_t colour)
{
    fake_commit();
    fk.mask = 0;
    fk.committed = fk.lost = fk.bad_masks = fk.mask_calls = 0;
    hal_perf_reset();
    hal_fill_span(s, y, x, len, colour);
    fake_commit();
}

/* The counters and the fake's tallies after draw() of a clipped span [x, x+len)
 * (len 0: nothing drawn). Returns NULL if they agree, else what differs. */
static const char *counts_problem(int x, int len)
{
    uint64_t w8 = hal_perf_event(HAL_EV_WRITES8), w16 = hal_perf_event(HAL_EV_WRITES16);
    uint64_t w32 = hal_perf_event(HAL_EV_WRITES32), writes = hal_perf_event(HAL_EV_WRITES);
    uint64_t bytes = hal_perf_event(HAL_EV_BYTES);
    if (fk.lost != 0) return "a byte written with no plane enabled";
    if (fk.bad_masks != 0) return "a plane mask with bits above plane 3";
    if (hal_perf_event(HAL_EV_PIXELS) != (uint64_t)len) return "pixels != len";
    if (hal_perf_event(HAL_EV_SYSMEM_WRITES) != 0 || hal_perf_event(HAL_EV_COPY_WRITES) != 0)
        return "system-memory or copy writes";
    if (writes != w8 + w16 + w32) return "writes != writes8 + writes16 + writes32";
    if (hal_perf_event(HAL_EV_VRAM_WRITES) != writes) return "vram_writes != writes";
    if (bytes != w8 + 2u * w16 + 4u * w32) return "bytes != n8 + 2 n16 + 4 n32";
    if (len == 0) {
        if (writes != 0 || bytes != 0 || fk.committed != 0 || hal_perf_tsc() != 0) return "a clipped-away span wrote";
        return NULL;
    }
    expect_counts e = expected(x, len);
    if (bytes != e.groups) return "bytes != 4-pixel groups covered";
    if (fk.committed != e.groups) return "bytes reaching the planes != groups covered (a byte written twice or missed)";
    if (w8 > e.max8) return "writes8 > partial groups + run head and tail";
    if (w16 > 2) return "writes16 > 2";
    if (w32 != e.dwords) return "writes32 != the aligned dwords of the whole-group run";
    if (hal_perf_tsc() != writes * 8u) return "tsc != 8 cycles per VRAM write";
    return NULL;
}

static int setup(void **state)
{
    (void)state;
    fake_reset();
    hal_perf_set_bus((hal_bus_model){8, 1});
    hal_perf_reset();
    return 0;
}

static hal_surface hidden_surface(void)
{
    hal_surface s = hal_begin_frame(HAL_PRESENT_FLIP);
    assert_ptr_equal(s.pixels, fk.cpu[HIDDEN]);
    assert_int_equal(s.planar, 1);
    assert_int_equal(s.in_vram, 1);
    return s;
}

/* Colours 1..255 but never the sentinel or the background, varying from
 * span to span so a stale byte from the last span shows. */
static uint8_t colour_for(int x, int len)
{
    uint32_t c = 1u + (uint32_t)(x * 7 + len * 13) % 254u;
    return (uint8_t)(c >= BACKGROUND ? c + 1u : c);
}

/* ---- tests ------------------------------------------------------------------ */

/* Every x and every len of one row, the row decoded and checked after each. */
static void exhaustive_row(int y)
{
    hal_surface s = hidden_surface();
    fake_window_row(HIDDEN, y);
    uint32_t spans = 0;
    for (int x = 0; x < HAL_WIDTH; x++) {
        for (int len = 1; len <= HAL_WIDTH - x; len++) {
            uint8_t colour = colour_for(x, len);
            draw(&s, y, x, len, colour);
            for (int px = 0; px < HAL_WIDTH; px++) {
                uint8_t want = (px >= x && px < x + len) ? colour : BACKGROUND;
                uint8_t got = pixel(HIDDEN, px, y);
                if (got != want)
                    fail_msg("row %d span x=%d len=%d: pixel %d is 0x%02x, want 0x%02x", y, x, len, px, got, want);
            }
            const char *why = counts_problem(x, len);
            if (why != NULL)
                fail_msg("row %d span x=%d len=%d: %s (w8 %llu w16 %llu w32 %llu bytes %llu)", y, x, len, why,
                         (unsigned long long)hal_perf_event(HAL_EV_WRITES8),
                         (unsigned long long)hal_perf_event(HAL_EV_WRITES16),
                         (unsigned long long)hal_perf_event(HAL_EV_WRITES32),
                         (unsigned long long)hal_perf_event(HAL_EV_BYTES));
            row_to_background(HIDDEN, y);
            spans++;
        }
    }
    assert_int_equal(spans, HAL_WIDTH * (HAL_WIDTH + 1) / 2);
    assert_no_stray_writes();
    /* the shown page was never touched */
    for (int p = 0; p < 4; p++)
        for (uint32_t i = 0; i < PLANE_BYTES; i++)
            if (fk.plane[0][p][i] != BACKGROUND) fail_msg("shown page plane %d byte %u changed", p, i);
}

static void test_exhaustive_row0(void **state)
{
    (void)state;
    exhaustive_row(0);
}

static void test_exhaustive_row1(void **state)
{
    (void)state;
    exhaustive_row(1);
}

static void test_exhaustive_row100(void **state)
{
    (void)state;
    exhaustive_row(100);
}

static void test_exhaustive_row199(void **state)
{
    (void)state;
    exhaustive_row(199);
}

/* A full row: 20 dword writes, 80 bytes, 320 pixels; a full frame 4,000 and 16,000. */
static void test_full_row_and_frame(void **state)
{
    (void)state;
    hal_surface s = hidden_surface();
    fake_window_row(HIDDEN, 37);
    draw(&s, 37, 0, HAL_WIDTH, 0xC3);
    assert_null(counts_problem(0, HAL_WIDTH));
    assert_int_equal(hal_perf_event(HAL_EV_WRITES32), 20);
    assert_int_equal(hal_perf_event(HAL_EV_WRITES8), 0);
    assert_int_equal(hal_perf_event(HAL_EV_WRITES16), 0);
    assert_int_equal(hal_perf_event(HAL_EV_WRITES), 20);
    assert_int_equal(hal_perf_event(HAL_EV_BYTES), 80);
    assert_int_equal(hal_perf_event(HAL_EV_PIXELS), 320);
    assert_int_equal(fk.mask_calls, 1); /* one mask, every plane */
    for (int px = 0; px < HAL_WIDTH; px++) assert_int_equal(pixel(HIDDEN, px, 37), 0xC3);

    fake_window_all();
    fake_commit();
    hal_perf_reset();
    for (int y = 0; y < HAL_HEIGHT; y++) {
        fake_window_row(HIDDEN, y);
        fk.mask = 0;
        hal_fill_span(&s, y, 0, HAL_WIDTH, 0x3C);
        fake_commit();
    }
    assert_int_equal(fk.lost, 0);
    assert_int_equal(hal_perf_event(HAL_EV_WRITES32), 4000);
    assert_int_equal(hal_perf_event(HAL_EV_WRITES), 4000);
    assert_int_equal(hal_perf_event(HAL_EV_VRAM_WRITES), 4000);
    assert_int_equal(hal_perf_event(HAL_EV_BYTES), 16000);
    assert_int_equal(hal_perf_event(HAL_EV_PIXELS), 64000);
    for (int y = 0; y < HAL_HEIGHT; y++)
        for (int x = 0; x < HAL_WIDTH; x++) {
            assert_int_equal(pixel(HIDDEN, x, y), 0x3C);
            assert_int_equal(pixel(0, x, y), BACKGROUND);
        }
    assert_no_stray_writes();
}

/* Clipped spans: exactly the clipped part of the row, or nothing; whole frames compared. */
static void test_clipping(void **state)
{
    (void)state;
    static const struct {
        int y, x, len;
        int cx, clen; /* the span after clipping; clen 0: nothing */
    } cases[] = {
        {0, -5, 10, 0, 5},
        {0, -1, 3, 0, 2},
        {1, -3, 3, 0, 0},
        {1, -4, 1, 0, 0},
        {100, -1000, INT_MAX, 0, 320},
        {199, -2, INT_MAX, 0, 320},
        {199, INT_MIN, INT_MAX, 0, 0},
        {199, INT_MIN, 1, 0, 0},
        {50, 300, 100, 300, 20},
        {50, 317, INT_MAX, 317, 3},
        {50, 319, 2, 319, 1},
        {51, 1, 400, 1, 319},
        {10, 320, 5, 0, 0},
        {10, 321, 1, 0, 0},
        {10, INT_MAX, INT_MAX, 0, 0},
        {10, 5, 0, 0, 0},
        {10, 5, -1, 0, 0},
        {10, 5, INT_MIN, 0, 0},
        {10, -5, -5, 0, 0},
        {-1, 0, 320, 0, 0},
        {-1, 3, 5, 0, 0},
        {200, 0, 320, 0, 0},
        {200, 7, 9, 0, 0},
        {INT_MIN, 0, 320, 0, 0},
        {INT_MAX, 0, 320, 0, 0},
    };
    hal_surface s = hidden_surface();
    fake_window_all(); /* few cases: commit and compare whole pages */
    for (size_t i = 0; i < sizeof cases / sizeof cases[0]; i++) {
        int y = cases[i].y, cx = cases[i].cx, clen = cases[i].clen;
        uint8_t colour = (uint8_t)(0x80u + i);
        draw(&s, y, cases[i].x, cases[i].len, colour);
        const char *why = counts_problem(cx, clen);
        if (why != NULL) fail_msg("case %zu (y=%d x=%d len=%d): %s", i, y, cases[i].x, cases[i].len, why);
        if (clen == 0) assert_int_equal(fk.mask_calls, 0);
        for (int page = 0; page < 2; page++)
            for (int py = 0; py < HAL_HEIGHT; py++)
                for (int px = 0; px < HAL_WIDTH; px++) {
                    int in = page == HIDDEN && py == y && px >= cx && px < cx + clen;
                    uint8_t want = in ? colour : BACKGROUND;
                    if (pixel(page, px, py) != want)
                        fail_msg("case %zu (y=%d x=%d len=%d): page %d pixel (%d, %d) is 0x%02x, want 0x%02x", i, y,
                                 cases[i].x, cases[i].len, page, px, py, pixel(page, px, py), want);
                }
        if (clen != 0) row_to_background(HIDDEN, y);
    }
    assert_no_stray_writes();
    /* a NULL surface or NULL pixels: nothing */
    hal_surface none = {NULL, 1, 1};
    draw(NULL, 0, 0, 320, 1);
    assert_null(counts_problem(0, 0));
    draw(&none, 0, 0, 320, 1);
    assert_null(counts_problem(0, 0));
}

/* Random overlapping spans (some clipped) against a linear reference frame. */
static void test_random_overlap(void **state)
{
    (void)state;
    static uint8_t ref[HAL_HEIGHT][HAL_WIDTH];
    memset(ref, BACKGROUND, sizeof ref);
    hal_surface s = hidden_surface();
    uint32_t rng = 12345u;
    uint64_t pixels = 0;
    for (int i = 0; i < 20000; i++) {
        rng = rng * 1103515245u + 12345u;
        int y = (int)((rng >> 8) % 204u) - 2;
        rng = rng * 1103515245u + 12345u;
        int x = (int)((rng >> 8) % 360u) - 20;
        rng = rng * 1103515245u + 12345u;
        int len = (int)((rng >> 8) % (i & 1 ? 346u : 20u)) - 5;
        rng = rng * 1103515245u + 12345u;
        uint8_t colour = (uint8_t)(1u + (rng >> 8) % 255u);
        int cx = x < 0 ? 0 : x, cend = x + len > HAL_WIDTH ? HAL_WIDTH : x + len;
        int clen = (y >= 0 && y < HAL_HEIGHT && cend > cx) ? cend - cx : 0;
        fake_window_row(HIDDEN, y >= 0 && y < HAL_HEIGHT ? y : 0);
        draw(&s, y, x, len, colour);
        const char *why = counts_problem(clen ? cx : 0, clen);
        if (why != NULL) fail_msg("span %d (y=%d x=%d len=%d): %s", i, y, x, len, why);
        pixels += (uint64_t)clen;
        if (clen == 0) continue;
        for (int px = cx; px < cend; px++) ref[y][px] = colour;
        for (int px = 0; px < HAL_WIDTH; px++)
            if (pixel(HIDDEN, px, y) != ref[y][px])
                fail_msg("span %d (y=%d x=%d len=%d): pixel %d is 0x%02x, want 0x%02x", i, y, x, len, px,
                         pixel(HIDDEN, px, y), ref[y][px]);
    }
    assert_true(pixels > 0);
    assert_no_stray_writes();
    for (int y = 0; y < HAL_HEIGHT; y++)
        for (int x = 0; x < HAL_WIDTH; x++) {
            assert_int_equal(pixel(HIDDEN, x, y), ref[y][x]);
            assert_int_equal(pixel(0, x, y), BACKGROUND);
        }
}

/* Flip mode on a planar target: the hidden page, planar; no shown page to
 * read back; the present flips the display start and writes nothing. */
static void test_flip_planar(void **state)
{
    (void)state;
    assert_int_equal(hal_target_display_start(), 0);
    hal_surface s = hal_begin_frame(HAL_PRESENT_FLIP);
    assert_ptr_equal(s.pixels, hal_target_vram(1));
    assert_int_equal(s.planar, 1);
    assert_int_equal(s.in_vram, 1);
    assert_null(hal_shown_page());

    fake_window_all();
    draw(&s, 5, 10, 7, 0x77);
    assert_null(counts_problem(10, 7));
    assert_int_equal(pixel(1, 10, 5), 0x77);
    assert_int_equal(pixel(1, 16, 5), 0x77);
    assert_int_equal(pixel(1, 17, 5), BACKGROUND);
    assert_int_equal(pixel(0, 10, 5), BACKGROUND);

    hal_perf_reset();
    hal_present(HAL_PRESENT_FLIP);
    assert_int_equal(hal_target_display_start(), 1);
    assert_int_equal(hal_perf_event(HAL_EV_WRITES), 0);
    assert_null(hal_shown_page());

    s = hal_begin_frame(HAL_PRESENT_FLIP);
    assert_ptr_equal(s.pixels, hal_target_vram(0));
    assert_int_equal(s.planar, 1);
    assert_int_equal(s.in_vram, 1);
    draw(&s, 5, 10, 1, 0x66);
    assert_int_equal(pixel(0, 10, 5), 0x66);
    assert_int_equal(pixel(1, 10, 5), 0x77); /* the shown page keeps its frame */

    hal_present(HAL_PRESENT_FLIP);
    assert_int_equal(hal_target_display_start(), 0);
    assert_ptr_equal(hal_begin_frame(HAL_PRESENT_FLIP).pixels, hal_target_vram(1));
    assert_null(hal_shown_page());

    /* the copy modes draw into linear system memory, even on a planar target */
    hal_surface c = hal_begin_frame(HAL_PRESENT_COPY32);
    assert_ptr_equal(c.pixels, hal_target_sysmem());
    assert_int_equal(c.planar, 0);
    assert_int_equal(c.in_vram, 0);
    assert_no_stray_writes();
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test_setup(test_exhaustive_row0, setup),    cmocka_unit_test_setup(test_exhaustive_row1, setup),
        cmocka_unit_test_setup(test_exhaustive_row100, setup),  cmocka_unit_test_setup(test_exhaustive_row199, setup),
        cmocka_unit_test_setup(test_full_row_and_frame, setup), cmocka_unit_test_setup(test_clipping, setup),
        cmocka_unit_test_setup(test_random_overlap, setup),     cmocka_unit_test_setup(test_flip_planar, setup),
    };
    return cmocka_run_group_tests_name("planar", tests, NULL, NULL);
}
