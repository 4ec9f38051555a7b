/* clip.c - Sutherland-Hodgman clipping of convex polygons in view space.
 * The intersection on an edge is always computed from its inside end toward its
 * outside end, so two polygons sharing an edge get bit-identical clipped vertices
 * whichever way round they walk it: no cracks between neighbouring walls. */
#include "clip.h"

int64_t clip_distance(const view_xform *v, view_pt p, unsigned plane)
{
    switch (plane) {
    case CLIP_NEAR: return (int64_t)p.z - VIEW_ZNEAR;
    case CLIP_LEFT: return (int64_t)p.z + p.x;
    case CLIP_RIGHT: return (int64_t)p.z - p.x;
    case CLIP_TOP: return (int64_t)(VIEW_CY + VIEW_LOOK(v)) * p.z - (int64_t)VIEW_FOCAL * p.y;
    default: return (int64_t)(VIEW_CY - VIEW_LOOK(v)) * p.z + (int64_t)VIEW_FOCAL * p.y;
    }
}

/* The point where edge a->b crosses the plane, with da >= 0 > db. The parameter
 * t = da / (da - db) is formed in 2.30 after scaling both distances below 2^31,
 * so (b - a) * t < 2^32 * 2^30 fits in 64 bits. */
static view_pt intersect(view_pt a, int64_t da, view_pt b, int64_t db)
{
    uint64_t den = (uint64_t)(da - db);
    uint64_t num = (uint64_t)da;
    while (den >= (1ull << 31)) {
        den >>= 1;
        num >>= 1;
    }
#if FX_DIV32
    /* num <= den < 2^31: t <= 2^30 (docs/ranges.md) */
    uint32_t rem;
    int64_t t = den ? (int64_t)fx_udiv64_32(num << 30, (uint32_t)den, &rem) : 0;
#else
    int64_t t = den ? (int64_t)((num << 30) / den) : 0;
#endif
    view_pt r;
    r.x = a.x + (int32_t)fx_asr64(((int64_t)b.x - a.x) * t, 30);
    r.y = a.y + (int32_t)fx_asr64(((int64_t)b.y - a.y) * t, 30);
    r.z = a.z + (int32_t)fx_asr64(((int64_t)b.z - a.z) * t, 30);
    return r;
}

static int clip_plane(clip_poly *p, const view_xform *v, unsigned plane)
{
    view_pt out[CLIP_MAX_VERTS];
    uint8_t on[CLIP_MAX_VERTS];
    int64_t d[CLIP_MAX_VERTS];
    int n = p->n, m = 0, inside = 0;
    for (int i = 0; i < n; i++) {
        d[i] = clip_distance(v, p->v[i], plane);
        inside += d[i] >= 0;
    }
    if (inside == n) return n;
    p->cut |= plane;
    if (inside == 0) return p->n = 0;
    for (int i = 0; i < n && m < CLIP_MAX_VERTS - 1; i++) {
        int j = (i + 1 == n) ? 0 : i + 1;
        if (d[i] >= 0) {
            on[m] = p->on[i];
            out[m++] = p->v[i];
        }
        if ((d[i] >= 0) != (d[j] >= 0)) {
            /* on this plane, and on any earlier plane both ends lie on */
            on[m] = (uint8_t)(plane | (p->on[i] & p->on[j]));
            out[m++] = (d[i] >= 0) ? intersect(p->v[i], d[i], p->v[j], d[j]) : intersect(p->v[j], d[j], p->v[i], d[i]);
        }
    }
    for (int i = 0; i < m; i++) {
        p->v[i] = out[i];
        p->on[i] = on[i];
    }
    return p->n = m;
}

int clip_polygon(clip_poly *p, const view_xform *v, unsigned mask)
{
    if (p->n > CLIP_MAX_VERTS - 5 || p->n < 0) p->n = 0; /* caller broke the contract: draw nothing */
    for (int i = 0; i < p->n; i++) p->on[i] = 0;
    p->cut = 0;
    if (!CFG_YCLIP) mask &= ~(unsigned)(CLIP_TOP | CLIP_BOTTOM);
    for (unsigned plane = 1; plane <= CLIP_BOTTOM && p->n >= 3; plane <<= 1)
        if (mask & plane) clip_plane(p, v, plane);
    return p->n >= 3 ? p->n : 0;
}

int clip_wall_x(const view_xform *v, view_pt p, view_pt q, unsigned mask, int32_t *xp, int32_t *xq)
{
    view_pt e[2] = {p, q};
    uint8_t on[2] = {0, 0};
    for (unsigned plane = CLIP_NEAR; plane <= CLIP_RIGHT; plane <<= 1) {
        if (!(mask & plane)) continue;
        int64_t d0 = clip_distance(v, e[0], plane), d1 = clip_distance(v, e[1], plane);
        if (d0 >= 0 && d1 >= 0) continue;
        if (d0 < 0 && d1 < 0) return 0;
        /* the quad's edge between the two ends is cut from its inside end, as in clip_plane */
        int out = d0 < 0 ? 0 : 1;
        e[out] = out ? intersect(e[0], d0, e[1], d1) : intersect(e[1], d1, e[0], d0);
        on[out] = (uint8_t)(plane | (on[0] & on[1]));
    }
    int32_t x[2];
    for (int i = 0; i < 2; i++)
        x[i] = (on[i] & CLIP_RIGHT) ? VIEW_W_FX : (on[i] & CLIP_LEFT) ? 0 : view_project_x(e[i]);
    *xp = x[0];
    *xq = x[1];
    return 1;
}

void clip_project(const view_xform *v, const clip_poly *p, screen_pt *out)
{
    for (int i = 0; i < p->n; i++) {
        out[i] = view_project(v, p->v[i]);
        if (p->on[i] & CLIP_LEFT) out[i].x = 0;
        if (p->on[i] & CLIP_RIGHT) out[i].x = VIEW_W_FX;
        if (p->on[i] & CLIP_TOP) out[i].y = 0;
        if (p->on[i] & CLIP_BOTTOM) out[i].y = VIEW_H_FX;
    }
}
