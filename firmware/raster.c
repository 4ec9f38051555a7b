/* raster.c - convex polygon scan conversion with exact edge stepping.
 * Each edge is walked top to bottom with an integer DDA (whole step plus a
 * remainder against the edge's height), so x at every scan line is exactly
 * floor(true x) in 16.16: no error accumulates however long the edge is, and
 * two polygons sharing an edge compute the same x on every line. */
#include "raster.h"

void rast_span(const rast_target *t, int y, int x0, int x1, uint8_t colour, uint32_t id)
{
    if (x1 <= x0) return;
    hal_fill_span(t->surf, y, x0, x1 - x0, colour);
    if (t->ids) {
        uint32_t *row = t->ids + y * VIEW_W;
        for (int x = x0; x < x1; x++) row[x] = id;
    }
}

/* Pixel index of the first sample at or right of (or below) a 16.16 coordinate:
 * ceil(v - 0.5). v is never negative here. */
static inline int32_t first_sample(int32_t v)
{
    return (v + 32767) >> 16;
}

/* Floor division for a positive divisor. */
static inline int64_t floor_div(int64_t a, int64_t b)
{
    int64_t q = a / b;
    return (a % b < 0) ? q - 1 : q;
}

/* Record x at every sample row of edge (xa,ya)->(xb,yb), ya < yb, into xs[]. */
static void walk_edge(int32_t *xs, int32_t xa, int32_t ya, int32_t xb, int32_t yb)
{
    int32_t row = first_sample(ya), end = first_sample(yb);
    if (row < 0 || end > VIEW_H) return; /* outside the contract: draw nothing */
    if (row >= end) return;
    int64_t dx = (int64_t)xb - xa, dy = (int64_t)yb - ya;
    int64_t yc = ((int64_t)row << 16) + 32768;
    int64_t num = (yc - ya) * dx;          /* < 2^16 * 2^25 */
    int64_t x = floor_div(num, dy);
    int64_t rem = num - x * dy;            /* in [0, dy) */
    int64_t step = floor_div(dx * 65536, dy);
    int64_t srem = dx * 65536 - step * dy; /* in [0, dy) */
    int64_t cur = xa + x;
    for (; row < end; row++) {
        xs[row] = (int32_t)cur;
        cur += step;
        rem += srem;
        if (rem >= dy) {
            rem -= dy;
            cur++;
        }
    }
}

uint32_t rast_convex(const rast_target *t, const screen_pt *pts, int n, uint8_t colour, uint32_t id)
{
    int32_t left[VIEW_H], right[VIEW_H];
    int32_t ymin = INT32_MAX, ymax = INT32_MIN;
    if (n < 3) return 0;
    for (int i = 0; i < n; i++) {
        if (pts[i].y < ymin) ymin = pts[i].y;
        if (pts[i].y > ymax) ymax = pts[i].y;
    }
    int32_t top = first_sample(ymin), bottom = first_sample(ymax);
    if (top < 0) top = 0;
    if (bottom > VIEW_H) bottom = VIEW_H;
    if (top >= bottom) return 0;
    for (int32_t y = top; y < bottom; y++) {
        left[y] = VIEW_W_FX;
        right[y] = 0;
    }
    for (int i = 0; i < n; i++) {
        screen_pt a = pts[i], b = pts[(i + 1 == n) ? 0 : i + 1];
        if (a.y < b.y) walk_edge(right, a.x, a.y, b.x, b.y);      /* going down: right side */
        else if (a.y > b.y) walk_edge(left, b.x, b.y, a.x, a.y);  /* going up: left side */
    }
    uint32_t drawn = 0;
    for (int32_t y = top; y < bottom; y++) {
        int32_t x0 = first_sample(left[y]), x1 = first_sample(right[y]);
        if (x0 < 0) x0 = 0;
        if (x1 > VIEW_W) x1 = VIEW_W;
        if (x1 > x0) {
            rast_span(t, y, x0, x1, colour, id);
            drawn += (uint32_t)(x1 - x0);
        }
    }
    return drawn;
}
