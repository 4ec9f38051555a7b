/* collide_sight.c - line of sight through the world (col_line_of_sight,
 * collide.h), as Doom's p_sight.c: the segs the 3-D segment crosses, found by a
 * box-and-line walk of the tree, and the openings of the two-sided ones.
 * Geometry and ranges: collide_geom.c.
 */
#include "collide.h"

#include "collide_int.h"

/* ------------------------------------------------------------ line of sight */

typedef struct {
    const scene *s;
    const world_state *w;
    grid_pt p, q;
    int64_t gx0, gy0, gx1, gy1; /* box of pq on the grid */
    int64_t z1, z2;
} sight_check;

/* Is the height z1 + (z2 - z1) * num / den (0 <= num <= den, den > 0) above hi
 * or below lo? |z1 - hi|, |z2 - z1| < 2^33 and den < 2^59: exact via w128_sign_diff. */
static int z_outside(const sight_check *c, int64_t num, int64_t den, int64_t lo, int64_t hi)
{
    int64_t dz = c->z2 - c->z1;
    if (w128_sign_diff(c->z1 - hi, den, -dz, num) > 0) return 1; /* (z1-hi)*den + dz*num > 0 */
    return w128_sign_diff(c->z1 - lo, den, -dz, num) < 0;        /* (z1-lo)*den + dz*num < 0 */
}

static int sight_leaf(void *vctx, uint32_t leaf, unsigned state)
{
    (void)state;
    sight_check *c = (sight_check *)vctx;
    const scene *s = c->s;
    const scn_leaf *l = &s->leaves[leaf];
    for (uint32_t i = 0; i < l->num_segs; i++) {
        const scn_seg *g = &s->segs[l->first_seg + i];
        grid_pt a = vert(s, g->v1), b = vert(s, g->v2);
        if (max64(a.x, b.x) < c->gx0 || min64(a.x, b.x) > c->gx1 || max64(a.y, b.y) < c->gy0 ||
            min64(a.y, b.y) > c->gy1)
            continue;
        if (!colg_seg_cross(c->p, c->q, a, b)) continue;
        const scn_line *ln = &s->lines[g->line];
        if (!CFG_TWO_SIDED || ln->sector[1] == SCN_NONE) return 1;
        const scn_sector *f = &s->sectors[ln->sector[0]], *k = &s->sectors[ln->sector[1]];
        int64_t lo = max64(f->floor_h, k->floor_h);
        int64_t hi = min64(obj_ceil(c->w, s, ln->sector[0]), obj_ceil(c->w, s, ln->sector[1]));
        if (hi <= lo) return 1; /* closed (a shut door): nothing passes, not even on the edge */
        int64_t o1 = orient(a, b, c->p), o2 = orient(a, b, c->q);
        if (o1 != o2) { /* crosses at t = o1 / (o1 - o2), in [0, 1] */
            int64_t num = o1, den = o1 - o2;
            if (den < 0) {
                num = -num;
                den = -den;
            }
            if (z_outside(c, num, den, lo, hi)) return 1;
            continue;
        }
        /* along the wall: the heights where the overlap starts and ends */
        int64_t dx = c->q.x - c->p.x, dy = c->q.y - c->p.y;
        int64_t dd = dx * dx + dy * dy;
        if (dd == 0) {
            if (z_outside(c, 0, 1, lo, hi) || z_outside(c, 1, 1, lo, hi)) return 1;
            continue;
        }
        int64_t ta = clamp64((a.x - c->p.x) * dx + (a.y - c->p.y) * dy, 0, dd);
        int64_t tb = clamp64((b.x - c->p.x) * dx + (b.y - c->p.y) * dy, 0, dd);
        if (z_outside(c, ta, dd, lo, hi) || z_outside(c, tb, dd, lo, hi)) return 1;
    }
    return 0;
}

int col_line_of_sight(const scene *s, const world_state *w, fx_t x1, fx_t y1, fx_t z1, fx_t x2, fx_t y2, fx_t z2)
{
    int64_t ax = clampw(x1), ay = clampw(y1), bx = clampw(x2), by = clampw(y2);
    sight_check c;
    c.s = s;
    c.w = w;
    c.p = to_grid(ax, ay);
    c.q = to_grid(bx, by);
    c.gx0 = min64(c.p.x, c.q.x);
    c.gx1 = max64(c.p.x, c.q.x);
    c.gy0 = min64(c.p.y, c.q.y);
    c.gy1 = max64(c.p.y, c.q.y);
    c.z1 = z1;
    c.z2 = z2;
    /* one grid step wider than the segment, so no seg the grid test can see is culled */
    int64_t e = (int64_t)1 << G_SHIFT;
    query_box b = {min64(ax, bx) - e, min64(ay, by) - e, max64(ax, bx) + e, max64(ay, by) + e};
    grid_pt line[2] = {c.p, c.q};
    return !colg_walk_leaves(s, &b, line, sight_leaf, &c);
}
