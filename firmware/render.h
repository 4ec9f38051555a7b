/* render.h - one frame of the world, in a selectable mode (prefix render_). */
#ifndef RENDER_H
#define RENDER_H

#include <stdint.h>
#include "raster.h"
#include "scene.h"
#include "view.h"

typedef enum {
    RENDER_SPANS,   /* front to back, sorted spans, zero overdraw (the default) */
    RENDER_PAINTER, /* Listing 62.1: back to front, with overdraw */
    RENDER_MODE_COUNT
} render_mode;

typedef struct {
    uint32_t nodes;     /* nodes visited */
    uint32_t leaves;    /* leaves visited */
    uint32_t segs;      /* wall pieces considered */
    uint32_t culled;    /* wall pieces rejected as back-facing */
    uint32_t polygons;  /* polygons that reached the rasteriser */
    uint32_t clipped_away; /* polygons entirely outside the frustum */
    uint32_t boxes_culled; /* subtrees rejected by their bounding box */
    uint32_t occluded;     /* polygons wholly behind nearer ones (spans: no edges added) */
    uint32_t edges;        /* edges entered into the scan (spans) */
    uint32_t spans;        /* spans emitted (spans) */
    uint32_t surfaces_drawn; /* surface batches filled (spans) */
    uint32_t refused;      /* 1: the work memory given was smaller than the scene needs */
} render_stats;

const char *render_mode_name(render_mode m);
int render_mode_parse(const char *name); /* -1 if unknown */

/* Work memory for the modes that need it (spans): see span_work_bytes(). */
typedef struct {
    void *mem;
    uint32_t bytes;
} render_work;

/* Work bytes the scene needs in any mode. */
uint32_t render_work_bytes(const scene *s);

/* Draw the scene seen from cam into t: every pixel of the frame is written (once
 * in mode spans). stats may be NULL. */
void render_frame(const scene *s, const camera *cam, render_mode mode, const rast_target *t,
                  const render_work *work, render_stats *stats);

/* Shared by the modes. */
void render_clear(const rast_target *t, uint8_t colour);

/* Draw the back-to-front (painter) frame. */
void painter_render(const scene *s, const view_xform *v, const rast_target *t, render_stats *st);

#endif
