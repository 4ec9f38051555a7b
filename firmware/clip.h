/* clip.h - clipping convex view-space polygons to the view frustum (prefix clip_).
 * Five planes: near (z >= VIEW_ZNEAR), left and right (|x| <= z, the 90-degree
 * field of view) and top and bottom (the 200-line screen, sheared by look).
 * After clipping, every vertex projects inside the screen rectangle. */
#ifndef CLIP_H
#define CLIP_H

#include "build_config.h"
#include "scene_format.h"
#include "view.h"

enum {
    CLIP_NEAR = 1u << 0,
    CLIP_LEFT = 1u << 1,
    CLIP_RIGHT = 1u << 2,
    CLIP_TOP = 1u << 3,
    CLIP_BOTTOM = 1u << 4,
    CLIP_ALL = 31u
};

#define CLIP_MAX_VERTS (CFG_POLY_VERTS + 5) /* clipping adds at most one vertex per plane */

typedef struct {
    int n;
    view_pt v[CLIP_MAX_VERTS];
    uint8_t on[CLIP_MAX_VERTS]; /* CLIP_* planes the vertex lies on by construction */
    unsigned cut;               /* CLIP_* planes that cut it (set by clip_polygon) */
} clip_poly;

/* Clip p in place against the planes in mask; returns the vertices left (0 if none).
 * A plane with every vertex inside costs one distance per vertex and nothing
 * more. The caller fills n and v; on[] and cut are set here. A build without
 * y-clipping (build_config.h) leaves the top and bottom planes out of mask. */
int clip_polygon(clip_poly *p, const view_xform *v, unsigned mask);

/* Project the clipped polygon to the screen. A vertex made by clipping against a
 * side, top or bottom plane is put exactly on that screen edge: its view
 * coordinates are rounded to 1/16384 unit, which near the eye (z of a few
 * hundredths of a unit) would otherwise move it up to a pixel inside the screen
 * and leave the border pixels uncovered. */
void clip_project(const view_xform *v, const clip_poly *p, screen_pt *out);

/* The screen x (16.16) of the two vertical edges of a wall standing on the view
 * points p and q (any height: only x and z are read): p and q clipped against
 * the near, left and right planes in mask exactly as clip_polygon clips such a
 * wall's quad (whose vertical edges those planes cut at the same t at every
 * height), then projected as clip_project projects its vertices. The fill rule
 * therefore puts the wall's pixels, on every row it covers, in the columns
 * [rast_first_sample(*xp), rast_first_sample(*xq)). Returns 0 if nothing is left. */
int clip_wall_x(const view_xform *v, view_pt p, view_pt q, unsigned mask, int32_t *xp, int32_t *xq);

/* Signed distance of a view point from one plane (>= 0 inside), in 18.14 * 2^8 units. */
int64_t clip_distance(const view_xform *v, view_pt p, unsigned plane);

#endif
