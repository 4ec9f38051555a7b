/* test_clip.c - frustum clipping, projection and convex fill: clipped vertices lie
 * inside every plane, project inside the screen, and polygons that share an edge
 * cover every pixel exactly once (no gap, no overlap), whatever the edge. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <cmocka.h>
#include <string.h>

#include "clip.h"
#include "hal.h"
#include "hal_null.h"
#include "raster.h"

static uint64_t rng = 12345;
static int32_t rnd(int32_t lo, int32_t hi)
{
    rng = rng * 6364136223846793005ull + 1442695040888963407ull;
    return (int32_t)((int64_t)lo + (int64_t)((rng >> 16) % (uint64_t)((int64_t)hi - lo + 1)));
}

static view_xform flat_view(int32_t look)
{
    camera c = {0, 0, 0, 0, look};
    view_xform v;
    view_setup(&v, &c);
    return v;
}

static void test_clip_inside_planes(void **state)
{
    (void)state;
    for (int iter = 0; iter < 20000; iter++) {
        view_xform v = flat_view(rnd(-100, 100));
        clip_poly p;
        p.n = rnd(3, 8);
        for (int i = 0; i < p.n; i++) {
            p.v[i].x = rnd(-(1 << 30), 1 << 30);
            p.v[i].y = rnd(-(1 << 29), 1 << 29);
            p.v[i].z = rnd(-(1 << 28), 1 << 30);
        }
        int n = clip_polygon(&p, &v, CLIP_ALL);
        assert_true(n == 0 || n >= 3);
        assert_true(n <= CLIP_MAX_VERTS);
        for (int i = 0; i < n; i++) {
            assert_true(p.v[i].z >= VIEW_ZNEAR - 1);
            /* within rounding of every plane: a few raw units times the plane's scale */
            for (unsigned pl = CLIP_LEFT; pl <= CLIP_BOTTOM; pl <<= 1)
                assert_true(clip_distance(&v, p.v[i], pl) >= -(int64_t)4 * 160);
            screen_pt s = view_project(&v, p.v[i]);
            assert_true(s.x >= 0 && s.x <= VIEW_W_FX && s.y >= 0 && s.y <= VIEW_H_FX);
        }
    }
}

static void test_clip_all_outside(void **state)
{
    (void)state;
    view_xform v = flat_view(0);
    clip_poly p = {3, {{0, 0, -100}, {100, 0, -100}, {0, 100, -50}}};
    assert_int_equal(clip_polygon(&p, &v, CLIP_ALL), 0);
    clip_poly q = {3, {{0, 0, 1000}, {100, 0, 1000}, {0, 100, 1000}}};
    assert_int_equal(clip_polygon(&q, &v, CLIP_ALL), 3); /* wholly inside: untouched */
    assert_int_equal(q.v[1].x, 100);
    /* fewer than 3 vertices is no area, wholly inside or not, whatever planes clip it */
    for (int n = 0; n < 3; n++)
        for (unsigned mask = 0; mask <= CLIP_ALL; mask++) {
            clip_poly d = {n, {{0, 0, 1000}, {100, 0, 1000}, {0, 100, 1000}}};
            assert_int_equal(clip_polygon(&d, &v, mask), 0);
        }
}

/* Count, per pixel, how many times polygons wrote it, through the id buffer. */
static uint32_t ids[HAL_PAGE_BYTES];

static void fill(const screen_pt *pts, int n, uint32_t id)
{
    hal_surface s = hal_begin_frame(HAL_PRESENT_COPY32);
    rast_target t = {&s, ids};
    tex_paint paint = tex_flat(1);
    rast_convex(&t, pts, n, &paint, id);
}

/* A polygon that breaks the contract (convex): a zig-zag across the near plane,
 * each vertex on the other side from the last, as many as allowed. Clipping it
 * would make one and a half times as many vertices; the clipper keeps to its
 * arrays (the sanitizers watch them) and gives at most CLIP_MAX_VERTS. */
static void test_zigzag_keeps_to_its_arrays(void **state)
{
    (void)state;
    view_xform v = flat_view(0);
    for (unsigned mask = CLIP_NEAR; mask <= CLIP_ALL; mask += CLIP_ALL - CLIP_NEAR)
        for (int first = 0; first < 2; first++) /* starting inside, and outside */
            for (int n0 = 3; n0 <= CLIP_MAX_VERTS - 5; n0++) {
                clip_poly p;
                p.n = n0;
                for (int i = 0; i < p.n; i++) {
                    p.v[i].x = (i - p.n / 2) * 64;
                    p.v[i].y = 0;
                    p.v[i].z = (i + first) % 2 ? -4096 : 4096;
                }
                int n = clip_polygon(&p, &v, mask);
                assert_true(n <= CLIP_MAX_VERTS);
            }
}

/* A polygon reaching above the screen's top edge: while its first sample row is
 * still row 0 (under half a row above), it draws rows 0 .. 9 as a polygon on the
 * screen would; beyond that it breaks rast_convex's contract (vertices on the
 * screen) and draws nothing, touching no row outside the screen (the sanitizers
 * watch the row tables on the stack). */
static void test_rows_above_the_top(void **state)
{
    (void)state;
    static const int32_t tops[] = {0, -16384, -32767, -32768, -65536, -98304, -98305, -3 * 65536};
    for (size_t k = 0; k < sizeof tops / sizeof tops[0]; k++) {
        hal_null_reset();
        hal_perf_reset();
        screen_pt q[4] = {{0, tops[k]}, {VIEW_W_FX, tops[k]}, {VIEW_W_FX, 10 * 65536}, {0, 10 * 65536}};
        fill(q, 4, 9);
        uint64_t want = rast_first_sample(tops[k]) == 0 ? 10 * VIEW_W : 0;
        assert_int_equal(hal_perf_event(HAL_EV_PIXELS), want);
    }
}

static void test_full_screen_quad(void **state)
{
    (void)state;
    hal_null_reset();
    hal_perf_reset();
    screen_pt q[4] = {{0, 0}, {VIEW_W_FX, 0}, {VIEW_W_FX, VIEW_H_FX}, {0, VIEW_H_FX}};
    fill(q, 4, 7);
    assert_int_equal(hal_perf_event(HAL_EV_PIXELS), 64000);
    /* counter-clockwise (seen from behind): nothing */
    screen_pt r[4] = {{0, 0}, {0, VIEW_H_FX}, {VIEW_W_FX, VIEW_H_FX}, {VIEW_W_FX, 0}};
    fill(r, 4, 7);
    assert_int_equal(hal_perf_event(HAL_EV_PIXELS), 64000);
}

/* A random convex fan split into triangles that share edges: every covered pixel
 * is written exactly once, and the union equals the whole fan polygon's coverage. */
static void test_shared_edges_exactly_once(void **state)
{
    (void)state;
    static uint32_t whole[HAL_PAGE_BYTES];
    for (int iter = 0; iter < 300; iter++) {
        /* a convex polygon: points on an ellipse, clockwise on screen (y down) */
        int n = rnd(3, 12);
        screen_pt pts[12];
        int32_t cx = rnd(40, 280) << 16, cy = rnd(30, 170) << 16;
        int32_t rx = rnd(1, 40) << 16, ry = rnd(1, 30) << 16;
        static const int32_t cs[12][2] = {{1000, 0},  {866, 500},   {500, 866},   {0, 1000},  {-500, 866}, {-866, 500},
                                          {-1000, 0}, {-866, -500}, {-500, -866}, {0, -1000}, {500, -866}, {866, -500}};
        int step = 12 / n;
        for (int i = 0; i < n; i++) {
            pts[i].x = cx + (int32_t)((int64_t)rx * cs[i * step][0] / 1000) + rnd(-3000, 3000);
            pts[i].y = cy + (int32_t)((int64_t)ry * cs[i * step][1] / 1000) + rnd(-3000, 3000);
        }
        /* the whole polygon alone */
        memset(ids, 0, sizeof ids);
        hal_perf_reset();
        fill(pts, n, 1);
        uint64_t whole_px = hal_perf_event(HAL_EV_PIXELS);
        memcpy(whole, ids, sizeof ids);
        /* as a fan of triangles */
        memset(ids, 0, sizeof ids);
        hal_perf_reset();
        for (int i = 1; i + 1 < n; i++) {
            screen_pt tri[3] = {pts[0], pts[i], pts[i + 1]};
            fill(tri, 3, (uint32_t)i + 1);
        }
        /* each triangle's pixels counted once: total equals the distinct pixels */
        uint64_t distinct = 0;
        for (int k = 0; k < HAL_PAGE_BYTES; k++) distinct += ids[k] != 0;
        assert_int_equal(hal_perf_event(HAL_EV_PIXELS), distinct);
        /* (ellipse points with jitter may be slightly non-convex: compare only when
         * the whole-polygon fill agrees in size) */
        if (whole_px == distinct)
            for (int k = 0; k < HAL_PAGE_BYTES; k++) assert_int_equal(whole[k] != 0, ids[k] != 0);
    }
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_clip_inside_planes),         cmocka_unit_test(test_clip_all_outside),
        cmocka_unit_test(test_zigzag_keeps_to_its_arrays), cmocka_unit_test(test_rows_above_the_top),
        cmocka_unit_test(test_full_screen_quad),           cmocka_unit_test(test_shared_edges_exactly_once),
    };
    return cmocka_run_group_tests_name("clip", tests, NULL, NULL);
}
