/* render.h - one frame of the world, in a selectable mode (prefix render_). */
#ifndef RENDER_H
#define RENDER_H

#include <stdint.h>
#include "objects.h"
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
    uint32_t objects_visible; /* objects drawn: in view (spans: and in a leaf the walk visited) */
    uint32_t object_faces;    /* object faces that reached the rasteriser */
    uint32_t object_pass;     /* spans: 1 if the frame ran the object pass (an object was in the frustum) */
    uint32_t overflow;        /* polygons dropped for a full pool: 0 while the scene's bounds hold */
    uint32_t flushes;         /* spans: batches drawn before the last because a pool was full */
    uint32_t yclip_skipped;   /* polygons inside the top and bottom planes: no y-clipping done */
    uint32_t planes_skipped;  /* floors and ceilings not set up: the eye is level with or beyond them */
} render_stats;

const char *render_mode_name(render_mode m);
int render_mode_parse(const char *name); /* -1 if unknown */

/* Work memory for the modes that need it (spans): see span_work_bytes(). */
typedef struct {
    void *mem;
    uint32_t bytes;
} render_work;

/* Work bytes the scene needs in any mode, with w's objects (w NULL: no objects;
 * w->objs NULL: the scene's own objects, as obj_init will place them). 0 if it
 * would not fit in 32 bits: the caller must refuse the scene. */
uint32_t render_work_bytes(const scene *s, const world_state *w);

/* Draw the scene seen from cam into t: every pixel of the frame is written (once
 * in mode spans). w: the objects and ceilings now (NULL: the static world as
 * compiled, no objects). A frame that needs more work memory than given is not
 * drawn: the background only, and stats->refused. stats may be NULL. */
void render_frame(const scene *s, const world_state *w, const camera *cam, render_mode mode, const rast_target *t,
                  const render_work *work, render_stats *stats);

/* Shared by the modes. */
void render_clear(const rast_target *t, uint8_t colour);

/* Draw the back-to-front (painter) frame; each object right after the nearest
 * visited leaf its box touches (the leaves' numbers and the objects' order need
 * painter_work_bytes of the work memory). */
void painter_render(const scene *s, const world_state *w, const view_xform *v, const rast_target *t,
                    const render_work *work, render_stats *st);
uint32_t painter_work_bytes(const scene *s, const world_state *w);

#endif
