/* render.h - one frame of the world, in a selectable mode (prefix render_): the
 * dispatcher over the modes (direct.h, spans.h, painter.h). Nothing below it
 * includes it: the modes share the lower layers (surfaces.h, raster.h,
 * render_stats.h), never this file. */
#ifndef RENDER_H
#define RENDER_H

#include <stdint.h>
#include "objects.h"
#include "render_stats.h"
#include "raster.h"
#include "scene.h"
#include "view.h"

typedef enum {
    RENDER_SPANS,   /* front to back, sorted edge lists and spans, zero overdraw (spans.h) */
    RENDER_PAINTER, /* Listing 62.1: back to front, with overdraw */
    RENDER_DIRECT,  /* front to back, each polygon row filled where free, zero overdraw (direct.h; the default) */
    RENDER_COLUMNS, /* Doom's: walls down columns, per-column clip, visplanes; direct's with objects (columns.h) */
    RENDER_MODE_COUNT
} render_mode;


const char *render_mode_name(render_mode m);
/* -1 if unknown or not in this build (CFG_RENDER_MODES) */
int render_mode_parse(const char *name);
/* The default of this build (direct if it carries it), and the mode after m
 * among the ones it carries (the mode key's cycle). */
render_mode render_mode_default(void);
render_mode render_mode_next(render_mode m);

/* Work memory for the modes (direct.h, spans.h, painter.h). */
typedef struct {
    void *mem;
    uint32_t bytes;
} render_work;

/* Work bytes the scene needs in any mode this build carries, with w's objects (w NULL: no objects;
 * w->objs NULL: the scene's own objects, as obj_init will place them). 0 if it
 * would not fit in 32 bits: the caller must refuse the scene. */
uint32_t render_work_bytes(const scene *s, const world_state *w);

/* Draw the scene seen from cam into t: every pixel of the frame is written (once
 * in mode spans). w: the objects and ceilings now (NULL: the static world as
 * compiled, no objects). A frame that needs more work memory than given is not
 * drawn: the background only, and stats->refused. stats may be NULL. */
void render_frame(const scene *s, const world_state *w, const camera *cam, render_mode mode, const rast_target *t,
                  const render_work *work, render_stats *stats);

#endif
