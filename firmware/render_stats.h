/* render_stats.h - what one frame did, counted by every render mode (the
 * render_stats record the CLI prints). Kept apart from render.h so that the
 * modes depend on it and not on the dispatcher. */
#ifndef RENDER_STATS_H
#define RENDER_STATS_H

#include <stdint.h>

typedef struct {
    uint32_t nodes;           /* nodes visited */
    uint32_t leaves;          /* leaves visited */
    uint32_t segs;            /* wall pieces considered */
    uint32_t culled;          /* wall pieces rejected as back-facing */
    uint32_t polygons;        /* polygons that reached the rasteriser */
    uint32_t clipped_away;    /* polygons entirely outside the frustum */
    uint32_t boxes_culled;    /* subtrees rejected by their bounding box */
    uint32_t occluded;        /* polygons wholly behind nearer ones (spans: no edges added) */
    uint32_t edges;           /* edges entered into the scan (spans) */
    uint32_t spans;           /* spans emitted (spans) */
    uint32_t surfaces_drawn;  /* spans: surface batches filled; direct: polygons that wrote a pixel */
    uint32_t refused;         /* 1: the work memory given was smaller than the scene needs */
    uint32_t objects_visible; /* objects drawn: in view (spans: and in a leaf the walk visited;
                               * direct: and writing at least one pixel) */
    uint32_t object_faces;    /* object faces that reached the rasteriser */
    uint32_t object_pass;     /* spans: 1 if the frame ran the object pass (an object was in the frustum) */
    uint32_t overflow;        /* polygons dropped for a full pool: 0 while the scene's bounds hold */
    uint32_t flushes;         /* spans: batches drawn before the last because a pool was full;
                               * direct: objects whose faces did not fit its pools (worked out again);
                               * columns: visplanes drawn early for a full pool, and direct's */
    uint32_t yclip_skipped;   /* polygons inside the top and bottom planes: no y-clipping done */
    uint32_t planes_skipped;  /* floors and ceilings not set up: the eye is level with or beyond them */
    uint32_t fallback;        /* columns: 1 if the frame was drawn by mode direct (objects in view, or the eye
                               * outside the world) */
} render_stats;

#endif
