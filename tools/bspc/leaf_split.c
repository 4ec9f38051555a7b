/* leaf_split.c - leaves whose floor polygon has more corners than the renderer
 * takes (SCN_MAX_LEAF_VERTS) are cut in two by a chord, again and again, until
 * every piece fits.
 *
 * A chord joins two corners of the convex polygon, so both pieces are convex,
 * keep the leaf's sector, and share the chord's two ends bit for bit: no new
 * point is made, so no T-junction either. The chord becomes a node whose front
 * child is the piece on its right; the segs go to the piece whose boundary they
 * lie on. Polygons within the limit are left alone, so the scenes that compiled
 * before compile to the same bytes.
 */
#include <stdlib.h>
#include <string.h>

#include "geom.h"

/* Is the chord i -> j a true cut: some corner strictly on each side of it?
 * (Corners in a straight row, as T-junction removal leaves, would make it an edge.) */
static int chord_cuts(const bs_pline *L, const bs_poly *p)
{
    int front = 0, back = 0;
    for (uint32_t k = 0; k < p->n && !(front && back); k++) {
        int s = bs_side(L, 0, p->v[k].x, p->v[k].y);
        front |= s > 0;
        back |= s < 0;
    }
    return front && back;
}

/* Corners i..j (front piece, closed by the chord j -> i) and j..i (back piece,
 * closed by i -> j); pl is the chord's line, running i -> j. */
static int cut_pieces(const bs_poly *p, uint32_t i, uint32_t j, uint32_t pl, bs_poly *front, bs_poly *back)
{
    uint32_t n = p->n;
    for (uint32_t k = i; k != j; k = (k + 1) % n)
        if (bs_poly_push(front, p->v[k].x, p->v[k].y, p->v[k].eline)) return -1;
    if (bs_poly_push(front, p->v[j].x, p->v[j].y, pl)) return -1;
    for (uint32_t k = j; k != i; k = (k + 1) % n)
        if (bs_poly_push(back, p->v[k].x, p->v[k].y, p->v[k].eline)) return -1;
    if (bs_poly_push(back, p->v[i].x, p->v[i].y, pl)) return -1;
    return 0;
}

/* Segs of the leaf to the side of the chord they lie on (the front keeps the array). */
static int share_segs(const bs_tree *t, const bs_pline *L, bs_leaf *f, bs_leaf *b)
{
    uint32_t kept = 0;
    for (uint32_t k = 0; k < f->nsegs; k++) {
        const bs_seg *g = &t->segs[f->segs[k]];
        int s = bs_side(L, 0, g->x1, g->y1) + bs_side(L, 0, g->x2, g->y2);
        if (s >= 0) {
            f->segs[kept++] = f->segs[k];
            continue;
        }
        if (bs_grow(&b->segs, &b->cap, b->nsegs + 1, sizeof(uint32_t))) return -1;
        b->segs[b->nsegs++] = f->segs[k];
    }
    f->nsegs = kept;
    return 0;
}

/* Cut leaf li once, near its middle. 1: no chord cuts it; -1: out of memory. */
static int split_leaf(bs_tree *t, uint32_t li)
{
    bs_poly *p = &t->leaves[li].poly;
    uint32_t n = p->n, i = 0, j = 0;
    bs_pline L;
    for (i = 0; i < n; i++) {
        j = (i + n / 2) % n;
        bs_pline_set(&L, p->v[i].x, p->v[i].y, (int64_t)p->v[j].x - p->v[i].x, (int64_t)p->v[j].y - p->v[i].y);
        if (chord_cuts(&L, p)) break;
    }
    if (i == n) return 1;
    if (bs_grow(&t->plines, &t->plcap, t->nplines + 1, sizeof(bs_pline)) ||
        bs_grow(&t->nodes, &t->nodecap, t->nnodes + 1, sizeof(bs_node)) ||
        bs_grow(&t->leaves, &t->leafcap, t->nleaves + 1, sizeof(bs_leaf)))
        return -1;
    uint32_t pl = t->nplines++;
    t->plines[pl] = L;

    bs_leaf *f = &t->leaves[li], *b = &t->leaves[t->nleaves];
    memset(b, 0, sizeof *b);
    bs_poly whole = f->poly, fp, bp;
    memset(&fp, 0, sizeof fp);
    memset(&bp, 0, sizeof bp);
    if (cut_pieces(&whole, i, j, pl, &fp, &bp) || share_segs(t, &L, f, b)) {
        bs_poly_free(&fp);
        bs_poly_free(&bp);
        free(b->segs);
        return -1;
    }
    bs_poly_free(&whole);
    uint32_t bi = t->nleaves++, ni = t->nnodes++;

    bs_node *N = &t->nodes[ni];
    memset(N, 0, sizeof *N);
    N->pline = pl;
    N->rev = 0;
    N->child[0] = SCN_LEAF_BIT | li;
    N->child[1] = SCN_LEAF_BIT | bi;
    if (f->parent == SCN_NONE) {
        t->root = ni;
    } else {
        bs_node *P = &t->nodes[f->parent];
        P->child[P->child[0] == (SCN_LEAF_BIT | li) ? 0 : 1] = ni;
    }
    f->poly = fp;
    b->poly = bp;
    b->sector = f->sector;
    f->depth = b->depth = f->depth + 1;
    f->parent = b->parent = ni;
    return 0;
}

int bs_split_big_leaves(bs_tree *t, const char *name, char *err, size_t errlen)
{
    /* pieces are appended, so the loop reaches them too; each cut halves a polygon */
    for (uint32_t li = 0; li < t->nleaves; li++) {
        while (t->leaves[li].poly.n > SCN_MAX_LEAF_VERTS) {
            int rc = split_leaf(t, li);
            if (rc < 0) return bs_fail(err, errlen, "%s: out of memory", name);
            if (rc > 0)
                return bs_fail(err, errlen,
                               "%s: leaf %u: floor polygon of %u vertices has no chord to cut it at "
                               "(the renderer takes %d)",
                               name, li, t->leaves[li].poly.n, SCN_MAX_LEAF_VERTS);
        }
    }
    return 0;
}
