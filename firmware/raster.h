/* raster.h - filling convex screen polygons (prefix rast_).
 * Sampling: pixel (px, py) is covered when its centre (px + 0.5, py + 0.5) lies
 * inside the polygon, with a top-left rule (left and top edges inclusive, right
 * and bottom edges exclusive), so polygons that share an edge share no pixel and
 * leave no gap between them. */
#ifndef RASTER_H
#define RASTER_H

#include <stdint.h>
#include "hal.h"
#include "view.h"

typedef struct {
    const hal_surface *surf;
    uint32_t *ids; /* optional surface-id buffer, 320 x 200, or NULL */
} rast_target;

/* Surface ids (DESIGN.md): kind << 24 | index. */
#define RAST_ID(kind, index) (((uint32_t)(kind) << 24) | ((uint32_t)(index) & 0xFFFFFFu))
enum { RAST_KIND_NONE, RAST_KIND_WALL, RAST_KIND_FLOOR, RAST_KIND_CEILING, RAST_KIND_OBJECT };

/* Pixel index of the first sample at or right of (or below) a 16.16 coordinate:
 * ceil(v - 0.5), for v >= 0. */
static inline int32_t rast_first_sample(int32_t v)
{
    return (v + 32767) >> 16;
}

/* A polygon edge walked down the screen with an exact DDA: x at each sample row
 * is floor(true x) in 16.16, so no error accumulates along the edge and every
 * user of an edge (the fill here, the span renderer's edge lists) gets the same
 * x on every row. */
typedef struct {
    int32_t x;                   /* 16.16 at the current row's sample centre */
    int32_t step, rem, srem, dy; /* x += step; rem += srem, carrying one at dy */
    int16_t row, end_row;        /* current row, first row not covered */
} rast_edge;

/* Set up edge (xa,ya)->(xb,yb) with ya < yb, both inside the screen. Returns 0
 * if it covers no sample row. */
int rast_edge_setup(rast_edge *e, int32_t xa, int32_t ya, int32_t xb, int32_t yb);

static inline void rast_edge_step(rast_edge *e)
{
    e->x += e->step;
    e->rem += e->srem;
    if (e->rem >= e->dy) {
        e->rem -= e->dy;
        e->x++;
    }
    e->row++;
}

/* Draw one span [x0, x1) of row y in a colour, with its id. */
void rast_span(const rast_target *t, int y, int x0, int x1, uint8_t colour, uint32_t id);

/* Fill a convex polygon whose vertices run clockwise on screen (y down), inside
 * [0,320] x [0,200]. A polygon that winds the other way (seen from behind, or
 * collapsed by rounding) covers nothing. Returns the pixels drawn. */
uint32_t rast_convex(const rast_target *t, const screen_pt *pts, int n, uint8_t colour, uint32_t id);

#endif
