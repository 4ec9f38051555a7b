/* collide_geom.c - exact integer geometry of the collision code on the
 * 1/4096-unit grid (collide_int.h): point to segment distance, segment
 * crossing, the swept circle, wall normals, and the box tests by which
 * bsp_walk.c's walk finds candidate segs (as Doom's p_maputl.c serves p_map.c
 * and p_sight.c).
 *
 * Ranges. Map coordinates are inside +-SCN_COORD_MAX units (vertices by the
 * loader, positions clamped by the callers), so a grid coordinate (16.16 >> 4)
 * is below 2^27 in magnitude, a difference of two below 2^28, a product of two
 * differences below 2^56 and a cross or dot product below 2^57: all int64. A
 * squared distance compared with r^2 * |ab|^2 (up to 2^114) goes through the
 * exact 128-bit w128_sign_diff(). Nothing here divides by a value that can be 0.
 */
#include "collide_int.h"

/* ------------------------------------------------------------ grid geometry */
/* 1 if the distance from p to the closed segment ab is below r (r2 = r*r, r < 2^23). */
int colg_near_seg(grid_pt p, grid_pt a, grid_pt b, int64_t r, int64_t r2)
{
    if (p.x + r <= min64(a.x, b.x) || p.x - r >= max64(a.x, b.x) || p.y + r <= min64(a.y, b.y) ||
        p.y - r >= max64(a.y, b.y))
        return 0;
    int64_t abx = b.x - a.x, aby = b.y - a.y, apx = p.x - a.x, apy = p.y - a.y;
    int64_t t = abx * apx + aby * apy;
    if (t <= 0) return apx * apx + apy * apy < r2;
    int64_t l2 = abx * abx + aby * aby;
    if (t >= l2) {
        int64_t bpx = p.x - b.x, bpy = p.y - b.y;
        return bpx * bpx + bpy * bpy < r2;
    }
    int64_t c = abx * apy - aby * apx;
    return w128_sign_diff(c, c, r2, l2) < 0; /* c^2 / l2 < r^2 */
}

/* Distance from p to the closed segment ab in grid units, rounded down (for
 * comparisons that need no exactness). */
int64_t colg_dist_seg(grid_pt p, grid_pt a, grid_pt b)
{
    int64_t abx = b.x - a.x, aby = b.y - a.y, apx = p.x - a.x, apy = p.y - a.y;
    int64_t t = abx * apx + aby * apy;
    int64_t l2 = abx * abx + aby * aby;
    if (t <= 0) return (int64_t)fx_isqrt64((uint64_t)(apx * apx + apy * apy));
    if (t >= l2) {
        int64_t bpx = p.x - b.x, bpy = p.y - b.y;
        return (int64_t)fx_isqrt64((uint64_t)(bpx * bpx + bpy * bpy));
    }
    int64_t len = (int64_t)fx_isqrt64((uint64_t)l2); /* >= 1: l2 > t > 0 */
    return (int64_t)(w128_uabs(abx * apy - aby * apx) / (uint64_t)len);
}

/* 1 if the closed segments pq and ab share a point. */
int colg_seg_cross(grid_pt p, grid_pt q, grid_pt a, grid_pt b)
{
    int d1 = sgn64(orient(a, b, p)), d2 = sgn64(orient(a, b, q));
    int d3 = sgn64(orient(p, q, a)), d4 = sgn64(orient(p, q, b));
    if (d1 * d2 > 0 || d3 * d4 > 0) return 0;
    if (d1 || d2 || d3 || d4) return 1;
    /* collinear (or a point): the boxes must overlap */
    return max64(min64(p.x, q.x), min64(a.x, b.x)) <= min64(max64(p.x, q.x), max64(a.x, b.x)) &&
           max64(min64(p.y, q.y), min64(a.y, b.y)) <= min64(max64(p.y, q.y), max64(a.y, b.y));
}

/* 1 if a circle of radius r moving along pq comes nearer than r to segment ab:
 * the distance between two segments is 0 if they cross, else the least of the
 * four end-point-to-segment distances. */
int colg_sweep_near(grid_pt p, grid_pt q, grid_pt a, grid_pt b, int64_t r, int64_t r2)
{
    return colg_seg_cross(p, q, a, b) || colg_near_seg(p, a, b, r, r2) || colg_near_seg(q, a, b, r, r2) ||
           colg_near_seg(a, p, q, r, r2) || colg_near_seg(b, p, q, r, r2);
}

/* (vx, vy) scaled to length 2^30 (2.30); 0 for the zero vector. |v| < 2^62. */
static int unit_vec(int64_t vx, int64_t vy, int32_t *nx, int32_t *ny)
{
    uint64_t m = w128_uabs(vx) > w128_uabs(vy) ? w128_uabs(vx) : w128_uabs(vy);
    if (m == 0) return 0;
    while (m < ((uint64_t)1 << 28)) {
        vx *= 2;
        vy *= 2;
        m <<= 1;
    }
    while (m >= ((uint64_t)1 << 29)) {
        vx = fx_asr64(vx, 1);
        vy = fx_asr64(vy, 1);
        m >>= 1;
    }
    /* |vx|, |vy| < 2^29: the square sum is below 2^59, its root at least max(|vx|, |vy|) */
    int64_t len = (int64_t)fx_isqrt64((uint64_t)(vx * vx + vy * vy));
    *nx = (int32_t)(vx * ((int64_t)1 << UNIT_SHIFT) / len);
    *ny = (int32_t)(vy * ((int64_t)1 << UNIT_SHIFT) / len);
    return 1;
}

/* The unit normal of segment ab at its point nearest p, pointing at p (the seg's
 * front normal if p is on it). */
int colg_seg_normal(grid_pt p, grid_pt a, grid_pt b, int32_t *nx, int32_t *ny)
{
    int64_t abx = b.x - a.x, aby = b.y - a.y, apx = p.x - a.x, apy = p.y - a.y;
    int64_t t = abx * apx + aby * apy, l2 = abx * abx + aby * aby;
    int64_t vx, vy;
    if (t <= 0) {
        vx = apx;
        vy = apy;
    } else if (t >= l2) {
        vx = p.x - b.x;
        vy = p.y - b.y;
    } else if (abx * apy - aby * apx > 0) { /* behind: left normal */
        vx = -aby;
        vy = abx;
    } else {
        vx = aby;
        vy = -abx;
    }
    if (vx == 0 && vy == 0) {
        vx = aby;
        vy = -abx;
    }
    return unit_vec(vx, vy, nx, ny);
}

/* ------------------------------------------------------------ tree walk */

static int box_meets(const int32_t bb[BOX_SIDES], const query_box *b)
{
    return bb[BOX_LEFT] <= b->x1 && bb[BOX_RIGHT] >= b->x0 && bb[BOX_BOTTOM] <= b->y1 && bb[BOX_TOP] >= b->y0;
}

/* 1 unless the line through p, q leaves every corner of bb strictly on one side. */
static int line_meets(const int32_t bb[BOX_SIDES], grid_pt p, grid_pt q)
{
    grid_pt lo = to_grid(bb[BOX_LEFT], bb[BOX_BOTTOM]), hi = to_grid(bb[BOX_RIGHT], bb[BOX_TOP]);
    grid_pt c[4] = {{lo.x, lo.y}, {hi.x, lo.y}, {hi.x, hi.y}, {lo.x, hi.y}};
    int pos = 0, neg = 0;
    for (int k = 0; k < 4; k++) {
        int64_t o = orient(p, q, c[k]);
        pos |= o >= 0;
        neg |= o <= 0;
    }
    return pos && neg;
}

typedef struct {
    const query_box *box;
    const grid_pt *line; /* NULL: any box that overlaps box */
} tree_query;

static int query_meets(void *ctx, const int32_t bb[BOX_SIDES], unsigned state)
{
    const tree_query *q = ctx;
    if (!box_meets(bb, q->box) || (q->line && !line_meets(bb, q->line[0], q->line[1]))) return -1;
    return (int)state;
}

/* Visit every leaf under a node box that overlaps b (and, with line, that the
 * line through line[0], line[1] meets), child 0 first. Returns 1 if fn stopped
 * the walk. */
int colg_walk_leaves(const scene *s, const query_box *b, const grid_pt *line, walk_visit fn, void *ctx)
{
    tree_query q = {b, line};
    const walk_rules rules = {0, query_meets, fn, ctx, 0};
    return walk_boxes(s, &rules, &q, 0, 0);
}
