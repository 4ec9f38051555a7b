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

void bs_poly_tidy(bs_poly *p)
{
    /* drop a point equal to the one after it (the later keeps its outgoing edge) */
    uint32_t n = p->n, k = 0;
    for (uint32_t i = 0; i < n; i++) {
        const bs_pv *a = &p->v[i], *b = &p->v[(i + 1) % n];
        if (n > 1 && a->x == b->x && a->y == b->y) continue;
        p->v[k++] = *a;
    }
    p->n = k;
    if (p->n < 3) {
        p->n = 0;
        return;
    }
    bs_i128 area = 0;
    for (uint32_t i = 0; i < p->n; i++) {
        const bs_pv *a = &p->v[i], *b = &p->v[(i + 1) % p->n];
        area += (bs_i128)a->x * b->y - (bs_i128)b->x * a->y;
    }
    if (area <= 0) p->n = 0;
}

/* one output of a cut: keep side K (+1 front, -1 back) */
static int cut(const bs_tree *t, const bs_poly *p, const int8_t *side, const int32_t *cx, const int32_t *cy,
               uint32_t pl, int K, bs_poly *out)
{
    uint32_t n = p->n;
    out->n = 0;
    for (uint32_t i = 0; i < n; i++) {
        const bs_pv *cur = &p->v[i];
        uint32_t j = (i + 1) % n;
        int sc = side[i], sn = side[j];
        if (sc == K) {
            if (bs_poly_push(out, cur->x, cur->y, cur->eline)) return -1;
            if (sn == -K && bs_poly_push(out, cx[i], cy[i], pl)) return -1; /* leaving */
        } else if (sc == 0) {
            if (bs_poly_push(out, cur->x, cur->y, sn == -K ? pl : cur->eline)) return -1;
        } else if (sn == K) {
            if (bs_poly_push(out, cx[i], cy[i], cur->eline)) return -1; /* entering */
        }
    }
    (void)t;
    bs_poly_tidy(out);
    return 0;
}

static int split_core(const bs_tree *t, const bs_poly *p, uint32_t pl, uint32_t rev, bs_poly *front, bs_poly *back)
{
    if (front) front->n = 0;
    if (back) back->n = 0;
    uint32_t n = p->n;
    if (n == 0) return 0;
    int8_t sbuf[64];
    int32_t xbuf[64], ybuf[64];
    int8_t *side = sbuf;
    int32_t *cx = xbuf, *cy = ybuf;
    if (n > 64) {
        side = malloc(n);
        cx = malloc(sizeof *cx * n);
        cy = malloc(sizeof *cy * n);
        if (!side || !cx || !cy) {
            free(side == sbuf ? NULL : side);
            free(cx == xbuf ? NULL : cx);
            free(cy == ybuf ? NULL : cy);
            return -1;
        }
    }
    int nf = 0, nb = 0;
    for (uint32_t i = 0; i < n; i++) {
        side[i] = (int8_t)bs_side(&t->plines[pl], rev, p->v[i].x, p->v[i].y);
        nf += side[i] > 0;
        nb += side[i] < 0;
    }
    for (uint32_t i = 0; i < n; i++) {
        uint32_t j = (i + 1) % n;
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
            rc = cut(t, p, side, cx, cy, pl, +1, front);
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
            rc = cut(t, p, side, cx, cy, pl, -1, back);
        }
    }
    if (side != sbuf) {
        free(side);
        free(cx);
        free(cy);
    }
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
