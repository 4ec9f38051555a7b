/* raster.h - filling convex screen polygons (prefix rast_).
 * Sampling: pixel (px, py) is covered when its centre (px + 0.5, py + 0.5) lies
 * inside the polygon, with a top-left rule (left and top edges inclusive, right
 * and bottom edges exclusive), so polygons that share an edge share no pixel and
 * leave no gap between them. */
#ifndef RASTER_H
#define RASTER_H

#include <stdint.h>
#include "hal.h"
#include "texture.h"
#include "view.h"

typedef struct {
    const hal_surface *surf;
    uint32_t *ids;    /* optional surface-id buffer, 320 x 200, or NULL */
    hal_tally *tally; /* a linear surface filled straight in, counted here (hal.h), or NULL: through hal_fill_span */
    uint8_t flat;     /* 1: textured paints are drawn in their flat colours (a slow link, say) */
} rast_target;

/* Surface ids (DESIGN.md): kind << 24 | index. */
#define RAST_ID(kind, index) (((uint32_t)(kind) << 24) | ((uint32_t)(index)&0xFFFFFFu))
enum { RAST_KIND_NONE, RAST_KIND_WALL, RAST_KIND_FLOOR, RAST_KIND_CEILING, RAST_KIND_OBJECT };

/* Pixel index of the first sample at or right of (or below) a 16.16 coordinate:
 * ceil(v - 0.5), for v >= 0. */
static inline int32_t rast_first_sample(int32_t v)
{
    return (v + 32767) >> 16;
}

/* Precision knob RAST_STEP_BITS: how an edge's x is stepped from row to row.
 *   0 (default)  an exact DDA: x at each sample row is floor(true x) in 16.16,
 *                a whole step plus a remainder carried against the edge's
 *                height, so no error accumulates however long the edge is.
 *   4..16        x starts at the edge's top vertex and steps by dx/dy rounded
 *                to RAST_STEP_BITS fraction bits, with no remainder: one add per
 *                row and one division per edge instead of two, but the error of
 *                the step (up to 2^-(RAST_STEP_BITS + 1) pixel) accumulates, up
 *                to 200 times that at the bottom of a full-height edge.
 * The default is the exact DDA. 16 bits moved no edge by more than a pixel over
 * the 211 views of make report, for 3.8% fewer instructions per frame (x86-64,
 * spans) and about 6% fewer on the Cortex-M3, but it decides exact ties (an edge
 * through a pixel centre, common from integer eye positions) off the fill rule:
 * from an eye on a vertex of the map's edge it left single pixels of a ceiling
 * unfilled next to the void. The exact DDA keeps the renderer in agreement with
 * the reference renderer pixel for pixel on every bench view.
 * Either way every user of an edge (the fill here, the span renderer's edge
 * lists and coverage) walks it with the same arithmetic from the same ends, so
 * polygons that share an edge still share no pixel and leave no gap. */
#ifndef RAST_STEP_BITS
#define RAST_STEP_BITS 0
#endif
#if RAST_STEP_BITS != 0 && (RAST_STEP_BITS < 4 || RAST_STEP_BITS > 16)
#error "RAST_STEP_BITS: 0 (exact DDA) or 4..16"
#endif

/* A polygon edge walked down the screen (see RAST_STEP_BITS). */
typedef struct {
    int32_t x;                   /* 16.16 at the current row's sample centre */
    int32_t step, rem, srem, dy; /* x += step; rem += srem, carrying one at dy */
    int16_t row, end_row;        /* current row, first row not covered */
} rast_edge;

/* Set up edge (xa,ya)->(xb,yb) with ya < yb, both inside the screen. Returns 0
 * if it covers no sample row. */
int rast_edge_setup(rast_edge *e, int32_t xa, int32_t ya, int32_t xb, int32_t yb);

/* An edge over two or more rows has dy > 1 row, so |step| < |dx| < 2^25 and x
 * stays within a row's width of the screen on every row it covers. One that
 * covers a single row may be nearly flat, its step cut from far beyond 32 bits;
 * the walkers may still step it once past its last row, so the add wraps
 * (unsigned) instead of overflowing, and that x is never used. */
static inline void rast_edge_step(rast_edge *e)
{
    e->x = (int32_t)((uint32_t)e->x + (uint32_t)e->step);
#if RAST_STEP_BITS == 0
    e->rem += e->srem;
    if (e->rem >= e->dy) {
        e->rem -= e->dy;
        e->x++;
    }
#endif
    e->row++;
}

void rast_ids(const rast_target *t, int y, int x0, int x1, uint32_t id);

/* The pixels a polygon's screen points can cover, as the fill rule samples
 * them: columns [x0, x1) and rows [y0, y1) of its bounding box, unclamped. */
typedef struct {
    int x0, x1, y0, y1;
} rast_box;

static inline rast_box rast_bounds(const screen_pt *pts, int n)
{
    int32_t xmin = INT32_MAX, xmax = INT32_MIN, ymin = INT32_MAX, ymax = INT32_MIN;
    for (int i = 0; i < n; i++) {
        if (pts[i].x < xmin) xmin = pts[i].x;
        if (pts[i].x > xmax) xmax = pts[i].x;
        if (pts[i].y < ymin) ymin = pts[i].y;
        if (pts[i].y > ymax) ymax = pts[i].y;
    }
    return (rast_box){rast_first_sample(xmin), rast_first_sample(xmax), rast_first_sample(ymin),
                      rast_first_sample(ymax)};
}

#if CFG_TEXTURES
/* A textured span's pixels, worked out and written (raster.c). */
void rast_textured(const rast_target *t, int y, int x0, int x1, const tex_paint *paint);
#endif

/* 1 if the paint's spans are textured on this target (else its flat colour). */
static inline int rast_textured_paint(const rast_target *t, const tex_paint *paint)
{
    return CFG_TEXTURES && paint->kind != TEX_FLAT && !t->flat;
}

/* Draw one span [x0, x1) of row y (0 <= x0, x1 <= 320, 0 <= y < 200) in its
 * paint, with its id; textured: rast_textured_paint(t, paint), which the fill
 * loops decide once for all their spans and pass as a constant. Inlined into
 * the fill loops whole (left to itself the compiler keeps an out-of-line part
 * and pays a call a span). */
static inline __attribute__((always_inline)) void rast_span_as(const rast_target *t, int y, int x0, int x1,
                                                               const tex_paint *paint, uint32_t id, int textured)
{
    if (x1 <= x0) return;
#if CFG_TEXTURES
    if (textured)
        rast_textured(t, y, x0, x1, paint);
    else
#else
    (void)textured;
#endif
        if (t->tally)
        hal_fill_linear(t->surf, y, x0, x1 - x0, paint->colour, t->tally);
    else
        hal_fill_span(t->surf, y, x0, x1 - x0, paint->colour);
    if (t->ids) rast_ids(t, y, x0, x1, id);
}

static inline __attribute__((always_inline)) void rast_span(const rast_target *t, int y, int x0, int x1,
                                                            const tex_paint *paint, uint32_t id)
{
    rast_span_as(t, y, x0, x1, paint, id, rast_textured_paint(t, paint));
}

/* The pixels of a convex polygon (clockwise on screen) on each row of [top,
 * bottom), a sub-range of its rows inside the screen: [lo[y], hi[y]), walked
 * with the same edge stepping as the fill, so whoever fills the rows fills
 * exactly its pixels. A row no edge reaches is left empty (lo >= hi). */
void rast_rows(const screen_pt *pts, int n, int top, int bottom, int16_t lo[VIEW_H], int16_t hi[VIEW_H]);

/* Fill a convex polygon whose vertices run clockwise on screen (y down), inside
 * [0,320] x [0,200]. A polygon that winds the other way (seen from behind, or
 * collapsed by rounding) covers nothing. Returns the pixels drawn. */
uint32_t rast_convex(const rast_target *t, const screen_pt *pts, int n, const tex_paint *paint, uint32_t id);

/* Fill the whole frame in one flat colour, with the id of no surface. */
void rast_clear(const rast_target *t, uint8_t colour);

#endif
