/* test_ranges.c - the renderer at the edges of its proven ranges (docs/ranges.md):
 * a scene whose vertices reach +-32,767 and whose heights reach +-16,383, seen
 * from every corner and edge of the coordinate box, at the height limits, at
 * angles all round and looking up and down, in both render modes. The sanitized
 * build halts on any signed overflow or out-of-bounds access; beyond that the two
 * modes, which share nothing after the transform but the edge DDA, must agree, and
 * an eye inside the world must see no hole. Run from the repository root. */
#define _POSIX_C_SOURCE 200809L
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include <cmocka.h>

#include "bspc.h"
#include "hal.h"
#include "hal_null.h"
#include "render.h"
#include "scene.h"
#include "scene_fixture.h"

#define U(v) ((fx_t)((int64_t)(v)*65536))

/* A room filling the whole box, floor and ceiling at the height limits, with a
 * raised block near each corner and a low room in the middle. */
static const char SCENE_TEXT[] = "sector hall floor=-16383 ceil=16383\n"
                                 "sector block floor=16000 ceil=16383\n"
                                 "sector low floor=-16383 ceil=-16300\n"
                                 "wall -32767 -32767 -32767 32767 hall\n"
                                 "wall -32767 32767 32767 32767 hall\n"
                                 "wall 32767 32767 32767 -32767 hall\n"
                                 "wall 32767 -32767 -32767 -32767 hall\n"
                                 /* block in the north-east corner: corner walls shared with the hall's outline
     * would make it a separate sector touching the box edge, so keep it 7 units in */
                                 "wall 32700 32700 32760 32700 hall block\n"
                                 "wall 32760 32700 32760 32760 hall block\n"
                                 "wall 32760 32760 32700 32760 hall block\n"
                                 "wall 32700 32760 32700 32700 hall block\n"
                                 "wall -32760 -32760 -32700 -32760 hall block\n"
                                 "wall -32700 -32760 -32700 -32700 hall block\n"
                                 "wall -32700 -32700 -32760 -32700 hall block\n"
                                 "wall -32760 -32700 -32760 -32760 hall block\n"
                                 "wall -100 -100 -100 100 low hall\n"
                                 "wall -100 100 100 100 low hall\n"
                                 "wall 100 100 100 -100 low hall\n"
                                 "wall 100 -100 -100 -100 low hall\n"
                                 "player 0 -20000 90\n";

typedef struct {
    uint8_t *blob;
    scene s;
    render_work work;
    uint32_t *ids[RENDER_MODE_COUNT];
} world;

static world W;

static int setup(void **state)
{
    (void)state;
    fixture_load_text(SCENE_TEXT, &W.blob, &W.s);
    W.work.bytes = render_work_bytes(&W.s, NULL);
    W.work.mem = malloc(W.work.bytes);
    assert_non_null(W.work.mem);
    for (int m = 0; m < RENDER_MODE_COUNT; m++) W.ids[m] = calloc(VIEW_W * VIEW_H, sizeof(uint32_t));
    return 0;
}

static int teardown(void **state)
{
    (void)state;
    for (int m = 0; m < RENDER_MODE_COUNT; m++) free(W.ids[m]);
    free(W.work.mem);
    free(W.blob);
    return 0;
}

static void draw(const camera *cam, render_mode mode, render_stats *st)
{
    hal_surface surf = hal_begin_frame(HAL_PRESENT_FLIP);
    rast_target t = {&surf, W.ids[mode]};
    memset(st, 0, sizeof *st);
    render_frame(&W.s, NULL, cam, mode, &t, &W.work, st);
    hal_present(HAL_PRESENT_FLIP);
}

/* 1 if the eye is inside the hall (or the low room or a block) and between its
 * floor and ceiling, by more than MARGIN. Nearer than sqrt 2 / 1024 unit to a
 * wall, floor or ceiling, the near plane (z = 1/1024) cuts the surface away and
 * the eye sees past it, as the reference renderer does. */
#define MARGIN (FX_ONE / 256)
static int inside_box(const camera *c, int32_t x0, int32_t y0, int32_t x1, int32_t y1)
{
    return c->x > U(x0) + MARGIN && c->x < U(x1) - MARGIN && c->y > U(y0) + MARGIN && c->y < U(y1) - MARGIN;
}

static int near_box(const camera *c, int32_t x0, int32_t y0, int32_t x1, int32_t y1)
{
    return c->x >= U(x0) - MARGIN && c->x <= U(x1) + MARGIN && c->y >= U(y0) - MARGIN && c->y <= U(y1) + MARGIN;
}

static int eye_inside_world(const camera *c)
{
    if (!inside_box(c, -32767, -32767, 32767, 32767)) return 0;
    int64_t floor = U(-16383), ceil = U(16383);
    if (inside_box(c, -100, -100, 100, 100)) {
        ceil = U(-16300);
    } else if (inside_box(c, 32700, 32700, 32760, 32760) || inside_box(c, -32760, -32760, -32700, -32700)) {
        floor = U(16000);
    } else if (near_box(c, -100, -100, 100, 100) || near_box(c, 32700, 32700, 32760, 32760) ||
               near_box(c, -32760, -32760, -32700, -32700)) {
        return 0; /* on or next to an inner wall */
    }
    return c->z > floor + MARGIN && c->z < ceil - MARGIN;
}

static void check_view(const camera *cam, int *views, int *inside)
{
    render_stats st[RENDER_MODE_COUNT];
    for (int m = 0; m < RENDER_MODE_COUNT; m++) draw(cam, (render_mode)m, &st[m]);
    assert_int_equal(st[RENDER_SPANS].refused, 0);
    uint32_t same = 0, holes = 0;
    for (int i = 0; i < VIEW_W * VIEW_H; i++) {
        same += W.ids[RENDER_SPANS][i] == W.ids[RENDER_PAINTER][i];
        holes += (W.ids[RENDER_SPANS][i] >> 24) == RAST_KIND_NONE;
    }
    /* The modes differ only where a pixel centre is within rounding of an edge. */
    if (same < VIEW_W * VIEW_H * 99u / 100u)
        fail_msg("camera (%d, %d, %d) angle %d look %d: spans and painter agree on %u pixels only", cam->x, cam->y,
                 cam->z, cam->angle_deg, cam->look, same);
    if (eye_inside_world(cam)) {
        ++*inside;
        if (holes)
            fail_msg("camera (%d, %d, %d) angle %d look %d: %u empty pixels with the eye inside the world", cam->x,
                     cam->y, cam->z, cam->angle_deg, cam->look, holes);
    }
    ++*views;
}

static void test_box_corners_and_edges(void **state)
{
    (void)state;
    /* positions on, just inside and just outside the box (the last is clamped) */
    static const int32_t xy[] = {INT32_MIN, -U(32767),    -U(32767) + 1, -U(32766), 0,
                                 U(32766),  U(32767) - 1, U(32767),      INT32_MAX};
    static const int32_t zs[] = {INT32_MIN, -U(16383), -U(16382), 0, U(16382), U(16383), INT32_MAX};
    static const int32_t angles[] = {0, 45, 90, 135, 180, 225, 270, 315};
    int views = 0, inside = 0;
    for (size_t ix = 0; ix < sizeof xy / sizeof xy[0]; ix++)
        for (size_t iy = 0; iy < sizeof xy / sizeof xy[0]; iy++)
            for (size_t iz = 0; iz < sizeof zs / sizeof zs[0]; iz++)
                for (size_t ia = 0; ia < sizeof angles / sizeof angles[0]; ia++) {
                    /* a small odd offset on half of them, so not every edge is a tie */
                    fx_t deg = U(angles[ia]) + (fx_t)((ix + iy + iz) & 1 ? 655 : 0);
                    int32_t look = (int32_t)((ix * 7 + iy * 3 + iz + ia) % 3) * 100 - 100;
                    camera cam = {xy[ix], xy[iy], zs[iz], deg, look};
                    check_view(&cam, &views, &inside);
                }
    print_message("%d views, %d with the eye inside the world\n", views, inside);
    assert_true(inside > 100);
}

/* Near the corners of the box the blocks are 7 units from the box's walls: eyes
 * in those gaps see the closest geometry at the largest coordinates. */
static void test_near_the_corner_blocks(void **state)
{
    (void)state;
    int views = 0, inside = 0;
    for (int k = 0; k < 400; k++) {
        int32_t sx = (k & 1) ? 1 : -1;
        fx_t x = sx * (U(32763) + (fx_t)((k * 7919) % U(3))),
             y = sx * (U(32700) - U(40) + (fx_t)((k * 104729) % U(80)));
        if (k & 2) {
            fx_t t = x;
            x = y;
            y = t;
        }
        camera cam = {x, y, (k & 4) ? U(16100) : U(-16300), (fx_t)((k * 2654435761u) % (360u << 16)),
                      (k % 5) * 50 - 100};
        check_view(&cam, &views, &inside);
    }
    assert_true(inside > 100);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_box_corners_and_edges),
        cmocka_unit_test(test_near_the_corner_blocks),
    };
    return cmocka_run_group_tests(tests, setup, teardown);
}
