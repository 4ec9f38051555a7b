/* collide.c - the player against the world (see collide.h): swept-circle moves
 * with sliding, and the floor under a point (as Doom's p_map.c: the geometry it
 * uses is collide_geom.c's, line of sight is collide_sight.c).
 *
 * Owns: the move rules (which wall blocks a body, where it stands), the
 * candidate segs of a move piece, and cutting a blocked piece to its furthest
 * clear point and sliding the rest along the wall met. Ranges: collide_geom.c.
 */
#include "collide.h"

#include "collide_int.h"

#define MOVE_MAX ((int64_t)1 << 33) /* |dx|, |dy| clamp (2 worlds) */
#define SUB_MAX (16 * FX_ONE)       /* longest sub-step */
#define BISECT_BITS 12              /* a blocked sub-step is cut to 1/4096 */
#define SLIDES 4                    /* tries per sub-step: 1 + 3 slides */
#define SKIN (FX_ONE / 64)          /* a slide leaves the wall by this */
#define MIN_SLIDE (FX_ONE / 256)    /* shorter slides are dropped */
#define CAND_MAX 128                /* candidate segs kept per move piece */
#define HUGE_H ((int64_t)1 << 40)   /* "no ceiling" (heights are < 2^31) */

/* ------------------------------------------------------------ moving */

typedef struct {
    const scene *s;
    const world_state *w; /* the ceilings now (doors) */
    int64_t r, r2;        /* radius on the grid (2^12 .. 2^22) and its square */
    int64_t rraw;         /* radius, 16.16 */
    int64_t height, step;
    query_box box;              /* the candidates cover this box */
    int64_t gx0, gy0, gx1, gy1; /* the same on the grid */
    int overflow;               /* more segs than CAND_MAX: checks walk the tree themselves */
    uint32_t n;
    uint32_t cand[CAND_MAX];
} mover;

typedef void (*seg_fn)(void *ctx, uint32_t seg);

typedef struct {
    const mover *m;
    seg_fn fn;
    void *ctx;
} seg_walk;

static int seg_in_box(const mover *m, uint32_t si)
{
    const scn_seg *g = &m->s->segs[si];
    grid_pt a = vert(m->s, g->v1), b = vert(m->s, g->v2);
    return max64(a.x, b.x) >= m->gx0 && min64(a.x, b.x) <= m->gx1 && max64(a.y, b.y) >= m->gy0 &&
           min64(a.y, b.y) <= m->gy1;
}

static int walk_leaf_segs(void *vctx, uint32_t leaf, unsigned state)
{
    (void)state;
    seg_walk *w = (seg_walk *)vctx;
    const scn_leaf *l = &w->m->s->leaves[leaf];
    for (uint32_t i = 0; i < l->num_segs; i++)
        if (seg_in_box(w->m, l->first_seg + i)) w->fn(w->ctx, l->first_seg + i);
    return 0;
}

static int gather_leaf(void *vctx, uint32_t leaf, unsigned state)
{
    (void)state;
    mover *m = (mover *)vctx;
    const scn_leaf *l = &m->s->leaves[leaf];
    for (uint32_t i = 0; i < l->num_segs; i++) {
        uint32_t si = l->first_seg + i;
        if (!seg_in_box(m, si)) continue;
        if (m->n == CAND_MAX) {
            m->overflow = 1;
            return 1;
        }
        m->cand[m->n++] = si;
    }
    return 0;
}

/* Collect the segs that can matter to a circle moving from p to q. */
static void gather(mover *m, int64_t px, int64_t py, int64_t qx, int64_t qy)
{
    int64_t e = m->rraw + FX_ONE; /* radius + more than the grid rounding */
    m->box.x0 = min64(px, qx) - e;
    m->box.x1 = max64(px, qx) + e;
    m->box.y0 = min64(py, qy) - e;
    m->box.y1 = max64(py, qy) + e;
    m->gx0 = fx_asr64(m->box.x0, G_SHIFT);
    m->gx1 = fx_asr64(m->box.x1, G_SHIFT);
    m->gy0 = fx_asr64(m->box.y0, G_SHIFT);
    m->gy1 = fx_asr64(m->box.y1, G_SHIFT);
    m->n = 0;
    m->overflow = 0;
    colg_walk_leaves(m->s, &m->box, 0, gather_leaf, m);
}

static void for_candidates(const mover *m, seg_fn fn, void *ctx)
{
    if (!m->overflow) {
        for (uint32_t i = 0; i < m->n; i++) fn(ctx, m->cand[i]);
        return;
    }
    seg_walk w = {m, fn, ctx};
    colg_walk_leaves(m->s, &m->box, 0, walk_leaf_segs, &w);
}

/* Where the body stands (its footing): highest floor and lowest ceiling over
 * the sectors its circle overlaps (the centre's included), and the centre's
 * sector. */
typedef struct {
    int64_t floor, ceil;
    uint32_t sector;
} footing;

/* Does a wall block a body standing on floor z? */
static int wall_blocks(const mover *m, const scn_line *ln, int64_t z)
{
    if (!CFG_TWO_SIDED || ln->sector[1] == SCN_NONE) return 1;
    const scn_sector *f = &m->s->sectors[ln->sector[0]], *b = &m->s->sectors[ln->sector[1]];
    int64_t fl = max64(f->floor_h, b->floor_h);
    int64_t ce = min64(obj_ceil(m->w, m->s, ln->sector[0]), obj_ceil(m->w, m->s, ln->sector[1]));
    return ce - fl < m->height || fl - z > m->step || ce - z < m->height;
}

typedef struct {
    const mover *m;
    grid_pt p, q;       /* the path */
    int64_t z;          /* floor stood on at the start of the sub-step */
    int blocked;        /* some wall blocks the path */
    int stuck;          /* a blocking wall that p already overlaps holds the move */
    int touched;        /* fmax, cmin hold something */
    int64_t fmax, cmin; /* over the sectors touched at q */
} path_check;

static void touch_sector(path_check *c, uint32_t sec)
{
    if (sec == SCN_NONE) return;
    const scn_sector *t = &c->m->s->sectors[sec];
    int64_t ceil = obj_ceil(c->m->w, c->m->s, sec);
    if (!c->touched || t->floor_h > c->fmax) c->fmax = t->floor_h;
    if (!c->touched || ceil < c->cmin) c->cmin = ceil;
    c->touched = 1;
}

/* A wall the start already overlaps: it blocks a move that brings the centre
 * nearer or takes it across (or, for a one-sided wall, from on it to behind it). */
static int escape_blocked(grid_pt p, grid_pt q, grid_pt a, grid_pt b, int one_sided)
{
    if (colg_dist_seg(q, a, b) < colg_dist_seg(p, a, b)) return 1;
    if (!colg_seg_cross(p, q, a, b)) return 0;
    int sp = sgn64(orient(a, b, p)), sq = sgn64(orient(a, b, q));
    if (sp * sq < 0) return 1;
    return one_sided && sp == 0 && sq > 0;
}

static void check_seg(void *ctx, uint32_t si)
{
    path_check *c = (path_check *)ctx;
    if (c->blocked) return;
    const mover *m = c->m;
    const scn_seg *g = &m->s->segs[si];
    const scn_line *ln = &m->s->lines[g->line];
    grid_pt a = vert(m->s, g->v1), b = vert(m->s, g->v2);
    if (colg_near_seg(c->q, a, b, m->r, m->r2)) {
        touch_sector(c, ln->sector[0]);
        touch_sector(c, ln->sector[1]);
    }
    if (!wall_blocks(m, ln, c->z)) return;
    if (!colg_near_seg(c->p, a, b, m->r, m->r2)) {
        if (colg_sweep_near(c->p, c->q, a, b, m->r, m->r2)) c->blocked = 1;
        return;
    }
    if (escape_blocked(c->p, c->q, a, b, ln->sector[1] == SCN_NONE)) c->blocked = c->stuck = 1;
}

/* Is the path p -> q (16.16) clear for a body that stood on floor z at the start
 * of the sub-step and stands as *at at p? Fills *out with where it would stand at
 * q. at == NULL: only compute *out (no end rules). */
static int try_path(const mover *m, int64_t px, int64_t py, int64_t qx, int64_t qy, int64_t z, const footing *at,
                    footing *out, int *stuck)
{
    path_check c;
    c.m = m;
    c.p = to_grid(px, py);
    c.q = to_grid(qx, qy);
    c.z = z;
    c.blocked = c.stuck = c.touched = 0;
    c.fmax = c.cmin = 0;
    for_candidates(m, check_seg, &c);
    if (stuck) *stuck = c.stuck;
    if (c.blocked && at) return 0;
    out->sector = scene_sector_at(m->s, (int32_t)qx, (int32_t)qy);
    touch_sector(&c, out->sector);
    if (c.touched) {
        out->floor = c.fmax;
        out->ceil = c.cmin;
    } else { /* over no sector at all: keep the height */
        out->floor = at ? at->floor : z;
        out->ceil = out->floor + HUGE_H;
    }
    if (!at) return 1;
    /* end rules, each relaxed when the start is no better (a bad start can leave) */
    if (out->sector == SCN_NONE && at->sector != SCN_NONE) return 0;
    if (out->ceil - out->floor < m->height && out->ceil - out->floor < at->ceil - at->floor) return 0;
    if (out->floor - z > m->step && out->floor > at->floor) return 0;
    if (out->ceil - z < m->height && out->ceil < at->ceil) return 0;
    return 1;
}

typedef struct {
    const mover *m;
    grid_pt l, h; /* last clear point, first blocked point */
    int64_t z;
    int found;
    int64_t best; /* distance from l to the nearest blocking seg */
    grid_pt a, b; /* that seg */
} contact_check;

static void contact_seg(void *ctx, uint32_t si)
{
    contact_check *c = (contact_check *)ctx;
    const mover *m = c->m;
    const scn_seg *g = &m->s->segs[si];
    const scn_line *ln = &m->s->lines[g->line];
    if (!wall_blocks(m, ln, c->z)) return;
    grid_pt a = vert(m->s, g->v1), b = vert(m->s, g->v2);
    if (colg_near_seg(c->l, a, b, m->r, m->r2)) { /* already overlapped: only if it holds the move */
        if (!escape_blocked(c->l, c->h, a, b, ln->sector[1] == SCN_NONE)) return;
    } else if (!colg_sweep_near(c->l, c->h, a, b, m->r, m->r2)) {
        return;
    }
    int64_t d = colg_dist_seg(c->l, a, b);
    if (!c->found || d < c->best) {
        c->found = 1;
        c->best = d;
        c->a = a;
        c->b = b;
    }
}

/* The unit normal (2.30) of the wall met between l and h, pointing back at l. */
static int contact_normal(const mover *m, int64_t z, int64_t lx, int64_t ly, int64_t hx, int64_t hy, int32_t *nx,
                          int32_t *ny)
{
    contact_check c;
    c.m = m;
    c.l = to_grid(lx, ly);
    c.h = to_grid(hx, hy);
    c.z = z;
    c.found = 0;
    c.best = 0;
    c.a = c.b = c.l;
    for_candidates(m, contact_seg, &c);
    return c.found && colg_seg_normal(c.l, c.a, c.b, nx, ny);
}

col_body col_player(void)
{
    col_body b = {COL_RADIUS, COL_HEIGHT, COL_STEP};
    return b;
}

static void mover_init(mover *m, const scene *s, const world_state *w, const col_body *body)
{
    col_body b = body ? *body : col_player();
    m->s = s;
    m->w = w;
    m->rraw = clamp64(b.radius, COL_RADIUS_MIN, COL_RADIUS_MAX);
    m->r = m->rraw >> G_SHIFT;
    m->r2 = m->r * m->r;
    m->height = max64(b.height, 0);
    m->step = max64(b.step, 0);
    m->n = 0;
    m->overflow = 0;
}

uint32_t col_move(const scene *s, const world_state *w, const col_body *body, fx_t *x, fx_t *y, fx_t *floor_z,
                  int64_t dx, int64_t dy)
{
    mover m;
    mover_init(&m, s, w, body);
    uint32_t flags = 0;
    int64_t px = clampw(*x), py = clampw(*y);
    dx = clamp64(dx, -MOVE_MAX, MOVE_MAX);
    dy = clamp64(dy, -MOVE_MAX, MOVE_MAX);

    footing st;
    gather(&m, px, py, px, py);
    try_path(&m, px, py, px, py, floor_z ? *floor_z : 0, 0, &st, 0);

    /* sub-steps of at most min(radius, 16 units): |d| < 2^34 raw, so on the grid
     * the square sum is below 2^61 and n below 2^18; d * n < 2^52 */
    int64_t gx = fx_asr64(dx, G_SHIFT), gy = fx_asr64(dy, G_SHIFT);
    int64_t len = (int64_t)fx_isqrt64((uint64_t)(gx * gx + gy * gy));
    int64_t sub = min64(m.rraw, SUB_MAX) >> G_SHIFT;
    int64_t n = (len + sub - 1) / sub;
    if (n == 0 && (dx || dy)) n = 1;
    int stalls = 0;
    for (int64_t i = 0; i < n; i++) {
        int64_t rx = dx * (i + 1) / n - dx * i / n, ry = dy * (i + 1) / n - dy * i / n;
        int64_t sx = px, sy = py, z = st.floor;
        for (int k = 0; k < SLIDES && (rx || ry); k++) {
            int64_t qx = clampw(px + rx), qy = clampw(py + ry);
            rx = qx - px;
            ry = qy - py;
            gather(&m, px, py, qx, qy);
            footing sq;
            int stuck = 0;
            if (try_path(&m, px, py, qx, qy, z, &st, &sq, &stuck)) {
                px = qx;
                py = qy;
                st = sq;
                break;
            }
            flags |= COL_BLOCKED | (stuck ? COL_STUCK : 0);
            /* the furthest clear fraction lo / 2^12 of the piece (|r| < 2^21, so r * 2^12 < 2^33) */
            int32_t lo = 0, hi = 1 << BISECT_BITS;
            footing slo = st;
            while (hi - lo > 1) {
                int32_t mid = (lo + hi) / 2;
                int64_t mx = px + fx_asr64(rx * mid, BISECT_BITS), my = py + fx_asr64(ry * mid, BISECT_BITS);
                if (try_path(&m, px, py, mx, my, z, &st, &sq, 0)) {
                    lo = mid;
                    slo = sq;
                } else {
                    hi = mid;
                }
            }
            int64_t lx = px + fx_asr64(rx * lo, BISECT_BITS), ly = py + fx_asr64(ry * lo, BISECT_BITS);
            int64_t hx = px + fx_asr64(rx * hi, BISECT_BITS), hy = py + fx_asr64(ry * hi, BISECT_BITS);
            rx -= lx - px;
            ry -= ly - py;
            px = lx;
            py = ly;
            st = slo;
            int32_t nx, ny;
            if (!contact_normal(&m, z, lx, ly, hx, hy, &nx, &ny)) break; /* an end rule: stop */
            /* slide: drop the part of the rest that goes into the wall. |r| < 2^21
             * and |n| <= 2^30: every product below 2^52 */
            int64_t into = fx_asr64(rx * nx + ry * ny, UNIT_SHIFT);
            if (into >= 0) break;
            rx -= fx_asr64(into * nx, UNIT_SHIFT);
            ry -= fx_asr64(into * ny, UNIT_SHIFT);
            if (w128_uabs(rx) < MIN_SLIDE && w128_uabs(ry) < MIN_SLIDE) break;
            rx += fx_asr64((int64_t)SKIN * nx, UNIT_SHIFT);
            ry += fx_asr64((int64_t)SKIN * ny, UNIT_SHIFT);
        }
        /* a piece that went nowhere (or nearly, twice) will do so again: stop */
        if (px == sx && py == sy) break;
        if (w128_uabs(px - sx) < SKIN && w128_uabs(py - sy) < SKIN) {
            if (++stalls >= 2) break;
        } else {
            stalls = 0;
        }
    }
    *x = (fx_t)px;
    *y = (fx_t)py;
    if (floor_z) *floor_z = fx_sat32(st.floor);
    return flags;
}

int col_floor_at(const scene *s, fx_t x, fx_t y, fx_t *floor)
{
    uint32_t sec = scene_sector_at(s, x, y);
    if (sec == SCN_NONE) return 0;
    *floor = s->sectors[sec].floor_h;
    return 1;
}
