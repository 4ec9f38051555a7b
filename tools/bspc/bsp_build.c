/* bsp_build.c - the 2-D BSP tree build: segs from linedefs, the vertex table,
 * exact seg splitting, leaves with their sector and convex floor region.
 *
 * The build is iterative (an explicit stack of work items, front child first;
 * nodes are numbered parent first, so the root is node 0). A work item is a
 * set of segs and the convex region (polygon) they lie in. split_choice.c
 * picks the partition, or says the set is convex and becomes a leaf.
 *
 * Splitting: a seg with its ends strictly on opposite sides is cut where the
 * partition meets the seg's own linedef (exact, rounded to 16.16; the point is
 * shared through the vertex table, so both sides of a two-sided line get the
 * same vertex). A cut that would round onto an end is no cut: the seg goes
 * wholly to the side of its other end. A seg on the partition (both ends within
 * BS_EPS) goes front if it runs the same way, back otherwise.
 */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "geom.h"

/* ---------------------------------------------------------------- vertices */

static uint32_t vhash(int32_t x, int32_t y)
{
    uint32_t h = (uint32_t)x * 0x9E3779B1u ^ ((uint32_t)y * 0x85EBCA77u);
    h ^= h >> 15;
    return h * 0xC2B2AE3Du;
}

static int vhash_grow(bs_tree *t)
{
    uint32_t nc = t->hcap ? t->hcap * 2 : 4096;
    uint32_t *nh = calloc(nc, sizeof *nh);
    if (!nh) return -1;
    for (uint32_t i = 0; i < t->nverts; i++) {
        uint32_t h = vhash(t->vx[i], t->vy[i]) & (nc - 1);
        while (nh[h]) h = (h + 1) & (nc - 1);
        nh[h] = i + 1;
    }
    free(t->vhash);
    t->vhash = nh;
    t->hcap = nc;
    return 0;
}

uint32_t bs_vertex(bs_tree *t, int32_t x, int32_t y)
{
    if ((uint64_t)(t->nverts + 1) * 2 > t->hcap && vhash_grow(t)) return SCN_NONE;
    uint32_t h = vhash(x, y) & (t->hcap - 1);
    while (t->vhash[h]) {
        uint32_t i = t->vhash[h] - 1;
        if (t->vx[i] == x && t->vy[i] == y) return i;
        h = (h + 1) & (t->hcap - 1);
    }
    uint32_t cap = t->vcap;
    if (bs_grow(&t->vx, &cap, t->nverts + 1, sizeof(int32_t))) return SCN_NONE;
    cap = t->vcap;
    if (bs_grow(&t->vy, &cap, t->nverts + 1, sizeof(int32_t))) return SCN_NONE;
    t->vcap = cap;
    t->vx[t->nverts] = x;
    t->vy[t->nverts] = y;
    t->vhash[h] = t->nverts + 1;
    return t->nverts++;
}

/* ---------------------------------------------------------------- work items */

typedef struct {
    uint32_t *segs;
    uint32_t n, cap;
    bs_poly poly;
    uint32_t parent, which, depth;
} work;

typedef struct {
    bs_tree *t;
    const bs_scene *s;
    const bspc_options *opt;
    bs_chooser *chooser;
    uint32_t warned;
    uint32_t *count; /* per sector, and one for SCN_NONE: make_leaf's tally */
} builder;

/* the sector a seg faces, as an index into count[] (the last entry: none) */
static uint32_t seg_sector(const builder *B, uint32_t seg)
{
    const bs_seg *g = &B->t->segs[seg];
    uint32_t sec = B->s->lines[g->line].sector[g->side];
    return sec < B->s->nsectors ? sec : B->s->nsectors;
}

static int push_seg(work *w, uint32_t seg)
{
    if (bs_grow(&w->segs, &w->cap, w->n + 1, sizeof(uint32_t))) return -1;
    w->segs[w->n++] = seg;
    return 0;
}

/* ---------------------------------------------------------------- splitting */

static int split_set(builder *B, work *w, bs_part c, work *front, work *back, char *err, size_t errlen)
{
    bs_tree *t = B->t;
    for (uint32_t i = 0; i < w->n; i++) {
        uint32_t gi = w->segs[i];
        bs_seg g = t->segs[gi];
        int a = bs_side(&t->plines[c.pl], c.rev, g.x1, g.y1);
        int b = bs_side(&t->plines[c.pl], c.rev, g.x2, g.y2);
        work *to;
        if (a == 0 && b == 0) {
            to = bs_same_dir(t, &g, c) ? front : back;
        } else if (a >= 0 && b >= 0) {
            to = front;
        } else if (a <= 0 && b <= 0) {
            to = back;
        } else {
            int32_t x, y;
            if (bs_intersect(t->plines, c.pl, g.line, &x, &y)) {
                /* cannot happen: ends on opposite sides means not parallel */
                return bs_fail(err, errlen, "%s: internal error: parallel split of linedef %u", B->s->name, g.line);
            }
            if (x == g.x1 && y == g.y1) {
                to = (b > 0) ? front : back; /* the cut rounds onto an end: no cut */
            } else if (x == g.x2 && y == g.y2) {
                to = (a > 0) ? front : back;
            } else {
                if (bs_seg_budget_check(t, B->s->name, 1, g.line, err, errlen)) return -1;
                uint32_t v = bs_vertex(t, x, y);
                if (v == SCN_NONE) return bs_fail(err, errlen, "%s: out of memory", B->s->name);
                if (bs_grow(&t->segs, &t->segcap, t->nsegs + 1, sizeof(bs_seg)))
                    return bs_fail(err, errlen, "%s: out of memory", B->s->name);
                uint32_t ni = t->nsegs++;
                bs_seg *p1 = &t->segs[gi], *p2 = &t->segs[ni];
                *p2 = g;
                p1->x2 = x;
                p1->y2 = y;
                p1->v2 = v;
                p2->x1 = x;
                p2->y1 = y;
                p2->v1 = v;
                t->part_splits++;
                /* piece 1 (v1 -> X) is on a's side, piece 2 on b's */
                if (push_seg(a > 0 ? front : back, gi) || push_seg(b > 0 ? front : back, ni))
                    return bs_fail(err, errlen, "%s: out of memory", B->s->name);
                continue;
            }
        }
        if (push_seg(to, gi)) return bs_fail(err, errlen, "%s: out of memory", B->s->name);
    }
    return 0;
}

/* ---------------------------------------------------------------- leaves */

static int make_leaf(builder *B, work *w, char *err, size_t errlen)
{
    bs_tree *t = B->t;
    if (bs_grow(&t->leaves, &t->leafcap, t->nleaves + 1, sizeof(bs_leaf)))
        return bs_fail(err, errlen, "%s: out of memory", B->s->name);
    uint32_t li = t->nleaves++;
    bs_leaf *L = &t->leaves[li];
    memset(L, 0, sizeof *L);
    L->segs = w->segs;
    L->nsegs = w->n;
    L->cap = w->cap;
    L->depth = w->depth;
    L->parent = w->parent;
    L->poly = w->poly;
    w->segs = NULL;
    w->poly.v = NULL;
    if (w->parent == SCN_NONE)
        t->root = SCN_LEAF_BIT | li;
    else
        t->nodes[w->parent].child[w->which] = SCN_LEAF_BIT | li;

    /* sector: the most common one among the segs' facing sides (the first seg's
     * on a tie), counted per sector in B->count, which is all zero between leaves */
    uint32_t best = SCN_NONE, bestn = 0, distinct = 0;
    for (uint32_t i = 0; i < L->nsegs; i++) distinct += B->count[seg_sector(B, L->segs[i])]++ == 0;
    for (uint32_t i = 0; i < L->nsegs; i++) {
        const bs_seg *g = &t->segs[L->segs[i]];
        uint32_t c = B->count[seg_sector(B, L->segs[i])];
        if (c > bestn) {
            bestn = c;
            best = B->s->lines[g->line].sector[g->side];
        }
    }
    for (uint32_t i = 0; i < L->nsegs; i++) B->count[seg_sector(B, L->segs[i])] = 0;
    L->sector = best;
    if (distinct > 1) {
        if (B->warned < 10)
            bs_warn(B->opt, "%s: leaf %u: segs face %u different sectors; using sector %u", B->s->name, li, distinct,
                    best);
        else if (B->warned == 10)
            bs_warn(B->opt, "%s: more leaves with mixed sectors (not listed)", B->s->name);
        B->warned++;
    }

    /* floor polygon: the region clipped by every seg's front half-plane */
    for (uint32_t i = 0; i < L->nsegs && L->poly.n; i++) {
        const bs_seg *g = &t->segs[L->segs[i]];
        if (bs_poly_clip_front(t, &L->poly, g->line, g->side))
            return bs_fail(err, errlen, "%s: out of memory", B->s->name);
    }
    bs_poly_tidy(&L->poly);
    return 0;
}

/* ---------------------------------------------------------------- the build */

void bs_tree_free(bs_tree *t)
{
    free(t->vx);
    free(t->vy);
    free(t->vhash);
    free(t->plines);
    free(t->line_v);
    free(t->segs);
    free(t->nodes);
    for (uint32_t i = 0; i < t->nleaves; i++) {
        free(t->leaves[i].segs);
        bs_poly_free(&t->leaves[i].poly);
    }
    free(t->leaves);
    memset(t, 0, sizeof *t);
}

static int setup(bs_tree *t, const bs_scene *s, char *err, size_t errlen)
{
    /* vertices that lines use, in scene order (duplicates merged) */
    uint32_t *map = malloc(sizeof *map * (s->nverts + 1));
    uint8_t *used = calloc(s->nverts + 1, 1);
    if (!map || !used) {
        free(map);
        free(used);
        return bs_fail(err, errlen, "%s: out of memory", s->name);
    }
    for (uint32_t i = 0; i < s->nlines; i++) used[s->lines[i].v1] = used[s->lines[i].v2] = 1;
    int64_t xmin = INT64_MAX, ymin = INT64_MAX, xmax = INT64_MIN, ymax = INT64_MIN;
    for (uint32_t i = 0; i < s->nverts; i++) {
        map[i] = SCN_NONE;
        if (!used[i]) continue;
        map[i] = bs_vertex(t, s->vx[i], s->vy[i]);
        if (map[i] == SCN_NONE) break;
        if (s->vx[i] < xmin) xmin = s->vx[i];
        if (s->vx[i] > xmax) xmax = s->vx[i];
        if (s->vy[i] < ymin) ymin = s->vy[i];
        if (s->vy[i] > ymax) ymax = s->vy[i];
    }
    free(used);
    t->norig = t->nverts;
    t->nplines = s->nlines + 4;
    t->plcap = t->nplines + 64;
    t->plines = malloc(sizeof *t->plines * t->plcap);
    t->segcap = s->nlines * 2 + 16;
    t->segs = malloc(sizeof *t->segs * t->segcap);
    t->line_v = malloc(sizeof *t->line_v * 2 * (s->nlines + 1));
    if (!t->plines || !t->segs || !t->line_v) {
        free(map);
        return bs_fail(err, errlen, "%s: out of memory", s->name);
    }
    for (uint32_t i = 0; i < s->nlines; i++) {
        const bs_line *l = &s->lines[i];
        uint32_t v1 = map[l->v1], v2 = map[l->v2];
        if (v1 == SCN_NONE || v2 == SCN_NONE) {
            free(map);
            return bs_fail(err, errlen, "%s: out of memory", s->name);
        }
        int32_t x1 = t->vx[v1], y1 = t->vy[v1], x2 = t->vx[v2], y2 = t->vy[v2];
        t->line_v[2 * i] = v1;
        t->line_v[2 * i + 1] = v2;
        bs_pline_set(&t->plines[i], x1, y1, (int64_t)x2 - x1, (int64_t)y2 - y1);
        t->segs[t->nsegs++] = (bs_seg){x1, y1, x2, y2, v1, v2, i, 0};
        if (l->sector[1] != SCN_NONE) t->segs[t->nsegs++] = (bs_seg){x2, y2, x1, y1, v2, v1, i, 1};
    }
    free(map);
    t->nsides = t->nsegs;

    /* world box: everything plus a margin, inside the coordinate range */
    const int64_t margin = (int64_t)64 << 16;
    xmin -= margin;
    ymin -= margin;
    xmax += margin;
    ymax += margin;
    if (xmin < -BS_COORD_RAW_MAX) xmin = -BS_COORD_RAW_MAX;
    if (ymin < -BS_COORD_RAW_MAX) ymin = -BS_COORD_RAW_MAX;
    if (xmax > BS_COORD_RAW_MAX) xmax = BS_COORD_RAW_MAX;
    if (ymax > BS_COORD_RAW_MAX) ymax = BS_COORD_RAW_MAX;
    t->world[0] = (int32_t)xmin;
    t->world[1] = (int32_t)ymin;
    t->world[2] = (int32_t)xmax;
    t->world[3] = (int32_t)ymax;
    uint32_t b = s->nlines;
    bs_pline_set(&t->plines[b + 0], (int32_t)xmin, (int32_t)ymin, 65536, 0);  /* bottom, east */
    bs_pline_set(&t->plines[b + 1], (int32_t)xmax, (int32_t)ymin, 0, 65536);  /* right, north */
    bs_pline_set(&t->plines[b + 2], (int32_t)xmax, (int32_t)ymax, -65536, 0); /* top, west */
    bs_pline_set(&t->plines[b + 3], (int32_t)xmin, (int32_t)ymax, 0, -65536); /* left, south */
    return 0;
}

int bs_build(const bs_scene *s, const bspc_options *opt, bs_tree *t, char *err, size_t errlen)
{
    memset(t, 0, sizeof *t);
    t->root = SCN_NONE;
    if (setup(t, s, err, errlen)) return -1;

    builder B;
    memset(&B, 0, sizeof B);
    B.t = t;
    B.s = s;
    B.opt = opt;
    B.chooser = bs_chooser_new(t, opt ? opt->split : BSPC_SPLIT_MIXED);
    B.count = calloc((size_t)s->nsectors + 1, sizeof *B.count);

    uint32_t scap = 0, sn = 0;
    work *stack = NULL;
    int rc = -1;
    if (!B.chooser || !B.count || bs_grow(&stack, &scap, 64, sizeof(work))) {
        bs_fail(err, errlen, "%s: out of memory", s->name);
        goto out;
    }
    {
        work root;
        memset(&root, 0, sizeof root);
        root.parent = SCN_NONE;
        for (uint32_t i = 0; i < t->nsegs; i++)
            if (push_seg(&root, i)) {
                bs_fail(err, errlen, "%s: out of memory", s->name);
                goto out;
            }
        uint32_t b = s->nlines;
        if (bs_poly_push(&root.poly, t->world[0], t->world[1], b + 0) ||
            bs_poly_push(&root.poly, t->world[2], t->world[1], b + 1) ||
            bs_poly_push(&root.poly, t->world[2], t->world[3], b + 2) ||
            bs_poly_push(&root.poly, t->world[0], t->world[3], b + 3)) {
            free(root.segs);
            bs_poly_free(&root.poly);
            bs_fail(err, errlen, "%s: out of memory", s->name);
            goto out;
        }
        stack[sn++] = root;
    }

    while (sn > 0) {
        work w = stack[--sn];
        bs_part c = {0, 0, 0, 0};
        int ch = bs_choose(B.chooser, w.segs, w.n, w.depth, &c);
        if (ch < 0) {
            free(w.segs);
            bs_poly_free(&w.poly);
            bs_fail(err, errlen, "%s: out of memory", s->name);
            goto out;
        }
        if (ch == 0 && c.pl == SCN_NONE) {
            /* a partition on no seg: add its line */
            if (bs_grow(&t->plines, &t->plcap, t->nplines + 1, sizeof(bs_pline))) {
                free(w.segs);
                bs_poly_free(&w.poly);
                bs_fail(err, errlen, "%s: out of memory", s->name);
                goto out;
            }
            if (c.axis == 0)
                bs_pline_set(&t->plines[t->nplines], c.c, 0, 0, 65536);
            else
                bs_pline_set(&t->plines[t->nplines], 0, c.c, 65536, 0);
            c.pl = t->nplines++;
            c.rev = 0;
        }
        if (ch > 0) {
            if (make_leaf(&B, &w, err, errlen)) {
                free(w.segs);
                bs_poly_free(&w.poly);
                goto out;
            }
            continue;
        }
        if (w.depth >= SCN_MAX_DEPTH) {
            free(w.segs);
            bs_poly_free(&w.poly);
            bs_fail(err, errlen, "%s: BSP tree deeper than %d nodes (try --split balanced)", s->name, SCN_MAX_DEPTH);
            goto out;
        }
        if (bs_grow(&t->nodes, &t->nodecap, t->nnodes + 1, sizeof(bs_node))) {
            free(w.segs);
            bs_poly_free(&w.poly);
            bs_fail(err, errlen, "%s: out of memory", s->name);
            goto out;
        }
        uint32_t ni = t->nnodes++;
        bs_node *N = &t->nodes[ni];
        memset(N, 0, sizeof *N);
        N->pline = c.pl;
        N->rev = c.rev;
        N->child[0] = N->child[1] = SCN_NONE;
        if (w.parent == SCN_NONE)
            t->root = ni;
        else
            t->nodes[w.parent].child[w.which] = ni;

        work f, b;
        memset(&f, 0, sizeof f);
        memset(&b, 0, sizeof b);
        f.parent = b.parent = ni;
        f.which = 0;
        b.which = 1;
        f.depth = b.depth = w.depth + 1;
        int e = split_set(&B, &w, c, &f, &b, err, errlen);
        if (!e && bs_poly_split(t, &w.poly, c.pl, c.rev, &f.poly, &b.poly))
            e = bs_fail(err, errlen, "%s: out of memory", s->name);
        free(w.segs);
        bs_poly_free(&w.poly);
        if (!e && bs_grow(&stack, &scap, sn + 2, sizeof(work))) e = bs_fail(err, errlen, "%s: out of memory", s->name);
        if (e) {
            free(f.segs);
            free(b.segs);
            bs_poly_free(&f.poly);
            bs_poly_free(&b.poly);
            goto out;
        }
        stack[sn++] = b;
        stack[sn++] = f; /* front first */
    }
    rc = 0;
out:
    for (uint32_t i = 0; i < sn; i++) {
        free(stack[i].segs);
        bs_poly_free(&stack[i].poly);
    }
    free(stack);
    bs_chooser_free(B.chooser);
    free(B.count);
    return rc;
}

uint64_t bs_seg_budget(const bs_tree *t)
{
    uint64_t log2 = 0;
    while (log2 < 32 && ((uint64_t)1 << log2) < t->nsides) log2++;
    return (uint64_t)t->nsides * (log2 + 2) + 4096u;
}

int bs_seg_budget_check(const bs_tree *t, const char *name, uint32_t more, uint32_t line, char *err, size_t errlen)
{
    uint64_t budget = bs_seg_budget(t);
    if ((uint64_t)t->nsegs + more <= budget) return 0;
    return bs_fail(err, errlen,
                   "%s: linedef %u: the tree cuts the %u wall sides into more than %llu pieces, the "
                   "compiler's budget (sides x (log2 sides + 2) + 4,096, above what maps whose walls "
                   "do not cross need)",
                   name, line, t->nsides, (unsigned long long)budget);
}
