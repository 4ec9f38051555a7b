/* columns.h - render mode "columns": Doom's renderer for the 2.5-D world, drawn
 * exactly (prefix cols_).
 *
 * The tree is walked front to back. Each front-facing wall piece (seg) covers
 * the screen columns the fill rule gives its vertical edges, and in each of
 * them splits what is still open of the column, top to bottom, into the front
 * sector's ceiling, the upper wall, the opening, the lower wall and the front
 * sector's floor (a one-sided wall has no opening). The rows come from the
 * clipped, projected wall quads, walked along x with an exact DDA, so a row
 * boundary is where a pixel centre's ray crosses it. Walls are drawn at once,
 * down their columns (texture.h's tex_column: one divide a column, then one
 * texture row stepped a pixel, the light fixed per column). What is left open
 * is narrowed to the opening, Doom's per-column clip; a column with nothing
 * open is closed (occlusion.h), and subtrees behind closed columns are not
 * walked. Floor and ceiling rows are gathered per sector into visplanes
 * (column extents), which become row spans at the end (tex_span: one depth a
 * row), or earlier when the pool of planes is full: every pixel is still
 * written exactly once.
 *
 * Walls in a flat colour go to visplanes too, so that row spans fill them a
 * dword at a time.
 *
 * Objects: an object is taken in at the first leaf of the walk its box touches
 * (obj_list.h, as mode direct does) and claims the pixels of its faces still
 * open; the walls drawn before are in front of it by the tree's order. The
 * claimed pixels are drawn after the walk by mode direct alone
 * (direct_render_within, told which objects claimed them), which sorts objects
 * and the world in front of them there exactly. The
 * gap rule needs an eye inside the world (eye.h): other frames are drawn by
 * mode direct whole, with the same work memory (render_stats.fallback).
 *
 * Memory: the objects' pixel mask and a bit per object, then the per-column
 * state, CFG_COLS_PLANES visplanes of 652 bytes and the objects in view, or
 * direct's need if larger (docs/needs.md); bounded by the screen and the
 * objects, never by the map. */
#ifndef COLUMNS_H
#define COLUMNS_H

#include <stdint.h>
#include "objects.h"
#include "raster.h"
#include "render_stats.h"
#include "scene.h"
#include "view.h"

uint32_t cols_work_bytes(const scene *s, const world_state *w);

void cols_render(const scene *sc, const world_state *w, const view_xform *v, const rast_target *t, render_stats *st,
                 void *work, uint32_t work_bytes);

#endif
