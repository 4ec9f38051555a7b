/* tjunc.c - T-junction removal after the tree build.
 *
 * Segs: every vertex that lies on the interior of a seg (within BS_TJ_TOL of it,
 * strictly between its ends) splits the seg there; the pieces stay in the same
 * leaf. This catches map vertices that end on another line and split points
 * made on one side of a two-sided line that the other side never saw.
 *
 * Leaf polygons: every leaf-polygon vertex and seg vertex that lies on the
 * interior of a leaf polygon's edge is inserted into that edge, so an edge
 * shared by two leaves has the same vertices on both sides.
 *
 * Both passes look points up in a uniform grid; inserted points come from the
 * same point set, so one pass reaches the fixed point.
 */
#include <stdlib.h>
#include <string.h>

#include "geom.h"

#define BS_TJ_TOL 3 /* raw units: a point this close to a seg or edge lies on it */

typedef struct {
    int64_t x0, y0;
    int shift;
    uint32_t nx, ny;
    uint32_t *start; /* nx * ny + 1 */
    uint32_t *pts;   /* point indices by cell */
} grid;

static int grid_build(grid *g, const bs_tree *t, const int32_t *px, const int32_t *py, uint32_t n)
{
    memset(g, 0, sizeof *g);
    g->x0 = t->world[0];
    g->y0 = t->world[1];
    int64_t w = (int64_t)t->world[2] - t->world[0] + 1, h = (int64_t)t->world[3] - t->world[1] + 1;
    g->shift = 20; /* 16 units */
    while ((w >> g->shift) * (h >> g->shift) > 4 * (int64_t)n + 1024) g->shift++;
    g->nx = (uint32_t)(w >> g->shift) + 1;
    g->ny = (uint32_t)(h >> g->shift) + 1;
    size_t cells = (size_t)g->nx * g->ny;
    g->start = calloc(cells + 1, sizeof *g->start);
    g->pts = malloc(sizeof *g->pts * (n + 1));
    uint32_t *cell = malloc(sizeof *cell * (n + 1));
    if (!g->start || !g->pts || !cell) {
        free(cell);
        return -1;
    }
    for (uint32_t i = 0; i < n; i++) {
        int64_t cx = ((int64_t)px[i] - g->x0) >> g->shift, cy = ((int64_t)py[i] - g->y0) >> g->shift;
        if (cx < 0) cx = 0;
        if (cy < 0) cy = 0;
        if (cx >= g->nx) cx = g->nx - 1;
        if (cy >= g->ny) cy = g->ny - 1;
        cell[i] = (uint32_t)(cy * g->nx + cx);
        g->start[cell[i] + 1]++;
    }
    for (size_t c = 0; c < cells; c++) g->start[c + 1] += g->start[c];
    uint32_t *fill = malloc(sizeof *fill * (cells + 1));
    if (!fill) {
        free(cell);
        return -1;
    }
    memcpy(fill, g->start, sizeof *fill * (cells + 1));
    for (uint32_t i = 0; i < n; i++) g->pts[fill[cell[i]]++] = i;
    free(fill);
    free(cell);
    return 0;
}

static void grid_free(grid *g)
{
    free(g->start);
    free(g->pts);
}

typedef struct {
    int32_t x, y;
    bs_i128 along; /* (P - A) . (B - A) */
    uint32_t seq;  /* order found: equal distances keep it */
} hit;

typedef struct {
    hit *h;
    uint32_t n, cap;
} hits;

static int hit_cmp(const void *a, const void *b)
{
    const hit *p = a, *q = b;
    if (p->along != q->along) return p->along > q->along ? 1 : -1;
    return (p->seq > q->seq) - (p->seq < q->seq);
}

/* points of the grid strictly inside segment A-B (within BS_TJ_TOL of it), sorted from A */
static int find_on_segment(const grid *g, const int32_t *px, const int32_t *py, int32_t ax, int32_t ay, int32_t bx,
                           int32_t by, hits *out)
{
    out->n = 0;
    int64_t dx = (int64_t)bx - ax, dy = (int64_t)by - ay;
    bs_i128 len2 = (bs_i128)dx * dx + (bs_i128)dy * dy;
    if (len2 == 0) return 0;
    bs_i128 thr = -1; /* the tolerance on the cross product, found for the first point near (most segs have none) */
    int64_t x0 = (ax < bx ? ax : bx) - BS_TJ_TOL, x1 = (ax > bx ? ax : bx) + BS_TJ_TOL;
    int64_t y0 = (ay < by ? ay : by) - BS_TJ_TOL, y1 = (ay > by ? ay : by) + BS_TJ_TOL;
    int64_t cx0 = (x0 - g->x0) >> g->shift, cx1 = (x1 - g->x0) >> g->shift;
    int64_t cy0 = (y0 - g->y0) >> g->shift, cy1 = (y1 - g->y0) >> g->shift;
    if (cx0 < 0) cx0 = 0;
    if (cy0 < 0) cy0 = 0;
    if (cx1 >= g->nx) cx1 = g->nx - 1;
    if (cy1 >= g->ny) cy1 = g->ny - 1;
    /* walk only the cells near the segment: for each row, the columns its
     * bounding strip crosses (a long diagonal touches few cells per row; the
     * range is widened by a cell, so rounding in it loses no point) */
    const double per_y = dy ? 1.0 / (double)dy : 0, per_cell = 1.0 / (double)((int64_t)1 << g->shift);
    for (int64_t cy = cy0; cy <= cy1; cy++) {
        int64_t rx0 = cx0, rx1 = cx1;
        if (dy != 0 && dx != 0) {
            /* x range of the segment within this row's y band, widened by one cell */
            int64_t ylo = g->y0 + (cy << g->shift) - BS_TJ_TOL;
            int64_t yhi = ylo + ((int64_t)1 << g->shift) + 2 * BS_TJ_TOL;
            if (ylo < y0) ylo = y0;
            if (yhi > y1) yhi = y1;
            double t0 = ((double)ylo - ay) * per_y, t1 = ((double)yhi - ay) * per_y;
            double xa = ax + t0 * (double)dx, xb = ax + t1 * (double)dx;
            double lo = xa < xb ? xa : xb, hi = xa > xb ? xa : xb;
            int64_t c0 = (int64_t)((lo - (double)g->x0) * per_cell) - 1;
            int64_t c1 = (int64_t)((hi - (double)g->x0) * per_cell) + 1;
            if (c0 > rx0) rx0 = c0;
            if (c1 < rx1) rx1 = c1;
        }
        for (int64_t cx = rx0; cx <= rx1; cx++) {
            size_t c = (size_t)cy * g->nx + (size_t)cx;
            for (uint32_t k = g->start[c]; k < g->start[c + 1]; k++) {
                uint32_t i = g->pts[k];
                int64_t qx = px[i], qy = py[i];
                if (qx < x0 || qx > x1 || qy < y0 || qy > y1) continue;
                if ((qx == ax && qy == ay) || (qx == bx && qy == by)) continue;
                if (thr < 0) thr = (bs_i128)bs_isqrt((bs_u128)(BS_TJ_TOL * BS_TJ_TOL) * (bs_u128)len2);
                bs_i128 cr = (bs_i128)(qx - ax) * dy - (bs_i128)(qy - ay) * dx;
                if (cr > thr || cr < -thr) continue;
                bs_i128 along = (bs_i128)(qx - ax) * dx + (bs_i128)(qy - ay) * dy;
                if (along <= 0 || along >= len2) continue;
                if (bs_grow(&out->h, &out->cap, out->n + 1, sizeof(hit))) return -1;
                out->h[out->n] = (hit){(int32_t)qx, (int32_t)qy, along, out->n};
                out->n++;
            }
        }
    }
    /* sort by distance from A and drop repeats: a damaged map can put thousands
     * of points on one seg, so no quadratic sort */
    if (out->n > 1) qsort(out->h, out->n, sizeof *out->h, hit_cmp);
    uint32_t k = 0;
    for (uint32_t i = 0; i < out->n; i++) {
        if (k > 0 && out->h[k - 1].x == out->h[i].x && out->h[k - 1].y == out->h[i].y) continue;
        out->h[k++] = out->h[i];
    }
    out->n = k;
    return 0;
}

int bs_tjunc_segs(bs_tree *t, const char *name, char *err, size_t errlen)
{
    /* the point set: every vertex some seg uses */
    uint8_t *used = calloc(t->nverts + 1, 1);
    if (!used) return bs_fail(err, errlen, "out of memory");
    for (uint32_t i = 0; i < t->nsegs; i++) used[t->segs[i].v1] = used[t->segs[i].v2] = 1;
    uint32_t n = 0;
    int32_t *px = malloc(sizeof *px * (t->nverts + 1)), *py = malloc(sizeof *py * (t->nverts + 1));
    uint32_t *vid = malloc(sizeof *vid * (t->nverts + 1));
    grid g;
    memset(&g, 0, sizeof g);
    hits H = {NULL, 0, 0};
    int rc = -1;
    if (!px || !py || !vid) goto out;
    for (uint32_t i = 0; i < t->nverts; i++)
        if (used[i]) {
            px[n] = t->vx[i];
            py[n] = t->vy[i];
            vid[n++] = i;
        }
    if (grid_build(&g, t, px, py, n)) goto out;
    for (uint32_t li = 0; li < t->nleaves; li++) {
        bs_leaf *L = &t->leaves[li];
        uint32_t nseg0 = L->nsegs;
        for (uint32_t k = 0; k < nseg0; k++) {
            uint32_t si = L->segs[k];
            bs_seg g0 = t->segs[si];
            if (find_on_segment(&g, px, py, g0.x1, g0.y1, g0.x2, g0.y2, &H)) goto out;
            if (H.n == 0) continue;
            if (bs_seg_budget_check(t, name, H.n, g0.line, err, errlen)) goto out;
            /* pieces: v1 -> h0 -> h1 ... -> v2; the first piece keeps index si */
            if (bs_grow(&t->segs, &t->segcap, t->nsegs + H.n, sizeof(bs_seg))) goto out;
            if (bs_grow(&L->segs, &L->cap, L->nsegs + H.n, sizeof(uint32_t))) goto out;
            int32_t cx = g0.x1, cy = g0.y1;
            uint32_t cv = g0.v1;
            for (uint32_t h = 0; h <= H.n; h++) {
                int32_t nx = h < H.n ? H.h[h].x : g0.x2, ny = h < H.n ? H.h[h].y : g0.y2;
                uint32_t nv = h < H.n ? bs_vertex(t, nx, ny) : g0.v2;
                if (nv == SCN_NONE) goto out;
                bs_seg piece = g0;
                piece.x1 = cx;
                piece.y1 = cy;
                piece.v1 = cv;
                piece.x2 = nx;
                piece.y2 = ny;
                piece.v2 = nv;
                if (h == 0) {
                    t->segs[si] = piece;
                } else {
                    t->segs[t->nsegs] = piece;
                    L->segs[L->nsegs++] = t->nsegs++;
                    t->tj_splits++;
                }
                cx = nx;
                cy = ny;
                cv = nv;
            }
        }
    }
    rc = 0;
out:
    if (rc) bs_fail(err, errlen, "out of memory");
    free(H.h);
    grid_free(&g);
    free(used);
    free(px);
    free(py);
    free(vid);
    return rc;
}

int bs_tjunc_polys(bs_tree *t, char *err, size_t errlen)
{
    /* the point set: every polygon vertex and every seg vertex */
    uint64_t total = 0;
    for (uint32_t i = 0; i < t->nleaves; i++) total += t->leaves[i].poly.n;
    total += t->nverts;
    if (total >= UINT32_MAX / 2) return bs_fail(err, errlen, "too many points");
    int32_t *px = malloc(sizeof *px * (total + 1)), *py = malloc(sizeof *py * (total + 1));
    grid g;
    memset(&g, 0, sizeof g);
    hits H = {NULL, 0, 0};
    bs_poly np = {NULL, 0, 0};
    int rc = -1;
    if (!px || !py) goto out;
    uint32_t n = 0;
    for (uint32_t i = 0; i < t->nleaves; i++)
        for (uint32_t k = 0; k < t->leaves[i].poly.n; k++) {
            px[n] = t->leaves[i].poly.v[k].x;
            py[n++] = t->leaves[i].poly.v[k].y;
        }
    {
        uint8_t *used = calloc(t->nverts + 1, 1);
        if (!used) goto out;
        for (uint32_t i = 0; i < t->nsegs; i++) used[t->segs[i].v1] = used[t->segs[i].v2] = 1;
        for (uint32_t i = 0; i < t->nverts; i++)
            if (used[i]) {
                px[n] = t->vx[i];
                py[n++] = t->vy[i];
            }
        free(used);
    }
    if (grid_build(&g, t, px, py, n)) goto out;
    for (uint32_t li = 0; li < t->nleaves; li++) {
        bs_poly *P = &t->leaves[li].poly;
        if (P->n == 0) continue;
        np.n = 0;
        for (uint32_t k = 0; k < P->n; k++) {
            const bs_pv a = P->v[k], b = P->v[(k + 1) % P->n];
            if (bs_poly_push(&np, a.x, a.y, a.eline)) goto out;
            if (find_on_segment(&g, px, py, a.x, a.y, b.x, b.y, &H)) goto out;
            for (uint32_t h = 0; h < H.n; h++) {
                if (bs_poly_push(&np, H.h[h].x, H.h[h].y, a.eline)) goto out;
                t->tj_pverts++;
            }
        }
        if (np.n != P->n) {
            bs_poly tmp = *P;
            *P = np;
            np = tmp;
        }
    }
    rc = 0;
out:
    if (rc) bs_fail(err, errlen, "out of memory");
    bs_poly_free(&np);
    free(H.h);
    grid_free(&g);
    free(px);
    free(py);
    return rc;
}
