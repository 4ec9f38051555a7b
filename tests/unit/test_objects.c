/* test_objects.c - moving objects and doors (docs/objects.md, "At run time"):
 * objects sorted into the span renderer's BSP-ordered world by key range and
 * 1/z, checked pixel by pixel against boxes ray-cast in double precision; the
 * work bound; painter's baseline; paths and doors over time; doors in the
 * frame and in collision; the engine's world state.
 *
 * World scenes are compiled with bspc_compile from inline text; models and
 * objects are attached to the loaded scene from arrays here, so the tests do
 * not depend on the compiler's model statements. Run from the repository root. */
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
#include "engine.h"
#include "hal.h"
#include "hal_null.h"
#include "obj_draw.h"
#include "wide128.h"
#include "objects.h"
#include "render.h"
#include "scene.h"
#include "scene_fixture.h"

#define U(v) ((fx_t)((v)*65536.0)) /* map units to 16.16 (test values are exact) */
#define PI 3.14159265358979323846

/* ------------------------------------------------------------ scenes */

typedef struct {
    uint8_t *blob;
    uint32_t len;
    scene s;
} loaded;

static void load_text(loaded *l, const char *text)
{
    l->len = fixture_load_text(text, &l->blob, &l->s);
}

static void unload(loaded *l)
{
    free(l->blob);
}

/* One room 512 x 512, floor 0, ceiling 128. */
static const char ROOM[] = "sector room floor=0 ceil=128 floor_color=sand:7 ceil_color=grey:6\n"
                           "wall 512 0 0 0 room mid=red:10\n"
                           "wall 0 0 0 512 room mid=red:8\n"
                           "wall 0 512 512 512 room mid=red:9\n"
                           "wall 512 512 512 0 room mid=red:7\n"
                           "player 256 64 90\n";

/* Two halves of a room (same floor, different ceilings) on either side of the
 * two-sided line x = 256. */
static const char HALVES[] = "sector w floor=0 ceil=160 floor_color=sand:7 ceil_color=grey:6\n"
                             "sector e floor=0 ceil=144 floor_color=sand:6 ceil_color=grey:5\n"
                             "wall 256 0 0 0 w mid=red:10\n"
                             "wall 0 0 0 256 w mid=red:8\n"
                             "wall 0 256 256 256 w mid=red:9\n"
                             "wall 256 256 256 0 w e upper=yellow:8\n"
                             "wall 256 256 512 256 e mid=blue:10\n"
                             "wall 512 256 512 0 e mid=blue:8\n"
                             "wall 512 0 256 0 e mid=blue:9\n"
                             "player 64 128 0\n";

/* Room a (y 0..256) and room b (y 264..520) with a strip between them: two
 * solid blocks (floor = ceiling) either side of a gap (x 104..152) that a test
 * can make a door. */
static const char TWO_ROOMS[] = "sector a floor=0 ceil=128 floor_color=sand:7 ceil_color=grey:6\n"
                                "sector b floor=0 ceil=128 floor_color=moss:7 ceil_color=grey:5\n"
                                "sector bl floor=0 ceil=0\n"
                                "sector gap floor=0 ceil=128 floor_color=grey:6 ceil_color=grey:4\n"
                                "sector br floor=0 ceil=0\n"
                                /* a */
                                "wall 256 0 0 0 a mid=red:10\n"
                                "wall 0 0 0 256 a mid=red:8\n"
                                "wall 256 256 256 0 a mid=red:8\n"
                                "wall 0 256 104 256 a bl mid=red:9 upper=red:9\n"
                                "wall 104 256 152 256 a gap upper=orange:7\n"
                                "wall 152 256 256 256 a br mid=red:9 upper=red:9\n"
                                /* the strip */
                                "wall 0 256 0 264 bl\n"
                                "wall 104 256 104 264 gap bl upper=grey:8\n"
                                "wall 152 264 152 256 gap br upper=grey:8\n"
                                "wall 256 264 256 256 br\n"
                                "wall 0 264 104 264 bl b\n"
                                "wall 104 264 152 264 gap b upper=orange:7\n"
                                "wall 152 264 256 264 br b\n"
                                /* b */
                                "wall 0 264 0 520 b mid=teal:8\n"
                                "wall 0 520 256 520 b mid=teal:10\n"
                                "wall 256 520 256 264 b mid=teal:8\n"
                                "player 128 64 90\n";

static uint32_t sector_named(const loaded *l, fx_t x, fx_t y)
{
    uint32_t s = scene_sector_at(&l->s, x, y);
    assert_true(s != SCN_NONE);
    return s;
}

/* Make the gap of TWO_ROOMS a door, closed at its floor, open at 112. */
static uint32_t make_door(loaded *l)
{
    uint32_t g = sector_named(l, U(128), U(260));
    scn_sector *sec = (scn_sector *)(void *)&l->s.sectors[g]; /* the blob is ours to change */
    sec->flags |= SCN_SECTOR_DOOR;
    sec->ceil_h = 0;
    sec->open_h = U(112);
    return g;
}

/* ------------------------------------------------------------ models */

#define MAXV 256
#define MAXF 128
static scn_model models[8];
static scn_mvert mverts[MAXV];
static scn_face faces[MAXF];
static uint32_t findex[MAXF * 16];
static uint32_t nmodels, nmverts, nfaces, nfindex;

static void models_reset(void)
{
    nmodels = nmverts = nfaces = nfindex = 0;
}

static uint32_t model_begin(void)
{
    scn_model *m = &models[nmodels];
    *m = (scn_model){nmverts, 0, nfaces, 0, 0, INT32_MAX, INT32_MIN};
    return nmodels++;
}

/* A box part W x D x H (whole units) with its bottom centre at (ax, ay, az), as
 * docs/objects.md builds it: ring (-,-), (+,-), (+,+), (-,+), sides, top, bottom. */
static void add_box(uint32_t mi, double w, double d, double h, double ax, double ay, double az, uint8_t colour)
{
    scn_model *m = &models[mi];
    uint32_t base = m->num_verts;
    static const int sx[4] = {-1, 1, 1, -1}, sy[4] = {-1, -1, 1, 1};
    for (int k = 0; k < 8; k++) {
        scn_mvert *v = &mverts[m->first_vert + m->num_verts++];
        v->x = U(ax + sx[k & 3] * w / 2);
        v->y = U(ay + sy[k & 3] * d / 2);
        v->z = U(az + (k >= 4 ? h : 0));
        int64_t d2 = (int64_t)v->x * v->x + (int64_t)v->y * v->y;
        int32_t r = (int32_t)ceil(sqrt((double)d2));
        if (r > m->radius) m->radius = r;
        if (v->z < m->zmin) m->zmin = v->z;
        if (v->z > m->zmax) m->zmax = v->z;
    }
    nmverts += 8;
    const uint32_t quads[6][4] = {{0, 1, 5, 4}, {1, 2, 6, 5}, {2, 3, 7, 6}, {3, 0, 4, 7}, {4, 5, 6, 7}, {0, 3, 2, 1}};
    for (int f = 0; f < 6; f++) {
        faces[nfaces++] = (scn_face){nfindex, 4, (uint8_t)(colour + f), 0};
        for (int k = 0; k < 4; k++) findex[nfindex++] = base + quads[f][k];
        m->num_faces++;
    }
}

static void attach(scene *s)
{
    s->models = models;
    s->nmodels = nmodels;
    s->mverts = mverts;
    s->nmverts = nmverts;
    s->faces = faces;
    s->nfaces = nfaces;
    s->findex = findex;
    s->nfindex = nfindex;
}

/* ------------------------------------------------------------ rendering */

static uint32_t ids[VIEW_W * VIEW_H];
static render_stats ST;

static camera cam_at(double x, double y, double z, double angle, int look)
{
    camera c = {U(x), U(y), U(z), U(angle), look};
    return c;
}

/* Render into ids; returns the pixels written. */
static uint64_t draw(const scene *s, const world_state *w, const camera *cam, render_mode mode)
{
    render_work work;
    work.bytes = render_work_bytes(s, w);
    work.mem = malloc(work.bytes);
    assert_non_null(work.mem);
    memset(ids, 0xEE, sizeof ids);
    hal_perf_reset();
    hal_surface surf = hal_begin_frame(HAL_PRESENT_FLIP);
    rast_target t = {&surf, ids};
    render_frame(s, w, cam, mode, &t, &work, &ST);
    hal_present(HAL_PRESENT_FLIP);
    free(work.mem);
    assert_int_equal(ST.refused, 0);
    return hal_perf_event(HAL_EV_PIXELS);
}

/* Spans: every pixel written exactly once, none left to the background (the
 * scenes are closed and the eye is inside). */
static void draw_exact(const scene *s, const world_state *w, const camera *cam)
{
    assert_int_equal(draw(s, w, cam, RENDER_SPANS), VIEW_W * VIEW_H);
    for (int i = 0; i < VIEW_W * VIEW_H; i++) assert_true((ids[i] >> 24) != RAST_KIND_NONE && ids[i] != 0xEEEEEEEEu);
}

static int count_id(uint32_t id)
{
    int n = 0;
    for (int i = 0; i < VIEW_W * VIEW_H; i++) n += ids[i] == id;
    return n;
}

static int count_kind(uint32_t kind)
{
    int n = 0;
    for (int i = 0; i < VIEW_W * VIEW_H; i++) n += (ids[i] >> 24) == kind;
    return n;
}

/* ------------------------------------------------------------ the analytic boxes */

typedef struct {
    double ox, oy, oz, yaw;        /* degrees */
    double x0, x1, y0, y1, z0, z1; /* model space */
} abox;

static abox box_of(const obj_state *o, double w, double d, double h)
{
    abox b = {o->x / 65536.0, o->y / 65536.0, o->z / 65536.0, o->yaw_deg / 65536.0, -w / 2, w / 2, -d / 2, d / 2, 0, h};
    return b;
}

/* Distance along the ray to the box, or INFINITY. */
static double hit(const abox *b, const double e[3], const double dir[3])
{
    double c = cos(-b->yaw * PI / 180), s = sin(-b->yaw * PI / 180);
    double px = e[0] - b->ox, py = e[1] - b->oy;
    double p[3] = {px * c - py * s, px * s + py * c, e[2] - b->oz};
    double d[3] = {dir[0] * c - dir[1] * s, dir[0] * s + dir[1] * c, dir[2]};
    double lo[3] = {b->x0, b->y0, b->z0}, hi[3] = {b->x1, b->y1, b->z1};
    double t0 = 0, t1 = INFINITY;
    for (int k = 0; k < 3; k++) {
        if (fabs(d[k]) < 1e-300) {
            if (p[k] < lo[k] || p[k] > hi[k]) return INFINITY;
            continue;
        }
        double a = (lo[k] - p[k]) / d[k], bb = (hi[k] - p[k]) / d[k];
        if (a > bb) {
            double x = a;
            a = bb;
            bb = x;
        }
        if (a > t0) t0 = a;
        if (bb < t1) t1 = bb;
    }
    return t0 <= t1 ? t0 : INFINITY;
}

/* With room_box set, the boxes are seen inside that box-shaped room only: a part
 * beyond its walls is hidden. */
static int room_box_set;
static double room_box[6]; /* x0, x1, y0, y1, z0, z1 */

/* Where the ray leaves the room (the eye is inside it). */
static double room_exit(const double e[3], const double dir[3])
{
    double t = INFINITY;
    for (int k = 0; k < 3; k++) {
        if (dir[k] > 0) t = fmin(t, (room_box[2 * k + 1] - e[k]) / dir[k]);
        if (dir[k] < 0) t = fmin(t, (room_box[2 * k] - e[k]) / dir[k]);
    }
    return t;
}

/* The nearest box through screen point (sx, sy) (pixels, y down), or -1. */
static int nearest(const camera *cam, const abox *b, int n, double sx, double sy)
{
    double a = cam->angle_deg / 65536.0 * PI / 180;
    double u = (sx - 160) / 160, v = (100 + cam->look - sy) / 160;
    double dir[3] = {cos(a) + u * sin(a), sin(a) - u * cos(a), v};
    double e[3] = {cam->x / 65536.0, cam->y / 65536.0, cam->z / 65536.0};
    int best = -1;
    double bt = room_box_set ? room_exit(e, dir) : INFINITY;
    for (int i = 0; i < n; i++) {
        double t = hit(&b[i], e, dir);
        if (t < bt) {
            bt = t;
            best = i;
        }
    }
    return best;
}

/* Every pixel whose centre and four points 0.02 pixel around it see the same box
 * (or none) must show that object (or something else). Returns the object pixels
 * expected; fails on any mismatch. ids_of[i]: the id of box i. */
static int check_boxes(const camera *cam, const abox *b, int n, const uint32_t *ids_of)
{
    int expected = 0, bad = 0;
    for (int py = 0; py < VIEW_H; py++)
        for (int px = 0; px < VIEW_W; px++) {
            double cx = px + 0.5, cy = py + 0.5;
            int k = nearest(cam, b, n, cx, cy);
            const double o = 0.02;
            if (nearest(cam, b, n, cx - o, cy) != k || nearest(cam, b, n, cx + o, cy) != k ||
                nearest(cam, b, n, cx, cy - o) != k || nearest(cam, b, n, cx, cy + o) != k)
                continue;
            uint32_t got = ids[py * VIEW_W + px];
            int ok = k < 0 ? (got >> 24) != RAST_KIND_OBJECT : got == ids_of[k];
            if (!ok && bad++ < 8)
                fprintf(stderr, "pixel %d,%d: id %08x, expected %s %d\n", px, py, got, k < 0 ? "no object" : "object",
                        k);
            expected += k >= 0;
        }
    assert_int_equal(bad, 0);
    return expected;
}

/* ------------------------------------------------------------ shared set-up */

typedef struct {
    obj_state objs[16];
    world_state w;
    abox boxes[16];
    uint32_t id[16];
} placed;

/* Object i of model mi (a single W x D x H box) at (x, y, z) turned by yaw. */
static void place(placed *p, uint32_t i, uint32_t mi, double x, double y, double z, double yaw, double w, double d,
                  double h)
{
    p->objs[i] = (obj_state){mi, U(x), U(y), U(z), U(yaw)};
    p->boxes[i] = box_of(&p->objs[i], w, d, h);
    p->id[i] = RAST_ID(RAST_KIND_OBJECT, i);
    if (p->w.n < i + 1) p->w.n = i + 1;
    p->w.objs = p->objs;
}

/* ------------------------------------------------------------ tests */

/* Objects on the floor of one room, seen from many places and angles: exact
 * overdraw and their silhouettes pixel for pixel (the bottom edges against the
 * floor neither leak floor into the object nor object below its outline). */
static void test_resting_on_floor(void **state)
{
    (void)state;
    loaded l;
    load_text(&l, ROOM);
    models_reset();
    uint32_t crate = model_begin();
    add_box(crate, 32, 32, 32, 0, 0, 0, 40);
    uint32_t slab = model_begin();
    add_box(slab, 96, 16, 8, 0, 0, 0, 60);
    attach(&l.s);
    placed p;
    memset(&p, 0, sizeof p);
    place(&p, 0, crate, 256, 256, 0, 0, 32, 32, 32);
    place(&p, 1, crate, 200, 180, 0, 30, 32, 32, 32);
    place(&p, 2, slab, 320, 160, 0, 17.5, 96, 16, 8);
    place(&p, 3, crate, 380, 300, 0, 45, 32, 32, 32);
    static const double views[][5] = {{256, 64, 41, 90, 0},       {100, 100, 41, 45, 0},   {256, 120, 41, 90, -60},
                                      {400, 60, 20, 120, 0},      {250, 200, 5, 60, 0},    {60, 300, 41, 0, 0},
                                      {300, 100, 100, 100, -100}, {450, 450, 41, 225, 30}, {256, 200, 41, 90, 0}};
    for (size_t i = 0; i < sizeof views / sizeof views[0]; i++) {
        camera c = cam_at(views[i][0], views[i][1], views[i][2], views[i][3], (int)views[i][4]);
        draw_exact(&l.s, &p.w, &c);
        int want = check_boxes(&c, p.boxes, 4, p.id);
        assert_true(want == 0 || ST.objects_visible > 0);
        assert_int_equal(count_kind(RAST_KIND_OBJECT) > 0, want > 0);
    }
    unload(&l);
}

/* An object in front of a wall hides it; the wall shows around it. */
static void test_object_hides_wall(void **state)
{
    (void)state;
    loaded l;
    load_text(&l, ROOM);
    models_reset();
    uint32_t m = model_begin();
    add_box(m, 40, 8, 64, 0, 0, 0, 40);
    attach(&l.s);
    placed p;
    memset(&p, 0, sizeof p);
    place(&p, 0, m, 256, 500, 0, 0, 40, 8, 64); /* 4 units from the north wall */
    camera c = cam_at(256, 300, 41, 90, 0);
    draw_exact(&l.s, NULL, &c);
    uint32_t wall = ids[100 * VIEW_W + 160];
    assert_int_equal(wall >> 24, RAST_KIND_WALL);
    draw_exact(&l.s, &p.w, &c);
    assert_true(check_boxes(&c, p.boxes, 1, p.id) > 1000);
    assert_int_equal(ids[100 * VIEW_W + 160], p.id[0]);
    assert_int_equal(ids[100 * VIEW_W + 20], wall);
    /* against the wall itself: the face touching it from the room side */
    place(&p, 0, m, 256, 508, 0, 0, 40, 8, 64);
    draw_exact(&l.s, &p.w, &c);
    assert_true(check_boxes(&c, p.boxes, 1, p.id) > 1000);
    /* and turned so two of its faces run into the wall */
    place(&p, 0, m, 256, 400, 0, 90, 40, 8, 64);
    p.objs[0].y = U(512 - 20);
    p.boxes[0] = box_of(&p.objs[0], 40, 8, 64);
    for (int a = 60; a <= 120; a += 15) {
        camera d = cam_at(256 + (a - 90) * 2, 300, 41, a, 0);
        draw_exact(&l.s, &p.w, &d);
        check_boxes(&d, p.boxes, 1, p.id);
    }
    unload(&l);
}

/* Seen from outside the room and above its ceiling, through the backs of its
 * walls and ceiling (culled), a box floating through the ceiling stands against
 * the void above the horizon: no world surface decides those pixels during the
 * walk, so the direct renderer draws them after it. Both renderers draw the
 * same ids, pixel for pixel, and the box shows. */
static void test_object_against_the_void(void **state)
{
    (void)state;
    loaded l;
    load_text(&l, ROOM);
    models_reset();
    uint32_t m = model_begin();
    add_box(m, 40, 40, 64, 0, 0, 0, 40);
    attach(&l.s);
    placed p;
    memset(&p, 0, sizeof p);
    place(&p, 0, m, 256, 100, 150, 30, 40, 40, 64);
    static uint32_t spans_ids[VIEW_W * VIEW_H];
    static const double views[][3] = {{256, -200, 90}, {-150, 60, 10}, {300, -90, 100}};
    for (size_t k = 0; k < sizeof views / sizeof views[0]; k++) {
        camera c = cam_at(views[k][0], views[k][1], 200, views[k][2], 0);
        draw(&l.s, &p.w, &c, RENDER_SPANS);
        memcpy(spans_ids, ids, sizeof spans_ids);
        int shown = count_id(p.id[0]);
        assert_true(shown > 500);
        draw(&l.s, &p.w, &c, RENDER_DIRECT);
        assert_int_equal(count_id(p.id[0]), shown);
        assert_memory_equal(ids, spans_ids, sizeof spans_ids);
    }
    unload(&l);
}

/* Behind a solid wall in another room: not drawn, and when its room's leaves are
 * not visited, not even considered. Through the gap, the part behind the blocks
 * stays hidden. */
static void test_object_behind_wall(void **state)
{
    (void)state;
    loaded l;
    load_text(&l, TWO_ROOMS);
    uint32_t g = make_door(&l);
    models_reset();
    uint32_t m = model_begin();
    add_box(m, 32, 32, 48, 0, 0, 0, 40);
    attach(&l.s);
    fx_t ceil[16];
    for (uint32_t i = 0; i < l.s.nsectors; i++) ceil[i] = l.s.sectors[i].ceil_h;
    placed p;
    memset(&p, 0, sizeof p);
    p.w.ceil = ceil;
    place(&p, 0, m, 128, 300, 0, 0, 32, 32, 48);
    camera c = cam_at(128, 64, 41, 90, 0);
    /* door closed: room b is behind closed columns */
    draw_exact(&l.s, &p.w, &c);
    assert_int_equal(count_kind(RAST_KIND_OBJECT), 0);
    assert_int_equal(ST.objects_visible, 0);
    uint32_t closed_crc = 0;
    for (int i = 0; i < VIEW_W * VIEW_H; i++) closed_crc = closed_crc * 31u + ids[i];
    /* open: seen through the gap, cut by its sides */
    ceil[g] = U(112);
    draw_exact(&l.s, &p.w, &c);
    assert_int_equal(ST.objects_visible, 1);
    int seen = count_id(p.id[0]);
    assert_true(seen > 100);
    uint32_t crc = 0;
    for (int i = 0; i < VIEW_W * VIEW_H; i++) crc = crc * 31u + ids[i];
    assert_true(crc != closed_crc);
    /* every object pixel lies inside the gap's columns, under its lintel */
    for (int py = 0; py < VIEW_H; py++)
        for (int px = 0; px < VIEW_W; px++) {
            if (ids[py * VIEW_W + px] != p.id[0]) continue;
            double x = px + 0.5; /* the gap's edges at y = 256 seen from y = 64 */
            double left = 160 + 160 * (104 - 128) / 192.0, right = 160 + 160 * (152 - 128) / 192.0;
            assert_true(x >= left - 1 && x <= right + 1);
        }
    /* half open: less of it */
    ceil[g] = U(24);
    draw_exact(&l.s, &p.w, &c);
    int low = count_id(p.id[0]);
    assert_true(low > 0 && low < seen);
    /* moved sideways behind a block: its leaves are visited, nothing of it shows */
    ceil[g] = U(112);
    place(&p, 0, m, 40, 290, 0, 0, 32, 32, 48);
    draw_exact(&l.s, &p.w, &c);
    assert_int_equal(count_id(p.id[0]), 0);
    unload(&l);
}

/* Two objects overlapping on screen, in both depth orders; and a stack. */
static void test_two_objects_overlap(void **state)
{
    (void)state;
    loaded l;
    load_text(&l, ROOM);
    models_reset();
    uint32_t m = model_begin();
    add_box(m, 32, 32, 32, 0, 0, 0, 40);
    uint32_t tall = model_begin();
    add_box(tall, 16, 16, 80, 0, 0, 0, 60);
    attach(&l.s);
    placed p;
    memset(&p, 0, sizeof p);
    place(&p, 0, m, 240, 200, 0, 10, 32, 32, 32);
    place(&p, 1, tall, 256, 280, 0, 0, 16, 16, 80);
    camera front = cam_at(250, 60, 41, 90, 0), back = cam_at(260, 440, 41, 270, 0);
    for (int k = 0; k < 2; k++) {
        const camera *c = k ? &back : &front;
        draw_exact(&l.s, &p.w, c);
        int want = check_boxes(c, p.boxes, 2, p.id);
        assert_true(want > 1000);
        assert_true(count_id(p.id[0]) > 100 && count_id(p.id[1]) > 100);
    }
    /* one on top of the other: abutting faces of two objects */
    place(&p, 1, m, 240, 200, 32, 10, 32, 32, 32);
    for (int k = 0; k < 2; k++) {
        camera c = k ? cam_at(240, 100, 80, 90, -40) : cam_at(150, 120, 20, 40, 10);
        draw_exact(&l.s, &p.w, &c);
        assert_true(check_boxes(&c, p.boxes, 2, p.id) > 500);
    }
    unload(&l);
}

/* An object across the two-sided line between two sectors. */
static void test_straddle(void **state)
{
    (void)state;
    loaded l;
    load_text(&l, HALVES);
    models_reset();
    uint32_t m = model_begin();
    add_box(m, 48, 24, 40, 0, 0, 0, 40);
    attach(&l.s);
    placed p;
    memset(&p, 0, sizeof p);
    place(&p, 0, m, 256, 128, 0, 20, 48, 24, 40);
    static const double views[][5] = {
        {64, 128, 41, 0, 0}, {448, 128, 41, 180, 0}, {256, 20, 41, 90, 0}, {180, 50, 100, 45, -100}};
    for (int i = 0; i < 4; i++) {
        camera c = cam_at(views[i][0], views[i][1], views[i][2], views[i][3], (int)views[i][4]);
        draw_exact(&l.s, &p.w, &c);
        int n = check_boxes(&c, p.boxes, 1, p.id);
        if (n <= 200) fprintf(stderr, "view %d: %d\n", i, n);
        assert_true(n > 200);
    }
    unload(&l);
}

/* Objects at the near plane and partly off screen: the eye a hair from a face,
 * inside an object's box, objects cut by every screen edge. */
static void test_near_and_offscreen(void **state)
{
    (void)state;
    loaded l;
    load_text(&l, ROOM);
    models_reset();
    uint32_t m = model_begin();
    add_box(m, 32, 32, 32, 0, 0, 0, 40);
    uint32_t big = model_begin();
    add_box(big, 200, 40, 100, 0, 0, 0, 60);
    attach(&l.s);
    placed p;
    memset(&p, 0, sizeof p);
    place(&p, 0, m, 256, 256, 0, 0, 32, 32, 32);
    place(&p, 1, big, 256, 330, 0, 0, 200, 40, 100);
    static const double eyes[][5] = {
        {256, 240 - 1.0 / 512, 20, 90, 0},  /* 1/512 unit from the crate's face */
        {256, 240 - 1.0 / 2048, 20, 90, 0}, /* nearer than the near plane */
        {256, 239, 16, 90, 80},             /* looking up close */
        {230, 245, 20, 60, -80},            /* beside it, looking down */
        {250, 200, 41, 75, 0},              /* the big one cut by both sides */
        {256, 256, 20, 90, 0},              /* inside the crate */
        {256, 300, 50, 90, 0},              /* inside the big one's box, outside it */
    };
    for (int i = 0; i < 7; i++) {
        camera c = cam_at(eyes[i][0], eyes[i][1], eyes[i][2], eyes[i][3], (int)eyes[i][4]);
        draw_exact(&l.s, &p.w, &c);
        if (i != 1 && i != 5) check_boxes(&c, p.boxes, 2, p.id); /* not past the near plane, not inside */
        assert_int_equal(draw(&l.s, &p.w, &c, RENDER_PAINTER) >= VIEW_W * VIEW_H, 1);
    }
    unload(&l);
}

/* Objects reaching into a wall (as Doom's things often do) and into each other:
 * the order along a line changes where they cross (intersecting spans). */
static void test_interpenetrating(void **state)
{
    (void)state;
    loaded l;
    load_text(&l, ROOM);
    models_reset();
    uint32_t m = model_begin();
    add_box(m, 40, 40, 24, 0, 0, 0, 40);
    uint32_t bar = model_begin();
    add_box(bar, 80, 12, 40, 0, 0, 0, 60);
    attach(&l.s);
    placed p;
    memset(&p, 0, sizeof p);
    place(&p, 0, m, 200, 500, 0, 30, 40, 40, 24);  /* half through the north wall */
    place(&p, 1, m, 512, 300, 0, 45, 40, 40, 24);  /* a corner through the east wall */
    place(&p, 2, bar, 300, 320, 0, 0, 80, 12, 40); /* a cross of two bars */
    place(&p, 3, bar, 300, 320, 4, 70, 80, 12, 40);
    place(&p, 4, m, 0, 0, 0, 0, 40, 40, 24); /* in the corner, three quarters in the walls */
    room_box_set = 1;
    const double rb[6] = {0, 512, 0, 512, 0, 128};
    memcpy(room_box, rb, sizeof rb);
    static const double views[][5] = {{200, 300, 41, 90, 0}, {150, 420, 30, 60, 0},    {400, 250, 41, 30, 0},
                                      {300, 150, 41, 90, 0}, {420, 420, 60, 225, -30}, {200, 200, 41, 0, 0},
                                      {60, 120, 41, 250, 0}, {300, 200, 90, 90, -100}};
    for (int i = 0; i < 8; i++) {
        camera c = cam_at(views[i][0], views[i][1], views[i][2], views[i][3], (int)views[i][4]);
        draw_exact(&l.s, &p.w, &c);
        check_boxes(&c, p.boxes, 5, p.id);
    }
    room_box_set = 0;
    unload(&l);
}

/* The exact 128-bit sign from 32-bit parts (what the Cortex-M3 computes for collision and every 1/z
 * comparison), against the compiler's 128-bit type. */
static void test_wide_products(void **state)
{
    (void)state;
    __extension__ typedef __int128 i128;
    const int64_t edge[] = {0,
                            1,
                            -1,
                            2,
                            (int64_t)1 << 31,
                            -((int64_t)1 << 31),
                            ((int64_t)1 << 32) - 1,
                            (int64_t)1 << 41,
                            ((int64_t)1 << 62) - 1,
                            -((int64_t)1 << 62),
                            INT64_MAX,
                            INT64_MIN + 1};
    int n = sizeof edge / sizeof edge[0];
    uint64_t r = 12345;
    for (int i = 0; i < 200000; i++) {
        int64_t v[4];
        for (int k = 0; k < 4; k++) {
            r = r * 6364136223846793005ull + 1442695040888963407ull;
            v[k] = (i & 1) ? edge[(r >> 33) % (uint64_t)n] : (int64_t)(r ^ (r << 7)) >> (r >> 58);
        }
        i128 want = (i128)v[0] * v[1] - (i128)v[2] * v[3];
        assert_int_equal(w128_sign_diff_parts(v[0], v[1], v[2], v[3]), (want > 0) - (want < 0));
    }
}

/* The 1/z order of flat planes is exact from the near plane to the far corner. */
static void test_inverse_depth_order(void **state)
{
    (void)state;
    camera cam = {0, 0, 0, 0, 0};
    view_xform v;
    view_setup(&v, &cam);
    /* floors below the eye at depths 1 raw apart are told apart everywhere on the
     * lower half; ceilings likewise; far ones against near ones */
    int32_t hs[] = {-1, -2, -16, -17, -65536, -65537, -U(100), -U(16383), -U(16383) + 1};
    for (size_t i = 0; i < sizeof hs / sizeof hs[0]; i++)
        for (size_t j = 0; j < sizeof hs / sizeof hs[0]; j++) {
            objd_plane a, b;
            objd_plane_flat(&v, hs[i], &a);
            objd_plane_flat(&v, hs[j], &b);
            if (a.d == 0 || b.d == 0) continue;
            for (int py = 101; py < 200; py += 7) {
                int f = objd_front(&a, 0, &b, 0, 0, 10, py);
                /* a nearer (higher, less far below the eye) is in front, except ties */
                if (fx_asr64(hs[i], 2) > fx_asr64(hs[j], 2) + 1) assert_int_equal(f, 1);
                if (fx_asr64(hs[i], 2) < fx_asr64(hs[j], 2) - 1) assert_int_equal(f, 0);
            }
        }
    /* a wall at the far corner of the box against one a unit nearer */
    scn_vertex a0 = {U(32767), -U(32767)}, a1 = {U(32767), U(32767)};
    scn_vertex b0 = {U(32766), -U(32767)}, b1 = {U(32766), U(32767)};
    cam.x = -U(32767);
    cam.y = -U(32767);
    cam.angle_deg = U(45);
    view_setup(&v, &cam);
    objd_plane wa, wb;
    objd_plane_wall(&v, &a0, &a1, &wa);
    objd_plane_wall(&v, &b0, &b1, &wb);
    assert_true(wa.d > 0 && wb.d > 0);
    for (int px = 0; px < VIEW_W; px += 29) {
        assert_int_equal(objd_front(&wb, 0, &wa, 0, 0, px, 100), 1);
        assert_int_equal(objd_front(&wa, 0, &wb, 0, 0, px, 100), 0);
    }
}

/* objd_front's ties, case by case, on planes written in view space (x right,
 * y up, z ahead; the centre of pixel (px, py) looks along (2 px + 1 - 320,
 * 2 VIEW_CY - 1 - 2 py, 320)). Pixel (160, VIEW_CY) looks along (1, -1, 320):
 * a floor H below the eye and a wall facing the eye at Z = 320 H meet on that
 * ray, so there both depths are exactly 320 H and the two tie. Every answer
 * below comes from where the surfaces lie, not from the function. */
#define TIE_H 1024               /* view units below the eye */
#define TIE_Z (320 * TIE_H)      /* the wall's depth, where the floor meets the ray */
#define TIE_N ((int32_t)1 << 29) /* a normal's length */
#define TIE_PX (VIEW_W / 2)
#define TIE_PY VIEW_CY

/* y = -TIE_H, seen from above (a floor, or the top of something below the eye) */
static objd_plane tie_floor(int32_t cx, int32_t cy, int32_t cz)
{
    return (objd_plane){0, -TIE_N, 0, cx, cy, cz, (int64_t)TIE_N * TIE_H};
}

/* z = TIE_Z, facing the eye (a wall, or an object's face towards the eye) */
static objd_plane tie_wall(int32_t cx, int32_t cy, int32_t cz)
{
    return (objd_plane){0, 0, TIE_N, cx, cy, cz, (int64_t)TIE_N * TIE_Z};
}

static int tie_front(const objd_plane *s, int s_obj, const objd_plane *p, int p_obj)
{
    return objd_front(s, s_obj, p, p_obj, 0, TIE_PX, TIE_PY);
}

static void test_abutting_ties(void **state)
{
    (void)state;
    const objd_plane floor = tie_floor(0, 0, 0), wall = tie_wall(0, 0, 0);
    /* the inputs really tie: one pixel nearer the screen's bottom the floor is
     * nearer, one nearer its middle the wall is, whatever the tie rules say */
    assert_int_equal(objd_front(&floor, 0, &wall, 0, 0, TIE_PX, TIE_PY + 1), 1);
    assert_int_equal(objd_front(&floor, 0, &wall, 0, 0, TIE_PX, TIE_PY - 1), 0);

    /* An object's face towards the eye standing on the floor (centroid 500
     * units above it, on the eye's side of the floor's plane): at the seam the
     * face is in front, as s and as p. */
    objd_plane standing = tie_wall(0, -TIE_H + 500, TIE_Z);
    assert_int_equal(tie_front(&standing, 1, &floor, 0), 1);
    assert_int_equal(tie_front(&floor, 0, &standing, 1), 0);
    /* an object's face hanging below the floor (centroid beyond it): behind */
    objd_plane sunk = tie_wall(0, -TIE_H - 500, TIE_Z);
    assert_int_equal(tie_front(&sunk, 1, &floor, 0), 0);
    assert_int_equal(tie_front(&floor, 0, &sunk, 1), 1);

    /* An object's top lying on the floor's plane but reaching through the wall
     * (centroid 1000 beyond it): the wall is in front; one lying before the
     * wall (centroid 1000 nearer) is in front of it. */
    objd_plane through = tie_floor(0, -TIE_H, TIE_Z + 1000), before = tie_floor(0, -TIE_H, TIE_Z - 1000);
    assert_int_equal(tie_front(&through, 1, &wall, 0), 0);
    assert_int_equal(tie_front(&wall, 0, &through, 1), 1);
    assert_int_equal(tie_front(&before, 1, &wall, 0), 1);
    assert_int_equal(tie_front(&wall, 0, &before, 1), 0);

    /* Two objects: a face standing on another's top (whose centroid lies in the
     * standing face's plane, so only the first rule decides) is in front of it,
     * whichever is numbered first. */
    objd_plane top = tie_floor(0, -TIE_H, TIE_Z);
    assert_int_equal(tie_front(&standing, 2, &top, 1), 1);
    assert_int_equal(tie_front(&standing, 1, &top, 2), 1);
    assert_int_equal(tie_front(&top, 1, &standing, 2), 0);
    assert_int_equal(tie_front(&top, 2, &standing, 1), 0);

    /* Two objects' tops in one plane (both centroids in it): the lower number first. */
    objd_plane top2 = tie_floor(5000, -TIE_H, TIE_Z);
    assert_int_equal(tie_front(&top, 1, &top2, 2), 1);
    assert_int_equal(tie_front(&top2, 2, &top, 1), 0);

    /* Two world surfaces meeting: the one whose 1/z grows faster down the
     * screen covers the rows below the seam, so the floor wins at the seam. */
    assert_int_equal(tie_front(&floor, 0, &wall, 0), 1);
    assert_int_equal(tie_front(&wall, 0, &floor, 0), 0);
    /* ... and across it: x + z = 321 TIE_H meets the wall on the seam ray
     * (x = TIE_H there) and is nearer to the right of it */
    objd_plane slant = {TIE_N, 0, TIE_N, 0, 0, 0, (int64_t)TIE_N * 321 * TIE_H};
    assert_int_equal(tie_front(&slant, 0, &wall, 0), 1);
    assert_int_equal(tie_front(&wall, 0, &slant, 0), 0);
    assert_int_equal(objd_front(&slant, 0, &wall, 0, 0, TIE_PX + 1, TIE_PY), 1);
    assert_int_equal(objd_front(&slant, 0, &wall, 0, 0, TIE_PX - 1, TIE_PY), 0);

    /* One plane, one gradient: an object's face lying in the floor goes after the world. */
    assert_int_equal(tie_front(&floor, 0, &top, 1), 1);
    assert_int_equal(tie_front(&top, 1, &floor, 0), 0);

    /* A plane through the eye (d = 0) is in front of everything. */
    objd_plane edge = {0, TIE_N, 0, 0, 0, 0, 0};
    assert_int_equal(tie_front(&floor, 0, &edge, 0), 0);
    assert_int_equal(tie_front(&edge, 0, &floor, 0), 1);
}

/* Painter draws the objects after the world, farthest first. */
static void test_painter(void **state)
{
    (void)state;
    loaded l;
    load_text(&l, ROOM);
    models_reset();
    uint32_t m = model_begin();
    add_box(m, 32, 32, 32, 0, 0, 0, 40);
    attach(&l.s);
    placed p;
    memset(&p, 0, sizeof p);
    place(&p, 0, m, 240, 200, 0, 0, 32, 32, 32);
    place(&p, 1, m, 256, 300, 0, 0, 32, 32, 32);
    camera c = cam_at(250, 60, 41, 90, 0);
    uint64_t px = draw(&l.s, &p.w, &c, RENDER_PAINTER);
    assert_true(px > VIEW_W * VIEW_H);
    assert_int_equal(ST.objects_visible, 2);
    assert_true(ST.object_faces >= 2);
    check_boxes(&c, p.boxes, 2, p.id); /* no wall in front of them: painter is exact here */
    draw_exact(&l.s, &p.w, &c);
    assert_int_equal(ST.objects_visible, 2);
    unload(&l);
}

/* The work bound counts the objects; a frame given less is refused. */
static void test_work_bound(void **state)
{
    (void)state;
    loaded l;
    load_text(&l, ROOM);
    models_reset();
    uint32_t m = model_begin();
    add_box(m, 16, 16, 16, 0, 0, 0, 40);
    attach(&l.s);
    placed p;
    memset(&p, 0, sizeof p);
    for (uint32_t i = 0; i < 16; i++) place(&p, i, m, 136 + 16 * i, 250 + (i % 3) * 24, 0, 7 * i, 16, 16, 16);
    uint32_t plain = render_work_bytes(&l.s, NULL), with = render_work_bytes(&l.s, &p.w);
    assert_true(with > plain);
    world_state fewer = p.w;
    fewer.n = 8;
    assert_true(render_work_bytes(&l.s, &fewer) < with && render_work_bytes(&l.s, &fewer) > plain);
    camera c = cam_at(256, 10, 41, 90, 0);
    for (int mode = 0; mode < RENDER_MODE_COUNT; mode++) {
        render_work work = {malloc(with), with - 1};
        hal_surface surf = hal_begin_frame(HAL_PRESENT_FLIP);
        rast_target t = {&surf, ids};
        memset(ids, 0xEE, sizeof ids);
        hal_perf_reset();
        render_frame(&l.s, &p.w, &c, (render_mode)mode, &t, &work, &ST);
        if (mode == RENDER_SPANS) assert_int_equal(ST.refused, 1);
        if (ST.refused) assert_int_equal(count_kind(RAST_KIND_NONE), VIEW_W * VIEW_H);
        work.bytes = with;
        render_frame(&l.s, &p.w, &c, (render_mode)mode, &t, &work, &ST);
        assert_int_equal(ST.refused, 0);
        assert_true(count_kind(RAST_KIND_OBJECT) > 500);
        /* the static world still needs no more than before */
        work.bytes = plain;
        render_frame(&l.s, NULL, &c, (render_mode)mode, &t, &work, &ST);
        assert_int_equal(ST.refused, 0);
        free(work.mem);
    }
    /* all 16 in view at once: every face that reached the rasteriser fit */
    draw_exact(&l.s, &p.w, &c);
    assert_int_equal(ST.objects_visible, 16);
    check_boxes(&c, p.boxes, 16, p.id);
    unload(&l);
}

/* ------------------------------------------------------------ time */

static void expect_near(double got, double want, double tol, const char *what, uint32_t t)
{
    if (fabs(got - want) > tol) fprintf(stderr, "%s at t = %u: %.6f, expected %.6f\n", what, t, got, want);
    assert_true(fabs(got - want) <= tol);
}

static double yaw_diff(double a, double b)
{
    double d = fmod(a - b, 360.0);
    if (d < 0) d += 360.0;
    return d < 180.0 ? d : 360.0 - d;
}

/* obj_update's paths against their closed forms. */
static void test_paths(void **state)
{
    (void)state;
    loaded l;
    load_text(&l, ROOM);
    models_reset();
    uint32_t m = model_begin();
    add_box(m, 16, 16, 16, 0, 0, 0, 40);
    attach(&l.s);
    scn_object so[4] = {
        {m, U(256), U(256), U(8), U(30), SCN_PATH_CIRCLE, U(128), 0, 8000, 0, SCN_NONE, SCN_NONE},
        {m, U(100), U(400), 0, U(350), SCN_PATH_LINE, U(256), -U(300), 4000, U(45), SCN_NONE, SCN_NONE},
        {m, U(300), U(100), U(2), U(10), SCN_PATH_NONE, 0, 0, 0, -U(3600), SCN_NONE, SCN_NONE},
        {m, U(200), U(200), 0, 0, SCN_PATH_CIRCLE, U(100.5), 0, 3600000, U(0.25), SCN_NONE, SCN_NONE},
    };
    l.s.objects = so;
    l.s.nobjects = 4;
    uint8_t *mem = malloc(obj_state_bytes(&l.s));
    world_state w;
    assert_int_equal(obj_init(&w, &l.s, mem, obj_state_bytes(&l.s) - 1), -1);
    assert_int_equal(obj_init(&w, &l.s, mem, obj_state_bytes(&l.s)), 0);
    assert_int_equal(w.n, 4);
    static const uint32_t times[] = {0, 1, 999, 1000, 1999, 2000, 2999, 4000, 6500, 8000, 123457, 3599999, 4294967295u};
    uint32_t prev = 0;
    for (size_t k = 0; k < sizeof times / sizeof times[0]; k++) {
        uint32_t t = times[k];
        obj_update(&w, &l.s, t, t - prev, U(10), U(10));
        prev = t;
        for (int i = 0; i < 4; i++) {
            const scn_object *o = &so[i];
            double x = o->x / 65536.0, y = o->y / 65536.0, yaw = o->yaw / 65536.0 + o->spin / 65536.0 * t / 1000.0;
            if (o->path == SCN_PATH_CIRCLE) {
                double th = 360.0 * (double)(t % o->period_ms) / o->period_ms;
                x += o->pa / 65536.0 * cos(th * PI / 180);
                y += o->pa / 65536.0 * sin(th * PI / 180);
                yaw += th + 90;
            } else if (o->path == SCN_PATH_LINE) {
                double ph = (double)(t % o->period_ms) / o->period_ms, f = ph < 0.5 ? 2 * ph : 2 - 2 * ph;
                x += f * o->pa / 65536.0;
                y += f * o->pb / 65536.0;
            }
            expect_near(w.objs[i].x / 65536.0, x, 1.0 / 1024, "x", t);
            expect_near(w.objs[i].y / 65536.0, y, 1.0 / 1024, "y", t);
            assert_int_equal(w.objs[i].z, o->z);
            assert_int_equal(w.objs[i].model, o->model);
            expect_near(yaw_diff(w.objs[i].yaw_deg / 65536.0, yaw), 0, 1.0 / 4096, "yaw", t);
            assert_true(w.objs[i].yaw_deg >= 0 && w.objs[i].yaw_deg < U(360));
        }
    }
    /* exact functions of t: the same t gives the same state whatever came before */
    obj_state again[4];
    memcpy(again, w.objs, sizeof again);
    obj_update(&w, &l.s, 777, 5, 0, 0);
    obj_update(&w, &l.s, 4294967295u, 1, 0, 0);
    assert_memory_equal(again, w.objs, sizeof again);
    free(mem);
    unload(&l);
}

/* Doors: opening, waiting, closing, reopening, from the player's position. */
static void test_door_motion(void **state)
{
    (void)state;
    loaded l;
    load_text(&l, TWO_ROOMS);
    uint32_t g = make_door(&l);
    uint8_t *mem = malloc(obj_state_bytes(&l.s));
    world_state w;
    assert_int_equal(obj_init(&w, &l.s, mem, obj_state_bytes(&l.s)), 0);
    assert_int_equal(w.ceil[g], 0);
    uint32_t t = 0;
#define STEP(dt, x, y) (t += (dt), obj_update(&w, &l.s, t, (dt), U(x), U(y)))
    STEP(100, 128, 100); /* 156 units from the gap: nothing */
    assert_int_equal(w.ceil[g], 0);
    STEP(100, 128, 193); /* 63 units from its wall: opens at 128 units a second */
    assert_int_equal(w.ceil[g], U(12.8));
    for (int i = 0; i < 4; i++) STEP(100, 128, 193);
    assert_int_equal(w.ceil[g], U(64));
    STEP(100, 128, 100); /* left: keeps opening to the top */
    STEP(300, 128, 100);
    assert_int_equal(w.ceil[g], U(112));
    STEP(2000, 128, 100); /* open, waiting */
    assert_int_equal(w.ceil[g], U(112));
    STEP(1000, 128, 100); /* waited 3 s since it was full open, and 3.x since the last trigger: falls */
    assert_true(w.ceil[g] < U(112));
    STEP(500, 128, 100);
    fx_t falling = w.ceil[g];
    assert_true(falling > 0 && falling < U(112));
    STEP(100, 128, 260); /* under it: rises again */
    assert_true(w.ceil[g] > falling);
    for (int i = 0; i < 10; i++) STEP(100, 128, 260);
    assert_int_equal(w.ceil[g], U(112));
    STEP(10000, 128, 100); /* a long frame: waits, then closes completely */
    assert_int_equal(w.ceil[g], 0);
    /* frame splits do not matter */
    world_state a = w;
    uint8_t *mem2 = malloc(obj_state_bytes(&l.s));
    world_state b;
    obj_init(&b, &l.s, mem2, obj_state_bytes(&l.s));
    obj_update(&w, &l.s, 0, 250, U(128), U(230));
    obj_update(&b, &l.s, 0, 100, U(128), U(230));
    obj_update(&b, &l.s, 0, 150, U(128), U(230));
    assert_int_equal(a.ceil[g], b.ceil[g]);
    for (int i = 0; i < 50; i++) obj_update(&b, &l.s, 0, 101, U(128), U(100));
    obj_update(&w, &l.s, 0, 5050, U(128), U(100));
    assert_int_equal(w.ceil[g], b.ceil[g]);
    assert_int_equal(w.ndoors, 1);
    assert_int_equal(w.doors[0].travel_ms, b.doors[0].travel_ms); /* the only door's motion */
#undef STEP
    free(mem2);
    free(mem);
    unload(&l);
}

/* A door triggers for a player standing in its sector, however far from its
 * walls: room a made a door (ceiling 64, open 128), the player in its middle,
 * 128 units from every wall (reach: OBJ_DOOR_REACH). */
static void test_door_over_the_player(void **state)
{
    (void)state;
    loaded l;
    load_text(&l, TWO_ROOMS);
    uint32_t a = sector_named(&l, U(128), U(128));
    scn_sector *sec = (scn_sector *)(void *)&l.s.sectors[a];
    sec->flags |= SCN_SECTOR_DOOR;
    sec->ceil_h = U(64);
    sec->open_h = U(128);
    assert_true(128 > OBJ_DOOR_REACH); /* the walls are all out of reach */
    uint8_t *mem = malloc(obj_state_bytes(&l.s));
    world_state w;
    assert_int_equal(obj_init(&w, &l.s, mem, obj_state_bytes(&l.s)), 0);
    assert_int_equal(w.ceil[a], U(64));
    obj_update(&w, &l.s, 100, 100, U(128), U(128));
    assert_true(w.ceil[a] > U(64));
    free(mem);
    unload(&l);
}

/* The state keeps motion for door sectors only, in sector order: with doors at
 * sectors a (0), b (1) and gap (3), a player in a and near the gap moves those
 * two and leaves b closed, whatever slot each door has. */
static void test_door_slots(void **state)
{
    (void)state;
    loaded l;
    load_text(&l, TWO_ROOMS);
    uint32_t g = make_door(&l);
    uint32_t a = sector_named(&l, U(128), U(100)), b = sector_named(&l, U(128), U(400));
    assert_true(a < b && b < g);
    scn_sector *sa = (scn_sector *)(void *)&l.s.sectors[a], *sb = (scn_sector *)(void *)&l.s.sectors[b];
    sa->flags |= SCN_SECTOR_DOOR;
    sa->open_h = U(200);
    sb->flags |= SCN_SECTOR_DOOR;
    sb->open_h = U(200);
    uint32_t bytes = obj_state_bytes(&l.s);
    /* ceilings of the 5 sectors (24 bytes), 3 door records (24), one word of bits (8) */
    assert_int_equal(bytes, 24 + 3 * sizeof(obj_door) + 8);
    uint8_t *mem = malloc(bytes);
    world_state w;
    assert_int_equal(obj_init(&w, &l.s, mem, bytes), 0);
    assert_int_equal(w.ndoors, 3);
    for (uint32_t t = 100; t <= 500; t += 100) obj_update(&w, &l.s, t, 100, U(128), U(193));
    assert_int_equal(w.ceil[a], U(128 + 64));
    assert_int_equal(w.ceil[g], U(64));
    assert_int_equal(w.ceil[b], U(128));
    assert_int_equal(w.doors[0].travel_ms, 500);
    assert_int_equal(w.doors[1].travel_ms, 0);
    assert_int_equal(w.doors[2].travel_ms, 500);
    free(mem);
    unload(&l);
}

/* A closed door blocks walking and sight; an open one lets both through. */
static void test_door_collision(void **state)
{
    (void)state;
    loaded l;
    load_text(&l, TWO_ROOMS);
    uint32_t g = make_door(&l);
    fx_t ceil[16];
    for (uint32_t i = 0; i < l.s.nsectors; i++) ceil[i] = l.s.sectors[i].ceil_h;
    world_state w = {0, 0, ceil, 0};
    fx_t x = U(128), y = U(200), fz = 0;
    col_move(&l.s, &w, NULL, &x, &y, &fz, 0, U(200));
    assert_true(y < U(256));
    assert_false(col_line_of_sight(&l.s, &w, U(128), U(200), U(40), U(128), U(400), U(40)));
    ceil[g] = U(30); /* too low to pass */
    x = U(128), y = U(200);
    col_move(&l.s, &w, NULL, &x, &y, &fz, 0, U(200));
    assert_true(y < U(256));
    assert_true(col_line_of_sight(&l.s, &w, U(128), U(200), U(20), U(128), U(400), U(20)));
    ceil[g] = U(112);
    x = U(128), y = U(200);
    col_move(&l.s, &w, NULL, &x, &y, &fz, 0, U(200));
    assert_int_equal(y, U(400));
    assert_true(col_line_of_sight(&l.s, &w, U(128), U(200), U(40), U(128), U(400), U(40)));
    /* NULL: as compiled (closed) */
    x = U(128), y = U(200);
    col_move(&l.s, NULL, NULL, &x, &y, &fz, 0, U(200));
    assert_true(y < U(256));
    /* the camera walks through when it is open */
    cam_state cam;
    cam_start(&cam, &l.s);
    cam.view.angle_deg = U(90);
    for (int i = 0; i < 40; i++) cam_move(&cam, &l.s, &w, HAL_KEY_FORWARD, 50);
    assert_true(cam.view.y > U(300));
    unload(&l);
}

/* The engine: the world state lives in the work area, time moves the objects,
 * doors open for the walking camera, frames show them. */
static void test_engine(void **state)
{
    (void)state;
    loaded l;
    load_text(&l, TWO_ROOMS);
    engine *e = calloc(1, sizeof *e);
    hal_null_reset();
    assert_int_equal(eng_init(e, l.blob, l.len, NULL), SCENE_OK);
    /* the engine reads the blob in place: a door made in it now is the engine's too */
    uint32_t g = make_door(&l);
    assert_true(e->sc.sectors[g].flags & SCN_SECTOR_DOOR);
    uint32_t bare = eng_work_bytes(e);
    models_reset();
    uint32_t m = model_begin();
    add_box(m, 24, 24, 24, 0, 0, 0, 40);
    attach(&e->sc);
    scn_object so[2] = {
        {m, U(128), U(160), 0, 0, SCN_PATH_CIRCLE, U(40), 0, 4000, 0, SCN_NONE, SCN_NONE},
        {m, U(128), U(400), 0, 0, SCN_PATH_NONE, 0, 0, 0, U(90), SCN_NONE, SCN_NONE},
    };
    e->sc.objects = so;
    e->sc.nobjects = 2;
    uint32_t need = eng_work_bytes(e);
    assert_true(need > bare);
    assert_true(need >= obj_state_bytes(&e->sc) + render_work_bytes(&e->sc, NULL));
    uint8_t *work = malloc(need);
    assert_int_equal(eng_set_work(e, work, need - 1), -1);
    assert_int_equal(eng_set_work(e, work, need), 0);
    assert_int_equal(e->world.n, 2);
    fx_t x0 = e->world.objs[0].x;
    eng_step(e, 0, 1000);
    assert_int_equal(e->t_ms, 1000);
    assert_true(e->world.objs[0].x != x0);
    assert_int_equal(e->stats.refused, 0);
    assert_int_equal(e->stats.objects_visible, 1); /* the other is behind the closed door */
    assert_int_equal(hal_perf_event(HAL_EV_PIXELS) % 64000, 0);
    /* walk up to the door: it opens, and the second object comes into view */
    for (int i = 0; i < 60 && e->world.ceil[g] < U(112); i++) eng_step(e, HAL_KEY_FORWARD, 50);
    assert_int_equal(e->world.ceil[g], U(112));
    eng_render(e, ids);
    assert_true(count_id(RAST_ID(RAST_KIND_OBJECT, 1)) > 0);
    /* an object in the frustum: every mode that has an object pass says it ran */
    static const render_mode passes[] = {RENDER_DIRECT, RENDER_SPANS};
    for (size_t k = 0; k < sizeof passes / sizeof passes[0]; k++) {
        e->mode = passes[k];
        eng_render(e, ids);
        assert_true(count_id(RAST_ID(RAST_KIND_OBJECT, 1)) > 0);
        assert_int_equal(e->stats.object_pass, 1);
    }
    e->mode = RENDER_PAINTER;
    eng_step(e, 0, 50);
    assert_int_equal(e->stats.refused, 0);
    assert_true(e->stats.object_faces > 0);
    /* the present key steps through every present mode, one a press, and round */
    hal_present_mode first = e->present;
    uint32_t seen = 0;
    for (int i = 0; i < HAL_PRESENT_COUNT; i++) {
        seen |= 1u << e->present;
        eng_step(e, HAL_KEY_NEXT_PRESENT, 0);
    }
    assert_int_equal(seen, (1u << HAL_PRESENT_COUNT) - 1);
    assert_int_equal(e->present, first);
    free(work);
    free(e);
    unload(&l);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_resting_on_floor),
        cmocka_unit_test(test_object_hides_wall),
        cmocka_unit_test(test_object_against_the_void),
        cmocka_unit_test(test_object_behind_wall),
        cmocka_unit_test(test_two_objects_overlap),
        cmocka_unit_test(test_straddle),
        cmocka_unit_test(test_near_and_offscreen),
        cmocka_unit_test(test_interpenetrating),
        cmocka_unit_test(test_wide_products),
        cmocka_unit_test(test_inverse_depth_order),
        cmocka_unit_test(test_abutting_ties),
        cmocka_unit_test(test_painter),
        cmocka_unit_test(test_work_bound),
        cmocka_unit_test(test_paths),
        cmocka_unit_test(test_door_motion),
        cmocka_unit_test(test_door_over_the_player),
        cmocka_unit_test(test_door_slots),
        cmocka_unit_test(test_door_collision),
        cmocka_unit_test(test_engine),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
