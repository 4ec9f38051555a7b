/* direct.h - render mode "direct": front to back, each polygon row drawn at
 * once where it is still free (prefix direct_).
 *
 * The BSP tree is walked front to back (seed 001, "Drawing polygons front to
 * back"). A mask of the pixels already written (cover.h) stands for the
 * per-scan-line span lists: each polygon's rows are filled straight into the
 * frame where the mask is still clear, and set in it, so every pixel is written
 * exactly once, with no edge lists, no surface stack and no second pass. Solid
 * walls close screen columns as in the other modes (occlusion.h), and the walk
 * stops when every column is closed or every line is full.
 *
 * Objects (docs/objects.md). The objects in view are listed before the walk,
 * sorted by the west edges of their boxes. An object becomes active when the
 * walk reaches the first leaf its box touches (unless it is already hidden
 * there): from then on, on every world polygon row the nearest active face
 * takes the pixels where a face is nearer than the world surface (1/z,
 * obj_draw.h's objd_front), at once, since nothing the walk reaches later can
 * be nearer there; after the walk the faces fill what is still free, the
 * nearest face at each pixel. World surfaces reached before the object's first
 * leaf are in front of it by the tree's order; those after it are sorted
 * against it by 1/z.
 *
 * Memory: a fixed part bounded by the screen (the mask, closed columns) and a
 * part per object of the world state (at most every object is in view), plus
 * fixed pools for the faces of the active objects; an object whose faces do not
 * fit the pools is worked out again where it is needed, so no pool can drop
 * anything (docs/needs.md gives the formula). */
#ifndef DIRECT_H
#define DIRECT_H

#include <stdint.h>
#include "cover.h"
#include "objects.h"
#include "raster.h"
#include "render_stats.h"
#include "scene.h"
#include "view.h"

/* Bytes of work memory direct_render needs with w's objects (w NULL: none). */
uint32_t direct_work_bytes(const scene *s, const world_state *w);

void direct_render(const scene *sc, const world_state *w, const view_xform *v, const rast_target *t, render_stats *st,
                   void *work, uint32_t work_bytes);

/* The pixels object obj (an index into w's objects) covers when this mode draws
 * it, each face's rows as row(ctx, y, x0, x1) with pixels [x0, x1): the faces
 * that face the eye, clipped to the near plane, stepped as drawn. Mode columns
 * leaves exactly these to direct_render_within. */
void direct_object_rows(const scene *sc, const world_state *w, const view_xform *v, uint32_t obj,
                        void (*row)(void *ctx, int y, int x0, int x1), void *ctx);

/* direct_render drawing only the pixels set in only: the others are left as
 * they are. only becomes the mode's own mask of written pixels (complemented in
 * place), so the work memory it needs is direct_work_bytes_within's, a mask
 * less.
 *
 * objects NULL: only may hold any pixels; columns with none are not walked.
 * Else a bit per object of w (bit k of word k / 32): the pixels of only are the
 * faces (direct_object_rows) of the objects set, all others are hidden. Then
 * the walk draws the world only while an object it has met is not yet done
 * (obj_draw.h: objd_subtree_depth), and ends when only is drawn: about the cost
 * of the objects, not of the screen. Mode columns hands over its objects so. */
void direct_render_within(const scene *sc, const world_state *w, const view_xform *v, const rast_target *t,
                          render_stats *st, void *work, uint32_t work_bytes, cov_mask *only, const uint32_t *objects);
uint32_t direct_work_bytes_within(const scene *s, const world_state *w);

#endif
