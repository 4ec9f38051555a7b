/* needs.c - what a compiled scene needs of a renderer: its features and the most
 * work one frame can take, for every camera (docs/needs.md has the proof).
 *
 * It reads the compiled form, exactly as the renderer will: split segs, leaf
 * polygons with T-junction points, the tree's partitions. Doubles are fine here
 * (the compiler runs on the host); every test is made with a slack far larger
 * than their rounding and than the renderer's own rounding, so the bounds can
 * only be too large, never too small. */
#include "needs.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "raster.h"
#include "scene.h"

/* Slack of every side test, in map units: the renderer's side tests round the
 * eye to 1/8192 unit and seg directions to 2 raw units; 1/16 unit covers both
 * many times over. */
#define SLACK (1.0 / 16.0)
/* Every camera the renderer accepts lies in this square (16.16 positions). */
#define BOX 32768.0
#define CLIP_EXTRA 5u /* vertices clipping can add: one per frustum plane (clip.h) */
#define WALL_EDGES (4u + CLIP_EXTRA)
#define REGION_MAX 1024 /* vertices of a leaf's region: the box's 4 + one per partition */

typedef struct {
    double x[REGION_MAX], y[REGION_MAX];
    int n;
} region;

static double unit(int32_t raw)
{
    return raw / 65536.0;
}

/* Keep the part of r where side(p) <= SLACK, side = signed distance from the line
 * through (px, py) along (dx, dy), positive on its left (sign = +1) or right (-1). */
static void clip_region(region *r, double px, double py, double dx, double dy, int sign)
{
    double len = sqrt(dx * dx + dy * dy);
    double d[REGION_MAX];
    region out;
    out.n = 0;
    for (int i = 0; i < r->n; i++) d[i] = sign * (dx * (r->y[i] - py) - dy * (r->x[i] - px)) / len - SLACK;
    for (int i = 0; i < r->n && out.n < REGION_MAX - 1; i++) {
        int j = (i + 1 == r->n) ? 0 : i + 1;
        if (d[i] <= 0) {
            out.x[out.n] = r->x[i];
            out.y[out.n++] = r->y[i];
        }
        if ((d[i] <= 0) != (d[j] <= 0)) {
            double t = d[i] / (d[i] - d[j]);
            out.x[out.n] = r->x[i] + t * (r->x[j] - r->x[i]);
            out.y[out.n++] = r->y[i] + t * (r->y[j] - r->y[i]);
        }
    }
    *r = out;
}

/* Wall polygons seg g can give, over every door state: one-sided, the middle;
 * two-sided, an upper part if the back ceiling can be below the front one and
 * a lower part if the back floor is above the front one (surfaces.c). */
static uint32_t wall_parts(const scene *s, const scn_seg *g)
{
    const scn_line *l = &s->lines[g->line];
    uint32_t fi = l->sector[g->side], bi = l->sector[g->side ^ 1u];
    const scn_sector *f = &s->sectors[fi];
    if (bi == SCN_NONE) return f->open_h > f->floor_h;
    if (bi == fi) return 0;
    const scn_sector *b = &s->sectors[bi];
    return (uint32_t)(b->ceil_h < f->open_h) + (uint32_t)(b->floor_h > f->floor_h);
}

/* Can the eye be in front of seg g anywhere in region r? */
static int may_face(const scene *s, const scn_seg *g, const region *r)
{
    const scn_vertex *a = &s->verts[g->v1], *b = &s->verts[g->v2];
    double ax = unit(a->x), ay = unit(a->y), dx = unit(b->x) - ax, dy = unit(b->y) - ay;
    double len = sqrt(dx * dx + dy * dy);
    if (len == 0) return 1; /* the renderer's test is then never true; count it anyway */
    for (int i = 0; i < r->n; i++) {
        double in_front = -(dx * (r->y[i] - ay) - dy * (r->x[i] - ax)) / len; /* right of a -> b */
        if (in_front > -SLACK) return 1;
    }
    return 0;
}

typedef struct {
    const scene *s;
    const uint32_t *parts; /* per seg */
    needs_report *rep;
} walls_ctx;

static void leaf_walls(walls_ctx *c, uint32_t leaf, const region *r)
{
    const scene *s = c->s;
    uint32_t edges = 0, surfs = 0;
    for (uint32_t g = 0; g < s->nsegs; g++) {
        if (!c->parts[g] || !may_face(s, &s->segs[g], r)) continue;
        edges += c->parts[g] * WALL_EDGES;
        surfs += c->parts[g];
    }
    if (edges > c->rep->wall_edges) {
        c->rep->wall_edges = edges;
        c->rep->worst_leaf = leaf;
    }
    if (surfs > c->rep->wall_surfaces) c->rep->wall_surfaces = surfs;
}

/* Depth-first over the tree, each child with its region (the parent's, cut by
 * the partition with slack on both sides: a point near a partition is in both). */
static int walk_regions(walls_ctx *c)
{
    const scene *s = c->s;
    uint32_t depth = s->hdr->max_depth + 2;
    uint32_t *stack = malloc(sizeof(uint32_t) * depth);
    region *regions = malloc(sizeof(region) * depth);
    if (!stack || !regions) {
        free(stack);
        free(regions);
        return -1;
    }
    int sp = 0;
    region *r0 = &regions[0];
    r0->n = 4;
    r0->x[0] = -BOX, r0->y[0] = -BOX;
    r0->x[1] = BOX, r0->y[1] = -BOX;
    r0->x[2] = BOX, r0->y[2] = BOX;
    r0->x[3] = -BOX, r0->y[3] = BOX;
    stack[sp++] = s->root;
    while (sp > 0) {
        sp--;
        uint32_t n = stack[sp];
        region here = regions[sp];
        if (n & SCN_LEAF_BIT) {
            if (here.n >= 3) leaf_walls(c, n & ~SCN_LEAF_BIT, &here);
            continue;
        }
        const scn_node *nd = &s->nodes[n];
        double px = unit(nd->x), py = unit(nd->y), dx = unit(nd->dx), dy = unit(nd->dy);
        for (int side = 0; side < 2; side++) {
            regions[sp] = here;
            /* front (side 0) is the right of the direction: keep left distance <= slack */
            clip_region(&regions[sp], px, py, dx, dy, side == 0 ? 1 : -1);
            stack[sp++] = nd->child[side];
        }
    }
    free(stack);
    free(regions);
    return 0;
}

/* ---- floors and ceilings: a sweep over the eye's height ------------------- */

typedef struct {
    int64_t h;
    uint32_t edges;
} height_w;

static int by_height(const void *a, const void *b)
{
    int64_t x = ((const height_w *)a)->h, y = ((const height_w *)b)->h;
    return (x > y) - (x < y);
}

static int by_value(const void *a, const void *b)
{
    int64_t x = *(const int64_t *)a, y = *(const int64_t *)b;
    return (x > y) - (x < y);
}

/* A floor is drawn for an eye above it (cz > floor), a ceiling for an eye below
 * it (cz < ceiling, whose highest is open_h). Over every integer eye height,
 * the most edges (or, with unit weights, polygons) at once. */
static uint32_t plane_sweep(const scene *s, int unit_weight)
{
    uint32_t n = 0;
    for (uint32_t i = 0; i < s->nleaves; i++)
        if (s->leaves[i].sector != SCN_NONE && s->leaves[i].num_pverts >= 3) n++;
    if (n == 0) return 0;
    height_w *fl = malloc(sizeof *fl * n), *ce = malloc(sizeof *ce * n);
    int64_t *cand = malloc(sizeof *cand * (2 * (size_t)n + 1));
    if (!fl || !ce || !cand) {
        free(fl), free(ce), free(cand);
        return UINT32_MAX;
    }
    uint32_t k = 0, nc = 0;
    for (uint32_t i = 0; i < s->nleaves; i++) {
        const scn_leaf *f = &s->leaves[i];
        if (f->sector == SCN_NONE || f->num_pverts < 3) continue;
        const scn_sector *sec = &s->sectors[f->sector];
        uint32_t w = unit_weight ? 1u : f->num_pverts + CLIP_EXTRA;
        fl[k] = (height_w){sec->floor_h, w};
        ce[k] = (height_w){sec->open_h, w};
        cand[nc++] = (int64_t)sec->floor_h + 1; /* the count of floors goes up here */
        cand[nc++] = sec->open_h;               /* the count of ceilings goes down here */
        k++;
    }
    cand[nc++] = INT64_MIN / 2;
    qsort(fl, n, sizeof *fl, by_height);
    qsort(ce, n, sizeof *ce, by_height);
    qsort(cand, nc, sizeof *cand, by_value);
    uint64_t best = 0, floors = 0, ceilings = 0;
    for (uint32_t i = 0; i < n; i++) ceilings += ce[i].edges;
    uint32_t fi = 0, ci = 0;
    for (uint32_t i = 0; i < nc; i++) {
        int64_t z = cand[i];
        while (fi < n && fl[fi].h < z) floors += fl[fi++].edges;    /* floor < z */
        while (ci < n && ce[ci].h <= z) ceilings -= ce[ci++].edges; /* ceiling > z stays */
        if (floors + ceilings > best) best = floors + ceilings;
    }
    free(fl), free(ce), free(cand);
    return best > UINT32_MAX ? UINT32_MAX : (uint32_t)best;
}

/* ---- the whole analysis ------------------------------------------------------ */

static uint32_t sat_add(uint32_t a, uint32_t b)
{
    return a > UINT32_MAX - b ? UINT32_MAX : a + b;
}

int needs_analyse(const scene *s, int look, needs_report *r)
{
    memset(r, 0, sizeof *r);
    scn_needs *n = &r->needs;
    n->features = scene_derived_features(s);
    if (look) n->features |= SCN_NEED_LOOK;
    scene_static_bounds(s, n);
    /* every polygon at once: the bound a renderer must use without this analysis */
    uint64_t all_e, all_s;
    scene_all_polygons(s, &all_e, &all_s);
    r->all_edges = all_e > UINT32_MAX ? UINT32_MAX : (uint32_t)all_e;
    r->all_surfaces = all_s > UINT32_MAX ? UINT32_MAX : (uint32_t)all_s;

    uint32_t *parts = calloc(s->nsegs ? s->nsegs : 1, sizeof *parts);
    if (!parts) return -1;
    for (uint32_t g = 0; g < s->nsegs; g++) parts[g] = wall_parts(s, &s->segs[g]);
    walls_ctx c = {s, parts, r};
    r->worst_leaf = SCN_NONE;
    int rc = s->nleaves ? walk_regions(&c) : 0;
    free(parts);
    if (rc) return -1;
    r->plane_edges = plane_sweep(s, 0);
    r->plane_surfaces = plane_sweep(s, 1);
    if (r->plane_edges == UINT32_MAX || r->plane_surfaces == UINT32_MAX) return -1;
    n->edges = sat_add(r->wall_edges, r->plane_edges);
    n->surfaces = sat_add(r->wall_surfaces, r->plane_surfaces);
    /* never above the plain count (the slack can only add what exists) */
    if (n->edges > r->all_edges) n->edges = r->all_edges;
    if (n->surfaces > r->all_surfaces) n->surfaces = r->all_surfaces;
    /* y-clipping: any polygon at all can be seen from just beside it, where it
     * crosses the top or bottom edge of the screen */
    if (n->surfaces > 0) n->features |= SCN_NEED_YCLIP;
    return 0;
}
