/* test_surfaces.c - surf_leaf's floor and ceiling: a leaf whose floor polygon has
 * fewer than 3 corners (the format allows 0 for a degenerate leaf) is no area,
 * so it gives no plane work at all: no polygon, no occlusion query, nothing
 * counted as clipped away. The same leaves with their corners do draw, so the
 * camera sees them. Run from the repository root. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#include <cmocka.h>

#include "clip.h"
#include "scene.h"
#include "scene_fixture.h"
#include "surfaces.h"

#define U(v) ((fx_t)((int64_t)(v)*65536))

/* An L-shaped room, so that the compiler makes more than one leaf. */
static const char ROOM[] = "sector room floor=0 ceil=128\n"
                           "wall 0 0 0 512 room\n"
                           "wall 0 512 256 512 room\n"
                           "wall 256 512 256 256 room\n"
                           "wall 256 256 512 256 room\n"
                           "wall 512 256 512 0 room\n"
                           "wall 512 0 0 0 room\n"
                           "player 128 128 45\n";

typedef struct {
    int planes, queries;
} sink_count;

static void on_polygon(void *ctx, const screen_pt *pts, int n, const tex_paint *paint, uint32_t id, uint32_t seg,
                       int32_t zmin, int32_t zmax)
{
    (void)pts, (void)paint, (void)id, (void)zmin, (void)zmax;
    assert_true(n >= 3);
    if (seg == SCN_NONE) ((sink_count *)ctx)->planes++;
}

static int on_hidden(void *ctx, const screen_pt *pts, int n)
{
    (void)pts, (void)n;
    ((sink_count *)ctx)->queries++;
    return 0;
}

/* surf_leaf over leaf i of s with its floor polygon cut to corners corners and
 * its walls left out. */
static sink_count leaf_planes(const scene *s, const view_xform *v, uint32_t i, uint32_t corners, render_stats *st)
{
    scn_leaf *leaves = malloc(s->nleaves * sizeof *leaves);
    memcpy(leaves, s->leaves, s->nleaves * sizeof *leaves);
    leaves[i].num_pverts = corners;
    leaves[i].num_segs = 0;
    scene t = *s;
    t.leaves = leaves;
    sink_count c = {0, 0};
    surf_sink sink = {on_polygon, on_hidden, &c, 1};
    memset(st, 0, sizeof *st);
    surf_leaf(&t, NULL, v, i, CLIP_ALL, &sink, NULL, st);
    free(leaves);
    return c;
}

static void test_degenerate_leaf_has_no_planes(void **state)
{
    (void)state;
    uint8_t *blob;
    scene s;
    fixture_load_text(ROOM, &blob, &s);
    assert_true(s.nleaves >= 2);
    /* from the corner of the L, looking down (and up) each way: every leaf's floor or ceiling shows */
    static const int32_t angles[] = {0, 90, 180, 270};
    uint32_t drawn = 0;
    for (size_t a = 0; a < sizeof angles / sizeof angles[0]; a++) {
        camera cam = {U(250), U(250), U(41), U(angles[a]), 0};
        view_xform v;
        view_setup(&v, &cam);
        for (uint32_t i = 0; i < s.nleaves; i++) {
            render_stats st;
            uint32_t n = s.leaves[i].num_pverts;
            assert_true(n >= 3);
            sink_count whole = leaf_planes(&s, &v, i, n, &st);
            drawn += whole.planes > 0;
            assert_int_equal(whole.planes + (int)st.occluded + (int)st.clipped_away, 2); /* floor and ceiling */
            for (uint32_t k = 0; k < 3; k++) {
                sink_count c = leaf_planes(&s, &v, i, k, &st);
                assert_int_equal(c.planes, 0);
                assert_int_equal(c.queries, 0);
                assert_int_equal(st.polygons, 0);
                assert_int_equal(st.clipped_away, 0);
                assert_int_equal(st.occluded, 0);
            }
        }
    }
    assert_true(drawn >= s.nleaves); /* each leaf seen from at least one side */
    free(blob);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_degenerate_leaf_has_no_planes),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
