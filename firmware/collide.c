/* collide.c - the player against the world (see collide.h): swept-circle moves
 * with sliding, the floor under a point, and line of sight.
 *
 * Owns: exact integer geometry on the 1/4096-unit grid (orientation, point to
 * segment distance, segment crossing), the box tests by which bsp_walk.c's
 * walk finds candidate segs, and the move and sight rules.
 *
 * Ranges. Map coordinates are inside +-SCN_COORD_MAX units (vertices by the
 * loader, positions clamped here), so a grid coordinate (16.16 >> 4) is below
 * 2^27 in magnitude, a difference of two below 2^28, a product of two
 * differences below 2^56 and a cross or dot product below 2^57: all int64. A
 * squared distance compared with r^2 * |ab|^2 (up to 2^114) goes through the
 * exact 128-bit w128_sign_diff(). Nothing here divides by a value that can be 0.
 */
#include "collide.h"

#include "bsp_walk.h"
#include "wide128.h"

#define G_SHIFT 4                                        /* grid = 16.16 >> 4: 1/4096 unit */
#define WORLD_RAW ((int64_t)SCN_COORD_MAX << FX_SHIFT)   /* positions are clamped to +-this */
#define MOVE_MAX ((int64_t)1 << 33)                      /* |dx|, |dy| clamp (2 worlds) */
#define SUB_MAX (16 * FX_ONE)                            /* longest sub-step */
#define BISECT_BITS 12                                   /* a blocked sub-step is cut to 1/4096 */
#define SLIDES 4                                         /* tries per sub-step: 1 + 3 slides */
#define SKIN (FX_ONE / 64)                               /* a slide leaves the wall by this */
#define MIN_SLIDE (FX_ONE / 256)                         /* shorter slides are dropped */
#define UNIT_SHIFT 30                                    /* unit normals are 2.30 */
#define CAND_MAX 128                                     /* candidate segs kept per move piece */
#define HUGE_H ((int64_t)1 << 40)                        /* "no ceiling" (heights are < 2^31) */

/* A point on the 1/4096-unit grid. */
typedef struct {
    int64_t x, y; /* grid units, |x|, |y| < 2^27 */
} grid_pt;

/* The map box a tree query covers: leaves under node boxes that overlap it. */
typedef struct {
    int64_t x0, y0, x1, y1; /* 16.16, inclusive */
} query_box;

static int64_t min64(int64_t a, int64_t b) { return a < b ? a : b; }
static int64_t max64(int64_t a, int64_t b) { return a > b ? a : b; }
static int64_t clamp64(int64_t v, int64_t lo, int64_t hi) { return v < lo ? lo : (v > hi ? hi : v); }
static int64_t clampw(int64_t v) { return clamp64(v, -WORLD_RAW, WORLD_RAW); }
static int sgn64(int64_t v) { return (v > 0) - (v < 0); }

/* ------------------------------------------------------------ grid geometry */

static grid_pt to_grid(int64_t x, int64_t y)
{
    grid_pt p = {fx_asr64(x, G_SHIFT), fx_asr64(y, G_SHIFT)};
    return p;
}

static grid_pt vert(const scene *s, uint32_t v)
{
    return to_grid(s->verts[v].x, s->verts[v].y);
}

/* (b - a) x (p - a): > 0 when p is left of a->b (behind a seg), < 0 right (in front). */
static int64_t orient(grid_pt a, grid_pt b, grid_pt p)
{
    return (b.x - a.x) * (p.y - a.y) - (b.y - a.y) * (p.x - a.x);
}

/* 1 if the distance from p to the closed segment ab is below r (r2 = r*r, r < 2^23). */
static int near_seg(grid_pt p, grid_pt a, grid_pt b, int64_t r, int64_t r2)
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
static int64_t dist_seg(grid_pt p, grid_pt a, grid_pt b)
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
static int seg_cross(grid_pt p, grid_pt q, grid_pt a, grid_pt b)
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
static int sweep_near(grid_pt p, grid_pt q, grid_pt a, grid_pt b, int64_t r, int64_t r2)
{
    return seg_cross(p, q, a, b) || near_seg(p, a, b, r, r2) || near_seg(q, a, b, r, r2) ||
           near_seg(a, p, q, r, r2) || near_seg(b, p, q, r, r2);
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
static int seg_normal(grid_pt p, grid_pt a, grid_pt b, int32_t *nx, int32_t *ny)
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
static int walk_leaves(const scene *s, const query_box *b, const grid_pt *line, walk_visit fn, void *ctx)
{
    tree_query q = {b, line};
    const walk_rules rules = {0, query_meets, fn, ctx, 0};
    return walk_boxes(s, &rules, &q, 0, 0);
}

/* ------------------------------------------------------------ moving */

typedef struct {
    const scene *s;
    const world_state *w; /* the ceilings now (doors) */
    int64_t r, r2;       /* radius on the grid (2^12 .. 2^22) and its square */
    int64_t rraw;        /* radius, 16.16 */
    int64_t height, step;
    query_box box;            /* the candidates cover this box */
    int64_t gx0, gy0, gx1, gy1; /* the same on the grid */
    int overflow;        /* more segs than CAND_MAX: checks walk the tree themselves */
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
    walk_leaves(m->s, &m->box, 0, gather_leaf, m);
}

static void for_candidates(const mover *m, seg_fn fn, void *ctx)
{
    if (!m->overflow) {
        for (uint32_t i = 0; i < m->n; i++) fn(ctx, m->cand[i]);
        return;
    }
    seg_walk w = {m, fn, ctx};
    walk_leaves(m->s, &m->box, 0, walk_leaf_segs, &w);
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
    grid_pt p, q;        /* the path */
    int64_t z;       /* floor stood on at the start of the sub-step */
    int blocked;     /* some wall blocks the path */
    int stuck;       /* a blocking wall that p already overlaps holds the move */
    int touched;     /* fmax, cmin hold something */
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
    if (dist_seg(q, a, b) < dist_seg(p, a, b)) return 1;
    if (!seg_cross(p, q, a, b)) return 0;
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
    if (near_seg(c->q, a, b, m->r, m->r2)) {
        touch_sector(c, ln->sector[0]);
        touch_sector(c, ln->sector[1]);
    }
    if (!wall_blocks(m, ln, c->z)) return;
    if (!near_seg(c->p, a, b, m->r, m->r2)) {
        if (sweep_near(c->p, c->q, a, b, m->r, m->r2)) c->blocked = 1;
        return;
    }
    if (escape_blocked(c->p, c->q, a, b, ln->sector[1] == SCN_NONE)) c->blocked = c->stuck = 1;
}

/* Is the path p -> q (16.16) clear for a body that stood on floor z at the start
 * of the sub-step and stands as *at at p? Fills *out with where it would stand at
 * q. at == NULL: only compute *out (no end rules). */
static int try_path(const mover *m, int64_t px, int64_t py, int64_t qx, int64_t qy, int64_t z,
                    const footing *at, footing *out, int *stuck)
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
    grid_pt l, h;        /* last clear point, first blocked point */
    int64_t z;
    int found;
    int64_t best;    /* distance from l to the nearest blocking seg */
    grid_pt a, b;        /* that seg */
} contact_check;

static void contact_seg(void *ctx, uint32_t si)
{
    contact_check *c = (contact_check *)ctx;
    const mover *m = c->m;
    const scn_seg *g = &m->s->segs[si];
    const scn_line *ln = &m->s->lines[g->line];
    if (!wall_blocks(m, ln, c->z)) return;
    grid_pt a = vert(m->s, g->v1), b = vert(m->s, g->v2);
    if (near_seg(c->l, a, b, m->r, m->r2)) { /* already overlapped: only if it holds the move */
        if (!escape_blocked(c->l, c->h, a, b, ln->sector[1] == SCN_NONE)) return;
    } else if (!sweep_near(c->l, c->h, a, b, m->r, m->r2)) {
        return;
    }
    int64_t d = dist_seg(c->l, a, b);
    if (!c->found || d < c->best) {
        c->found = 1;
        c->best = d;
        c->a = a;
        c->b = b;
    }
}

/* The unit normal (2.30) of the wall met between l and h, pointing back at l. */
static int contact_normal(const mover *m, int64_t z, int64_t lx, int64_t ly, int64_t hx, int64_t hy,
                          int32_t *nx, int32_t *ny)
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
    return c.found && seg_normal(c.l, c.a, c.b, nx, ny);
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
        if (!seg_cross(c->p, c->q, a, b)) continue;
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
    return !walk_leaves(s, &b, line, sight_leaf, &c);
}
