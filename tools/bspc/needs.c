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

/* Margin of the walk's early decisions, in map units: far above the rounding
 * of the region's vertices (each a convex combination of its parent's, within
 * 1e-9 unit after the deepest tree) and of the side test itself. */
#define DECIDE_EPS (1.0 / 65536.0)

/* Keep the part of in where side(p) <= SLACK, side = signed distance from the line
 * through (px, py) along (dx, dy), positive on its left (sign = +1) or right (-1). */
static void clip_region(const region *in, region *out, double px, double py, double dx, double dy, int sign)
{
    double len = sqrt(dx * dx + dy * dy);
    double d[REGION_MAX];
    out->n = 0;
    for (int i = 0; i < in->n; i++) d[i] = sign * (dx * (in->y[i] - py) - dy * (in->x[i] - px)) / len - SLACK;
    for (int i = 0; i < in->n && out->n < REGION_MAX - 1; i++) {
        int j = (i + 1 == in->n) ? 0 : i + 1;
        if (d[i] <= 0) {
            out->x[out->n] = in->x[i];
            out->y[out->n++] = in->y[i];
        }
        if ((d[i] <= 0) != (d[j] <= 0)) {
            double t = d[i] / (d[i] - d[j]);
            out->x[out->n] = in->x[i] + t * (in->x[j] - in->x[i]);
            out->y[out->n++] = in->y[i] + t * (in->y[j] - in->y[i]);
        }
    }
}

static void copy_region(region *dst, const region *src)
{
    dst->n = src->n;
    memcpy(dst->x, src->x, sizeof dst->x[0] * (size_t)src->n);
    memcpy(dst->y, src->y, sizeof dst->y[0] * (size_t)src->n);
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

/* A seg's line in map units: from (ax, ay) along (dx, dy) of length len. */
typedef struct {
    double ax, ay, dx, dy, len;
    double nx, ny, c; /* in front by about nx * x + ny * y + c (unit normal): for decide */
} seg_line;

static seg_line line_of(const scene *s, const scn_seg *g)
{
    const scn_vertex *a = &s->verts[g->v1], *b = &s->verts[g->v2];
    seg_line l;
    l.ax = unit(a->x), l.ay = unit(a->y), l.dx = unit(b->x) - l.ax, l.dy = unit(b->y) - l.ay;
    l.len = sqrt(l.dx * l.dx + l.dy * l.dy);
    l.nx = l.len > 0 ? l.dy / l.len : 0;
    l.ny = l.len > 0 ? -l.dx / l.len : 0;
    l.c = -(l.nx * l.ax + l.ny * l.ay);
    return l;
}

/* How far vertex i of r is in front of (right of) the seg's line. */
static double in_front(const seg_line *l, const region *r, int i)
{
    return -(l->dx * (r->y[i] - l->ay) - l->dy * (r->x[i] - l->ax)) / l->len;
}

/* Can the eye be in front of the seg anywhere in region r? (len > 0) */
static int may_face(const seg_line *l, const region *r)
{
    for (int i = 0; i < r->n; i++)
        if (in_front(l, r, i) > -SLACK) return 1;
    return 0;
}

/* What the leaves inside region r will answer for the seg: every leaf region
 * below lies within r's convex hull, so if all of r is in front (by more than
 * the margin) every leaf's may_face is 1, if all of r is behind every one is 0. */
enum { SEG_BEHIND, SEG_UNDECIDED, SEG_FACING };

static int decide(const seg_line *l, const region *r)
{
    int behind = 0, front = 0;
    for (int i = 0; i < r->n; i++) {
        double f = l->nx * r->x[i] + l->ny * r->y[i] + l->c;
        if (f >= -SLACK - DECIDE_EPS) front = 1;  /* not wholly behind */
        if (f <= -SLACK + DECIDE_EPS) behind = 1; /* not wholly in front */
        if (front && behind) return SEG_UNDECIDED;
    }
    return front ? SEG_FACING : SEG_BEHIND;
}

typedef struct {
    const scene *s;
    const uint32_t *parts; /* per seg */
    const seg_line *lines; /* per seg */
    uint32_t *list;        /* the undecided segs of the nodes on the path, one block each */
    needs_report *rep;
} walls_ctx;

/* One entry of the walk's stack: a node, its region, the undecided segs of its
 * parent (list[from .. from+count)) and the parts of those already facing. */
typedef struct {
    uint32_t node, from, count;
    uint32_t edges, surfs;   /* of the segs facing the whole region */
    uint64_t more_e, more_s; /* of the undecided ones: what a leaf below can add at most */
} walk_item;

/* Can a leaf below beat the most found so far? (If not, the subtree is skipped:
 * the leaves are met in the same order, so the result and worst_leaf stay.) */
static int may_beat(const walls_ctx *c, const walk_item *it)
{
    return it->edges + it->more_e > c->rep->wall_edges || it->surfs + it->more_s > c->rep->wall_surfaces;
}

static void leaf_walls(walls_ctx *c, uint32_t leaf, const region *r, const walk_item *it)
{
    uint32_t edges = it->edges, surfs = it->surfs;
    for (uint32_t k = 0; k < it->count; k++) {
        uint32_t g = c->list[it->from + k];
        int d = decide(&c->lines[g], r);
        if (d == SEG_BEHIND || (d == SEG_UNDECIDED && !may_face(&c->lines[g], r))) continue;
        edges += c->parts[g] * WALL_EDGES;
        surfs += c->parts[g];
    }
    if (edges > c->rep->wall_edges) {
        c->rep->wall_edges = edges;
        c->rep->worst_leaf = leaf;
    }
    if (surfs > c->rep->wall_surfaces) c->rep->wall_surfaces = surfs;
}

/* The parent's undecided segs judged against this node's region: those facing
 * all of it join its sums, those behind all of it leave, the rest are copied to
 * list[*top ..] for its children. */
static walk_item narrow(walls_ctx *c, const walk_item *it, const region *r, uint32_t *top)
{
    walk_item out = {it->node, *top, 0, it->edges, it->surfs, 0, 0};
    for (uint32_t k = 0; k < it->count; k++) {
        uint32_t g = c->list[it->from + k];
        int d = decide(&c->lines[g], r);
        if (d == SEG_FACING) {
            out.edges += c->parts[g] * WALL_EDGES;
            out.surfs += c->parts[g];
        } else if (d == SEG_UNDECIDED) {
            c->list[*top + out.count++] = g;
            out.more_e += c->parts[g] * WALL_EDGES;
            out.more_s += c->parts[g];
        }
    }
    *top += out.count;
    return out;
}

/* Depth-first over the tree, each child with its region (the parent's, cut by
 * the partition with slack on both sides: a point near a partition is in both).
 * Each leaf counts the segs its region may face; the segs decided for a whole
 * subtree are settled at its root, so a leaf tests only those whose line passes
 * near its region. */
static int walk_regions(walls_ctx *c)
{
    const scene *s = c->s;
    uint32_t depth = s->hdr->max_depth + 2;
    walk_item *stack = malloc(sizeof(walk_item) * depth);
    region *regions = malloc(sizeof(region) * depth);
    region *here = malloc(sizeof(region));
    if (!stack || !regions || !here) {
        free(stack);
        free(regions);
        free(here);
        return -1;
    }
    /* the root's list: every seg with parts (a zero-length seg always counts) */
    walk_item root = {s->root, 0, 0, 0, 0, 0, 0};
    for (uint32_t g = 0; g < s->nsegs; g++) {
        if (!c->parts[g]) continue;
        if (c->lines[g].len == 0) {
            root.edges += c->parts[g] * WALL_EDGES;
            root.surfs += c->parts[g];
        } else {
            c->list[root.count++] = g;
            root.more_e += c->parts[g] * WALL_EDGES;
            root.more_s += c->parts[g];
        }
    }
    int sp = 0;
    region *r0 = &regions[0];
    r0->n = 4;
    r0->x[0] = -BOX, r0->y[0] = -BOX;
    r0->x[1] = BOX, r0->y[1] = -BOX;
    r0->x[2] = BOX, r0->y[2] = BOX;
    r0->x[3] = -BOX, r0->y[3] = BOX;
    stack[sp++] = root;
    while (sp > 0) {
        sp--;
        walk_item it = stack[sp];
        uint32_t n = it.node, top = it.from + it.count; /* blocks above belong to finished subtrees */
        if (!may_beat(c, &it)) continue;
        copy_region(here, &regions[sp]);
        if (n & SCN_LEAF_BIT) {
            if (here->n >= 3) leaf_walls(c, n & ~SCN_LEAF_BIT, here, &it);
            continue;
        }
        walk_item mine = narrow(c, &it, here, &top);
        if (!may_beat(c, &mine)) continue;
        const scn_node *nd = &s->nodes[n];
        double px = unit(nd->x), py = unit(nd->y), dx = unit(nd->dx), dy = unit(nd->dy);
        for (int side = 0; side < 2; side++) {
            /* front (side 0) is the right of the direction: keep left distance <= slack */
            clip_region(here, &regions[sp], px, py, dx, dy, side == 0 ? 1 : -1);
            stack[sp] = mine;
            stack[sp++].node = nd->child[side];
        }
    }
    free(stack);
    free(regions);
    free(here);
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

    size_t ns = s->nsegs ? s->nsegs : 1, depth = (size_t)s->hdr->max_depth + 3;
    uint32_t *parts = calloc(ns, sizeof *parts);
    seg_line *lines = malloc(ns * sizeof *lines);
    uint32_t *list = malloc(ns * depth * sizeof *list); /* a block per node of a path, each <= nsegs */
    int rc = -1;
    if (parts && lines && list) {
        for (uint32_t g = 0; g < s->nsegs; g++) {
            parts[g] = wall_parts(s, &s->segs[g]);
            lines[g] = line_of(s, &s->segs[g]);
        }
        walls_ctx c = {s, parts, lines, list, r};
        r->worst_leaf = SCN_NONE;
        rc = s->nleaves ? walk_regions(&c) : 0;
    }
    free(parts);
    free(lines);
    free(list);
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
