/* leaf_poly.c - convex polygons of the BSP build: the region of each work item
 * and each leaf's floor polygon (SCN_SEC_PVERTS).
 *
 * A polygon is counter-clockwise; every vertex remembers the line its outgoing
 * edge lies on (a linedef's line, or a world-box edge). Cutting a polygon by a
 * line puts the new vertex at the exact intersection of the two *lines*
 * (bs_intersect), not of the rounded edge, so two leaves that meet the same
 * pair of lines get the same point bit for bit, and neighbours share corners.
 */
#include <stdlib.h>
#include <string.h>

#include "geom.h"

void bs_poly_free(bs_poly *p)
{
    free(p->v);
    p->v = NULL;
    p->n = p->cap = 0;
}

int bs_poly_push(bs_poly *p, int32_t x, int32_t y, uint32_t eline)
{
    if (bs_grow(&p->v, &p->cap, p->n + 1, sizeof(bs_pv))) return -1;
    p->v[p->n++] = (bs_pv){x, y, eline};
    return 0;
}

/* drop a point equal to the one after it (the later keeps its outgoing edge);
 * nothing moves until the first one dropped */
static void drop_repeats(bs_poly *p)
{
    uint32_t n = p->n, k = 0;
    for (uint32_t i = 0; i < n; i++) {
        const bs_pv *a = &p->v[i], *b = &p->v[i + 1 < n ? i + 1 : 0];
        if (n > 1 && a->x == b->x && a->y == b->y) continue;
        if (k != i) p->v[k] = *a;
        k++;
    }
    p->n = k;
}

/* twice the signed area: the sum of the cross products of each vertex and the
 * next (a repeated point adds 0, so repeats may be dropped before or after) */
static bs_i128 area2(const bs_pv *v, uint32_t n)
{
    bs_i128 area = 0;
    for (uint32_t i = 0; i < n; i++) {
        const bs_pv *a = &v[i], *b = &v[i + 1 < n ? i + 1 : 0];
        area += (int64_t)a->x * b->y - (int64_t)b->x * a->y; /* each term < 2^63 */
    }
    return area;
}

/* drop_repeats, then empty a polygon of fewer than 3 points or of no positive
 * area (area: area2 of the polygon) */
static void tidy_with_area(bs_poly *p, bs_i128 area)
{
    drop_repeats(p);
    if (p->n < 3 || area <= 0) p->n = 0;
}

void bs_poly_tidy(bs_poly *p)
{
    tidy_with_area(p, area2(p->v, p->n));
}

/* one output of a cut: keep side K (+1 front, -1 back) */
static int cut(const bs_poly *p, const int8_t *side, const int32_t *cx, const int32_t *cy, uint32_t pl, int K,
               bs_poly *out)
{
    uint32_t n = p->n, m = 0;
    /* each vertex gives at most itself and one crossing */
    if (n > UINT32_MAX / 2 || bs_grow(&out->v, &out->cap, 2 * n, sizeof(bs_pv))) return -1;
    bs_pv *o = out->v;
    for (uint32_t i = 0; i < n; i++) {
        const bs_pv *cur = &p->v[i];
        int sc = side[i], sn = side[i + 1 < n ? i + 1 : 0];
        if (sc == K) {
            o[m++] = *cur;
            if (sn == -K) o[m++] = (bs_pv){cx[i], cy[i], pl}; /* leaving */
        } else if (sc == 0) {
            o[m++] = (bs_pv){cur->x, cur->y, sn == -K ? pl : cur->eline};
        } else if (sn == K) {
            o[m++] = (bs_pv){cx[i], cy[i], cur->eline}; /* entering */
        }
    }
    out->n = m;
    tidy_with_area(out, area2(o, m));
    return 0;
}

static int split_core(const bs_tree *t, const bs_poly *p, uint32_t pl, uint32_t rev, bs_poly *front, bs_poly *back)
{
    if (front) front->n = 0;
    if (back) back->n = 0;
    uint32_t n = p->n;
    if (n == 0) return 0;
    int32_t buf[3 * 64];
    int32_t *cx = buf, *cy = buf + 64;
    int8_t *side = (int8_t *)(buf + 128);
    if (n > 64) { /* one block: the crossings' x, y, then the sides */
        cx = malloc((sizeof *cx * 2 + 1) * (size_t)n);
        if (!cx) return -1;
        cy = cx + n;
        side = (int8_t *)(cy + n);
    }
    int nf = 0, nb = 0;
    const bs_pline *L = &t->plines[pl];
    if (L->small) { /* bs_side with the line held in registers */
        const int64_t x0 = L->x, y0 = L->y, dx = L->rdx, dy = L->rdy, thr = L->thr;
        for (uint32_t i = 0; i < n; i++) {
            int64_t c = (p->v[i].x - x0) * dy - (p->v[i].y - y0) * dx;
            int sd = (c > thr) - (c < -thr);
            side[i] = (int8_t)(rev ? -sd : sd);
        }
    } else {
        for (uint32_t i = 0; i < n; i++) side[i] = (int8_t)bs_side(L, rev, p->v[i].x, p->v[i].y);
    }
    for (uint32_t i = 0; i < n; i++) {
        nf += side[i] > 0;
        nb += side[i] < 0;
    }
    for (uint32_t i = 0; i < n && nf && nb; i++) {
        uint32_t j = i + 1 < n ? i + 1 : 0;
        if (side[i] * side[j] < 0) {
            if (bs_intersect(t->plines, p->v[i].eline, pl, &cx[i], &cy[i])) {
                /* edge parallel to the line yet crossing it: only by rounding; use the midpoint */
                cx[i] = (int32_t)(((int64_t)p->v[i].x + p->v[j].x) / 2);
                cy[i] = (int32_t)(((int64_t)p->v[i].y + p->v[j].y) / 2);
            }
        }
    }
    int rc = 0;
    if (front) {
        if (nb == 0) { /* wholly in front (or on the line) */
            if (bs_grow(&front->v, &front->cap, n, sizeof(bs_pv)) == 0) {
                memcpy(front->v, p->v, sizeof(bs_pv) * n);
                front->n = n;
                if (nf == 0) front->n = 0; /* flat on the line: degenerate */
            } else {
                rc = -1;
            }
        } else if (nf > 0) {
            rc = cut(p, side, cx, cy, pl, +1, front);
        }
    }
    if (back && rc == 0) {
        if (nf == 0) {
            if (bs_grow(&back->v, &back->cap, n, sizeof(bs_pv)) == 0) {
                memcpy(back->v, p->v, sizeof(bs_pv) * n);
                back->n = n;
                if (nb == 0) back->n = 0;
            } else {
                rc = -1;
            }
        } else if (nb > 0) {
            rc = cut(p, side, cx, cy, pl, -1, back);
        }
    }
    if (cx != buf) free(cx);
    return rc;
}

int bs_poly_split(const bs_tree *t, const bs_poly *p, uint32_t pl, uint32_t rev, bs_poly *front, bs_poly *back)
{
    memset(front, 0, sizeof *front);
    memset(back, 0, sizeof *back);
    return split_core(t, p, pl, rev, front, back);
}

int bs_poly_clip_front(const bs_tree *t, bs_poly *p, uint32_t pl, uint32_t rev)
{
    bs_poly f;
    memset(&f, 0, sizeof f);
    if (split_core(t, p, pl, rev, &f, NULL)) {
        bs_poly_free(&f);
        return -1;
    }
    bs_poly_free(p);
    *p = f;
    return 0;
}
