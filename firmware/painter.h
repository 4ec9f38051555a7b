/* painter.h - render mode "painter" (prefix painter_): the Listing 62.1
 * pipeline, back to front with overdraw, kept as the baseline the
 * zero-overdraw modes are measured against (painter.c says how objects are
 * placed among the leaves). */
#ifndef PAINTER_H
#define PAINTER_H

#include <stdint.h>
#include "objects.h"
#include "raster.h"
#include "render_stats.h"
#include "scene.h"
#include "view.h"

/* Bytes of work memory painter_render needs with w's objects (w NULL: none):
 * the objects' order and a merge buffer; 0 without objects. */
uint32_t painter_work_bytes(const scene *s, const world_state *w);

/* Draw the back-to-front frame; each object right after the nearest visited
 * leaf its box touches. A frame with objects and less work memory than
 * painter_work_bytes is the background only, and st->refused. */
void painter_render(const scene *sc, const world_state *w, const view_xform *v, const rast_target *t, render_stats *st,
                    void *work, uint32_t work_bytes);

#endif
