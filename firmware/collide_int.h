/* collide_int.h - what the parts of the collision code share (prefix colg_):
 * the 1/4096-unit grid, exact segment and circle geometry, and the box walk of
 * the tree that finds candidate segs. Included by collide.c (moving),
 * collide_geom.c and collide_sight.c only; collide.h is the public API.
 *
 * Ranges (see collide_geom.c): grid coordinates below 2^27 in magnitude,
 * products of differences below 2^57, so int64 holds them; a product of
 * products goes through the exact 128-bit w128_sign_diff().
 */
#ifndef COLLIDE_INT_H
#define COLLIDE_INT_H

#include <stdint.h>

#include "bsp_walk.h"
#include "fixed.h"
#include "scene.h"
#include "wide128.h"

#define G_SHIFT 4                                      /* grid = 16.16 >> 4: 1/4096 unit */
#define WORLD_RAW ((int64_t)SCN_COORD_MAX << FX_SHIFT) /* positions are clamped to +-this */
#define UNIT_SHIFT 30                                  /* unit normals are 2.30 */

/* A point on the 1/4096-unit grid. */
typedef struct {
    int64_t x, y; /* grid units, |x|, |y| < 2^27 */
} grid_pt;

/* The map box a tree query covers: leaves under node boxes that overlap it. */
typedef struct {
    int64_t x0, y0, x1, y1; /* 16.16, inclusive */
} query_box;

/* inline: called per candidate seg in every check, and kept inlined as they
 * were when all of this was one file */
static inline int64_t min64(int64_t a, int64_t b)
{
    return a < b ? a : b;
}
static inline int64_t max64(int64_t a, int64_t b)
{
    return a > b ? a : b;
}
static inline int64_t clamp64(int64_t v, int64_t lo, int64_t hi)
{
    return v < lo ? lo : (v > hi ? hi : v);
}
static inline int64_t clampw(int64_t v)
{
    return clamp64(v, -WORLD_RAW, WORLD_RAW);
}
static inline int sgn64(int64_t v)
{
    return (v > 0) - (v < 0);
}

static inline grid_pt to_grid(int64_t x, int64_t y)
{
    grid_pt p = {fx_asr64(x, G_SHIFT), fx_asr64(y, G_SHIFT)};
    return p;
}

static inline grid_pt vert(const scene *s, uint32_t v)
{
    return to_grid(s->verts[v].x, s->verts[v].y);
}

/* (b - a) x (p - a): > 0 when p is left of a->b (behind a seg), < 0 right (in front). */
static inline int64_t orient(grid_pt a, grid_pt b, grid_pt p)
{
    return (b.x - a.x) * (p.y - a.y) - (b.y - a.y) * (p.x - a.x);
}


/* 1 if the distance from p to the closed segment ab is below r (r2 = r*r, r < 2^23). */
int colg_near_seg(grid_pt p, grid_pt a, grid_pt b, int64_t r, int64_t r2);

/* Distance from p to the closed segment ab in grid units, rounded down. */
int64_t colg_dist_seg(grid_pt p, grid_pt a, grid_pt b);

/* 1 if the closed segments pq and ab share a point. */
int colg_seg_cross(grid_pt p, grid_pt q, grid_pt a, grid_pt b);

/* 1 if a circle of radius r moving along pq comes nearer than r to segment ab. */
int colg_sweep_near(grid_pt p, grid_pt q, grid_pt a, grid_pt b, int64_t r, int64_t r2);

/* The unit normal (2.30) of segment ab at its point nearest p, pointing at p;
 * 0 if there is none. */
int colg_seg_normal(grid_pt p, grid_pt a, grid_pt b, int32_t *nx, int32_t *ny);

/* Visit every leaf under a node box that overlaps b (and, with line, that the
 * line through line[0], line[1] meets), child 0 first. Returns 1 if fn stopped
 * the walk. */
int colg_walk_leaves(const scene *s, const query_box *b, const grid_pt *line, walk_visit fn, void *ctx);

#endif
