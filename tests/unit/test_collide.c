/* test_collide.c - the player against the world (firmware/collide.c) and the
 * camera that walks with it (firmware/camera.c): stopping at walls, sliding,
 * steps, low gaps, fast moves, starts on a wall line or vertex, line of sight,
 * and a long random walk through freedoom2.wad:MAP01 checked against the map's
 * one-sided walls with exact 128-bit integer geometry.
 *
 * Small scenes are written inline to temporary files and compiled with
 * bspc_compile. Run from the repository root.
 */
#define _POSIX_C_SOURCE 200809L
#include <math.h>
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
#include "camera.h"
#include "collide.h"
#include "hal.h"
#include "scene.h"
#include "scene_fixture.h"

__extension__ typedef __int128 i128;

#define U(v) ((fx_t)((v)*65536.0)) /* map units to 16.16 (test values are exact) */
#define EPS (FX_ONE / 32)          /* slack for "stops at radius" */

static double un(int64_t raw)
{
    return (double)raw / 65536.0;
}

/* ------------------------------------------------------------ scenes */

typedef struct {
    uint8_t *blob;
    scene s;
} loaded;

static void load_spec(loaded *l, const char *spec)
{
    char err[512];
    size_t len = 0;
    bspc_options o = bspc_defaults();
    int rc = bspc_compile(spec, &o, &l->blob, &len, NULL, err, sizeof err);
    if (rc) fprintf(stderr, "%s\n", err);
    assert_int_equal(rc, 0);
    assert_int_equal(scene_load(&l->s, l->blob, (uint32_t)len, NULL), SCENE_OK);
}

static void load_text(loaded *l, const char *text)
{
    fixture_load_text(text, &l->blob, &l->s);
}

static void unload(loaded *l)
{
    free(l->blob);
}

/* n rooms in a row along x, each 256 x 256, room i over x in [256 i, 256 (i+1)];
 * the walls between them two-sided; the player in room 0 at (128, 128) facing east. */
static void load_chain(loaded *l, int n, const int *floors, const int *ceils)
{
    char text[8192];
    int at = 0;
    for (int i = 0; i < n; i++)
        at += snprintf(text + at, sizeof text - at, "sector r%d floor=%d ceil=%d\n", i, floors[i], ceils[i]);
    at += snprintf(text + at, sizeof text - at, "wall 0 0 0 256 r0\n");
    for (int i = 0; i < n; i++) {
        int x0 = 256 * i, x1 = 256 * (i + 1);
        at += snprintf(text + at, sizeof text - at, "wall %d 0 %d 0 r%d\nwall %d 256 %d 256 r%d\n", x1, x0, i, x0, x1,
                       i);
        if (i + 1 < n)
            at += snprintf(text + at, sizeof text - at, "wall %d 256 %d 0 r%d r%d\n", x1, x1, i, i + 1);
        else
            at += snprintf(text + at, sizeof text - at, "wall %d 256 %d 0 r%d\n", x1, x1, i);
    }
    snprintf(text + at, sizeof text - at, "player 128 128 0\n");
    load_text(l, text);
}

static void load_room(loaded *l) /* one room, floor 0, ceiling 128 */
{
    int f = 0, c = 128;
    load_chain(l, 1, &f, &c);
}

/* ------------------------------------------------------------ exact checks */

static int sgn128(i128 v)
{
    return (v > 0) - (v < 0);
}

static i128 orient(int64_t ax, int64_t ay, int64_t bx, int64_t by, int64_t px, int64_t py)
{
    return (i128)(bx - ax) * (py - ay) - (i128)(by - ay) * (px - ax);
}

/* closed segments pq and ab share a point (raw 16.16, exact) */
static int crosses(int64_t px, int64_t py, int64_t qx, int64_t qy, int64_t ax, int64_t ay, int64_t bx, int64_t by)
{
    int d1 = sgn128(orient(ax, ay, bx, by, px, py)), d2 = sgn128(orient(ax, ay, bx, by, qx, qy));
    int d3 = sgn128(orient(px, py, qx, qy, ax, ay)), d4 = sgn128(orient(px, py, qx, qy, bx, by));
    if (d1 * d2 > 0 || d3 * d4 > 0) return 0;
    if (d1 || d2 || d3 || d4) return 1;
    int64_t lo = px < qx ? px : qx, hi = px < qx ? qx : px;
    int64_t alo = ax < bx ? ax : bx, ahi = ax < bx ? bx : ax;
    if (hi < alo || ahi < lo) return 0;
    lo = py < qy ? py : qy, hi = py < qy ? qy : py;
    alo = ay < by ? ay : by, ahi = ay < by ? by : ay;
    return !(hi < alo || ahi < lo);
}

/* distance in map units from p to segment ab (raw) */
static double seg_dist(int64_t px, int64_t py, int64_t ax, int64_t ay, int64_t bx, int64_t by)
{
    double abx = un(bx - ax), aby = un(by - ay), apx = un(px - ax), apy = un(py - ay);
    double l2 = abx * abx + aby * aby, t = l2 > 0 ? (abx * apx + aby * apy) / l2 : 0;
    if (t < 0) t = 0;
    if (t > 1) t = 1;
    double dx = apx - t * abx, dy = apy - t * aby;
    return sqrt(dx * dx + dy * dy);
}

typedef struct {
    int64_t ax, ay, bx, by;
    uint32_t sec[2];
} tline;

typedef struct {
    tline *all, *solid; /* every line; the one-sided ones */
    uint32_t nall, nsolid;
} walls;

static void walls_of(const scene *s, walls *w)
{
    w->all = calloc(s->nlines, sizeof(tline));
    w->solid = calloc(s->nlines, sizeof(tline));
    w->nall = w->nsolid = 0;
    for (uint32_t i = 0; i < s->nlines; i++) {
        const scn_line *ln = &s->lines[i];
        tline t = {s->verts[ln->v1].x,
                   s->verts[ln->v1].y,
                   s->verts[ln->v2].x,
                   s->verts[ln->v2].y,
                   {ln->sector[0], ln->sector[1]}};
        w->all[w->nall++] = t;
        if (ln->sector[1] == SCN_NONE) w->solid[w->nsolid++] = t;
    }
}

static void walls_free(walls *w)
{
    free(w->all);
    free(w->solid);
}

/* nearest one-sided wall, map units */
static double solid_dist(const walls *w, int64_t x, int64_t y)
{
    double best = 1e30;
    for (uint32_t i = 0; i < w->nsolid; i++) {
        const tline *t = &w->solid[i];
        double d = seg_dist(x, y, t->ax, t->ay, t->bx, t->by);
        if (d < best) best = d;
    }
    return best;
}

static int crosses_solid(const walls *w, int64_t px, int64_t py, int64_t qx, int64_t qy)
{
    for (uint32_t i = 0; i < w->nsolid; i++) {
        const tline *t = &w->solid[i];
        if (crosses(px, py, qx, qy, t->ax, t->ay, t->bx, t->by)) return 1;
    }
    return 0;
}

/* inside the area enclosed by some sector's lines (ray-crossing parity per
 * sector, exact; a line with the same sector on both sides does not count) */
static int inside_some_sector(const scene *s, const walls *w, int64_t px, int64_t py)
{
    uint8_t *odd = calloc(s->nsectors, 1);
    for (uint32_t i = 0; i < w->nall; i++) {
        const tline *t = &w->all[i];
        if (t->sec[0] == t->sec[1]) continue;
        if ((t->ay > py) == (t->by > py)) continue;
        i128 lhs = (i128)(px - t->ax) * (t->by - t->ay), rhs = (i128)(py - t->ay) * (t->bx - t->ax);
        if (t->by > t->ay ? lhs < rhs : lhs > rhs)
            for (int k = 0; k < 2; k++)
                if (t->sec[k] != SCN_NONE) odd[t->sec[k]] ^= 1;
    }
    int in = 0;
    for (uint32_t sec = 0; sec < s->nsectors; sec++) in |= odd[sec];
    free(odd);
    return in;
}

/* ------------------------------------------------------------ walls */

static void walk(const scene *s, fx_t *x, fx_t *y, fx_t *fz, double dx, double dy, int steps)
{
    for (int i = 0; i < steps; i++) col_move(s, NULL, NULL, x, y, fz, U(dx), U(dy));
}

static void test_wall_stops_at_radius(void **state)
{
    (void)state;
    loaded l;
    load_room(&l);
    static const int dir[8][2] = {{1, 0}, {-1, 0}, {0, 1}, {0, -1}, {1, 1}, {-1, 1}, {1, -1}, {-1, -1}};
    for (int k = 0; k < 8; k++)
        for (int fast = 0; fast < 2; fast++) {
            fx_t x = U(128), y = U(128), fz = 0;
            if (fast)
                col_move(&l.s, NULL, NULL, &x, &y, &fz, (int64_t)U(1000) * dir[k][0], (int64_t)U(1000) * dir[k][1]);
            else
                walk(&l.s, &x, &y, &fz, 8 * dir[k][0], 8 * dir[k][1], 40);
            double ex = dir[k][0] ? 128 + 112 * dir[k][0] : 128, ey = dir[k][1] ? 128 + 112 * dir[k][1] : 128;
            /* at the wall: within 1/32 unit short of radius, never nearer (a grid step) */
            assert_true(fabs(un(x) - ex) <= 1.0 / 32 && fabs(un(y) - ey) <= 1.0 / 32);
            assert_true(un(x) >= 16 - 1.0 / 4096 && un(x) <= 240 + 1.0 / 4096);
            assert_true(un(y) >= 16 - 1.0 / 4096 && un(y) <= 240 + 1.0 / 4096);
            assert_true(fz == 0);
        }
    /* a single step blocked exactly: reported */
    fx_t x = U(230), y = U(128), fz = 0;
    assert_true(col_move(&l.s, NULL, NULL, &x, &y, &fz, U(20), 0) & COL_BLOCKED);
    assert_false(col_move(&l.s, NULL, NULL, &x, &y, &fz, -U(20), 0) & COL_BLOCKED);
    unload(&l);
}

static void test_slide_keeps_parallel_component(void **state)
{
    (void)state;
    loaded l;
    load_room(&l);
    /* at 45 degrees into the east wall: x stops, y keeps all of its motion */
    fx_t x = U(200), y = U(64), fz = 0;
    col_move(&l.s, NULL, NULL, &x, &y, &fz, U(100), U(100));
    assert_true(fabs(un(x) - 240) <= 1.0 / 32);
    assert_true(fabs(un(y) - 164) <= 1.0 / 16);
    /* many small steps along the wall: no sticking, no creeping in */
    for (int i = 0; i < 50; i++) {
        col_move(&l.s, NULL, NULL, &x, &y, &fz, -U(4), -U(4));
        col_move(&l.s, NULL, NULL, &x, &y, &fz, U(5), -U(1));
        assert_true(un(x) <= 240 + 1.0 / 4096);
    }
    assert_true(un(y) >= 16 - 1.0 / 4096); /* down into the corner, not through the floor wall */
    assert_true(fabs(un(y) - 16) <= 1.0 / 32);
    unload(&l);

    /* a wall at 45 degrees to an eastward move */
    load_text(&l, "sector r floor=0 ceil=128\n"
                  "wall 0 0 0 256 r\nwall 0 256 128 256 r\nwall 128 256 256 128 r\n"
                  "wall 256 128 256 0 r\nwall 256 0 0 0 r\nplayer 100 100 0\n");
    x = U(150);
    y = U(160);
    col_move(&l.s, NULL, NULL, &x, &y, &fz, U(100), 0);
    double d = (384 - un(x) - un(y)) / sqrt(2.0);             /* distance to the diagonal */
    double along = (un(x) - 150 - (un(y) - 160)) / sqrt(2.0); /* motion along it */
    assert_true(d >= 16 - 1.0 / 1024 && d <= 16 + 1.0 / 16);
    assert_true(fabs(along - 100 / sqrt(2.0)) <= 1.0 / 8);
    unload(&l);
}

static void test_corner(void **state)
{
    (void)state;
    loaded l;
    load_room(&l);
    walls w;
    walls_of(&l.s, &w);
    fx_t x = U(128), y = U(128), fz = 0;
    for (int i = 0; i < 200; i++) {
        col_move(&l.s, NULL, NULL, &x, &y, &fz, U(3), U(5));
        assert_true(solid_dist(&w, x, y) >= 16 - 1.0 / 1024);
    }
    assert_true(fabs(un(x) - 240) <= 1.0 / 32 && fabs(un(y) - 240) <= 1.0 / 32);
    walls_free(&w);
    unload(&l);
}

static void test_steps_up(void **state)
{
    (void)state;
    loaded l;
    int f24[] = {0, 24}, f25[] = {0, 25}, c2[] = {128, 128};
    fx_t x, y, fz;

    load_chain(&l, 2, f24, c2);
    x = U(128), y = U(128), fz = 0;
    walk(&l.s, &x, &y, &fz, 8, 0, 60);
    assert_true(fabs(un(x) - 496) <= 1.0 / 32);
    assert_int_equal(fz, U(24));
    x = U(128), y = U(128), fz = 0; /* in one call */
    col_move(&l.s, NULL, NULL, &x, &y, &fz, U(1000), 0);
    assert_true(fabs(un(x) - 496) <= 1.0 / 32);
    assert_int_equal(fz, U(24));
    /* standing over the edge: the circle overhangs the step, the floor is the step's */
    x = U(250), y = U(128);
    col_move(&l.s, NULL, NULL, &x, &y, &fz, 0, 0);
    assert_int_equal(fz, U(24));
    fx_t leaf;
    assert_true(col_floor_at(&l.s, x, y, &leaf) && leaf == 0);
    unload(&l);

    load_chain(&l, 2, f25, c2);
    x = U(128), y = U(128), fz = 0;
    walk(&l.s, &x, &y, &fz, 8, 0, 60);
    assert_true(fabs(un(x) - 240) <= 1.0 / 32);
    assert_int_equal(fz, 0);
    x = U(128), y = U(128);
    col_move(&l.s, NULL, NULL, &x, &y, &fz, U(1000), U(3));
    assert_true(un(x) <= 240 + 1.0 / 4096 && un(x) >= 240 - 1.0 / 32);
    unload(&l);

    /* a staircase of 24s is climbed, one step per 16-unit sub-step */
    int stairs[] = {0, 24, 48, 72, 96}, c5[] = {200, 200, 200, 200, 200};
    load_chain(&l, 5, stairs, c5);
    x = U(128), y = U(128), fz = 0;
    walk(&l.s, &x, &y, &fz, 10, 0, 130);
    assert_true(fabs(un(x) - (1280 - 16)) <= 1.0 / 32);
    assert_int_equal(fz, U(96));
    unload(&l);
}

static void test_low_gaps(void **state)
{
    (void)state;
    static const struct {
        int f[2], c[2];
        int pass;
    } cases[] = {
        {{0, 0}, {128, 55}, 0},                            /* a gap lower than 56 */
        {{0, 0}, {128, 56}, 1},                            /* exactly 56 */
        {{0, 24}, {128, 79}, 0},                           /* a step up into a room 55 high */
        {{0, 24}, {128, 80}, 1},   {{0, 0}, {55, 128}, 0}, /* from a room too low for us: the opening is too */
        {{100, 0}, {300, 120}, 0},                         /* down from a ledge under a ceiling only 20 above it */
        {{100, 0}, {300, 156}, 1},                         /* 56 above it: fine, and down any height */
        {{0, 10}, {128, 10}, 0},                           /* a closed door */
    };
    for (size_t k = 0; k < sizeof cases / sizeof cases[0]; k++) {
        loaded l;
        load_chain(&l, 2, cases[k].f, cases[k].c);
        fx_t x = U(128), y = U(128), fz = 0;
        walk(&l.s, &x, &y, &fz, 8, 0, 60);
        if (cases[k].pass) {
            assert_true(fabs(un(x) - 496) <= 1.0 / 32);
            assert_int_equal(fz, U(cases[k].f[1]));
        } else {
            assert_true(fabs(un(x) - 240) <= 1.0 / 32);
            assert_int_equal(fz, U(cases[k].f[0]));
        }
        unload(&l);
    }
}

static void test_walk_down_steps(void **state)
{
    (void)state;
    loaded l;
    int f[] = {0, -16, -40, -300}, c[] = {128, 128, 128, 128};
    load_chain(&l, 4, f, c);
    fx_t x = U(128), y = U(128), fz = 0;
    fx_t prev = 0;
    for (int i = 0; i < 120; i++) {
        col_move(&l.s, NULL, NULL, &x, &y, &fz, U(8), 0);
        assert_true(fz <= prev); /* only down */
        prev = fz;
    }
    assert_true(fabs(un(x) - (1024 - 16)) <= 1.0 / 32);
    assert_int_equal(fz, U(-300));
    /* and no way back up the 260-unit drop */
    walk(&l.s, &x, &y, &fz, -8, 0, 60);
    assert_true(fabs(un(x) - (768 + 16)) <= 1.0 / 32);
    assert_int_equal(fz, U(-300));
    unload(&l);
}

/* Two rooms separated by a wall one unit thick: no move of any length or
 * direction gets from one to the other. */
static void test_fast_moves_never_tunnel(void **state)
{
    (void)state;
    loaded l;
    load_text(&l, "sector w floor=0 ceil=128\nsector e floor=0 ceil=128\n"
                  "wall 0 0 0 256 w\nwall 0 256 300 256 w\nwall 300 256 300 0 w\nwall 300 0 0 0 w\n"
                  "wall 301 0 301 256 e\nwall 301 256 600 256 e\nwall 600 256 600 0 e\nwall 600 0 301 0 e\n"
                  "player 100 128 0\n");
    walls w;
    walls_of(&l.s, &w);
    uint64_t rng = 12345;
    fx_t x = U(100), y = U(128), fz = 0;
    for (int i = 0; i < 600; i++) {
        rng = rng * 6364136223846793005ull + 1442695040888963407ull;
        double a = (double)(rng >> 11) / 9007199254740992.0 * 2 * M_PI;
        double len = (i % 3 == 0) ? 1000 : (double)((rng >> 20) % 5000);
        fx_t px = x, py = y;
        col_move(&l.s, NULL, NULL, &x, &y, &fz, (int64_t)(len * cos(a) * 65536), (int64_t)(len * sin(a) * 65536));
        assert_true(un(x) <= 300 - 16 + 1.0 / 4096);
        assert_true(solid_dist(&w, x, y) >= 16 - 1.0 / 1024);
        assert_true(inside_some_sector(&l.s, &w, x, y));
        (void)px;
        (void)py;
    }
    /* head-on at a thin pillar from far away */
    unload(&l);
    load_text(&l, "sector r floor=0 ceil=128\n"
                  "wall 0 0 0 256 r\nwall 0 256 600 256 r\nwall 600 256 600 0 r\nwall 600 0 0 0 r\n"
                  "wall 300 64 301 64 r\nwall 301 64 301 192 r\nwall 301 192 300 192 r\nwall 300 192 300 64 r\n"
                  "player 100 128 0\n");
    x = U(100), y = U(128);
    col_move(&l.s, NULL, NULL, &x, &y, &fz, U(30000), 0);
    assert_true(fabs(un(x) - 284) <= 1.0 / 32);
    x = U(550), y = U(128);
    col_move(&l.s, NULL, NULL, &x, &y, &fz, -(int64_t)U(30000) * 4, 0); /* a huge move (clamped) */
    assert_true(fabs(un(x) - 317) <= 1.0 / 32);
    walls_free(&w);
    unload(&l);
}

/* Starting exactly on a wall line, on a vertex, at exactly radius, outside. */
static void test_degenerate_starts(void **state)
{
    (void)state;
    loaded l;
    load_room(&l);
    fx_t x, y, fz = 0;
    uint32_t fl;
    x = 0, y = U(128); /* on the west wall */
    fl = col_move(&l.s, NULL, NULL, &x, &y, &fz, -U(50), 0);
    assert_true(fl & COL_STUCK);
    assert_true(x >= 0);
    col_move(&l.s, NULL, NULL, &x, &y, &fz, U(50), 0);
    assert_true(fabs(un(x) - 50) <= 1.0 / 32 && y == U(128));
    x = 0, y = U(128); /* along the wall line: allowed, it does not go deeper */
    col_move(&l.s, NULL, NULL, &x, &y, &fz, 0, U(20));
    assert_true(x >= 0 && un(y) > 128);
    x = 0, y = 0; /* on the corner vertex */
    col_move(&l.s, NULL, NULL, &x, &y, &fz, -U(50), -U(50));
    assert_true(x >= 0 && y >= 0 && x <= U(1) / 4 && y <= U(1) / 4); /* (slides push it off the walls) */
    fx_t x0 = x, y0 = y;
    col_move(&l.s, NULL, NULL, &x, &y, &fz, U(50), U(50));
    assert_true(x == x0 + U(50) && y == y0 + U(50));
    x = U(16), y = U(128); /* exactly radius from the wall: free to slide along it */
    fl = col_move(&l.s, NULL, NULL, &x, &y, &fz, -U(1), U(50));
    assert_true(x >= U(16) && x <= U(16) + EPS);
    assert_true(fabs(un(y) - 178) <= 1.0 / 16);
    x = U(5), y = U(5); /* inside both corner walls: out diagonally */
    col_move(&l.s, NULL, NULL, &x, &y, &fz, U(100), U(100));
    assert_true(fabs(un(x) - 105) <= 1.0 / 32 && fabs(un(y) - 105) <= 1.0 / 32);
    x = -U(100), y = U(128); /* outside the map: the wall still holds */
    col_move(&l.s, NULL, NULL, &x, &y, &fz, U(200), 0);
    assert_true(un(x) <= -16 + 1.0 / 4096);
    unload(&l);

    int f[] = {0, 0}, c[] = {128, 128};
    load_chain(&l, 2, f, c);
    x = U(256), y = U(128); /* on a two-sided line: both ways */
    col_move(&l.s, NULL, NULL, &x, &y, &fz, U(40), 0);
    assert_int_equal(x, U(296));
    col_move(&l.s, NULL, NULL, &x, &y, &fz, -U(80), 0);
    assert_int_equal(x, U(216));
    x = U(256), y = 0; /* on the vertex where it meets the outer walls */
    col_move(&l.s, NULL, NULL, &x, &y, &fz, 0, U(60));
    assert_true(x == U(256) && y == U(60));
    unload(&l);
}

/* A body big enough that its moves meet more segs than the candidate buffer
 * holds (a sawtooth wall of 400 segs): the checks walk the tree instead. */
static void test_many_walls_big_body(void **state)
{
    (void)state;
    char *text = malloc(65536);
    int at = sprintf(text, "sector r floor=0 ceil=128\nwall 0 0 0 800 r\n");
    for (int k = 0; k < 200; k++)
        at += sprintf(text + at, "wall %d 800 %d 810 r\nwall %d 810 %d 800 r\n", 8 * k, 8 * k + 4, 8 * k + 4,
                      8 * k + 8);
    sprintf(text + at, "wall 1600 800 1600 0 r\nwall 1600 0 0 0 r\nplayer 800 400 0\n");
    loaded l;
    load_text(&l, text);
    free(text);
    walls w;
    walls_of(&l.s, &w);
    col_body big = {U(300), U(56), U(24)};
    fx_t x = U(800), y = U(400), fz = 0;
    uint64_t rng = 99;
    int blocked = 0;
    for (int i = 0; i < 300; i++) {
        rng = rng * 6364136223846793005ull + 1442695040888963407ull;
        double a = (double)(rng >> 11) / 9007199254740992.0 * 2 * M_PI;
        blocked += (col_move(&l.s, NULL, &big, &x, &y, &fz, (int64_t)(60 * cos(a) * 65536),
                             (int64_t)(60 * sin(a) * 65536)) &
                    COL_BLOCKED) != 0;
        assert_true(solid_dist(&w, x, y) >= 300 - 1.0 / 1024);
    }
    assert_true(blocked > 50);
    /* pressed against the teeth, sliding east along them */
    x = U(400), y = U(400);
    for (int i = 0; i < 100; i++) {
        col_move(&l.s, NULL, &big, &x, &y, &fz, U(4), U(8));
        assert_true(solid_dist(&w, x, y) >= 300 - 1.0 / 1024);
    }
    assert_true(un(y) >= 499.9 && un(x) > 700); /* (resting on the teeth's slopes, a little under 500) */
    walls_free(&w);
    unload(&l);
}

/* ------------------------------------------------------------ line of sight */

static void test_line_of_sight(void **state)
{
    (void)state;
    loaded l;
    int f[] = {0, 48, 0}, c[] = {128, 96, 128}; /* a window sector: sill 48, lintel 96 */
    load_chain(&l, 3, f, c);
    const scene *s = &l.s;
    fx_t y = U(128);
    assert_true(col_line_of_sight(s, NULL, U(128), y, U(60), U(640), y, U(60)));
    assert_false(col_line_of_sight(s, NULL, U(128), y, U(40), U(640), y, U(40)));
    assert_false(col_line_of_sight(s, NULL, U(128), y, U(100), U(640), y, U(100)));
    assert_true(col_line_of_sight(s, NULL, U(128), y, U(48), U(640), y, U(48)));  /* on the sill: passes */
    assert_true(col_line_of_sight(s, NULL, U(128), y, U(96), U(640), y, U(96)));  /* on the lintel */
    assert_true(col_line_of_sight(s, NULL, U(128), y, U(50), U(640), y, U(90)));  /* 60 and 80 at the lines */
    assert_false(col_line_of_sight(s, NULL, U(128), y, U(0), U(640), y, U(120))); /* 30 at the first */
    assert_false(col_line_of_sight(s, NULL, U(128), y, U(120), U(640), y, U(0))); /* 90, then 30 */
    /* slopes that pass exactly through an edge of the opening: 0 -> 96 over 512,
     * crossing x=256 at 24 (below) */
    assert_false(col_line_of_sight(s, NULL, U(128), y, U(0), U(640), y, U(96)));
    /* symmetric */
    assert_true(col_line_of_sight(s, NULL, U(640), y, U(90), U(128), y, U(50)));
    /* inside one room: nothing in the way at any height */
    assert_true(col_line_of_sight(s, NULL, U(20), U(20), U(-500), U(230), U(230), U(500)));
    /* through the outer wall */
    assert_false(col_line_of_sight(s, NULL, U(128), y, U(60), U(900), y, U(60)));
    assert_false(col_line_of_sight(s, NULL, U(128), y, U(60), U(128), U(-10), U(60)));
    /* along the two-sided line x = 256 (collinear): the opening decides */
    assert_true(col_line_of_sight(s, NULL, U(256), U(10), U(60), U(256), U(200), U(70)));
    assert_false(col_line_of_sight(s, NULL, U(256), U(10), U(30), U(256), U(200), U(70)));
    /* a corner grazed: blocks (the end point of a one-sided wall) */
    assert_false(col_line_of_sight(s, NULL, U(200), U(-56), U(60), U(312), U(56), U(60)));
    /* a point */
    assert_true(col_line_of_sight(s, NULL, U(100), U(100), U(10), U(100), U(100), U(20)));
    unload(&l);

    /* a closed door (floor = ceiling) blocks at every height */
    int fd[] = {0, 0, 0}, cd[] = {128, 0, 128};
    load_chain(&l, 3, fd, cd);
    for (int z = -10; z <= 130; z += 10)
        assert_false(col_line_of_sight(&l.s, NULL, U(128), U(128), U(z), U(640), U(128), U(z)));
    unload(&l);

    /* against an exact oracle on many random sight lines in the window scene:
     * blocked iff some one-sided wall is touched, or some two-sided wall is
     * crossed outside its opening */
    load_chain(&l, 3, f, c);
    uint64_t rng = 7;
    int vis = 0, blk = 0;
    walls w;
    walls_of(&l.s, &w);
    for (int i = 0; i < 3000; i++) {
        int64_t p[6];
        for (int k = 0; k < 6; k++) {
            rng = rng * 6364136223846793005ull + 1442695040888963407ull;
            int64_t range = (k == 2 || k == 5) ? 140 : (k == 0 || k == 3 ? 800 : 280);
            p[k] = (int64_t)((rng >> 24) % (uint64_t)(range * 4)) * 16384 -
                   (k == 0 || k == 3 ? 16 * 65536 : 12 * 65536);
        }
        /* oracle: x crossings of the walls x = 256, 512 within the rooms' y span */
        int expect = 1;
        for (uint32_t j = 0; j < w.nall && expect; j++) {
            const tline *t = &w.all[j];
            if (!crosses(p[0], p[1], p[3], p[4], t->ax, t->ay, t->bx, t->by)) continue;
            if (t->sec[1] == SCN_NONE) {
                expect = 0;
                break;
            }
            /* a vertical two-sided line at x = ax: the height where the sight line meets it */
            if (p[0] == p[3]) { /* along it: check both ends of the overlap (here: the end points) */
                continue;       /* (not generated: x values are rarely equal; skip) */
            }
            i128 num = (i128)(t->ax - p[0]), den = (i128)(p[3] - p[0]);
            /* z = z1 + (z2 - z1) num / den; compare with [48, 96] exactly */
            if (den < 0) num = -num, den = -den;
            i128 zz = (i128)p[2] * den + (i128)(p[5] - p[2]) * num;
            if (zz > (i128)U(96) * den || zz < (i128)U(48) * den) expect = 0;
        }
        if (p[0] == p[3]) continue;
        int got = col_line_of_sight(&l.s, NULL, (fx_t)p[0], (fx_t)p[1], (fx_t)p[2], (fx_t)p[3], (fx_t)p[4], (fx_t)p[5]);
        assert_int_equal(got, expect);
        vis += got;
        blk += !got;
    }
    assert_true(vis > 100 && blk > 100);
    walls_free(&w);
    unload(&l);
}

/* ------------------------------------------------------------ MAP01 */

static int have_freedoom2(void)
{
    char path[1024];
    return bspc_find_wad("freedoom2.wad", path, sizeof path) == 0;
}

/* Where the body stands is sound: every sector whose lines come clearly nearer
 * than the radius (the centre's sector too) has its floor at or under fz and its
 * ceiling at least 56 above fz, and every two-sided line that near has an
 * opening of at least 56. Returns 0 and says why if not. */
static int standing_sound(const scene *s, const walls *w, int64_t x, int64_t y, fx_t fz, int quiet)
{
    uint32_t sec = scene_sector_at(s, (fx_t)x, (fx_t)y);
    if (sec != SCN_NONE && (s->sectors[sec].floor_h > fz || s->sectors[sec].ceil_h - fz < U(56))) {
        if (!quiet) fprintf(stderr, "centre sector %u does not fit at %.3f\n", sec, un(fz));
        return 0;
    }
    for (uint32_t i = 0; i < w->nall; i++) {
        const tline *t = &w->all[i];
        if (t->sec[1] == SCN_NONE || seg_dist(x, y, t->ax, t->ay, t->bx, t->by) >= 16 - 1.0 / 1024) continue;
        for (int k = 0; k < 2; k++) {
            const scn_sector *q = &s->sectors[t->sec[k]];
            if (q->floor_h > fz || q->ceil_h - fz < U(56)) {
                if (!quiet)
                    fprintf(stderr, "line %u: sector %u (%.3f..%.3f) does not fit at %.3f\n", i, t->sec[k],
                            un(q->floor_h), un(q->ceil_h), un(fz));
                return 0;
            }
        }
    }
    return 1;
}

/* A random point of the map where the body fits (a leaf polygon's centre). */
static int random_start(const scene *s, const walls *w, uint64_t *rng, fx_t *x, fx_t *y, fx_t *fz)
{
    for (int tries = 0; tries < 1000; tries++) {
        *rng = *rng * 6364136223846793005ull + 1442695040888963407ull;
        const scn_leaf *lf = &s->leaves[(*rng >> 33) % s->nleaves];
        if (lf->sector == SCN_NONE || lf->num_pverts < 3) continue;
        int64_t sx = 0, sy = 0;
        for (uint32_t k = 0; k < lf->num_pverts; k++) {
            sx += s->pverts[lf->first_pvert + k].x;
            sy += s->pverts[lf->first_pvert + k].y;
        }
        *x = (fx_t)(sx / lf->num_pverts);
        *y = (fx_t)(sy / lf->num_pverts);
        if (solid_dist(w, *x, *y) < 17 || !inside_some_sector(s, w, *x, *y)) continue;
        if (col_move(s, NULL, NULL, x, y, fz, 0, 0) & COL_STUCK) continue;
        if (!standing_sound(s, w, *x, *y, *fz, 1)) continue;
        return 1;
    }
    return 0;
}

/* Random walks through MAP01: from the player start, then from random places,
 * short moves (below two radii, so the straight segment between the positions
 * is checked too) and long ones (up to 3000 units in one call). */
static void random_walk(const char *spec, int moves, int want_sectors)
{
    loaded l;
    load_spec(&l, spec);
    const scene *s = &l.s;
    walls w;
    walls_of(s, &w);
    fx_t x = s->hdr->player_x, y = s->hdr->player_y, fz = 0;
    col_move(s, NULL, NULL, &x, &y, &fz, 0, 0);
    assert_true(solid_dist(&w, x, y) >= 16);
    assert_true(standing_sound(s, &w, x, y, fz, 0));
    uint64_t rng = 2024;
    double heading = 0;
    uint8_t *seen = calloc(s->nsectors, 1);
    int visited = 0, blocked = 0, climbed = 0, dropped = 0;
    double travelled = 0;
    for (int i = 0; i < moves; i++) {
        if (i % 3000 == 0 && i > 0) assert_true(random_start(s, &w, &rng, &x, &y, &fz));
        rng = rng * 6364136223846793005ull + 1442695040888963407ull;
        heading += ((double)((rng >> 33) % 2001) - 1000) / 1000 * 0.4;
        int long_move = i % 3000 >= 2700;
        double len = long_move ? (double)((rng >> 13) % 3000) : (double)((rng >> 13) % 31001) / 1000;
        fx_t px = x, py = y, pz = fz;
        uint32_t fl = col_move(s, NULL, NULL, &x, &y, &fz, (int64_t)(len * cos(heading) * 65536),
                               (int64_t)(len * sin(heading) * 65536));
        assert_false(fl & COL_STUCK);
        if (fl & COL_BLOCKED) {
            blocked++;
            rng = rng * 6364136223846793005ull + 1442695040888963407ull;
            heading = (double)(rng >> 11) / 9007199254740992.0 * 2 * M_PI;
        }
        travelled += hypot(un(x - px), un(y - py));
        /* inside the map, never nearer than the radius to a one-sided wall */
        uint32_t sec = scene_sector_at(s, x, y);
        assert_true(sec != SCN_NONE);
        assert_true(inside_some_sector(s, &w, x, y));
        double d = solid_dist(&w, x, y);
        if (d < 16 - 1.0 / 1024) fprintf(stderr, "move %d: %.6f from a wall at (%.4f, %.4f)\n", i, d, un(x), un(y));
        assert_true(d >= 16 - 1.0 / 1024);
        /* short moves (< 2 radii): the straight segment between the two positions
         * crosses no one-sided wall (the circle's path was at least a radius away) */
        if (!long_move) assert_false(crosses_solid(&w, px, py, x, y));
        /* one step up per sub-step of 16 units; standing where the body fits */
        if (!long_move && len <= 16) assert_true((int64_t)fz - pz <= U(24));
        assert_true(standing_sound(s, &w, x, y, fz, 0));
        climbed += fz > pz;
        dropped += fz < pz;
        if (!seen[sec]) {
            seen[sec] = 1;
            visited++;
        }
    }
    fprintf(stderr, "%s: %d of %u sectors visited, %.0f units travelled, %d blocked, %d up, %d down\n", spec, visited,
            s->nsectors, travelled, blocked, climbed, dropped);
    assert_true(visited >= want_sectors);
    assert_true(travelled > 4 * moves);
    free(seen);
    walls_free(&w);
    unload(&l);
}

static void test_map01_random_walk(void **state)
{
    (void)state;
    if (!have_freedoom2()) skip();
    random_walk("freedoom2.wad:MAP01", 24000, 30);
}

/* every Freedoom map (slow: set COLLIDE_TEST_ALL_MAPS=1 to run it) */
static void test_all_maps_random_walk(void **state)
{
    (void)state;
    if (!getenv("COLLIDE_TEST_ALL_MAPS") || !have_freedoom2()) skip();
    char spec[64];
    for (int k = 0; k < 32; k++) {
        snprintf(spec, sizeof spec, "freedoom2.wad:MAP%02d", k + 1);
        random_walk(spec, 6000, 1);
    }
    for (int k = 0; k < 36; k++) {
        snprintf(spec, sizeof spec, "freedoom1.wad:E%dM%d", k / 9 + 1, k % 9 + 1);
        random_walk(spec, 6000, 1);
    }
}

/* Line of sight in MAP01 against a brute-force oracle over every line. */
static void test_map01_sight(void **state)
{
    (void)state;
    if (!have_freedoom2()) skip();
    loaded l;
    load_spec(&l, "freedoom2.wad:MAP01");
    const scene *s = &l.s;
    walls w;
    walls_of(s, &w);
    int64_t x0 = INT64_MAX, x1 = INT64_MIN, y0 = INT64_MAX, y1 = INT64_MIN;
    for (uint32_t i = 0; i < w.nall; i++) {
        if (w.all[i].ax < x0) x0 = w.all[i].ax;
        if (w.all[i].ax > x1) x1 = w.all[i].ax;
        if (w.all[i].ay < y0) y0 = w.all[i].ay;
        if (w.all[i].ay > y1) y1 = w.all[i].ay;
    }
    uint64_t rng = 5;
    int vis = 0;
    for (int i = 0; i < 2000; i++) {
        int64_t p[6];
        for (int k = 0; k < 6; k++) {
            rng = rng * 6364136223846793005ull + 1442695040888963407ull;
            uint64_t r = rng >> 16;
            if (k == 2 || k == 5)
                p[k] = (int64_t)(r % (256u << 16)) - (64 << 16);
            else if (k == 0 || k == 3)
                p[k] = x0 + (int64_t)(r % (uint64_t)(x1 - x0));
            else
                p[k] = y0 + (int64_t)(r % (uint64_t)(y1 - y0));
        }
        if (i % 2) { /* half of them short, so that many are visible */
            p[3] = p[0] + (p[3] - p[0]) / 16;
            p[4] = p[1] + (p[4] - p[1]) / 16;
        }
        p[0] &= ~(int64_t)15, p[1] &= ~(int64_t)15, p[3] &= ~(int64_t)15, p[4] &= ~(int64_t)15; /* on the grid */
        int expect = 1;
        for (uint32_t j = 0; j < w.nall && expect; j++) {
            const tline *t = &w.all[j];
            if (!crosses(p[0], p[1], p[3], p[4], t->ax, t->ay, t->bx, t->by)) continue;
            if (t->sec[1] == SCN_NONE) {
                expect = 0;
                break;
            }
            const scn_sector *a = &s->sectors[t->sec[0]], *b = &s->sectors[t->sec[1]];
            int64_t lo = a->floor_h > b->floor_h ? a->floor_h : b->floor_h;
            int64_t hi = a->ceil_h < b->ceil_h ? a->ceil_h : b->ceil_h;
            if (hi <= lo) {
                expect = 0;
                break;
            }
            i128 o1 = orient(t->ax, t->ay, t->bx, t->by, p[0], p[1]),
                 o2 = orient(t->ax, t->ay, t->bx, t->by, p[3], p[4]);
            if (o1 == o2) continue; /* collinear: rare, skipped */
            i128 num = o1, den = o1 - o2;
            if (den < 0) num = -num, den = -den;
            i128 zz = (i128)p[2] * den + (i128)(p[5] - p[2]) * num;
            if (zz > (i128)hi * den || zz < (i128)lo * den) expect = 0;
        }
        int got = col_line_of_sight(s, NULL, (fx_t)p[0], (fx_t)p[1], (fx_t)p[2], (fx_t)p[3], (fx_t)p[4], (fx_t)p[5]);
        if (got != expect)
            fprintf(stderr, "sight %d: (%.4f %.4f %.4f)-(%.4f %.4f %.4f) got %d\n", i, un(p[0]), un(p[1]), un(p[2]),
                    un(p[3]), un(p[4]), un(p[5]), got);
        assert_int_equal(got, expect);
        vis += got;
    }
    assert_true(vis > 50);
    walls_free(&w);
    unload(&l);
}

/* ------------------------------------------------------------ camera */

/* Under a ceiling lower than the eye's height (a door shut on the eye, a crusher)
 * the floor wins over the ceiling gap: the eye stays 41 above the floor it
 * stands on, never sinking into it, standing or turning. */
static void test_camera_floor_wins_under_a_low_ceiling(void **state)
{
    (void)state;
    static const int ceils[] = {0, 8, 32, 44};
    for (size_t k = 0; k < sizeof ceils / sizeof ceils[0]; k++) {
        loaded l;
        int f[] = {16, 16}, c[] = {16 + ceils[k], 16 + ceils[k]};
        load_chain(&l, 2, f, c);
        cam_state cam;
        cam_start(&cam, &l.s);
        assert_int_equal(cam.view.z, U(16 + 41));
        for (int i = 0; i < 20; i++) {
            cam_move(&cam, &l.s, NULL, i < 10 ? 0 : HAL_KEY_TURN_LEFT, 28);
            assert_int_equal(cam.eye_floor, U(16));
            assert_int_equal(cam.view.z, U(16 + 41));
        }
        unload(&l);
    }
}


static void test_camera_walks_and_climbs(void **state)
{
    (void)state;
    loaded l;
    int f[] = {0, 24}, c[] = {128, 128};
    load_chain(&l, 2, f, c);
    cam_state cam, twin;
    cam_start(&cam, &l.s);
    cam_start(&twin, &l.s);
    assert_int_equal(cam.view.z, U(41));
    fx_t prevz = cam.view.z;
    for (int i = 0; i < 80; i++) {
        cam_move(&cam, &l.s, NULL, HAL_KEY_FORWARD, 28);
        cam_move(&twin, &l.s, NULL, HAL_KEY_FORWARD, 28);
        fx_t floor;
        assert_true(col_floor_at(&l.s, cam.view.x, cam.view.y, &floor));
        assert_true(cam.view.z >= floor + U(17)); /* eased, but never near the floor */
        assert_true(cam.view.z - prevz <= U(24)); /* and no jump above a step */
        assert_true(cam.view.z >= prevz);         /* only up here */
        prevz = cam.view.z;
    }
    assert_memory_equal(&cam, &twin, sizeof cam);        /* deterministic */
    assert_true(fabs(un(cam.view.x) - 496) <= 1.0 / 32); /* stopped by the wall */
    assert_int_equal(cam.view.z, U(24 + 41));
    assert_int_equal(cam.feet, U(24));
    /* fly up: the eye rises, walking still collides */
    for (int i = 0; i < 10; i++) cam_move(&cam, &l.s, NULL, HAL_KEY_FLY_UP | HAL_KEY_FORWARD, 100);
    assert_true(llabs((int64_t)cam.view.z - U(24 + 41 + 128)) <= 16); /* 12.8 units a frame, truncated */
    assert_true(un(cam.view.x) <= 496 + 1.0 / 4096);
    for (int i = 0; i < 30; i++) cam_move(&cam, &l.s, NULL, HAL_KEY_FLY_DOWN, 100);
    assert_int_equal(cam.view.z, U(24 + 41)); /* not below floor + 41 */
    /* walking back down the step eases the eye down to 41 */
    for (int i = 0; i < 40; i++) cam_move(&cam, &l.s, NULL, HAL_KEY_BACK, 28);
    assert_true(cam.view.z > U(41) && cam.view.z < U(24 + 41)); /* on the way down */
    for (int i = 0; i < 20; i++) cam_move(&cam, &l.s, NULL, 0, 28);
    assert_int_equal(cam.view.z, U(41));
    /* noclip walks through the wall */
    cam.noclip = 1;
    for (int i = 0; i < 80; i++) cam_move(&cam, &l.s, NULL, HAL_KEY_FORWARD, 28);
    assert_true(un(cam.view.x) > 512);
    /* cam_follow_floor puts the eye on the floor at once */
    cam.noclip = 0;
    cam.view.x = U(300);
    cam.view.y = U(100);
    cam_follow_floor(&cam, &l.s);
    assert_int_equal(cam.view.z, U(24 + 41));
    unload(&l);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_wall_stops_at_radius),
        cmocka_unit_test(test_slide_keeps_parallel_component),
        cmocka_unit_test(test_corner),
        cmocka_unit_test(test_steps_up),
        cmocka_unit_test(test_low_gaps),
        cmocka_unit_test(test_walk_down_steps),
        cmocka_unit_test(test_fast_moves_never_tunnel),
        cmocka_unit_test(test_degenerate_starts),
        cmocka_unit_test(test_many_walls_big_body),
        cmocka_unit_test(test_line_of_sight),
        cmocka_unit_test(test_map01_random_walk),
        cmocka_unit_test(test_all_maps_random_walk),
        cmocka_unit_test(test_map01_sight),
        cmocka_unit_test(test_camera_walks_and_climbs),
        cmocka_unit_test(test_camera_floor_wins_under_a_low_ceiling),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
