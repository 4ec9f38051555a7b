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

/* Draw one span [x0, x1) of row y in a colour, with its id. */
void rast_span(const rast_target *t, int y, int x0, int x1, uint8_t colour, uint32_t id);

/* Fill a convex polygon whose vertices run clockwise on screen (y down), inside
 * [0,320] x [0,200]. A polygon that winds the other way (seen from behind, or
 * collapsed by rounding) covers nothing. Returns the pixels drawn. */
uint32_t rast_convex(const rast_target *t, const screen_pt *pts, int n, uint8_t colour, uint32_t id);

#endif
