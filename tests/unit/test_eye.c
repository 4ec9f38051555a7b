/* test_eye.c - eye_in_world next to the end of a short one-sided wall: every eye
 * position nearer than EYE_MARGIN to the wall is refused, and every position that
 * eye.c's stated rounding bound puts certainly beyond the margin past either end
 * is taken. The wall is short (64 raw units, as a split seg can be), where the
 * shifted products' rounding terms weigh most. Run from the repository root. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <cmocka.h>

#include "eye.h"
#include "scene.h"
#include "scene_fixture.h"

#define U(v) ((fx_t)((int64_t)(v)*65536))
/* eye.c's room from the boundary (16.16) and the same in its shifted units */
#define MARGIN (((int64_t)VIEW_ZNEAR + 1) << (17 - VIEW_SHIFT))
#define MARGIN_X (MARGIN >> 3)
#define LEN 64 /* the wall's length, raw, along +x */

static const char ROOM[] = "sector room floor=0 ceil=128\n"
                           "wall 0 0 0 512 room\n"
                           "wall 0 512 512 512 room\n"
                           "wall 512 512 512 0 room\n"
                           "wall 512 0 0 0 room\n"
                           "player 256 256 0\n";

static int64_t abs64(int64_t v)
{
    return v < 0 ? -v : v;
}

/* 1 if the eye at offset (px, py) raw past an end of the wall (px >= 0 away from
 * the wall along it) is certainly farther than the margin as near_segment
 * measures it: its product d.e, taken exactly (in eye.c's units: the direction
 * halved, the offset shifted by 3, here times 8 to stay whole), exceeds eye.c's
 * threshold by more than the rounding bound eye.c states for the shifted terms
 * (|dx| + |dy| + |ex| + |ey| + 2). */
static int certainly_far(int64_t px, int64_t py)
{
    int64_t dx = LEN / 2;
    int64_t exact8 = dx * px;                                               /* 8 (dx * ex) */
    int64_t round8 = 8 * (dx + 2) + abs64(px) + abs64(py);                  /* 8 x the bound */
    int64_t limit8 = 8 * (dx * (MARGIN_X + 1) + 2) + abs64(px) + abs64(py); /* 8 x the threshold */
    return exact8 - round8 > limit8;
}

/* Squared distance (raw) from (x, y) to the wall [0, LEN] x {0}. */
static int64_t dist2(int64_t x, int64_t y)
{
    int64_t dx = x < 0 ? -x : (x > LEN ? x - LEN : 0);
    return dx * dx + y * y;
}

static void test_near_the_end_of_a_short_wall(void **state)
{
    (void)state;
    uint8_t *blob;
    scene s;
    fixture_load_text(ROOM, &blob, &s);
    /* Every seg becomes the one short wall at the room's middle (its line stays a
     * one-sided outer wall, so an eye near it is outside the world). */
    const int64_t ax = U(256), ay = U(256);
    scn_vertex *verts = malloc((s.nverts + 2) * sizeof *verts);
    memcpy(verts, s.verts, s.nverts * sizeof *verts);
    verts[s.nverts] = (scn_vertex){(fx_t)ax, (fx_t)ay};
    verts[s.nverts + 1] = (scn_vertex){(fx_t)(ax + LEN), (fx_t)ay};
    scn_seg *segs = malloc(s.nsegs * sizeof *segs);
    for (uint32_t i = 0; i < s.nsegs; i++) {
        segs[i] = s.segs[i];
        segs[i].v1 = s.nverts;
        segs[i].v2 = s.nverts + 1;
    }
    scene t = s;
    t.verts = verts;
    t.segs = segs;
    view_xform v;
    camera cam = {U(256), U(256), U(41), 0, 0};
    view_setup(&v, &cam);
    uint32_t far = 0, near = 0;
    for (int64_t y = -260; y <= 260; y++)
        for (int64_t x = -260; x <= LEN + 260; x++) {
            v.cx = ax + x;
            v.cy = ay + y;
            int in = eye_in_world(&t, NULL, &v);
            if (dist2(x, y) < MARGIN * MARGIN) {
                assert_int_equal(in, 0);
                near++;
            }
            /* past b (x > LEN) or past a (x < 0), measured away from the wall */
            int64_t px = x > LEN ? x - LEN : -x;
            if (px > 0 && certainly_far(px, y)) {
                if (!in) fprintf(stderr, "eye at (%lld, %lld) raw from a: refused\n", (long long)x, (long long)y);
                assert_int_equal(in, 1);
                far++;
            }
        }
    assert_true(near > 0 && far > 0);
    /* the room itself, unchanged: its middle is inside */
    v.cx = ax;
    v.cy = ay;
    assert_int_equal(eye_in_world(&s, NULL, &v), 1);
    free(segs);
    free(verts);
    free(blob);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_near_the_end_of_a_short_wall),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
