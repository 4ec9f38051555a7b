/* raster.c - convex polygon scan conversion.
 * Each edge is walked top to bottom with an integer DDA (RAST_STEP_BITS in
 * raster.h: by default the exact whole step plus a remainder against the
 * edge's height, or a step rounded to fewer bits), and two polygons sharing an edge
 * compute the same x on every line, whichever renderer walks it. */
#include "raster.h"

void rast_ids(const rast_target *t, int y, int x0, int x1, uint32_t id)
{
    uint32_t *row = t->ids + y * VIEW_W;
    for (int x = x0; x < x1; x++) row[x] = id;
}

/* Floor division for a positive divisor. */
static inline int64_t floor_div(int64_t a, int64_t b)
{
    int64_t q = a / b;
    return (a % b < 0) ? q - 1 : q;
}

int rast_edge_setup(rast_edge *e, int32_t xa, int32_t ya, int32_t xb, int32_t yb)
{
    int32_t row = rast_first_sample(ya), end = rast_first_sample(yb);
    if (row < 0 || end > VIEW_H) return 0; /* outside the contract: draw nothing */
    if (row >= end) return 0;
    /* |dx| < 2^25 and the first sample is under one row below ya: the products
     * stay below 2^42 */
    int64_t dx = (int64_t)xb - xa, dy = (int64_t)yb - ya;
#if RAST_STEP_BITS == 0
    int64_t num = (((int64_t)row << 16) + 32768 - ya) * dx;
#if FX_DIV32
    /* docs/ranges.md: the first sample lies in [ya, yb), so |x| <= |dx| < 2^25;
     * over more than one row's height, |step| < |dx| too */
    if (dy > 65536) {
        uint32_t r;
        e->x = xa + fx_floordiv64_32(num, (uint32_t)dy, &r);
        e->rem = (int32_t)r;
        e->step = fx_floordiv64_32(dx * 65536, (uint32_t)dy, &r);
        e->srem = (int32_t)r;
        e->dy = (int32_t)dy;
        e->row = (int16_t)row;
        e->end_row = (int16_t)end;
        return 1;
    }
#endif
    int64_t x = floor_div(num, dy);
    int64_t step = floor_div(dx * 65536, dy);
    e->x = (int32_t)(xa + x);
    e->rem = (int32_t)(num - x * dy); /* in [0, dy) */
    e->step = (int32_t)step;
    e->srem = (int32_t)(dx * 65536 - step * dy);
#else
    /* dx / dy rounded to RAST_STEP_BITS fraction bits, in 16.16; x from the top
     * vertex with that step */
    int64_t step = floor_div(dx * (2 << RAST_STEP_BITS) + dy, 2 * dy) * (1 << (16 - RAST_STEP_BITS));
    e->x = (int32_t)(xa + fx_asr64((((int64_t)row << 16) + 32768 - ya) * step, 16));
    e->rem = e->srem = 0;
    e->step = (int32_t)step;
#endif
    e->dy = (int32_t)dy;
    e->row = (int16_t)row;
    e->end_row = (int16_t)end;
    return 1;
}

void rast_rows(const screen_pt *pts, int n, int top, int bottom, int16_t lo[VIEW_H], int16_t hi[VIEW_H])
{
    for (int y = top; y < bottom; y++) {
        lo[y] = VIEW_W;
        hi[y] = 0;
    }
    for (int i = 0; i < n; i++) {
        screen_pt a = pts[i], b = pts[(i + 1 == n) ? 0 : i + 1];
        if (a.y == b.y) continue;
        int leading = a.y > b.y; /* going up the screen: a left edge */
        rast_edge e;
        if (!(leading ? rast_edge_setup(&e, b.x, b.y, a.x, a.y) : rast_edge_setup(&e, a.x, a.y, b.x, b.y))) continue;
        int16_t *side = leading ? lo : hi;
        for (; e.row < e.end_row; rast_edge_step(&e)) {
            int col = rast_first_sample(e.x);
            side[e.row] = (int16_t)(col < 0 ? 0 : (col > VIEW_W ? VIEW_W : col));
        }
    }
}

/* Record x at every sample row of edge (xa,ya)->(xb,yb), ya < yb, into xs[]. */
static void walk_edge(int32_t *xs, int32_t xa, int32_t ya, int32_t xb, int32_t yb)
{
    rast_edge e;
    if (!rast_edge_setup(&e, xa, ya, xb, yb)) return;
    for (; e.row < e.end_row; rast_edge_step(&e)) xs[e.row] = e.x;
}

#if CFG_TEXTURES
void rast_textured(const rast_target *t, int y, int x0, int x1, const tex_paint *paint)
{
    uint32_t row[VIEW_W / 4]; /* indexed by screen column, aligned as the surface's rows */
    uint8_t *px = (uint8_t *)row;
    tex_span(paint, y, x0, x1, px);
    if (t->tally)
        hal_put_linear(t->surf, y, x0, x1 - x0, px, t->tally);
    else
        hal_put_span(t->surf, y, x0, x1 - x0, px);
}
#endif

uint32_t rast_convex(const rast_target *t, const screen_pt *pts, int n, const tex_paint *paint, uint32_t id)
{
    int32_t left[VIEW_H], right[VIEW_H];
    int32_t ymin = INT32_MAX, ymax = INT32_MIN;
    if (n < 3) return 0;
    for (int i = 0; i < n; i++) {
        if (pts[i].y < ymin) ymin = pts[i].y;
        if (pts[i].y > ymax) ymax = pts[i].y;
    }
    int32_t top = rast_first_sample(ymin), bottom = rast_first_sample(ymax);
    if (top < 0) top = 0;
    if (bottom > VIEW_H) bottom = VIEW_H;
    if (top >= bottom) return 0;
    for (int32_t y = top; y < bottom; y++) {
        left[y] = VIEW_W_FX;
        right[y] = 0;
    }
    for (int i = 0; i < n; i++) {
        screen_pt a = pts[i], b = pts[(i + 1 == n) ? 0 : i + 1];
        if (a.y < b.y)
            walk_edge(right, a.x, a.y, b.x, b.y); /* going down: right side */
        else if (a.y > b.y)
            walk_edge(left, b.x, b.y, a.x, a.y); /* going up: left side */
    }
    uint32_t drawn = 0;
    for (int32_t y = top; y < bottom; y++) {
        int32_t x0 = rast_first_sample(left[y]), x1 = rast_first_sample(right[y]);
        if (x0 < 0) x0 = 0;
        if (x1 > VIEW_W) x1 = VIEW_W;
        if (x1 > x0) {
            rast_span(t, y, x0, x1, paint, id);
            drawn += (uint32_t)(x1 - x0);
        }
    }
    return drawn;
}

void rast_clear(const rast_target *t, uint8_t colour)
{
    tex_paint paint = tex_flat(colour);
    for (int y = 0; y < VIEW_H; y++) rast_span(t, y, 0, VIEW_W, &paint, RAST_ID(RAST_KIND_NONE, 0));
}
