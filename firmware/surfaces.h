/* surfaces.h - a leaf's visible surfaces as clipped, projected screen polygons
 * (prefix surf_): its floor and ceiling (from the leaf's convex polygon, at its
 * sector's heights) and the visible parts of its front-facing wall pieces. Every
 * render mode turns leaves into polygons here and differs only in what it does
 * with them (the sink). */
#ifndef SURFACES_H
#define SURFACES_H

#include <stdint.h>
#include "objects.h"
#include "render_stats.h"
#include "scene.h"
#include "clip.h"
#include "texture.h"
#include "occlusion.h"
#include "view.h"

typedef struct {
    /* Called once per polygon that survived clipping: n >= 3 screen vertices,
     * clockwise on screen, inside [0,320] x [0,200]. seg: the seg whose wall it is
     * part of, or SCN_NONE for the floor or ceiling its id names (a sky step has
     * a ceiling's id but is a wall: its seg tells). zmin, zmax: the view depths
     * of its clipped vertices (view units), the range it spans. */
    void (*polygon)(void *ctx, const screen_pt *pts, int n, const tex_paint *paint, uint32_t id, uint32_t seg,
                    int32_t zmin, int32_t zmax);
    /* May be NULL. Asked before clipping, with the polygon's vertices projected
     * unclipped (clamped to the screen; asked only when every vertex is in
     * front of the near plane): 1 if the screen box of those points (widened
     * by a pixel for the rounding of clipped vertices) is already wholly
     * drawn, and the polygon is dropped unclipped. */
    int (*hidden)(void *ctx, const screen_pt *pts, int n);
    void *ctx;
    uint8_t flat; /* 1: every paint is a flat colour (the target draws flat: rast_target.flat) */
} surf_sink;

/* Emit the leaf's surfaces in an order that is correct back to front within the
 * leaf (floor and ceiling first, then walls). w: the ceilings now (doors; NULL:
 * as compiled). clip_mask: planes still to clip against (bsp_walk.h). occ (may
 * be NULL): closed columns; wall pieces wholly inside them are skipped, and
 * solid walls (one-sided, or a closed door's) close the columns they cover. */
void surf_leaf(const scene *s, const world_state *w, const view_xform *v, uint32_t leaf, unsigned clip_mask,
               const surf_sink *sink, occ_columns *occ, render_stats *st);

/* surf_leaf's two halves: the floor and ceiling (those asked for: SURF_FLOOR,
 * SURF_CEILING), and the walls. */
enum { SURF_FLOOR = 1, SURF_CEILING = 2 };
void surf_leaf_planes(const scene *s, const world_state *w, const view_xform *v, uint32_t leaf, unsigned clip_mask,
                      const surf_sink *sink, render_stats *st, unsigned which);
void surf_leaf_walls(const scene *s, const world_state *w, const view_xform *v, uint32_t leaf, unsigned clip_mask,
                     const surf_sink *sink, occ_columns *occ, render_stats *st);

/* The quad of a wall standing on view points a, b (a on the left seen from its
 * front) from height bottom to top, clockwise on screen from a's top: the one
 * every mode clips, so that their walls' edges agree. */
void surf_wall_quad(const view_xform *v, view_pt a, view_pt b, int32_t bottom, int32_t top, clip_poly *p);

/* Front-facing: the eye strictly on the right of a -> b (edge-on is culled).
 * Exact: an eye 1/65536 in front of a wall, looking along it, sees the wall in
 * a few columns, and dropping the offset's low bits would cull it as edge-on. */
int surf_faces_eye(const view_xform *v, const scn_vertex *a, const scn_vertex *b);

/* A wall part's paint (part: SCN_PART_*): its texture, hung by Doom's pegging
 * from the heights the sectors have now (front floor and ceiling, back floor and
 * ceiling: a door's texture moves with the door), or its flat colour in a build
 * without textures. light: the front sector's light level; tic: the level time
 * (anim.h: the frame an animated texture shows, how far a scrolling side moved). */
tex_paint surf_part_paint(const scene *sc, const view_xform *v, const scn_seg *g, int part, int32_t ff, int32_t fc,
                          int32_t bf, int32_t bc, uint8_t light, uint8_t colour, uint32_t tic);

/* A sector's ceiling now: obj_ceil's rule, with its test of w made once per leaf
 * (ceil: w->ceil, or NULL for the ceilings as compiled). */
static inline int32_t surf_ceil_now(const scene *sc, const fx_t *ceil, uint32_t i)
{
    return (CFG_DOORS && ceil) ? ceil[i] : sc->sectors[i].ceil_h;
}

#endif
