/* split_choice.c - choice of the partition line for a set of segs (bspc_split).
 *
 * Candidates are the distinct lines of the set's segs. Each is scored by
 * counting the segs that would go front, go back, or be split:
 *   fewest    fewest splits, then best balance |front - back|
 *   balanced  best balance, then fewest splits
 *   mixed     SPLIT_COST * splits + an imbalance term that grows as the
 *             smaller side empties + DIAG_COST if diagonal (the default),
 *             with a one-level look-ahead on mid-sized sets: the best LOOK
 *             candidates are compared by their cost plus the best cost of
 *             each of their two children.
 * A candidate with nothing behind it does not divide the set; a set with no
 * such candidate is convex and becomes a leaf.
 *
 * Depth. The mixed strategy keeps the tree under SCN_MAX_DEPTH and in practice
 * under DEPTH_BUDGET: a set of n segs at depth d with d + 2 log2(n) >= budget
 * is scored balance first, and when every seg line of such a set would only
 * peel off a few segs (the outside of a round pillar) an axis-aligned line
 * through the middle of the set, on no seg, is used instead.
 *
 * Speed. Axis-aligned candidates (most lines of most maps) are scored without
 * looking at the segs one by one: per axis the set keeps the sorted low and
 * high extents of the segs that cross that axis' lines and the sorted positions
 * of the segs parallel to them, and one sweep over the sorted candidates
 * counts front, back and split segs for all of them. The counts equal those of
 * the exact side test of geom.h (for an axis-aligned line "on" means within
 * BS_EPS on that axis). Diagonal candidates are scored by a loop over the set
 * with an early exit once they cannot win; large sets score an even sample.
 */
#include <stdlib.h>
#include <string.h>

#include "geom.h"

/* Tuning, measured on the 68 Freedoom maps (tools/bench_bsp.py). */
#ifndef SPLIT_COST
#define SPLIT_COST 48 /* mixed: the cost of one split */
#endif
#ifndef BAL_Q
#define BAL_Q 16 /* mixed: imbalance |f - b| costs |f - b| * Q / (min(f, b) + Q) */
#endif
#ifndef DIAG_COST
#define DIAG_COST 4 /* mixed: extra cost of a diagonal partition */
#endif
#ifndef DIAG_ALL
#define DIAG_ALL 32 /* sets with at most this many diagonal lines score them all */
#endif
#ifndef DIAG_SAMPLE
#define DIAG_SAMPLE 24 /* otherwise this many, spread evenly */
#endif
#ifndef DEPTH_BUDGET
#define DEPTH_BUDGET 52 /* mixed: a set that might reach deeper than this balances first */
#endif
#ifndef PEEL
#define PEEL 8 /* ... and uses a line on no seg if the best keeps < 1/PEEL on a side */
#endif
#ifndef LOOK
#define LOOK 3 /* mixed: look-ahead over this many best candidates */
#endif
#ifndef LOOK_MIN
#define LOOK_MIN 32 /* on sets of at least this many segs */
#endif
#ifndef LOOK_MAX_DEPTH
#define LOOK_MAX_DEPTH 40 /* and above this depth */
#endif
#ifndef SMALL
#define SMALL 24 /* sets this small are scored by plain loops, without the index */
#endif
#ifndef CHUNK
#define CHUNK 16 /* segs per chunk of a chunked set */
#endif
#ifndef CHUNK_MIN
#define CHUNK_MIN 128 /* sets of at least this many segs with diagonals to score are chunked */
#endif
#define MAX_RANK 8

typedef struct {
    uint32_t pl, rev;
    int kind;  /* 0 diagonal, 1 horizontal (dy == 0), 2 vertical (dx == 0) */
    int pos;   /* axis-aligned: points north (vertical) / east (horizontal) */
    int32_t c; /* axis-aligned: x of a vertical line, y of a horizontal one */
} cand;

/* the box of the seg ends of one chunk of a chunked set */
typedef struct {
    int32_t x0, y0, x1, y1;
} chunk_box;

/* mixed, on a set that could grow the tree past DEPTH_BUDGET: balance first */
#define MODE_RESCUE 100

typedef struct {
    uint32_t front, back, splits;
    int valid;
    int cut; /* eval_loop stopped early: the candidate costs more than its bar */
    int64_t cost;
} score;

typedef struct {
    cand c;
    score s;
} ranked;

/* per axis (0: x, vertical lines; 1: y, horizontal lines) */
typedef struct {
    uint64_t *lo, *hi; /* segs crossing the axis' lines: extent << 32 | seg, sorted */
    uint64_t *al;      /* segs parallel to them: position << 32 | positive << 31 | seg, sorted */
    uint32_t nn, nal;
} axis_index;

typedef struct {
    axis_index ax[2];
    uint32_t cap;
} index_set;

struct bs_chooser {
    const bs_tree *t;
    int strategy;
    int mode;        /* the strategy, or MODE_RESCUE, for the set being scored */
    uint32_t *stamp; /* per line: the set that last listed it */
    uint32_t stampno;
    cand *cands;
    uint32_t ccap;
    int32_t *xy; /* the set's seg ends, x1 y1 x2 y2 */
    uint32_t xycap;
    uint64_t *tmp; /* radix sort scratch */
    uint32_t tmpcap;
    index_set idx;  /* of the set being chosen for */
    index_set cidx; /* of a look-ahead child */
    uint32_t *child[2];
    uint32_t childcap;
    uint8_t *mark; /* per seg: look-ahead destination, bit 0 front, bit 1 back */
    uint32_t markcap;
    /* the chunks of the set being scored (nchunked: its size, 0 when not chunked) */
    uint32_t nchunked, nchunks;
    chunk_box *cbox;
    uint32_t cbcap;
};

bs_chooser *bs_chooser_new(const bs_tree *t, bspc_split strategy)
{
    bs_chooser *C = calloc(1, sizeof *C);
    if (!C) return NULL;
    C->t = t;
    C->strategy = (int)strategy;
    C->stamp = calloc(t->nplines + 1, sizeof *C->stamp);
    if (!C->stamp) {
        free(C);
        return NULL;
    }
    return C;
}

static void index_free(index_set *x)
{
    for (int a = 0; a < 2; a++) {
        free(x->ax[a].lo);
        free(x->ax[a].hi);
        free(x->ax[a].al);
    }
}

void bs_chooser_free(bs_chooser *C)
{
    if (!C) return;
    free(C->stamp);
    free(C->cands);
    free(C->xy);
    free(C->tmp);
    index_free(&C->idx);
    index_free(&C->cidx);
    free(C->child[0]);
    free(C->child[1]);
    free(C->mark);
    free(C->cbox);
    free(C);
}

int bs_same_dir(const bs_tree *t, const bs_seg *g, bs_part p)
{
    if (g->line == p.pl) return g->side == p.rev;
    const bs_pline *A = &t->plines[g->line], *B = &t->plines[p.pl];
    bs_i128 dot = (bs_i128)A->rdx * B->rdx + (bs_i128)A->rdy * B->rdy;
    if (g->side) dot = -dot;
    if (p.rev) dot = -dot;
    return dot > 0;
}

/* ------------------------------------------------------------ sorting */

/* the sort key of a coordinate: order-preserving, unsigned */
static uint64_t key_of(int32_t v)
{
    return (uint64_t)((uint32_t)v ^ 0x80000000u) << 32;
}
static int32_t val_of(uint64_t k)
{
    return (int32_t)((uint32_t)(k >> 32) ^ 0x80000000u);
}

/* sort by the upper 32 bits: insertion sort when short, else LSD radix (digits
 * that are the same for every entry, such as the fraction of whole-unit maps,
 * cost one counting pass) */
static void sort_keys(uint64_t *a, uint32_t n, uint64_t *tmp)
{
    if (n < 48) {
        for (uint32_t i = 1; i < n; i++) {
            uint64_t v = a[i];
            uint32_t j = i;
            while (j > 0 && (a[j - 1] >> 32) > (v >> 32)) {
                a[j] = a[j - 1];
                j--;
            }
            a[j] = v;
        }
        return;
    }
    /* the four digits' counts in one pass (a pass's order does not change them) */
    uint32_t cnt[4][257];
    memset(cnt, 0, sizeof cnt);
    for (uint32_t i = 0; i < n; i++) {
        uint32_t k = (uint32_t)(a[i] >> 32);
        cnt[0][(k & 255u) + 1]++;
        cnt[1][((k >> 8) & 255u) + 1]++;
        cnt[2][((k >> 16) & 255u) + 1]++;
        cnt[3][(k >> 24) + 1]++;
    }
    uint64_t *src = a, *dst = tmp;
    for (int d = 0; d < 4; d++) {
        int shift = 32 + 8 * d;
        uint32_t *c = cnt[d];
        if (c[((src[0] >> shift) & 255u) + 1] == n) continue;
        for (int k = 0; k < 256; k++) c[k + 1] += c[k];
        for (uint32_t i = 0; i < n; i++) dst[c[(src[i] >> shift) & 255u]++] = src[i];
        uint64_t *s = src;
        src = dst;
        dst = s;
    }
    if (src != a) memcpy(a, src, sizeof(uint64_t) * n);
}

/* entries whose coordinate is < v, or <= v */
static uint32_t count_lt(const uint64_t *a, uint32_t n, int64_t v)
{
    uint32_t lo = 0, hi = n;
    while (lo < hi) {
        uint32_t m = (lo + hi) / 2;
        if (val_of(a[m]) < v)
            lo = m + 1;
        else
            hi = m;
    }
    return lo;
}

static uint32_t count_le(const uint64_t *a, uint32_t n, int64_t v)
{
    uint32_t lo = 0, hi = n;
    while (lo < hi) {
        uint32_t m = (lo + hi) / 2;
        if (val_of(a[m]) <= v)
            lo = m + 1;
        else
            hi = m;
    }
    return lo;
}

/* ------------------------------------------------------------ scoring */

static int64_t cost_of(int mode, uint32_t f, uint32_t b, uint32_t sp, int diag)
{
    int64_t imb = (f > b) ? (int64_t)(f - b) : (int64_t)(b - f);
    switch (mode) {
    case BSPC_SPLIT_FEWEST: return ((int64_t)sp << 32) + imb;
    case BSPC_SPLIT_BALANCED: return (imb << 32) + sp;
    case MODE_RESCUE: return (int64_t)sp + 4 * imb;
    default: {
        /* imbalance matters most when one side is nearly empty (a peel-off) */
        int64_t m = f < b ? f : b;
        /* the same quotient in 32 bits when it fits (a division costs less) */
        int64_t bal = imb < (1 << 26) ? (int64_t)((uint32_t)imb * BAL_Q / (uint32_t)(m + BAL_Q))
                                      : imb * BAL_Q / (m + BAL_Q);
        return (int64_t)sp * SPLIT_COST + bal + (diag ? DIAG_COST : 0);
    }
    }
}

/* lower bound of the cost once sp splits are known (for the early exit) */
static int64_t cost_floor(int mode, uint32_t sp)
{
    switch (mode) {
    case BSPC_SPLIT_FEWEST: return (int64_t)sp << 32;
    case BSPC_SPLIT_BALANCED: return 0;
    case MODE_RESCUE: return (int64_t)sp;
    default: return (int64_t)sp * SPLIT_COST;
    }
}

static cand make_cand(const bs_tree *t, uint32_t pl, uint32_t rev)
{
    const bs_pline *L = &t->plines[pl];
    cand c;
    c.pl = pl;
    c.rev = rev;
    if (L->dy == 0) {
        c.kind = 1;
        c.pos = (L->dx > 0) != (rev != 0);
        c.c = L->y;
    } else if (L->dx == 0) {
        c.kind = 2;
        c.pos = (L->dy > 0) != (rev != 0);
        c.c = L->x;
    } else {
        c.kind = 0;
        c.pos = 0;
        c.c = 0;
    }
    return c;
}

static score finish(int mode, score r, const cand *c)
{
    r.valid = r.back > 0;
    if (r.valid) r.cost = cost_of(mode, r.front, r.back, r.splits, c->kind == 0);
    return r;
}

/* A small line (bs_pline.small: cross products fit in 64 bits) held in
 * registers, and the sides of segs counted against it unreversed. */
typedef struct {
    int64_t x0, y0, dx, dy, thr;
    bs_part p;
    uint32_t right, left, on_f, on_b, splits;
} side_count;

/* bs_side's arithmetic on segs [lo, hi) of xy / segs; 0, or 1 once the splits
 * cost more than best (the count is then cut short) */
static int count_segs(const bs_chooser *C, side_count *k, const uint32_t *segs, const int32_t *xy, uint32_t lo,
                      uint32_t hi, int64_t best)
{
    const bs_tree *t = C->t;
    const int64_t x0 = k->x0, y0 = k->y0, dx = k->dx, dy = k->dy, thr = k->thr;
    for (uint32_t i = lo; i < hi; i++) {
        const int32_t *q = xy + 4 * i;
        int64_t c1 = (q[0] - x0) * dy - (q[1] - y0) * dx;
        int64_t c2 = (q[2] - x0) * dy - (q[3] - y0) * dx;
        int split = 0;
        if (c1 > thr) { /* a on the right */
            if (c2 >= -thr)
                k->right++;
            else
                split = 1;
        } else if (c1 < -thr) {
            if (c2 <= thr)
                k->left++;
            else
                split = 1;
        } else if (c2 > thr) {
            k->right++;
        } else if (c2 < -thr) {
            k->left++;
        } else if (bs_same_dir(t, &t->segs[segs[i]], k->p)) {
            k->on_f++;
        } else {
            k->on_b++;
        }
        if (split && cost_floor(C->mode, ++k->splits) > best) return 1;
    }
    return 0;
}

static side_count side_count_of(const bs_pline *L, const cand *c)
{
    side_count k = {L->x, L->y, L->rdx, L->rdy, L->thr, {c->pl, c->rev, 0, 0}, 0, 0, 0, 0, 0};
    return k;
}

static score score_of(const bs_chooser *C, const cand *c, const side_count *k)
{
    score r = {0, 0, 0, 0, 0, 0};
    r.front = (c->rev ? k->left : k->right) + k->on_f + k->splits;
    r.back = (c->rev ? k->right : k->left) + k->on_b + k->splits;
    r.splits = k->splits;
    return finish(C->mode, r, c);
}

/* eval_loop for a small line (nearly every line) */
static score eval_small(const bs_chooser *C, const cand *c, const uint32_t *segs, const int32_t *xy, uint32_t n,
                        int64_t best)
{
    side_count k = side_count_of(&C->t->plines[c->pl], c);
    if (count_segs(C, &k, segs, xy, 0, n, best)) return (score){0, 0, 0, 0, 1, 0};
    return score_of(C, c, &k);
}

/* eval_loop for a small line on a chunked set: a chunk whose box lies wholly
 * on one side (the box's two corners extreme across the line tell) counts at
 * once; only the chunks the line passes near are counted seg by seg. The
 * counts, and so the score, are those of eval_small: a box wholly beyond thr
 * holds no seg that is on the line or split. */
static score eval_chunked(const bs_chooser *C, const cand *c, const uint32_t *segs, const int32_t *xy, int64_t best)
{
    side_count k = side_count_of(&C->t->plines[c->pl], c);
    const int64_t x0 = k.x0, y0 = k.y0, dx = k.dx, dy = k.dy, thr = k.thr;
    for (uint32_t b = 0; b < C->nchunks; b++) {
        const chunk_box *B = &C->cbox[b];
        /* cross = (x - x0) dy - (y - y0) dx: least and most over the box */
        int64_t lo = ((dy > 0 ? B->x0 : B->x1) - x0) * dy - ((dx > 0 ? B->y1 : B->y0) - y0) * dx;
        int64_t hi = ((dy > 0 ? B->x1 : B->x0) - x0) * dy - ((dx > 0 ? B->y0 : B->y1) - y0) * dx;
        uint32_t first = b * CHUNK, end = first + CHUNK < C->nchunked ? first + CHUNK : C->nchunked;
        if (lo > thr)
            k.right += end - first;
        else if (hi < -thr)
            k.left += end - first;
        else if (count_segs(C, &k, segs, xy, first, end, best))
            return (score){0, 0, 0, 0, 1, 0};
    }
    return score_of(C, c, &k);
}

/* exact scoring by a loop over the set (xy: its seg ends, 4 per seg, copied
 * together for speed); gives up (invalid, cut) once worse than best */
static score eval_loop(const bs_chooser *C, const cand *c, const uint32_t *segs, const int32_t *xy, uint32_t n,
                       int64_t best)
{
    const bs_tree *t = C->t;
    if (t->plines[c->pl].small)
        return C->nchunked == n ? eval_chunked(C, c, segs, xy, best) : eval_small(C, c, segs, xy, n, best);
    const bs_pline *L = &t->plines[c->pl];
    bs_part p = {c->pl, c->rev, 0, 0};
    score r = {0, 0, 0, 0, 0, 0};
    for (uint32_t i = 0; i < n; i++) {
        const int32_t *q = xy + 4 * i;
        int a = bs_side(L, c->rev, q[0], q[1]);
        int b = bs_side(L, c->rev, q[2], q[3]);
        if (a == 0 && b == 0) {
            if (bs_same_dir(t, &t->segs[segs[i]], p))
                r.front++;
            else
                r.back++;
        } else if (a >= 0 && b >= 0) {
            r.front++;
        } else if (a <= 0 && b <= 0) {
            r.back++;
        } else {
            r.front++;
            r.back++;
            r.splits++;
            if (cost_floor(C->mode, r.splits) > best) {
                r.cut = 1;
                return r;
            }
        }
    }
    return finish(C->mode, r, c);
}

/* ------------------------------------------------------------ the index */

static int index_reserve(index_set *x, uint32_t n)
{
    if (n <= x->cap) return 0;
    uint32_t nc = n + n / 2 + 64;
    for (int a = 0; a < 2; a++) {
        uint64_t **arr[3] = {&x->ax[a].lo, &x->ax[a].hi, &x->ax[a].al};
        for (int k = 0; k < 3; k++) {
            uint64_t *q = realloc(*arr[k], sizeof(uint64_t) * nc);
            if (!q) return -1;
            *arr[k] = q;
        }
    }
    x->cap = nc;
    return 0;
}

static int index_build(bs_chooser *C, index_set *x, const uint32_t *segs, uint32_t n)
{
    const bs_tree *t = C->t;
    if (index_reserve(x, n) || bs_grow(&C->tmp, &C->tmpcap, n + 1, sizeof(uint64_t))) return -1;
    for (int a = 0; a < 2; a++) x->ax[a].nn = x->ax[a].nal = 0;
    for (uint32_t i = 0; i < n; i++) {
        uint32_t id = segs[i];
        const bs_seg *g = &t->segs[id];
        int32_t v1[2] = {g->x1, g->y1}, v2[2] = {g->x2, g->y2};
        for (int a = 0; a < 2; a++) {
            axis_index *A = &x->ax[a];
            int64_t d = (int64_t)v2[a] - v1[a];
            if (d > 2 * BS_EPS || d < -2 * BS_EPS) {
                A->lo[A->nn] = key_of(d > 0 ? v1[a] : v2[a]) | id;
                A->hi[A->nn++] = key_of(d > 0 ? v2[a] : v1[a]) | id;
            } else {
                /* parallel to this axis' lines; positive: north for x, east for y */
                uint64_t positive = (a == 0) ? (g->y2 > g->y1) : (g->x2 > g->x1);
                A->al[A->nal++] = key_of(v1[a]) | positive << 31 | id;
            }
        }
    }
    for (int a = 0; a < 2; a++) {
        axis_index *A = &x->ax[a];
        sort_keys(A->lo, A->nn, C->tmp);
        sort_keys(A->hi, A->nn, C->tmp);
        sort_keys(A->al, A->nal, C->tmp);
    }
    return 0;
}

/* the index of a look-ahead child: the parent's entries whose seg goes to it */
static int index_filter(bs_chooser *C, index_set *dst, const index_set *src, uint8_t bit)
{
    uint32_t need = src->ax[0].nn + src->ax[0].nal;
    if (index_reserve(dst, need)) return -1;
    for (int a = 0; a < 2; a++) {
        const axis_index *S = &src->ax[a];
        axis_index *D = &dst->ax[a];
        uint32_t nlo = 0, nhi = 0, nal = 0;
        for (uint32_t i = 0; i < S->nn; i++)
            if (C->mark[S->lo[i] & 0x7FFFFFFFu] & bit) D->lo[nlo++] = S->lo[i];
        for (uint32_t i = 0; i < S->nn; i++)
            if (C->mark[S->hi[i] & 0x7FFFFFFFu] & bit) D->hi[nhi++] = S->hi[i];
        for (uint32_t i = 0; i < S->nal; i++)
            if (C->mark[S->al[i] & 0x7FFFFFFFu] & bit) D->al[nal++] = S->al[i];
        D->nn = nlo; /* == nhi: the same segs */
        D->nal = nal;
    }
    return 0;
}

/* counts for an axis-aligned line at c from the prefix counts (see eval_axis) */
static score axis_score(int mode, const cand *c, uint32_t nn, uint32_t lo_lt, uint32_t hi_le, uint32_t al_lt,
                        uint32_t al_le, uint32_t pos_lt, uint32_t pos_le, uint32_t nal, uint32_t npos)
{
    uint32_t high = nn - lo_lt; /* crossing segs wholly on the high side (or touching) */
    uint32_t low = hi_le;       /* wholly on the low side */
    uint32_t sp = nn - high - low;
    uint32_t p_low = pos_lt, p_high = npos - pos_le;
    uint32_t n_low = al_lt - pos_lt, n_high = (nal - npos) - (al_le - pos_le);
    uint32_t p_on = npos - p_low - p_high, n_on = (nal - npos) - n_low - n_high;
    uint32_t hs = high + p_high + n_high, ls = low + p_low + n_low;
    score r = {0, 0, sp, 0, 0, 0};
    /* front is the right side: east of a north-going line, south of an east-going one */
    int front_high = (c->kind == 2) ? c->pos : !c->pos;
    r.front = (front_high ? hs : ls) + sp + (c->pos ? p_on : n_on);
    r.back = (front_high ? ls : hs) + sp + (c->pos ? n_on : p_on);
    return finish(mode, r, c);
}

/* scoring of one axis-aligned line (any c) by binary searches */
static score eval_axis(const bs_chooser *C, const index_set *x, const cand *c)
{
    const axis_index *A = &x->ax[c->kind == 2 ? 0 : 1];
    int64_t lo = (int64_t)c->c - BS_EPS, hi = (int64_t)c->c + BS_EPS;
    uint32_t al_lt = count_lt(A->al, A->nal, lo), al_le = count_le(A->al, A->nal, hi);
    uint32_t pos_lt = 0, pos_le = 0, npos = 0;
    for (uint32_t i = 0; i < A->nal; i++) {
        uint32_t p = (uint32_t)(A->al[i] >> 31) & 1u;
        npos += p;
        if (i < al_lt) pos_lt += p;
        if (i < al_le) pos_le += p;
    }
    return axis_score(C->mode, c, A->nn, count_lt(A->lo, A->nn, lo), count_le(A->hi, A->nn, hi), al_lt, al_le, pos_lt,
                      pos_le, A->nal, npos);
}

static void rank_insert(ranked *top, uint32_t *ntop, uint32_t k, const cand *c, score s)
{
    if (*ntop == k && s.cost >= top[k - 1].s.cost) return;
    uint32_t i = (*ntop < k) ? (*ntop)++ : k - 1;
    while (i > 0 && top[i - 1].s.cost > s.cost) {
        top[i] = top[i - 1];
        i--;
    }
    top[i].c = *c;
    top[i].s = s;
}

/* Every axis-aligned candidate of one axis in one sweep: the parallel segs
 * that lie exactly on an axis-aligned line are the candidates, in order. */
static void sweep_axis(bs_chooser *C, const index_set *x, int a, ranked *top, uint32_t *ntop, uint32_t k)
{
    const bs_tree *t = C->t;
    const axis_index *A = &x->ax[a];
    uint32_t npos = 0;
    for (uint32_t i = 0; i < A->nal; i++) npos += (uint32_t)(A->al[i] >> 31) & 1u;
    uint32_t lo_lt = 0, hi_le = 0, al_lt = 0, al_le = 0, pos_lt = 0, pos_le = 0;
    int have_last = 0;
    int32_t last = 0;
    for (uint32_t i = 0; i < A->nal; i++) {
        uint32_t id = (uint32_t)A->al[i] & 0x7FFFFFFFu;
        const bs_seg *g = &t->segs[id];
        const bs_pline *L = &t->plines[g->line];
        if (a == 0 ? (L->dx != 0) : (L->dy != 0)) continue; /* a tiny piece of a diagonal */
        int32_t cc = (a == 0) ? L->x : L->y;
        if (have_last && cc == last) continue;
        have_last = 1;
        last = cc;
        cand c = make_cand(t, g->line, g->side);
        int64_t lo = (int64_t)cc - BS_EPS, hi = (int64_t)cc + BS_EPS;
        while (lo_lt < A->nn && val_of(A->lo[lo_lt]) < lo) lo_lt++;
        while (hi_le < A->nn && val_of(A->hi[hi_le]) <= hi) hi_le++;
        while (al_lt < A->nal && val_of(A->al[al_lt]) < lo) pos_lt += (uint32_t)(A->al[al_lt++] >> 31) & 1u;
        while (al_le < A->nal && val_of(A->al[al_le]) <= hi) pos_le += (uint32_t)(A->al[al_le++] >> 31) & 1u;
        /* a candidate whose splits alone cost more than the last ranked one is not scored */
        if (*ntop == k && cost_floor(C->mode, lo_lt - hi_le) >= top[k - 1].s.cost) continue;
        score s = axis_score(C->mode, &c, A->nn, lo_lt, hi_le, al_lt, al_le, pos_lt, pos_le, A->nal, npos);
        if (s.valid) rank_insert(top, ntop, k, &c, s);
    }
}

/* Cut the set (its ends in xy) into chunks of CHUNK segs in the set's own
 * order, and find the box of each chunk's ends for eval_chunked. The order is
 * the map's (a map lists walls room by room) and what the splits made of it,
 * so most chunks are small boxes. */
static int chunk_set(bs_chooser *C, uint32_t n)
{
    uint32_t nb = (n + CHUNK - 1) / CHUNK;
    if (bs_grow(&C->cbox, &C->cbcap, nb, sizeof *C->cbox)) return -1;
    const int32_t *xy = C->xy;
    for (uint32_t b = 0; b < nb; b++) {
        chunk_box B = {INT32_MAX, INT32_MAX, INT32_MIN, INT32_MIN};
        uint32_t end = (b + 1) * CHUNK < n ? (b + 1) * CHUNK : n;
        for (const int32_t *q = xy + 4 * b * CHUNK; q < xy + 4 * end; q += 2) {
            B.x0 = q[0] < B.x0 ? q[0] : B.x0;
            B.x1 = q[0] > B.x1 ? q[0] : B.x1;
            B.y0 = q[1] < B.y0 ? q[1] : B.y0;
            B.y1 = q[1] > B.y1 ? q[1] : B.y1;
        }
        C->cbox[b] = B;
    }
    C->nchunked = n;
    C->nchunks = nb;
    return 0;
}

/* The bar of a loop-scored candidate: what it must stay under to be ranked. */
static int64_t bar_of(const ranked *top, uint32_t ntop, uint32_t k, int64_t cap)
{
    int64_t bar = ntop == k ? top[k - 1].s.cost : INT64_MAX;
    return cap < bar ? cap : bar;
}

/* A loop-scored candidate into the ranking; a cut one only says that it
 * costs more than the bar it was given. */
static void rank_loop(bs_chooser *C, const cand *c, const uint32_t *segs, uint32_t n, ranked *top, uint32_t *ntop,
                      uint32_t k, int64_t cap, int *cut)
{
    score s = eval_loop(C, c, segs, C->xy, n, bar_of(top, *ntop, k, cap));
    if (s.valid) rank_insert(top, ntop, k, c, s);
    *cut |= s.cut;
}

/* Score the candidates of a set; the best k go to top[] (k >= 1). x: the
 * set's index, or NULL for a small set. Candidates costing more than cap may
 * be cut short: *cut says some were, so that a set with nothing ranked is
 * convex only if none was. Returns the number ranked, or -1 on allocation
 * failure. */
static int score_set(bs_chooser *C, const uint32_t *segs, uint32_t n, uint32_t depth, const index_set *x, ranked *top,
                     uint32_t k, int64_t cap, int *cut)
{
    const bs_tree *t = C->t;
    C->mode = C->strategy;
    if (C->strategy == BSPC_SPLIT_MIXED) {
        /* a balanced subtree of n segs needs about log2(n) levels: leave twice that */
        uint32_t lg = 0;
        while ((1u << lg) < n && lg < 31) lg++;
        if (depth + 2 * lg >= DEPTH_BUDGET) C->mode = MODE_RESCUE;
    }
    if (bs_grow(&C->cands, &C->ccap, n + 1, sizeof(cand))) return -1;
    if (bs_grow(&C->xy, &C->xycap, 4 * n + 4, sizeof(int32_t))) return -1;
    int32_t *xy = C->xy;
    uint32_t nc = 0, ndiag = 0, ntop = 0;
    *cut = 0;
    C->nchunked = 0;
    C->stampno++;
    for (uint32_t i = 0; i < n; i++) {
        const bs_seg *g = &t->segs[segs[i]];
        xy[4 * i] = g->x1;
        xy[4 * i + 1] = g->y1;
        xy[4 * i + 2] = g->x2;
        xy[4 * i + 3] = g->y2;
        if (C->stamp[g->line] == C->stampno) continue;
        C->stamp[g->line] = C->stampno;
        cand c = make_cand(t, g->line, g->side);
        if (x && c.kind) continue; /* the sweep scores those */
        C->cands[nc++] = c;
        ndiag += c.kind == 0;
    }
    if (x && n >= CHUNK_MIN && ndiag > 0 && chunk_set(C, n)) return -1;
    /* axis-aligned first: they set a low bar for the early exits of the rest */
    if (x) {
        sweep_axis(C, x, 0, top, &ntop, k);
        sweep_axis(C, x, 1, top, &ntop, k);
    } else {
        for (uint32_t i = 0; i < nc; i++) {
            const cand *c = &C->cands[i];
            if (c->kind) rank_loop(C, c, segs, n, top, &ntop, k, cap, cut);
        }
    }
    uint32_t want = ndiag <= DIAG_ALL ? ndiag : DIAG_SAMPLE;
    uint32_t kd = 0, id = 0;
    for (uint32_t i = 0; i < nc && kd < want; i++) {
        const cand *c = &C->cands[i];
        if (c->kind) continue;
        /* the kd-th pick is the diagonal candidate of rank kd * ndiag / want */
        if ((uint64_t)kd * ndiag / want == id) {
            rank_loop(C, c, segs, n, top, &ntop, k, cap, cut);
            kd++;
        }
        id++;
    }
    if (ntop == 0 && !*cut && want < ndiag) {
        /* the sample found nothing: every diagonal before calling it convex */
        for (uint32_t i = 0; i < nc; i++)
            if (!C->cands[i].kind) rank_loop(C, &C->cands[i], segs, n, top, &ntop, k, cap, cut);
    }
    return (int)ntop;
}

/* look-ahead: the children of c (classification only: a seg to be split goes
 * to both whole, close enough for scoring) into child[0] / child[1] and mark[] */
static int classify_children(bs_chooser *C, const uint32_t *segs, uint32_t n, const cand *c, uint32_t *nf, uint32_t *nb)
{
    const bs_tree *t = C->t;
    if (n > C->childcap) {
        uint32_t cap = n + n / 2 + 64;
        for (int k = 0; k < 2; k++) {
            uint32_t *q = realloc(C->child[k], sizeof(uint32_t) * cap);
            if (!q) return -1;
            C->child[k] = q;
        }
        C->childcap = cap;
    }
    if (bs_grow(&C->mark, &C->markcap, t->nsegs + 1, 1)) return -1;
    const bs_pline *L = &t->plines[c->pl];
    bs_part p = {c->pl, c->rev, 0, 0};
    *nf = *nb = 0;
    for (uint32_t i = 0; i < n; i++) {
        const bs_seg *g = &t->segs[segs[i]];
        int a = bs_side(L, c->rev, g->x1, g->y1);
        int b = bs_side(L, c->rev, g->x2, g->y2);
        int to_f, to_b;
        if (a == 0 && b == 0) {
            to_f = bs_same_dir(t, g, p);
            to_b = !to_f;
        } else {
            to_f = a > 0 || b > 0;
            to_b = a < 0 || b < 0;
        }
        C->mark[segs[i]] = (uint8_t)(to_f | to_b << 1);
        if (to_f) C->child[0][(*nf)++] = segs[i];
        if (to_b) C->child[1][(*nb)++] = segs[i];
    }
    return 0;
}

int bs_choose(bs_chooser *C, const uint32_t *segs, uint32_t n, uint32_t depth, bs_part *out)
{
    ranked top[MAX_RANK];
    uint32_t k = 1;
    if (C->strategy == BSPC_SPLIT_MIXED && n >= LOOK_MIN && depth < LOOK_MAX_DEPTH) k = LOOK;
    const index_set *x = NULL;
    if (n > SMALL) {
        if (index_build(C, &C->idx, segs, n)) return -1;
        x = &C->idx;
    }
    int cut;
    int nt = score_set(C, segs, n, depth, x, top, k, INT64_MAX, &cut);
    if (nt < 0) return -1;
    if (nt == 0) return 1;
    int mode = C->mode;
    uint32_t pick = 0;
    if (nt > 1 && mode != MODE_RESCUE) {
        /* one level of look-ahead: the candidate's cost plus its children's best */
        int64_t bestv = INT64_MAX;
        for (int i = 0; i < nt; i++) {
            uint32_t nch[2];
            if (classify_children(C, segs, n, &top[i].c, &nch[0], &nch[1])) return -1;
            int64_t v = top[i].s.cost;
            for (int side = 0; side < 2 && v < bestv; side++) {
                const index_set *cx = NULL;
                if (nch[side] > SMALL && x) {
                    if (index_filter(C, &C->cidx, x, (uint8_t)(1u << side))) return -1;
                    cx = &C->cidx;
                }
                /* the child's best matters only while it keeps v under bestv */
                int64_t cap = bestv == INT64_MAX ? INT64_MAX : bestv - v - 1;
                ranked ct;
                int r = score_set(C, C->child[side], nch[side], depth + 1, cx, &ct, 1, cap, &cut);
                if (r < 0) return -1;
                if (r > 0)
                    v += ct.s.cost;
                else if (cut)
                    v = bestv; /* costs more than cap: this candidate loses */
            }
            if (v < bestv) {
                bestv = v;
                pick = (uint32_t)i;
            }
        }
        C->mode = mode;
    }
    out->pl = top[pick].c.pl;
    out->rev = top[pick].c.rev;
    if (mode == MODE_RESCUE && n >= PEEL) {
        /* every seg line may peel off only a few segs (the outside of a round
         * pillar): try an axis-aligned line through the middle of the set */
        score best = top[pick].s;
        uint32_t small = best.front < best.back ? best.front : best.back;
        if (small * PEEL < n) {
            if (!x) {
                if (index_build(C, &C->idx, segs, n)) return -1;
                x = &C->idx;
            }
            for (int a = 0; a < 2; a++) {
                const axis_index *A = &x->ax[a];
                if (A->nn < 2) continue;
                /* the median of the crossing segs' low ends, on a whole 1/16 unit */
                int64_t mid = ((int64_t)val_of(A->lo[A->nn / 2]) + val_of(A->hi[A->nn / 2])) / 2;
                mid &= ~(int64_t)0xFFF;
                cand c = {SCN_NONE, 0, a == 0 ? 2 : 1, 1, (int32_t)mid};
                score s = eval_axis(C, x, &c);
                if (s.valid && s.front > 0 && s.cost < best.cost) {
                    best = s;
                    out->pl = SCN_NONE;
                    out->rev = 0;
                    out->axis = a;
                    out->c = c.c;
                }
            }
        }
    }
    return 0;
}
