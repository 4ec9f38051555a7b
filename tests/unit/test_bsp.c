/* test_bsp.c - unit tests of the BSP compiler (tools/bspc) through its library API:
 * invariants of the compiled blob on small text scenes and on freedoom2.wad:MAP01,
 * and the error messages for bad scenes.
 *
 * Invariants checked on every blob (check_blob):
 *   header, section bounds and CRC; every node and leaf reached once from the root;
 *   every seg on the correct side of every partition on its leaf's root path;
 *   leaf polygons convex and counter-clockwise, every seg end a vertex of its
 *   leaf's polygon; the segs of each linedef side chain from its start to its end
 *   with no gap or overlap and their lengths sum to the linedef's; no zero-length
 *   seg; no vertex on the interior of a seg; no polygon vertex on the interior of
 *   another leaf polygon's edge; node boxes hold everything below them.
 * Tolerances are in raw 16.16 units (1/65536 map unit): TOL for "on a line".
 *
 * Objects and doors (docs/objects.md): models of text scenes compile to the
 * vertices, faces, colours and bounds the contract defines; objects land on the
 * floor; doors carry their open ceiling; freedoom2.wad:MAP01's things and door
 * sectors are found as counted here from its lumps; every bad statement is
 * refused with its line.
 *
 * Build: gcc -std=c11 -Ifirmware -Itools/bspc tests/unit/test_bsp.c, every
 * tools/bspc C file but main.c, firmware/crc32.c, -lcmocka -lm; run from the
 * repository root (it reads tests/scenes/default.scene).
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
#include "crc32.h"
#include "scene.h"
#include "scene_format.h"
#include "scene_fixture.h"

__extension__ typedef __int128 i128;

#define TOL 8 /* raw units */

/* ------------------------------------------------------------ blob view */

typedef struct {
    scn_header h;
    scn_vertex *v;
    scn_sector *sec;
    scn_line *ln;
    scn_seg *seg;
    scn_node *node;
    scn_leaf *leaf;
    scn_vertex *pv;
    uint32_t nv, nsec, nln, nseg, nnode, nleaf, npv;
} view;

static void *section(const uint8_t *b, size_t len, const scn_header *h, int k, size_t rec)
{
    const scn_section *s = &h->sec[k];
    assert_true(s->offset % 4 == 0);
    assert_true((uint64_t)s->offset + (uint64_t)s->count * rec <= len);
    void *p = malloc((size_t)s->count * rec + 1);
    assert_non_null(p);
    memcpy(p, b + s->offset, (size_t)s->count * rec);
    return p;
}

static void view_open(view *w, const uint8_t *b, size_t len)
{
    assert_true(len >= sizeof(scn_header));
    memcpy(&w->h, b, sizeof w->h);
    assert_int_equal(w->h.magic, SCN_MAGIC);
    assert_int_equal(w->h.version, SCN_VERSION);
    assert_int_equal(w->h.header_bytes, sizeof(scn_header));
    assert_int_equal(w->h.total_bytes, len);
    assert_int_equal(w->h.crc32, crc_update(0, b + 16, len - 16));
    w->v = section(b, len, &w->h, SCN_SEC_VERTICES, sizeof(scn_vertex));
    w->sec = section(b, len, &w->h, SCN_SEC_SECTORS, sizeof(scn_sector));
    w->ln = section(b, len, &w->h, SCN_SEC_LINES, sizeof(scn_line));
    w->seg = section(b, len, &w->h, SCN_SEC_SEGS, sizeof(scn_seg));
    w->node = section(b, len, &w->h, SCN_SEC_NODES, sizeof(scn_node));
    w->leaf = section(b, len, &w->h, SCN_SEC_LEAVES, sizeof(scn_leaf));
    w->pv = section(b, len, &w->h, SCN_SEC_PVERTS, sizeof(scn_vertex));
    assert_int_equal(w->h.sec[SCN_SEC_PALETTE].count, 256);
    assert_true(w->h.sec[SCN_SEC_PALETTE].offset + 768 <= len);
    w->nv = w->h.sec[SCN_SEC_VERTICES].count;
    w->nsec = w->h.sec[SCN_SEC_SECTORS].count;
    w->nln = w->h.sec[SCN_SEC_LINES].count;
    w->nseg = w->h.sec[SCN_SEC_SEGS].count;
    w->nnode = w->h.sec[SCN_SEC_NODES].count;
    w->nleaf = w->h.sec[SCN_SEC_LEAVES].count;
    w->npv = w->h.sec[SCN_SEC_PVERTS].count;
}

static void view_close(view *w)
{
    free(w->v);
    free(w->sec);
    free(w->ln);
    free(w->seg);
    free(w->node);
    free(w->leaf);
    free(w->pv);
}

/* ------------------------------------------------------------ geometry */

static i128 cross3(int64_t ax, int64_t ay, int64_t bx, int64_t by, int64_t px, int64_t py)
{
    return (i128)(bx - ax) * (py - ay) - (i128)(by - ay) * (px - ax);
}

/* signed distance (raw units) of p from the node's partition, > 0 in front */
static double node_dist(const scn_node *n, int64_t px, int64_t py)
{
    i128 c = (i128)(px - n->x) * n->dy - (i128)(py - n->y) * n->dx;
    return (double)c / sqrt((double)n->dx * n->dx + (double)n->dy * n->dy);
}

/* is p strictly inside segment a-b, within TOL of it? */
static int on_interior(int64_t ax, int64_t ay, int64_t bx, int64_t by, int64_t px, int64_t py)
{
    if ((px == ax && py == ay) || (px == bx && py == by)) return 0;
    double len = sqrt((double)(bx - ax) * (bx - ax) + (double)(by - ay) * (by - ay));
    if (len == 0) return 0;
    double d = fabs((double)cross3(ax, ay, bx, by, px, py)) / len;
    if (d > TOL) return 0;
    i128 along = (i128)(px - ax) * (bx - ax) + (i128)(py - ay) * (by - ay);
    i128 len2 = (i128)(bx - ax) * (bx - ax) + (i128)(by - ay) * (by - ay);
    return along > 0 && along < len2;
}

static double seglen(const view *w, uint32_t a, uint32_t b)
{
    double dx = (double)w->v[b].x - w->v[a].x, dy = (double)w->v[b].y - w->v[a].y;
    return sqrt(dx * dx + dy * dy) / 65536.0;
}

/* ------------------------------------------------------------ invariants */

typedef struct {
    uint32_t node;
    int side;
} step;

static void check_leaf_sides(const view *w, uint32_t li, const step *path, uint32_t depth)
{
    const scn_leaf *L = &w->leaf[li];
    for (uint32_t k = 0; k < L->num_segs; k++) {
        const scn_seg *g = &w->seg[L->first_seg + k];
        uint32_t ends[2] = {g->v1, g->v2};
        for (uint32_t d = 0; d < depth; d++) {
            const scn_node *n = &w->node[path[d].node];
            for (int e = 0; e < 2; e++) {
                double s = node_dist(n, w->v[ends[e]].x, w->v[ends[e]].y);
                if (path[d].side == 0)
                    assert_true(s >= -TOL);
                else
                    assert_true(s <= TOL);
            }
        }
    }
    /* the floor polygon is on the right side too */
    for (uint32_t k = 0; k < L->num_pverts; k++) {
        const scn_vertex *p = &w->pv[L->first_pvert + k];
        for (uint32_t d = 0; d < depth; d++) {
            double s = node_dist(&w->node[path[d].node], p->x, p->y);
            if (path[d].side == 0)
                assert_true(s >= -TOL);
            else
                assert_true(s <= TOL);
        }
    }
}

static void bbox_holds(const int32_t box[4], int64_t x, int64_t y)
{
    assert_true(y <= box[0] && y >= box[1] && x >= box[2] && x <= box[3]);
}

/* walks the tree; checks sides, reachability, depth and node boxes */
static void check_tree(const view *w)
{
    uint8_t *seen_node = calloc(w->nnode + 1, 1), *seen_leaf = calloc(w->nleaf + 1, 1);
    step *path = calloc(SCN_MAX_DEPTH + 2, sizeof *path);
    assert_true(seen_node && seen_leaf && path);
    /* iterative DFS: stack of (child ref, depth, which side of the parent) */
    typedef struct {
        uint32_t ref, depth;
        int side;
    } item;
    item *st = calloc((size_t)w->nnode * 2 + 4, sizeof *st);
    assert_non_null(st);
    uint32_t sn = 0, maxd = 0;
    st[sn++] = (item){w->h.root, 0, 0};
    while (sn) {
        item it = st[--sn];
        if (it.depth > 0) path[it.depth - 1].side = it.side;
        if (it.ref & SCN_LEAF_BIT) {
            uint32_t li = it.ref & ~SCN_LEAF_BIT;
            assert_true(li < w->nleaf);
            assert_false(seen_leaf[li]);
            seen_leaf[li] = 1;
            if (it.depth > maxd) maxd = it.depth;
            check_leaf_sides(w, li, path, it.depth);
            continue;
        }
        assert_true(it.ref < w->nnode);
        assert_false(seen_node[it.ref]);
        seen_node[it.ref] = 1;
        assert_true(it.depth < SCN_MAX_DEPTH);
        path[it.depth].node = it.ref;
        const scn_node *n = &w->node[it.ref];
        assert_false(n->dx == 0 && n->dy == 0);
        st[sn++] = (item){n->child[1], it.depth + 1, 1};
        st[sn++] = (item){n->child[0], it.depth + 1, 0};
    }
    for (uint32_t i = 0; i < w->nnode; i++) assert_true(seen_node[i]);
    for (uint32_t i = 0; i < w->nleaf; i++) assert_true(seen_leaf[i]);
    assert_int_equal(maxd, w->h.max_depth);
    assert_true(maxd <= SCN_MAX_DEPTH);

    /* node boxes: a leaf child's box holds its segs and polygon */
    for (uint32_t i = 0; i < w->nnode; i++)
        for (int c = 0; c < 2; c++) {
            uint32_t ref = w->node[i].child[c];
            if (!(ref & SCN_LEAF_BIT)) continue;
            const scn_leaf *L = &w->leaf[ref & ~SCN_LEAF_BIT];
            for (uint32_t k = 0; k < L->num_segs; k++) {
                const scn_seg *g = &w->seg[L->first_seg + k];
                bbox_holds(w->node[i].bbox[c], w->v[g->v1].x, w->v[g->v1].y);
                bbox_holds(w->node[i].bbox[c], w->v[g->v2].x, w->v[g->v2].y);
            }
            for (uint32_t k = 0; k < L->num_pverts; k++)
                bbox_holds(w->node[i].bbox[c], w->pv[L->first_pvert + k].x, w->pv[L->first_pvert + k].y);
        }
    free(st);
    free(path);
    free(seen_node);
    free(seen_leaf);
}

static void check_leaves(const view *w)
{
    uint32_t segs_seen = 0;
    for (uint32_t li = 0; li < w->nleaf; li++) {
        const scn_leaf *L = &w->leaf[li];
        assert_true(L->num_segs > 0);
        assert_int_equal(L->first_seg, segs_seen);
        segs_seen += L->num_segs;
        assert_true((uint64_t)L->first_pvert + L->num_pverts <= w->npv);
        assert_true(L->num_pverts == 0 || L->num_pverts >= 3);
        /* the leaf's sector faces at least one of its segs */
        int faced = 0;
        for (uint32_t k = 0; k < L->num_segs; k++) {
            const scn_seg *g = &w->seg[L->first_seg + k];
            if (w->ln[g->line].sector[g->side] == L->sector) faced = 1;
        }
        assert_true(faced);
        const scn_vertex *P = &w->pv[L->first_pvert];
        uint32_t n = L->num_pverts;
        if (n == 0) continue;
        /* counter-clockwise and convex */
        i128 area = 0;
        for (uint32_t k = 0; k < n; k++) {
            const scn_vertex *a = &P[k], *b = &P[(k + 1) % n], *c = &P[(k + 2) % n];
            area += (i128)a->x * b->y - (i128)b->x * a->y;
            assert_false(a->x == b->x && a->y == b->y);
            double lab = hypot((double)b->x - a->x, (double)b->y - a->y);
            double lbc = hypot((double)c->x - b->x, (double)c->y - b->y);
            /* turning left or straight at b, within TOL of straight */
            double turn = (double)cross3(a->x, a->y, b->x, b->y, c->x, c->y);
            assert_true(turn >= -TOL * (lab > lbc ? lab : lbc));
        }
        assert_true(area > 0);
        /* every seg end is a vertex of the polygon (the seg lies on its boundary) */
        for (uint32_t k = 0; k < L->num_segs; k++) {
            const scn_seg *g = &w->seg[L->first_seg + k];
            uint32_t ends[2] = {g->v1, g->v2};
            int idx[2] = {-1, -1};
            for (int e = 0; e < 2; e++)
                for (uint32_t q = 0; q < n; q++)
                    if (P[q].x == w->v[ends[e]].x && P[q].y == w->v[ends[e]].y) idx[e] = (int)q;
            assert_true(idx[0] >= 0 && idx[1] >= 0);
            /* the seg faces into the leaf, so it runs against the counter-clockwise
             * boundary: from its end forward to its start, the polygon's vertices
             * lie on it */
            const scn_vertex *a = &w->v[g->v1], *b = &w->v[g->v2];
            for (int q = (idx[1] + 1) % (int)n; q != idx[0]; q = (q + 1) % (int)n)
                assert_true(on_interior(a->x, a->y, b->x, b->y, P[q].x, P[q].y));
        }
    }
    assert_int_equal(segs_seen, w->nseg);
}

typedef struct {
    double t0, t1;
    uint32_t a, b;
} piece;

static int cmp_piece(const void *x, const void *y)
{
    const piece *p = x, *q = y;
    return (p->t0 > q->t0) - (p->t0 < q->t0);
}

/* the segs of each linedef side chain from its start to its end */
static void check_pieces(const view *w)
{
    piece *pc = malloc(sizeof *pc * (w->nseg + 1));
    uint32_t *order = malloc(sizeof *order * (w->nseg + 1));
    uint32_t *start = calloc((size_t)w->nln * 2 + 2, sizeof *start);
    assert_true(pc && order && start);
    for (uint32_t i = 0; i < w->nseg; i++) {
        const scn_seg *g = &w->seg[i];
        assert_true(g->line < w->nln && g->side < 2 && g->v1 < w->nv && g->v2 < w->nv);
        assert_true(w->ln[g->line].sector[g->side] != SCN_NONE);
        /* no zero-length seg */
        assert_true(g->v1 != g->v2);
        assert_false(w->v[g->v1].x == w->v[g->v2].x && w->v[g->v1].y == w->v[g->v2].y);
        start[(size_t)g->line * 2 + g->side + 1]++;
    }
    for (size_t k = 0; k < (size_t)w->nln * 2; k++) start[k + 1] += start[k];
    uint32_t *fill = malloc(sizeof *fill * ((size_t)w->nln * 2 + 2));
    memcpy(fill, start, sizeof *fill * ((size_t)w->nln * 2 + 1));
    for (uint32_t i = 0; i < w->nseg; i++) order[fill[(size_t)w->seg[i].line * 2 + w->seg[i].side]++] = i;
    for (uint32_t l = 0; l < w->nln; l++) {
        const scn_line *L = &w->ln[l];
        for (uint32_t s = 0; s < 2; s++) {
            uint32_t a = start[l * 2 + s], b = start[l * 2 + s + 1];
            if (L->sector[s] == SCN_NONE) {
                assert_int_equal(a, b);
                continue;
            }
            assert_true(b > a);
            uint32_t from = s ? L->v2 : L->v1, to = s ? L->v1 : L->v2;
            double dx = (double)w->v[to].x - w->v[from].x, dy = (double)w->v[to].y - w->v[from].y;
            double len2 = dx * dx + dy * dy;
            double sum = 0;
            uint32_t np = 0;
            for (uint32_t k = a; k < b; k++) {
                const scn_seg *g = &w->seg[order[k]];
                double t0 = (((double)w->v[g->v1].x - w->v[from].x) * dx +
                             ((double)w->v[g->v1].y - w->v[from].y) * dy) /
                            len2;
                double t1 = (((double)w->v[g->v2].x - w->v[from].x) * dx +
                             ((double)w->v[g->v2].y - w->v[from].y) * dy) /
                            len2;
                assert_true(t1 > t0); /* runs the way of its side */
                pc[np++] = (piece){t0, t1, g->v1, g->v2};
                sum += seglen(w, g->v1, g->v2);
            }
            qsort(pc, np, sizeof *pc, cmp_piece);
            assert_int_equal(pc[0].a, from);
            assert_int_equal(pc[np - 1].b, to);
            for (uint32_t k = 1; k < np; k++) assert_int_equal(pc[k].a, pc[k - 1].b);
            assert_true(fabs(sum - seglen(w, from, to)) < 1e-3);
        }
    }
    free(fill);
    free(pc);
    free(order);
    free(start);
}

/* no vertex on the interior of a seg; no polygon or seg vertex on the interior of a
 * leaf polygon's edge (a uniform grid keeps this fast on real maps) */
typedef struct {
    int64_t x0, y0;
    int shift;
    uint32_t nx, ny;
    uint32_t *start, *idx;
    const int64_t *px, *py;
} grid;

static void grid_make(grid *g, const int64_t *px, const int64_t *py, uint32_t n)
{
    int64_t x0 = INT64_MAX, y0 = INT64_MAX, x1 = INT64_MIN, y1 = INT64_MIN;
    for (uint32_t i = 0; i < n; i++) {
        if (px[i] < x0) x0 = px[i];
        if (py[i] < y0) y0 = py[i];
        if (px[i] > x1) x1 = px[i];
        if (py[i] > y1) y1 = py[i];
    }
    g->x0 = x0 - 64;
    g->y0 = y0 - 64;
    g->shift = 22; /* 64 units */
    g->nx = (uint32_t)((x1 - g->x0) >> g->shift) + 2;
    g->ny = (uint32_t)((y1 - g->y0) >> g->shift) + 2;
    g->px = px;
    g->py = py;
    g->start = calloc((size_t)g->nx * g->ny + 1, sizeof *g->start);
    g->idx = malloc(sizeof *g->idx * (n + 1));
    assert_true(g->start && g->idx);
    for (uint32_t i = 0; i < n; i++) {
        size_t c = (size_t)((py[i] - g->y0) >> g->shift) * g->nx + (size_t)((px[i] - g->x0) >> g->shift);
        g->start[c + 1]++;
    }
    for (size_t c = 0; c < (size_t)g->nx * g->ny; c++) g->start[c + 1] += g->start[c];
    uint32_t *fill = malloc(sizeof *fill * ((size_t)g->nx * g->ny + 1));
    memcpy(fill, g->start, sizeof *fill * ((size_t)g->nx * g->ny + 1));
    for (uint32_t i = 0; i < n; i++) {
        size_t c = (size_t)((py[i] - g->y0) >> g->shift) * g->nx + (size_t)((px[i] - g->x0) >> g->shift);
        g->idx[fill[c]++] = i;
    }
    free(fill);
}

static int grid_any_inside(const grid *g, int64_t ax, int64_t ay, int64_t bx, int64_t by)
{
    int64_t lx = (ax < bx ? ax : bx) - TOL, hx = (ax > bx ? ax : bx) + TOL;
    int64_t ly = (ay < by ? ay : by) - TOL, hy = (ay > by ? ay : by) + TOL;
    int64_t c0 = (lx - g->x0) >> g->shift, c1 = (hx - g->x0) >> g->shift;
    int64_t r0 = (ly - g->y0) >> g->shift, r1 = (hy - g->y0) >> g->shift;
    if (c0 < 0) c0 = 0;
    if (r0 < 0) r0 = 0;
    if (c1 >= g->nx) c1 = g->nx - 1;
    if (r1 >= g->ny) r1 = g->ny - 1;
    for (int64_t r = r0; r <= r1; r++)
        for (int64_t c = c0; c <= c1; c++) {
            size_t cell = (size_t)r * g->nx + (size_t)c;
            for (uint32_t k = g->start[cell]; k < g->start[cell + 1]; k++) {
                uint32_t i = g->idx[k];
                if (on_interior(ax, ay, bx, by, g->px[i], g->py[i])) return 1;
            }
        }
    return 0;
}

static void check_tjunctions(const view *w)
{
    uint32_t n = 0, cap = w->nv + w->npv + 1;
    int64_t *px = malloc(sizeof *px * cap), *py = malloc(sizeof *py * cap);
    uint8_t *used = calloc(w->nv + 1, 1);
    assert_true(px && py && used);
    for (uint32_t i = 0; i < w->nseg; i++) used[w->seg[i].v1] = used[w->seg[i].v2] = 1;
    for (uint32_t i = 0; i < w->nv; i++)
        if (used[i]) {
            px[n] = w->v[i].x;
            py[n++] = w->v[i].y;
        }
    uint32_t nsegv = n;
    grid gs;
    grid_make(&gs, px, py, nsegv);
    for (uint32_t i = 0; i < w->nseg; i++) {
        const scn_vertex *a = &w->v[w->seg[i].v1], *b = &w->v[w->seg[i].v2];
        assert_false(grid_any_inside(&gs, a->x, a->y, b->x, b->y));
    }
    for (uint32_t i = 0; i < w->npv; i++) {
        px[n] = w->pv[i].x;
        py[n++] = w->pv[i].y;
    }
    grid ga;
    grid_make(&ga, px, py, n);
    for (uint32_t li = 0; li < w->nleaf; li++) {
        const scn_leaf *L = &w->leaf[li];
        for (uint32_t k = 0; k < L->num_pverts; k++) {
            const scn_vertex *a = &w->pv[L->first_pvert + k];
            const scn_vertex *b = &w->pv[L->first_pvert + (k + 1) % L->num_pverts];
            assert_false(grid_any_inside(&ga, a->x, a->y, b->x, b->y));
        }
    }
    free(gs.start);
    free(gs.idx);
    free(ga.start);
    free(ga.idx);
    free(px);
    free(py);
    free(used);
}

static void check_blob(const uint8_t *b, size_t len)
{
    view w;
    view_open(&w, b, len);
    for (uint32_t i = 0; i < w.nln; i++) {
        assert_true(w.ln[i].v1 < w.nv && w.ln[i].v2 < w.nv);
        assert_true(w.ln[i].sector[0] < w.nsec);
        assert_true(w.ln[i].sector[1] == SCN_NONE || w.ln[i].sector[1] < w.nsec);
    }
    for (uint32_t i = 0; i < w.nv; i++) {
        assert_true(w.v[i].x <= SCN_COORD_MAX * 65536 && w.v[i].x >= -SCN_COORD_MAX * 65536);
        assert_true(w.v[i].y <= SCN_COORD_MAX * 65536 && w.v[i].y >= -SCN_COORD_MAX * 65536);
    }
    assert_true(w.h.player_sector == SCN_NONE || w.h.player_sector < w.nsec);
    check_tree(&w);
    check_leaves(&w);
    check_pieces(&w);
    check_tjunctions(&w);
    view_close(&w);
}

/* ------------------------------------------------------------ helpers */

static int compile_text(const char *text, bspc_split split, uint8_t **blob, size_t *len, bspc_stats *st, char *err,
                        size_t errlen, char **pathout)
{
    char *path = fixture_write_temp(text);
    bspc_options o = bspc_defaults();
    o.split = split;
    int rc = bspc_compile(path, &o, blob, len, st, err, errlen);
    if (pathout)
        *pathout = path;
    else {
        unlink(path);
        free(path);
    }
    return rc;
}

static int have_freedoom2(void)
{
    char path[1024];
    return bspc_find_wad("freedoom2.wad", path, sizeof path) == 0;
}

/* a room with a diagonal-walled pillar pair and a two-sided diagonal ledge */
static const char *diag_scene = "# test scene: diagonal walls\n"
                                "sector room floor=0 ceil=128 floor_color=sand:6 ceil_color=grey:8\n"
                                "sector ledge floor=24 ceil=128 floor_color=moss:6 ceil_color=grey:8 light=200\n"
                                "wall 0 0 0 300 room\n"
                                "wall 0 300 300 300 room\n"
                                "wall 300 300 300 0 room\n"
                                "wall 300 0 0 0 room\n"
                                /* diamond pillar */
                                "wall 100 37 137 100 room mid=red:9\n"
                                "wall 137 100 100 163 room mid=red:9\n"
                                "wall 100 163 63 100 room mid=red:9\n"
                                "wall 63 100 100 37 room mid=red:9\n"
                                /* triangular raised ledge (two-sided walls, the ledge on their left) */
                                "wall 170 190 250 230 room ledge\n"
                                "wall 250 230 210 270 room ledge\n"
                                "wall 210 270 170 190 room ledge\n"
                                /* a skewed pillar */
                                "wall 200 40 251 61 room mid=blue:9\n"
                                "wall 251 61 233 113 room mid=blue:9\n"
                                "wall 233 113 190 97 room mid=blue:9\n"
                                "wall 190 97 200 40 room mid=blue:9\n"
                                "player 30 30 45\n";

/* ------------------------------------------------------------ tests */

static void test_default_scene_all_strategies(void **state)
{
    (void)state;
    const char *path = "tests/scenes/default.scene";
    FILE *f = fopen(path, "r");
    if (!f) skip();
    fclose(f);
    bspc_split sp[3] = {BSPC_SPLIT_FEWEST, BSPC_SPLIT_BALANCED, BSPC_SPLIT_MIXED};
    for (int i = 0; i < 3; i++) {
        bspc_options o = bspc_defaults();
        o.split = sp[i];
        uint8_t *b = NULL;
        size_t len = 0;
        bspc_stats st;
        char err[512];
        int rc = bspc_compile(path, &o, &b, &len, &st, err, sizeof err);
        if (rc) fprintf(stderr, "%s\n", err);
        assert_int_equal(rc, 0);
        assert_true(st.input_walls >= 40 && st.input_walls <= 80);
        check_blob(b, len);
        view w;
        view_open(&w, b, len);
        assert_true(w.h.player_sector != SCN_NONE);
        assert_int_equal(w.nln, st.input_walls);
        assert_int_equal(w.nseg, st.segs);
        assert_int_equal(w.nleaf, st.leaves);
        assert_int_equal(w.nnode, st.nodes);
        assert_int_equal(w.nv, st.vertices);
        assert_int_equal(w.h.max_depth, st.max_depth);
        view_close(&w);
        free(b);
    }
}

static void test_diagonal_scene_fractional_splits(void **state)
{
    (void)state;
    bspc_split sp[3] = {BSPC_SPLIT_FEWEST, BSPC_SPLIT_BALANCED, BSPC_SPLIT_MIXED};
    int fractional = 0;
    for (int i = 0; i < 3; i++) {
        uint8_t *b = NULL;
        size_t len = 0;
        bspc_stats st;
        char err[512];
        int rc = compile_text(diag_scene, sp[i], &b, &len, &st, err, sizeof err, NULL);
        if (rc) fprintf(stderr, "%s\n", err);
        assert_int_equal(rc, 0);
        check_blob(b, len);
        view w;
        view_open(&w, b, len);
        /* vertices after those the lines use are split points */
        uint32_t norig = 0;
        for (uint32_t k = 0; k < w.nln; k++) {
            if (w.ln[k].v1 + 1 > norig) norig = w.ln[k].v1 + 1;
            if (w.ln[k].v2 + 1 > norig) norig = w.ln[k].v2 + 1;
        }
        for (uint32_t k = norig; k < w.nv; k++)
            if ((w.v[k].x & 0xFFFF) || (w.v[k].y & 0xFFFF)) fractional++;
        if (sp[i] == BSPC_SPLIT_BALANCED) assert_true(st.splits > 0);
        view_close(&w);
        free(b);
    }
    assert_true(fractional > 0);
}

/* the whole coordinate range, walls longer than 32767 units, fractional ends */
static void test_extreme_scene(void **state)
{
    (void)state;
    const char *txt = "sector a floor=-16383 ceil=16383\n"
                      "sector b floor=10 ceil=90\n"
                      "wall -32767 -32767 -32767 32767 a\n"
                      "wall -32767 32767 32767 32767 a\n"
                      "wall 32767 32767 32767 -32767 a\n"
                      "wall 32767 -32767 -32767 -32767 a\n"
                      "wall -30000 -29999.99 29999.7 30000.3 a a\n"
                      "wall 30000 -30000 -29000.5 29999.5 a a\n"
                      "wall 1000 -1000 1000.5 -1200.25 b a\n"
                      "wall 1000.5 -1200.25 900 -1100 b a\n"
                      "wall 900 -1100 1000 -1000 b a\n"
                      "player -30000 30000 -45\n";
    bspc_split sp[3] = {BSPC_SPLIT_FEWEST, BSPC_SPLIT_BALANCED, BSPC_SPLIT_MIXED};
    for (int i = 0; i < 3; i++) {
        uint8_t *b = NULL;
        size_t len = 0;
        char err[512];
        int rc = compile_text(txt, sp[i], &b, &len, NULL, err, sizeof err, NULL);
        if (rc) fprintf(stderr, "%s\n", err);
        assert_int_equal(rc, 0);
        check_blob(b, len);
        view w;
        view_open(&w, b, len);
        assert_int_equal(w.h.player_angle, 315 * 65536);
        assert_int_equal(w.h.player_sector, 0);
        view_close(&w);
        free(b);
    }
}

static void test_decimal_coordinates(void **state)
{
    (void)state;
    /* 0.1 = 6553.6 raw -> 6554; -0.5 = -32768 raw exactly */
    const char *txt = "sector s floor=0.5 ceil=100.25\n"
                      "wall 0.1 -0.5 0.1 64 s\n"
                      "wall 0.1 64 64 64 s\n"
                      "wall 64 64 64 -0.5 s\n"
                      "wall 64 -0.5 0.1 -0.5 s\n"
                      "player 32 32 90.5\n";
    uint8_t *b = NULL;
    size_t len = 0;
    char err[512];
    assert_int_equal(compile_text(txt, BSPC_SPLIT_MIXED, &b, &len, NULL, err, sizeof err, NULL), 0);
    check_blob(b, len);
    view w;
    view_open(&w, b, len);
    assert_int_equal(w.v[w.ln[0].v1].x, 6554);
    assert_int_equal(w.v[w.ln[0].v1].y, -32768);
    assert_int_equal(w.sec[0].floor_h, 32768);
    assert_int_equal(w.sec[0].ceil_h, 100 * 65536 + 16384);
    assert_int_equal(w.h.player_angle, 90 * 65536 + 32768);
    assert_int_equal(w.h.player_sector, 0);
    view_close(&w);
    free(b);
}

static void test_freedoom2_map01(void **state)
{
    (void)state;
    if (!have_freedoom2()) skip();
    bspc_split sp[3] = {BSPC_SPLIT_MIXED, BSPC_SPLIT_FEWEST, BSPC_SPLIT_BALANCED};
    bspc_stats st[3];
    for (int i = 0; i < 3; i++) {
        bspc_options o = bspc_defaults();
        o.split = sp[i];
        uint8_t *b = NULL;
        size_t len = 0;
        char err[512];
        int rc = bspc_compile("freedoom2.wad:MAP01", &o, &b, &len, &st[i], err, sizeof err);
        if (rc) fprintf(stderr, "%s\n", err);
        assert_int_equal(rc, 0);
        check_blob(b, len);
        view w;
        view_open(&w, b, len);
        assert_true(w.h.player_sector != SCN_NONE);
        int fractional = 0;
        for (uint32_t k = 0; k < w.nv; k++)
            if ((w.v[k].x & 0xFFFF) || (w.v[k].y & 0xFFFF)) fractional++;
        assert_true(fractional > 0);
        view_close(&w);
        free(b);
    }
    /* the strategies do what they say */
    assert_true(st[1].splits <= st[2].splits);
    assert_true(st[2].max_depth <= st[1].max_depth);
    assert_true(st[0].max_depth <= 50);
}

/* every Freedoom map (slow: set BSPC_TEST_ALL_MAPS=1 to run it) */
static void test_all_freedoom_maps(void **state)
{
    (void)state;
    const char *e = getenv("BSPC_TEST_ALL_MAPS");
    if (!e || !*e || !have_freedoom2()) skip();
    char spec[64];
    for (int k = 0; k < 68; k++) {
        if (k < 36)
            snprintf(spec, sizeof spec, "freedoom1.wad:E%dM%d", k / 9 + 1, k % 9 + 1);
        else
            snprintf(spec, sizeof spec, "freedoom2.wad:MAP%02d", k - 35);
        uint8_t *b = NULL;
        size_t len = 0;
        char err[512];
        bspc_stats st;
        int rc = bspc_compile(spec, NULL, &b, &len, &st, err, sizeof err);
        if (rc) fprintf(stderr, "%s\n", err);
        assert_int_equal(rc, 0);
        check_blob(b, len);
        free(b);
    }
}

/* ------------------------------------------------------------ objects and doors */

static const char *objects_scene = "sector room floor=0 ceil=128 floor_color=sand:7\n"
                                   "sector dais floor=24 ceil=128\n"
                                   "sector door1 floor=0 ceil=0 door=112 floor_color=grey:6 ceil_color=grey:5\n"
                                   "wall 0 0 0 256 room\n"
                                   "wall 0 256 256 256 room\n"
                                   "wall 256 256 256 0 room\n"
                                   "wall 256 0 128 0 room\n"
                                   "wall 128 0 96 0 room door1\n"
                                   "wall 96 0 0 0 room\n"
                                   "wall 128 0 128 -16 door1\n"
                                   "wall 128 -16 96 -16 door1\n"
                                   "wall 96 -16 96 0 door1\n"
                                   /* a raised square in the room's north-east: a hole in room, the dais in it */
                                   "wall 160 160 160 224 dais room\n"
                                   "wall 160 224 224 224 dais room\n"
                                   "wall 224 224 224 160 dais room\n"
                                   "wall 224 160 160 160 dais room\n"
                                   "player 64 128 0\n"
                                   "model crate\n"
                                   "part box w=32 d=32.00001 h=32 at=1,2,3 color=brown:8 top=brown:10 bottom=1\n"
                                   "end\n"
                                   "model ship  # two touching parts\n"
                                   "part box   w=48 d=16 h=8  at=0,0,0   color=grey:9\n"
                                   "part prism sides=3 r=12 h=4 at=30,0,2 color=red:8 top=red:10\n"
                                   "end\n"
                                   "model gem\n"
                                   "part prism sides=7 r=10.3 h=5 at=0.5,-0.25,-2 side=blue:15 color=blue:0\n"
                                   "end\n"
                                   "object crate 64 64\n"         /* on the room's floor */
                                   "object gem 192 192 yaw=-30\n" /* on the dais */
                                   "object 1 128 128 z=96 yaw=450 path=circle:64:8000\n"
                                   "object ship 20 20 z=-16383 path=line:200:-10:4000 spin=-45.5\n";

static void *sec_copy(const uint8_t *b, size_t len, int k, size_t rec, uint32_t *count)
{
    scn_header h;
    memcpy(&h, b, sizeof h);
    *count = h.sec[k].count;
    return section(b, len, &h, k, rec);
}

/* Newell normal of a face, in doubles */
static void face_normal(const scn_mvert *v, const uint32_t *idx, int n, double nrm[3])
{
    nrm[0] = nrm[1] = nrm[2] = 0;
    for (int i = 0; i < n; i++) {
        const scn_mvert *a = &v[idx[i]], *c = &v[idx[(i + 1) % n]];
        nrm[0] += ((double)a->y - c->y) * ((double)a->z + c->z);
        nrm[1] += ((double)a->z - c->z) * ((double)a->x + c->x);
        nrm[2] += ((double)a->x - c->x) * ((double)a->y + c->y);
    }
}

static int64_t round_away(double v)
{
    return (int64_t)(v < 0 ? -floor(-v + 0.5) : floor(v + 0.5));
}

static void test_objects_and_doors(void **state)
{
    (void)state;
    uint8_t *b = NULL;
    size_t len = 0;
    bspc_stats st;
    char err[512];
    int rc = compile_text(objects_scene, BSPC_SPLIT_MIXED, &b, &len, &st, err, sizeof err, NULL);
    if (rc) fprintf(stderr, "%s\n", err);
    assert_int_equal(rc, 0);
    check_blob(b, len);
    assert_int_equal(st.models, 3);
    assert_int_equal(st.objects, 4);
    assert_int_equal(st.doors, 1);
    /* the loader takes it */
    uint32_t *al = malloc(len + 4);
    memcpy(al, b, len);
    scene sc;
    scene_error se;
    assert_int_equal(scene_load(&sc, al, (uint32_t)len, &se), SCENE_OK);
    free(al);

    uint32_t nm, nv, nf, ni, no, ns;
    scn_model *m = sec_copy(b, len, SCN_SEC_MODELS, sizeof *m, &nm);
    scn_mvert *mv = sec_copy(b, len, SCN_SEC_MVERTS, sizeof *mv, &nv);
    scn_face *f = sec_copy(b, len, SCN_SEC_FACES, sizeof *f, &nf);
    uint32_t *fi = sec_copy(b, len, SCN_SEC_FINDEX, sizeof *fi, &ni);
    scn_object *o = sec_copy(b, len, SCN_SEC_OBJECTS, sizeof *o, &no);
    scn_sector *sec = sec_copy(b, len, SCN_SEC_SECTORS, sizeof *sec, &ns);
    assert_int_equal(nm, 3);
    assert_int_equal(no, 4);
    assert_int_equal(nv, 8 + 8 + 6 + 14);
    assert_int_equal(nf, 6 + 6 + 5 + 9);

    /* the crate: d = 32.00001 rounds to 2097153 raw, an odd size whose half
     * rounds away from the centre */
    const int32_t U = 65536;
    assert_int_equal(m[0].first_vert, 0);
    assert_int_equal(m[0].num_verts, 8);
    assert_int_equal(m[0].first_face, 0);
    assert_int_equal(m[0].num_faces, 6);
    static const int sx[4] = {-1, 1, 1, -1}, sy[4] = {-1, -1, 1, 1};
    for (int k = 0; k < 8; k++) {
        assert_int_equal(mv[k].x, 1 * U + sx[k % 4] * 16 * U);
        assert_int_equal(mv[k].y, 2 * U + sy[k % 4] * (16 * U + 1));
        assert_int_equal(mv[k].z, k < 4 ? 3 * U : 35 * U);
    }
    assert_int_equal(m[0].zmin, 3 * U);
    assert_int_equal(m[0].zmax, 35 * U);
    {
        /* ceil of the exact distance of the farthest corner (17, 18 + 1 raw) */
        double d = sqrt((double)(17 * U) * (17 * U) + (double)(18 * U + 1) * (18 * U + 1));
        assert_true(m[0].radius == (int32_t)ceil(d));
    }
    /* outward normals: every face's normal points away from its part's centre */
    for (uint32_t mi = 0; mi < nm; mi++)
        for (uint32_t k = 0; k < m[mi].num_faces; k++) {
            const scn_face *F = &f[m[mi].first_face + k];
            assert_true(F->num_index >= 3 && F->num_index <= SCN_MAX_FACE_VERTS);
            const scn_mvert *base = mv + m[mi].first_vert;
            double c[3] = {0, 0, 0}, fc[3] = {0, 0, 0}, nrm[3];
            uint32_t cnt = 0;
            for (uint32_t j = 0; j < m[mi].num_faces; j++) { /* the part's centre: mean of its faces' vertices */
                const scn_face *G = &f[m[mi].first_face + j];
                if (G->part != F->part) continue;
                for (uint32_t q = 0; q < G->num_index; q++) {
                    c[0] += base[fi[G->first_index + q]].x;
                    c[1] += base[fi[G->first_index + q]].y;
                    c[2] += base[fi[G->first_index + q]].z;
                    cnt++;
                }
            }
            for (uint32_t q = 0; q < F->num_index; q++) {
                assert_true(fi[F->first_index + q] < m[mi].num_verts);
                fc[0] += base[fi[F->first_index + q]].x / (double)F->num_index;
                fc[1] += base[fi[F->first_index + q]].y / (double)F->num_index;
                fc[2] += base[fi[F->first_index + q]].z / (double)F->num_index;
            }
            face_normal(base, fi + F->first_index, F->num_index, nrm);
            double dot = 0;
            for (int a = 0; a < 3; a++) dot += nrm[a] * (fc[a] - c[a] / cnt);
            assert_true(dot > 0);
        }
    /* crate colours: sides brown:8 with contrast (edge along x: lighter), top brown:10, bottom 1 */
    assert_int_equal(f[0].colour, 11 * 16 + 9); /* (-,-) -> (+,-): runs along x */
    assert_int_equal(f[1].colour, 11 * 16 + 7); /* (+,-) -> (+,+): runs along y */
    assert_int_equal(f[2].colour, 11 * 16 + 9);
    assert_int_equal(f[3].colour, 11 * 16 + 7);
    assert_int_equal(f[4].colour, 11 * 16 + 10);
    assert_int_equal(f[5].colour, 1);
    /* crate faces in the documented order */
    static const uint32_t crate_faces[6][4] = {{0, 1, 5, 4}, {1, 2, 6, 5}, {2, 3, 7, 6},
                                               {3, 0, 4, 7}, {4, 5, 6, 7}, {0, 3, 2, 1}};
    for (int k = 0; k < 6; k++) {
        assert_int_equal(f[k].num_index, 4);
        assert_int_equal(f[k].part, 0);
        for (int q = 0; q < 4; q++) assert_int_equal(fi[f[k].first_index + q], crate_faces[k][q]);
    }

    /* the ship: two parts; the prism's corners by the documented formula */
    assert_int_equal(m[1].first_vert, 8);
    assert_int_equal(m[1].num_verts, 14);
    assert_int_equal(m[1].num_faces, 11);
    assert_int_equal(f[m[1].first_face + 6].part, 1);
    for (int k = 0; k < 3; k++) {
        double a = 2 * M_PI * k / 3;
        const scn_mvert *v = &mv[8 + 8 + k];
        assert_int_equal(v->x, 30 * U + round_away(12.0 * U * cos(a)));
        assert_int_equal(v->y, round_away(12.0 * U * sin(a)));
        assert_int_equal(v->z, 2 * U);
        assert_int_equal(mv[8 + 8 + 3 + k].z, 6 * U);
    }
    assert_int_equal(mv[8 + 8 + 1].x, 24 * U); /* touches the box's +x face */
    assert_int_equal(m[1].radius, 42 * U);
    assert_int_equal(m[1].zmin, 0);
    assert_int_equal(m[1].zmax, 8 * U);
    /* the prism's sides: 0 diagonal (red:8), 1 along y (darker), 2 diagonal; top red:10 */
    assert_int_equal(f[m[1].first_face + 6].colour, 16 + 8);
    assert_int_equal(f[m[1].first_face + 7].colour, 16 + 7);
    assert_int_equal(f[m[1].first_face + 9].colour, 16 + 10);
    assert_int_equal(f[m[1].first_face + 10].colour, 16 + 8);
    assert_int_equal(f[m[1].first_face + 9].num_index, 3);

    /* the gem: fractional radius and centre; shades clamp at 15 and 0 */
    int32_t r = 675021; /* 10.3 -> 675020.8 raw */
    for (int k = 0; k < 7; k++) {
        double a = 2 * M_PI * k / 7;
        const scn_mvert *v = &mv[22 + k];
        assert_int_equal(v->x, 32768 + round_away((double)r * cos(a)));
        assert_int_equal(v->y, -16384 + round_away((double)r * sin(a)));
        assert_int_equal(v->z, -2 * U);
        assert_int_equal(mv[22 + 7 + k].z, 3 * U);
    }
    /* side 3 (between the corners at 3/7 and 4/7 of a turn) runs along y: one darker */
    assert_int_equal(mv[22 + 3].x, mv[22 + 4].x);
    for (int k = 0; k < 7; k++) assert_int_equal(f[m[2].first_face + k].colour, 8 * 16 + (k == 3 ? 14 : 15));
    assert_int_equal(f[m[2].first_face + 7].colour, 8 * 16);
    assert_int_equal(f[m[2].first_face + 8].num_index, 7);
    assert_int_equal(fi[f[m[2].first_face + 8].first_index + 1], 6); /* bottom: 0, 6, 5, ... */

    /* objects: z on the floor under them, yaw modulo 360, paths */
    assert_int_equal(o[0].model, 0);
    assert_int_equal(o[0].z, 0);
    assert_int_equal(o[0].path, SCN_PATH_NONE);
    assert_int_equal(o[1].model, 2);
    assert_int_equal(o[1].z, 24 * U);
    assert_int_equal(o[1].yaw, 330 * U);
    assert_int_equal(o[2].model, 1);
    assert_int_equal(o[2].x, 128 * U);
    assert_int_equal(o[2].z, 96 * U);
    assert_int_equal(o[2].yaw, 90 * U);
    assert_int_equal(o[2].path, SCN_PATH_CIRCLE);
    assert_int_equal(o[2].pa, 64 * U);
    assert_int_equal(o[2].pb, 0);
    assert_int_equal(o[2].period_ms, 8000);
    assert_int_equal(o[3].z, -16383 * U);
    assert_int_equal(o[3].path, SCN_PATH_LINE);
    assert_int_equal(o[3].pa, 200 * U);
    assert_int_equal(o[3].pb, -10 * U);
    assert_int_equal(o[3].period_ms, 4000);
    assert_int_equal(o[3].spin, -(45 * U + U / 2));

    /* the door */
    assert_int_equal(ns, 3);
    assert_int_equal(sec[2].flags & SCN_SECTOR_DOOR, SCN_SECTOR_DOOR);
    assert_int_equal(sec[2].ceil_h, 0);
    assert_int_equal(sec[2].open_h, 112 * U);
    assert_int_equal(sec[0].flags & SCN_SECTOR_DOOR, 0);
    assert_int_equal(sec[0].open_h, sec[0].ceil_h);
    free(m);
    free(mv);
    free(f);
    free(fi);
    free(o);
    free(sec);
    free(b);
}

/* ---- freedoom2.wad:MAP01 counted from its lumps ---- */

typedef struct {
    uint8_t *data;
    uint32_t size;
} wlump;

static int wad_map_lump(const char *wad, const char *map, const char *name, wlump *out)
{
    FILE *fp = fopen(wad, "rb");
    if (!fp) return -1;
    uint8_t h[12];
    int found = -1;
    if (fread(h, 1, 12, fp) == 12) {
        uint32_t n = h[4] | h[5] << 8 | h[6] << 16 | (uint32_t)h[7] << 24;
        uint32_t d = h[8] | h[9] << 8 | h[10] << 16 | (uint32_t)h[11] << 24;
        uint8_t *dir = malloc((size_t)n * 16);
        fseek(fp, (long)d, SEEK_SET);
        if (fread(dir, 16, n, fp) == n) {
            int in_map = 0;
            for (uint32_t i = 0; i < n && found < 0; i++) {
                char nm[9] = {0};
                memcpy(nm, dir + 16 * i + 8, 8);
                if (strcmp(nm, map) == 0)
                    in_map = 1;
                else if (in_map && strcmp(nm, name) == 0) {
                    uint32_t pos = dir[16 * i] | dir[16 * i + 1] << 8 | dir[16 * i + 2] << 16 |
                                   (uint32_t)dir[16 * i + 3] << 24;
                    out->size = dir[16 * i + 4] | dir[16 * i + 5] << 8 | dir[16 * i + 6] << 16 |
                                (uint32_t)dir[16 * i + 7] << 24;
                    out->data = malloc(out->size + 1);
                    fseek(fp, (long)pos, SEEK_SET);
                    found = fread(out->data, 1, out->size, fp) == out->size ? 0 : -1;
                }
            }
        }
        free(dir);
    }
    fclose(fp);
    return found;
}

static unsigned u16(const uint8_t *p)
{
    return p[0] | p[1] << 8;
}

static void test_freedoom2_map01_objects_and_doors(void **state)
{
    (void)state;
    if (!have_freedoom2()) skip();
    char wad[1024];
    assert_int_equal(bspc_find_wad("freedoom2.wad", wad, sizeof wad), 0);
    wlump th, ld, sd, se;
    assert_int_equal(wad_map_lump(wad, "MAP01", "THINGS", &th), 0);
    assert_int_equal(wad_map_lump(wad, "MAP01", "LINEDEFS", &ld), 0);
    assert_int_equal(wad_map_lump(wad, "MAP01", "SIDEDEFS", &sd), 0);
    assert_int_equal(wad_map_lump(wad, "MAP01", "SECTORS", &se), 0);

    /* the thing table, read as the reference renderer reads it */
    FILE *tf = fopen("tools/bspc/things.txt", "r");
    assert_non_null(tf);
    int types[512], ntypes = 0;
    char line[256];
    while (fgets(line, sizeof line, tf)) {
        char *hash = strchr(line, '#');
        if (hash) *hash = 0;
        int t, r, h;
        char col[64], name[128];
        int got = sscanf(line, "%d %d %d %63s %127s", &t, &r, &h, col, name);
        if (got <= 0) continue;
        assert_int_equal(got, 5);
        assert_true(ntypes < 512);
        types[ntypes++] = t;
    }
    fclose(tf);
    uint32_t want_objects = 0, nthings = th.size / 10;
    for (uint32_t i = 0; i < nthings; i++) {
        const uint8_t *r = th.data + 10 * i;
        unsigned type = u16(r + 6), flags = u16(r + 8);
        int listed = 0;
        for (int k = 0; k < ntypes; k++) listed |= types[k] == (int)type;
        if (listed && (flags & 2) && !(flags & 0x10)) want_objects++;
    }

    /* door sectors by the contract's rule */
    uint32_t nsec = se.size / 26, nlines = ld.size / 14;
    uint8_t *door = calloc(nsec, 1);
    uint32_t want_doors = 0;
    for (uint32_t i = 0; i < nlines; i++) {
        const uint8_t *r = ld.data + 14 * i;
        unsigned sp = u16(r + 6), tag = u16(r + 8), back = u16(r + 12);
        int manual = sp == 1 || (sp >= 26 && sp <= 28) || (sp >= 31 && sp <= 34) || sp == 117 || sp == 118;
        if (manual && back != 0xFFFF) door[u16(sd.data + 30 * back + 28)] = 1;
        if ((sp == 63 || sp == 90) && tag)
            for (uint32_t k = 0; k < nsec; k++)
                if (u16(se.data + 26 * k + 24) == tag) door[k] = 1;
    }
    for (uint32_t k = 0; k < nsec; k++) want_doors += door[k];

    uint8_t *b = NULL;
    size_t len = 0;
    bspc_stats st;
    char err[512];
    int rc = bspc_compile("freedoom2.wad:MAP01", NULL, &b, &len, &st, err, sizeof err);
    if (rc) fprintf(stderr, "%s\n", err);
    assert_int_equal(rc, 0);
    uint32_t no, ns, nm;
    scn_object *o = sec_copy(b, len, SCN_SEC_OBJECTS, sizeof *o, &no);
    scn_sector *sec = sec_copy(b, len, SCN_SEC_SECTORS, sizeof *sec, &ns);
    scn_model *m = sec_copy(b, len, SCN_SEC_MODELS, sizeof *m, &nm);
    fprintf(stderr, "MAP01: %u things -> %u objects on %u models; %u doors\n", nthings, no, nm, want_doors);
    /* the things first, then the see-through middle textures (scn_object.side) */
    uint32_t nthing_objs = 0;
    while (nthing_objs < no && o[nthing_objs].side == SCN_NONE) nthing_objs++;
    for (uint32_t k = nthing_objs; k < no; k++) assert_int_not_equal(o[k].side, SCN_NONE);
    assert_true(want_objects > 50);
    assert_int_equal(nthing_objs, want_objects);
    assert_int_equal(st.objects, no);
    assert_int_equal(st.models, nm);
    assert_true(nm >= 5 && nm < no);
    assert_true(want_doors >= 3);
    assert_int_equal(st.doors, want_doors);
    /* objects in THINGS order, each on the floor of some sector, yaw = angle */
    uint32_t j = 0;
    for (uint32_t i = 0; i < nthings && j < nthing_objs; i++) {
        const uint8_t *r = th.data + 10 * i;
        if ((int16_t)u16(r) * 65536 != o[j].x || (int16_t)u16(r + 2) * 65536 != o[j].y) continue;
        int a = ((int16_t)u16(r + 4) % 360 + 360) % 360;
        assert_int_equal(o[j].yaw, a * 65536);
        int on_floor = 0;
        for (uint32_t k = 0; k < ns; k++) on_floor |= sec[k].floor_h == o[j].z;
        assert_true(on_floor);
        assert_true(o[j].model < nm);
        assert_int_equal(m[o[j].model].zmin, 0);
        j++;
    }
    assert_int_equal(j, nthing_objs);
    for (uint32_t k = 0; k < ns; k++) {
        assert_int_equal(!!(sec[k].flags & SCN_SECTOR_DOOR), door[k]);
        if (door[k]) {
            assert_true(sec[k].open_h >= sec[k].ceil_h);
            assert_true(sec[k].open_h <= SCN_HEIGHT_MAX * 65536);
        } else {
            assert_int_equal(sec[k].open_h, sec[k].ceil_h);
        }
    }
    uint32_t *al = malloc(len + 4);
    memcpy(al, b, len);
    scene sc;
    assert_int_equal(scene_load(&sc, al, (uint32_t)len, NULL), SCENE_OK);
    free(al);
    free(o);
    free(sec);
    free(m);
    free(door);
    free(b);
    free(th.data);
    free(ld.data);
    free(sd.data);
    free(se.data);
}

/* ------------------------------------------------------------ errors */

typedef struct {
    const char *text;
    int line;           /* expected line in the message, 0: none */
    const char *needle; /* expected words */
} bad_case;

static const bad_case bad[] = {
    {"sector a floor=0 ceil=64\nwall 0 0 0 64 b\nplayer 1 1 0\n", 2, "unknown sector 'b'"},
    {"sector a floor=0 ceil=64\nwall 0 0 0 64 5\nplayer 1 1 0\n", 2, "unknown sector 5"},
    {"sector a floor=0 ceil=64\nwall 0 0 0 0 a\nplayer 1 1 0\n", 2, "zero length"},
    {"sector a floor=0 ceil=64\nwall 0 0 0 64 a\nwall 0 64 64 64 a\nwall 64 64 64 0 a\n"
     "wall 64 0 0 0 a\nwall 0 64 0 0 a\nplayer 1 1 0\n",
     6, "duplicates the wall on line 2"},
    {"sector a floor=0 ceil=64\nwall 0 0 0 64 a\nwall 0 64 64 64 a\nwall 64 64 64 0 a\n"
     "player 32 32 0\n",
     0, "not closed"},
    {"sector a floor=0 ceil=64\nwall 0 0 64 0 a\nwall 64 0 64 64 a\nwall 64 64 0 64 a\n"
     "wall 0 64 0 0 a\nplayer 32 32 0\n",
     2, "face away"},
    {"sector a floor=0 ceil=64\nwall 0 0 0 40000 a\nplayer 1 1 0\n", 2, "out of range"},
    {"sector a floor=0 ceil=20000\n", 1, "out of range"},
    {"sector a floor=0 ceil=64\nwall 0 0 0 64 a\nwall 0 64 64 64 a\nwall 64 64 64 0 a\n"
     "wall 64 0 0 0 a\n",
     0, "no player start"},
    {"sector a floor=0 ceil=64\nwall 0 0 0 64 a\nwall 0 64 64 64 a\nwall 64 64 64 0 a\n"
     "wall 64 0 0 0 a\nplayer 100 100 0\n",
     6, "not inside any sector"},
    {"sector a floor=0 ceil=64\nwall 0 0 0 6x4 a\n", 2, "not a number"},
    {"sector a floor=0 ceil=64\nwal 0 0 0 64 a\n", 2, "unknown statement 'wal'"},
    {"sector a floor=0 ceil=64 floor_color=pink\n", 1, "unknown colour"},
    {"sector a floor=0\n", 1, "missing ceil"},
    {"sector a floor=0 ceil=64\nsector a floor=0 ceil=64\n", 2, "already used"},
    {"", 0, "no walls"},
/* models, objects and doors (docs/objects.md) */
#define ROOM_                                                                                                          \
    "sector a floor=0 ceil=64\nwall 0 0 0 64 a\nwall 0 64 64 64 a\nwall 64 64 64 0 a\nwall 64 0 0 0 a\nplayer 32 32 "  \
    "0\n"
    {ROOM_ "object crate 10 10\n", 7, "unknown model 'crate'"},
    {ROOM_ "object 0 10 10\n", 7, "unknown model 0"},
    {ROOM_ "model m\nend\n", 8, "has no parts"},
    {ROOM_ "model m\npart box w=1 d=1 h=1\n", 7, "'end' missing"},
    {ROOM_ "model m\npart box w=1 d=1 h=1\nwall 0 0 1 1 a\nend\n", 9, "not allowed inside model 'm'"},
    {ROOM_ "model m\npart box w=1 d=1 h=1\nmodel n\n", 9, "not allowed inside model"},
    {ROOM_ "part box w=1 d=1 h=1\n", 7, "outside a model"},
    {ROOM_ "end\n", 7, "outside a model"},
    {ROOM_ "model m\npart box w=1 d=1 h=1\nend\nmodel m\n", 10, "name 'm' already used"},
    {ROOM_ "model 9m\n", 7, "bad name"},
    {ROOM_ "model m\npart cone r=1 h=1\n", 8, "expected 'part box"},
    {ROOM_ "model m\npart box w=1 d=1\n", 8, "missing h="},
    {ROOM_ "model m\npart prism r=1 h=1\n", 8, "missing sides="},
    {ROOM_ "model m\npart prism sides=17 r=1 h=1\n", 8, "sides=17"},
    {ROOM_ "model m\npart prism sides=2 r=1 h=1\n", 8, "sides=2"},
    {ROOM_ "model m\npart box w=0 d=1 h=1\n", 8, "w=0 out of range"},
    {ROOM_ "model m\npart box w=-3 d=1 h=1\n", 8, "w=-3 out of range"},
    {ROOM_ "model m\npart box w=2049 d=1 h=1\n", 8, "out of range"},
    {ROOM_ "model m\npart box w=1 d=1 h=1 r=3\n", 8, "unknown key 'r'"},
    {ROOM_ "model m\npart box w=1 d=1 h=1 h=2\n", 8, "h given twice"},
    {ROOM_ "model m\npart box w=1 d=1 h=1 at=1,2\n", 8, "expected at=X,Y,Z"},
    {ROOM_ "model m\npart box w=1 d=1 h=1 at=1,2,1025\n", 8, "out of range"},
    {ROOM_ "model m\npart box w=2000 d=1 h=1 at=100,0,0\n", 8, "outside the model's range"},
    {ROOM_ "model m\npart box w=1 d=1 h=1000 at=0,0,100\n", 8, "outside the model's range"},
    {ROOM_ "model m\npart box w=1 d=1 h=1 color=pink\n", 8, "unknown colour"},
    {ROOM_ "model m\npart prism sides=16 r=0.00002 h=1\n", 8, "too small"},
    {ROOM_ "model m\npart box w=10 d=10 h=10\npart box w=10 d=10 h=10 at=9.99,0,0\n", 9, "overlaps part 1"},
    {ROOM_ "model m\npart box w=10 d=10 h=10\npart prism sides=16 r=5 h=10 at=0,0,9\n", 9, "overlaps part 1"},
    {ROOM_ "model m\npart prism sides=16 r=1 h=1\npart prism sides=16 r=1 h=1 at=0,0,1\n"
           "part prism sides=16 r=1 h=1 at=0,0,2\n",
     10, "more than 64"},
    {ROOM_ "model m\npart box w=1 d=1 h=1\nend\nobject m 10\n", 10, "expected 'object MODEL X Y"},
    {ROOM_ "model m\npart box w=1 d=1 h=1\nend\nobject m 40000 10\n", 10, "out of range"},
    {ROOM_ "model m\npart box w=1 d=1 h=1\nend\nobject m 100 100\n", 10, "not inside any sector"},
    {ROOM_ "model m\npart box w=1 d=1 h=1\nend\nobject m 10 10 z=16384\n", 10, "z=16384 out of range"},
    {ROOM_ "model m\npart box w=1 d=1 h=1\nend\nobject m 10 10 z=1 z=2\n", 10, "z given twice"},
    {ROOM_ "model m\npart box w=1 d=1 h=1\nend\nobject m 10 10 speed=2\n", 10, "unknown key 'speed'"},
    {ROOM_ "model m\npart box w=1 d=1 h=1\nend\nobject m 10 10 spin=3601\n", 10, "spin=3601 out of range"},
    {ROOM_ "model m\npart box w=1 d=1 h=1\nend\nobject m 10 10 yaw=x\n", 10, "not a number"},
    {ROOM_ "model m\npart box w=1 d=1 h=1\nend\nobject m 10 10 path=circle:5\n", 10, "expected circle:R:PERIOD_MS"},
    {ROOM_ "model m\npart box w=1 d=1 h=1\nend\nobject m 10 10 path=spiral:5:100\n", 10, "expected circle"},
    {ROOM_ "model m\npart box w=1 d=1 h=1\nend\nobject m 10 10 path=circle:0:100\n", 10, "radius out of range"},
    {ROOM_ "model m\npart box w=1 d=1 h=1\nend\nobject m 10 10 path=circle:5:0\n", 10, "period 0"},
    {ROOM_ "model m\npart box w=1 d=1 h=1\nend\nobject m 10 10 path=circle:5:3600001\n", 10, "period 3600001"},
    {ROOM_ "model m\npart box w=1 d=1 h=1\nend\nobject m 10 10 path=circle:5:1.5\n", 10, "period 1.5"},
    {ROOM_ "model m\npart box w=1 d=1 h=1\nend\nobject m 10 10 path=line:0:0:100\n", 10, "zero length"},
    {ROOM_ "model m\npart box w=1 d=1 h=1\nend\nobject m 10 10 path=line:1:2:3:4\n", 10, "expected circle"},
    {ROOM_ "model m\npart box w=1 d=1 h=1\nend\nobject m 32000 10 z=0 path=circle:800:100\n", 10,
     "leaves the world box"},
    {ROOM_ "model m\npart box w=1 d=1 h=1\nend\nobject m -32000 10 z=0 path=line:-800:0:100\n", 10,
     "leaves the world box"},
    {"sector a floor=0 ceil=64 door=63\n", 1, "door=H is below ceil"},
    {"sector a floor=0 ceil=64 door=16384\n", 1, "door=16384 out of range"},
    {"sector a floor=0 ceil=64 door=64 door=70\n", 1, "door given twice"},
#undef ROOM_
};

static void test_bad_text_scenes(void **state)
{
    (void)state;
    for (size_t i = 0; i < sizeof bad / sizeof bad[0]; i++) {
        uint8_t *b = NULL;
        size_t len = 0;
        char err[512] = "";
        char *path = NULL;
        int rc = compile_text(bad[i].text, BSPC_SPLIT_MIXED, &b, &len, NULL, err, sizeof err, &path);
        if (rc != -1 || !strstr(err, path) || !strstr(err, bad[i].needle))
            fprintf(stderr, "case %zu: rc %d, message '%s'\n", i, rc, err);
        assert_int_equal(rc, -1);
        assert_null(b);
        assert_non_null(strstr(err, path));
        assert_non_null(strstr(err, bad[i].needle));
        if (bad[i].line) {
            char want[600];
            snprintf(want, sizeof want, "%s:%d:", path, bad[i].line);
            if (!strstr(err, want)) fprintf(stderr, "case %zu: no '%s' in '%s'\n", i, want, err);
            assert_non_null(strstr(err, want));
        }
        unlink(path);
        free(path);
    }
}

static void test_missing_file(void **state)
{
    (void)state;
    uint8_t *b = NULL;
    size_t len = 0;
    char err[512];
    assert_int_equal(bspc_compile("/nonexistent/x.scene", NULL, &b, &len, NULL, err, sizeof err), -1);
    assert_non_null(strstr(err, "/nonexistent/x.scene"));
    assert_int_equal(bspc_compile("nosuchfile.wad:MAP01", NULL, &b, &len, NULL, err, sizeof err), -1);
    assert_non_null(strstr(err, "cannot find nosuchfile.wad"));
    /* a WAD without a map is looked for like one with a map (tests/test_bspc.py has
     * the message of one that exists: its maps) */
    assert_int_equal(bspc_compile("x.wad", NULL, &b, &len, NULL, err, sizeof err), -1);
    assert_non_null(strstr(err, "cannot find x.wad"));
}

static void test_wad_errors(void **state)
{
    (void)state;
    uint8_t *b = NULL;
    size_t len = 0;
    char err[512];
    if (have_freedoom2()) {
        assert_int_equal(bspc_compile("freedoom2.wad:MAP99", NULL, &b, &len, NULL, err, sizeof err), -1);
        assert_non_null(strstr(err, "freedoom2.wad:MAP99"));
        assert_non_null(strstr(err, "no map MAP99"));
    }
    /* a PWAD with one map whose linedef 1 names sidedef 9999 */
    uint8_t wad[1024];
    memset(wad, 0, sizeof wad);
    size_t at = 12;
    struct {
        const char *name;
        uint32_t pos, size;
    } dir[6];
    int nd = 0;
#define LUMP(nm)                                                                                                       \
    do {                                                                                                               \
        dir[nd].name = nm;                                                                                             \
        dir[nd].pos = (uint32_t)at;                                                                                    \
    } while (0)
#define END_LUMP() (dir[nd].size = (uint32_t)at - dir[nd].pos, nd++)
#define W16(v) (wad[at] = (uint8_t)((v)&255), wad[at + 1] = (uint8_t)(((v) >> 8) & 255), at += 2)
    LUMP("MAP01");
    END_LUMP();
    LUMP("THINGS");
    W16(32);
    W16(32);
    W16(0);
    W16(1);
    W16(7);
    END_LUMP();
    LUMP("LINEDEFS");
    int lines[4][2] = {{0, 1}, {1, 2}, {2, 3}, {3, 0}};
    for (int i = 0; i < 4; i++) {
        W16(lines[i][0]);
        W16(lines[i][1]);
        W16(1);
        W16(0);
        W16(0);
        W16(i == 1 ? 9999 : i);
        W16(0xFFFF);
    }
    END_LUMP();
    LUMP("SIDEDEFS");
    for (int i = 0; i < 4; i++) {
        W16(0);
        W16(0);
        memcpy(wad + at, "-\0\0\0\0\0\0\0-\0\0\0\0\0\0\0STARTAN3", 24);
        at += 24;
        W16(0);
    }
    END_LUMP();
    LUMP("VERTEXES");
    int vs[4][2] = {{0, 0}, {0, 64}, {64, 64}, {64, 0}};
    for (int i = 0; i < 4; i++) {
        W16(vs[i][0]);
        W16(vs[i][1]);
    }
    END_LUMP();
    LUMP("SECTORS");
    W16(0);
    W16(64);
    memcpy(wad + at, "FLOOR4_8CEIL3_5\0", 16);
    at += 16;
    W16(160);
    W16(0);
    W16(0);
    END_LUMP();
    uint32_t dirofs = (uint32_t)at;
    for (int i = 0; i < nd; i++) {
        uint32_t v[2] = {dir[i].pos, dir[i].size};
        for (int k = 0; k < 2; k++)
            for (int j = 0; j < 4; j++) wad[at++] = (uint8_t)(v[k] >> (8 * j));
        memset(wad + at, 0, 8);
        memcpy(wad + at, dir[i].name, strlen(dir[i].name));
        at += 8;
    }
    memcpy(wad, "PWAD", 4);
    for (int j = 0; j < 4; j++) wad[4 + j] = (uint8_t)((uint32_t)nd >> (8 * j));
    for (int j = 0; j < 4; j++) wad[8 + j] = (uint8_t)(dirofs >> (8 * j));
    char path[] = "/tmp/test_bsp_wad_XXXXXX";
    int fd = mkstemp(path);
    assert_true(fd >= 0);
    assert_int_equal(write(fd, wad, at), (ssize_t)at);
    close(fd);
    /* the name must end in .wad */
    char wpath[64], spec[80];
    snprintf(wpath, sizeof wpath, "%s.wad", path);
    assert_int_equal(rename(path, wpath), 0);
    snprintf(spec, sizeof spec, "%s:MAP01", wpath);
    assert_int_equal(bspc_compile(spec, NULL, &b, &len, NULL, err, sizeof err), -1);
    assert_non_null(strstr(err, spec));
    assert_non_null(strstr(err, "linedef 1: sidedef 9999 out of range (have 4)"));
    /* fix it: the map compiles */
    FILE *f = fopen(wpath, "r+b");
    assert_non_null(f);
    fseek(f, (long)(dir[2].pos + 14 + 10), SEEK_SET);
    uint8_t one[2] = {1, 0};
    fwrite(one, 1, 2, f);
    fclose(f);
    int rc = bspc_compile(spec, NULL, &b, &len, NULL, err, sizeof err);
    if (rc) fprintf(stderr, "%s\n", err);
    assert_int_equal(rc, 0);
    check_blob(b, len);
    free(b);
    b = NULL;
    /* a map without SECTORS */
    f = fopen(wpath, "r+b");
    assert_non_null(f);
    fseek(f, (long)(dirofs + 16 * 5 + 8), SEEK_SET);
    fwrite("SECTORX", 1, 7, f);
    fclose(f);
    assert_int_equal(bspc_compile(spec, NULL, &b, &len, NULL, err, sizeof err), -1);
    assert_non_null(strstr(err, "no SECTORS lump"));
    unlink(wpath);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_default_scene_all_strategies),
        cmocka_unit_test(test_diagonal_scene_fractional_splits),
        cmocka_unit_test(test_decimal_coordinates),
        cmocka_unit_test(test_extreme_scene),
        cmocka_unit_test(test_freedoom2_map01),
        cmocka_unit_test(test_objects_and_doors),
        cmocka_unit_test(test_freedoom2_map01_objects_and_doors),
        cmocka_unit_test(test_all_freedoom_maps),
        cmocka_unit_test(test_bad_text_scenes),
        cmocka_unit_test(test_missing_file),
        cmocka_unit_test(test_wad_errors),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
