/* crossings.c - walls that cross each other (docs/scene-format.md, Checks).
 *
 * Two walls cross when each has its ends strictly on opposite sides of the
 * other's line: their insides meet at one point. Such a map has sectors that
 * overlap, and no tree can give every piece of floor one sector: the renderer
 * would show holes. Walls that only touch (an end on another wall, a shared
 * corner) and walls on one line do not cross. A wall with the same sector on
 * both sides (a Doom trigger line, a self-referencing sector) divides nothing,
 * so it may cross others: freedoom2.wad MAP20's linedef 1647 does.
 *
 * The search sorts the walls by their left end and compares each with those
 * whose x range meets its own, so a map of short walls costs n log n.
 */
#include <stdlib.h>

#include "bspc_int.h"

typedef struct {
    int32_t x0, x1, y0, y1; /* the wall's box */
    uint32_t line;
} xwall;

static int cmp_x0(const void *a, const void *b)
{
    const xwall *p = a, *q = b;
    if (p->x0 != q->x0) return p->x0 < q->x0 ? -1 : 1;
    return p->line < q->line ? -1 : p->line > q->line;
}

static int sign128(bs_i128 v)
{
    return (v > 0) - (v < 0);
}

/* side of (px, py) relative to the line a -> b: +1, -1 or 0 (exact) */
static int orient(int64_t ax, int64_t ay, int64_t bx, int64_t by, int64_t px, int64_t py)
{
    return sign128((bs_i128)(bx - ax) * (py - ay) - (bs_i128)(by - ay) * (px - ax));
}

/* value + delta * num / den rounded to the nearest raw unit (den > 0) */
static int32_t lerp_round(int64_t value, int64_t delta, bs_i128 num, bs_i128 den)
{
    bs_i128 p = (bs_i128)delta * num * 2;
    bs_i128 q = p >= 0 ? (p + den) / (2 * den) : -((-p + den) / (2 * den));
    return (int32_t)(value + (int64_t)q);
}

/* Do lines a and b cross? If so, their crossing point rounded to 16.16. */
static int cross(const bs_scene *s, uint32_t a, uint32_t b, int32_t *x, int32_t *y)
{
    const bs_line *la = &s->lines[a], *lb = &s->lines[b];
    int64_t ax = s->vx[la->v1], ay = s->vy[la->v1], bx = s->vx[la->v2], by = s->vy[la->v2];
    int64_t cx = s->vx[lb->v1], cy = s->vy[lb->v1], dx = s->vx[lb->v2], dy = s->vy[lb->v2];
    if (orient(ax, ay, bx, by, cx, cy) * orient(ax, ay, bx, by, dx, dy) >= 0) return 0;
    if (orient(cx, cy, dx, dy, ax, ay) * orient(cx, cy, dx, dy, bx, by) >= 0) return 0;
    /* a + t (b - a) with t = ((c - a) x (d - c)) / ((b - a) x (d - c)) */
    bs_i128 num = (bs_i128)(cx - ax) * (dy - cy) - (bs_i128)(cy - ay) * (dx - cx);
    bs_i128 den = (bs_i128)(bx - ax) * (dy - cy) - (bs_i128)(by - ay) * (dx - cx);
    if (den < 0) {
        num = -num;
        den = -den;
    }
    *x = lerp_round(ax, bx - ax, num, den);
    *y = lerp_round(ay, by - ay, num, den);
    return 1;
}

static int refuse(const bs_scene *s, uint32_t a, uint32_t b, int32_t x, int32_t y, char *err, size_t errlen)
{
    char bx[32], by[32];
    const bs_line *la = &s->lines[a], *lb = &s->lines[b];
    if (la->src_line > lb->src_line) {
        const bs_line *t = la;
        la = lb;
        lb = t;
    }
    if (s->is_text)
        return bs_fail(err, errlen, "%s:%d: wall crosses the wall of line %d at (%s, %s)", s->name, la->src_line,
                       lb->src_line, bs_fxstr(x, bx), bs_fxstr(y, by));
    return bs_fail(err, errlen, "%s: linedef %d crosses linedef %d at (%s, %s)", s->name, la->src_line, lb->src_line,
                   bs_fxstr(x, bx), bs_fxstr(y, by));
}

int bs_check_crossings(const bs_scene *s, char *err, size_t errlen)
{
    if (s->nlines < 2) return 0;
    xwall *w = malloc(sizeof *w * s->nlines);
    if (!w) return bs_fail(err, errlen, "%s: out of memory", s->name);
    uint32_t n = 0;
    for (uint32_t i = 0; i < s->nlines; i++) {
        const bs_line *l = &s->lines[i];
        if (l->sector[0] == l->sector[1]) continue;
        int32_t x1 = s->vx[l->v1], y1 = s->vy[l->v1], x2 = s->vx[l->v2], y2 = s->vy[l->v2];
        w[n++] = (xwall){x1 < x2 ? x1 : x2, x1 < x2 ? x2 : x1, y1 < y2 ? y1 : y2, y1 < y2 ? y2 : y1, i};
    }
    qsort(w, n, sizeof *w, cmp_x0);
    /* the first crossing in line order, so the message does not depend on the sort */
    uint32_t best_a = SCN_NONE, best_b = SCN_NONE;
    int32_t best_x = 0, best_y = 0;
    for (uint32_t i = 0; i < n; i++)
        for (uint32_t j = i + 1; j < n && w[j].x0 <= w[i].x1; j++) {
            if (w[j].y0 > w[i].y1 || w[j].y1 < w[i].y0) continue;
            int32_t x, y;
            if (!cross(s, w[i].line, w[j].line, &x, &y)) continue;
            uint32_t a = w[i].line < w[j].line ? w[i].line : w[j].line;
            uint32_t b = w[i].line ^ w[j].line ^ a;
            if (best_a == SCN_NONE || a < best_a || (a == best_a && b < best_b)) {
                best_a = a;
                best_b = b;
                best_x = x;
                best_y = y;
            }
        }
    free(w);
    if (best_a == SCN_NONE) return 0;
    return refuse(s, best_a, best_b, best_x, best_y, err, errlen);
}
