/* test_view.c - the world-to-view transform and the projection over the whole
 * coordinate box (docs/ranges.md): eyes and points at the corners and edges of
 * the box, at angles all round, against the same geometry in double precision.
 * A product that overflowed or a view coordinate that wrapped on its way into
 * 32 bits would be off by about 2^32 raw; the tolerance here is a few raw. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <cmocka.h>
#include <math.h>

#include "scene_format.h"
#include "view.h"

#define LIM ((int32_t)SCN_COORD_MAX << 16)
#define HLIM ((int32_t)SCN_HEIGHT_MAX << 16)

static uint64_t rng = 977;
static int32_t rnd(int32_t lo, int32_t hi)
{
    rng = rng * 6364136223846793005ull + 1442695040888963407ull;
    return (int32_t)((int64_t)lo + (int64_t)((rng >> 16) % (uint64_t)((int64_t)hi - lo + 1)));
}

/* Box coordinates worth trying: the corners, the middle, just inside the edges. */
static const int32_t EDGE[] = {-LIM, -LIM + 1, -(1 << 16), 0, 1, 1 << 16, LIM - 1, LIM};
#define NEDGE (int)(sizeof EDGE / sizeof EDGE[0])

static view_xform setup(int32_t x, int32_t y, int32_t z, fx_t deg)
{
    camera c = {x, y, z, deg, 0};
    view_xform v;
    view_setup(&v, &c);
    return v;
}

/* The view point in double from the transform's own sin and cos (the table's
 * precision is test_fixed.c's business); 18.14 raw. */
static void expect_point(const view_xform *v, int32_t wx, int32_t wy, int32_t h)
{
    view_pt p = view_point(v, wx, wy, h);
    double dx = (double)wx - (double)v->cx, dy = (double)wy - (double)v->cy;
    double s = v->sin / 1073741824.0, c = v->cos / 1073741824.0;
    double ez = (dx * c + dy * s) / 4.0, ex = (dx * s - dy * c) / 4.0, ey = ((double)h - (double)v->cz) / 4.0;
    if (fabs(p.z - ez) > 2.0 || fabs(p.x - ex) > 2.0 || fabs(p.y - ey) > 1.0)
        fail_msg("view_point(%d, %d, %d) from (%lld, %lld, %lld): got (%d, %d, %d), expected (%.1f, %.1f, %.1f)", wx,
                 wy, h, (long long)v->cx, (long long)v->cy, (long long)v->cz, p.x, p.y, p.z, ex, ey, ez);
    /* docs/ranges.md: |x|, |z| <= 65534 sqrt 2 units, |y| <= 32766 units */
    const double xz_max = 65534.0 * 1.41421357 * 16384.0 + 2.0;
    assert_true(fabs((double)p.x) <= xz_max && fabs((double)p.z) <= xz_max);
    assert_true(fabs((double)p.y) <= 32766.0 * 16384.0 + 1.0);
}

static void test_view_point_corners_all_round(void **state)
{
    (void)state;
    for (int ex = 0; ex < NEDGE; ex++)
        for (int ey = 0; ey < NEDGE; ey++)
            for (int a = 0; a < 360 * 4; a += 7) { /* every 1.75 degrees, plus the quadrants below */
                int32_t z = (a & 1) ? HLIM : -HLIM;
                view_xform v = setup(EDGE[ex], EDGE[ey], z, (fx_t)(a << 14));
                for (int px = 0; px < NEDGE; px += 7)
                    for (int py = 0; py < NEDGE; py += 7) expect_point(&v, EDGE[px], EDGE[py], -z);
            }
    for (int q = 0; q < 4; q++) {
        view_xform v = setup(-LIM, -LIM, HLIM, (fx_t)((q * 90) << 16));
        expect_point(&v, LIM, LIM, -HLIM);
        expect_point(&v, LIM, -LIM, HLIM);
        expect_point(&v, -LIM, LIM, -HLIM);
    }
}

static void test_view_point_random_in_box(void **state)
{
    (void)state;
    for (int i = 0; i < 200000; i++) {
        view_xform v = setup(rnd(-LIM, LIM), rnd(-LIM, LIM), rnd(-HLIM, HLIM), rnd(INT32_MIN, INT32_MAX));
        expect_point(&v, rnd(-LIM, LIM), rnd(-LIM, LIM), rnd(-HLIM, HLIM));
    }
}

/* An eye outside the box is clamped onto it, whatever the input. */
static void test_view_setup_clamps(void **state)
{
    (void)state;
    view_xform v = setup(INT32_MAX, INT32_MIN, INT32_MAX, INT32_MIN);
    assert_int_equal(v.cx, LIM);
    assert_int_equal(v.cy, -LIM);
    assert_int_equal(v.cz, HLIM);
    camera c = {0, 0, 0, 0, 1000};
    view_setup(&v, &c);
    assert_int_equal(v.look, VIEW_LOOK_MAX);
    c.look = -1000;
    view_setup(&v, &c);
    assert_int_equal(v.look, -VIEW_LOOK_MAX);
}

/* Any view point in range, z at or beyond the near plane: the projection lands
 * on the screen rectangle, and inside the frustum it is the true one. */
static void test_projection_in_range(void **state)
{
    (void)state;
    const int32_t xz = (int32_t)(65534.0 * 1.41421356 * 16384.0);
    for (int i = 0; i < 200000; i++) {
        int32_t look = rnd(-VIEW_LOOK_MAX, VIEW_LOOK_MAX);
        camera c = {0, 0, 0, 0, look};
        view_xform v;
        view_setup(&v, &c);
        view_pt p;
        int scale = rnd(0, 3); /* near the eye, mid range, the far corners of the box */
        int32_t zmax = scale == 0 ? 64 : (scale == 1 ? 1 << 20 : xz);
        p.z = rnd(VIEW_ZNEAR, zmax);
        p.x = rnd(-xz, xz);
        p.y = rnd(-32766 * 16384, 32766 * 16384);
        if (i & 1) p.x = (int32_t)((int64_t)p.x % ((int64_t)p.z + 1)); /* half inside left/right */
        screen_pt s = view_project(&v, p);
        assert_true(s.x >= 0 && s.x <= VIEW_W_FX && s.y >= 0 && s.y <= VIEW_H_FX);
        double sx = 160.0 * 65536.0 + (double)p.x * 160.0 * 65536.0 / p.z;
        double sy = (100.0 + look) * 65536.0 - (double)p.y * 160.0 * 65536.0 / p.z;
        if (sx >= 0 && sx <= VIEW_W_FX && fabs(s.x - sx) > 1.0)
            fail_msg("x of (%d, %d, %d): %d, expected %.1f", p.x, p.y, p.z, s.x, sx);
        if (sy >= 0 && sy <= VIEW_H_FX && fabs(s.y - sy) > 1.0)
            fail_msg("y of (%d, %d, %d): %d, expected %.1f", p.x, p.y, p.z, s.y, sy);
    }
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_view_point_corners_all_round),
        cmocka_unit_test(test_view_point_random_in_box),
        cmocka_unit_test(test_view_setup_clamps),
        cmocka_unit_test(test_projection_in_range),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
