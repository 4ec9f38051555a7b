/* obj_draw.h - moving objects on screen (prefix objd_): where an object is in the
 * tree, its faces in view space and on screen, and the 1/z planes by which the
 * span renderer sorts object faces against each other and against the world
 * (docs/objects.md, "At run time"; Black Book ch. 67's span sorting: abutting
 * surfaces by the tie rule below, intersecting ones by spans.c finding where
 * along a line one overtakes the other).
 *
 * 1/z. Every plane a surface lies in is kept in view space as n . p = d, with
 * the normal's largest component in [2^29, 2^30) and d > 0 (the eye, p = 0, is
 * on the side n . p < d). Through the centre of pixel (px, py) that plane is at
 *
 *     1/z = (a px + b py + c) / (320 d)        (z in view units, 18.14 raw)
 *     a = 2 nx,  b = -2 ny,  c = nx (1 - 320) + ny (199 + 2 look) + 320 nz
 *
 * an integer plane over the pixel centres with one integer denominator per
 * surface. |a|, |b| < 2^31, |c| < 2^40.1, so the numerator M = a px + b py + c
 * is below 2^41 anywhere on screen, and 0 < d < 2^61.5. Two surfaces are
 * compared by the exact 128-bit cross products M1 d2 and M2 d1 (< 2^101.5):
 * monotone in z from the near plane (z = 1/1024 unit, 1/z = 2^-4 per raw
 * unit) to the far corner of the box (z ~ 92,682 units, 1/z ~ 2^-30.5), with no
 * rounding at all in the comparison; what is left is the rounding of the
 * geometry itself (vertices to 1/16384 unit). */
#ifndef OBJ_DRAW_H
#define OBJ_DRAW_H

#include <stdint.h>
#include "clip.h"
#include "objects.h"
#include "scene.h"
#include "view.h"

/* Back-face epsilon, view units (18.14 raw: 16 = 1/1024 map unit, the near
 * plane's distance): a face whose plane passes within this distance of the eye,
 * or behind it, is culled. Such a face is seen edge-on: on screen it is a sliver
 * its neighbours border, and its plane, fitted to vertices rounded to 1/16384
 * unit, says little about its depth. */
#define OBJ_BACKFACE_EPS VIEW_ZNEAR

/* Near-match epsilon of the 1/z sort, view units (16 raw = 1/1024 map unit):
 * two surfaces whose depths at a pixel centre differ by less than this abut
 * there (an object resting on a floor, against a wall, or on another object).
 * The geometry's own rounding stays below 1/8192 unit, so abutting surfaces
 * always tie, and surfaces this close cannot be told apart by depth anyway. */
#define OBJ_TIE_EPS 16

/* The top of the key range of an object's faces in mode spans: open, so that
 * every world surface from the object's first visited leaf on is sorted
 * against it by 1/z (docs/objects.md). */
#define OBJD_KEY_OPEN 0xFFFFFFFEu

typedef struct {
    int32_t nx, ny, nz; /* normal, largest component in [2^29, 2^30) */
    int32_t cx, cy, cz; /* object faces: the centroid of the face's vertices */
    int64_t d;          /* n . p on the plane; > 0, or 0: no usable plane (edge-on through the eye) */
} objd_plane;

/* The plane of a floor or ceiling at height h (16.16) and of a wall along map
 * points a -> b, as surfaces.c projects them. */
void objd_plane_flat(const view_xform *v, int32_t h, objd_plane *p);
void objd_plane_wall(const view_xform *v, const scn_vertex *a, const scn_vertex *b, objd_plane *p);

/* Which of two surfaces is nearer at the centre of pixel (px, py) (clamped to the
 * screen): 1 if s is in front of p. s_obj, p_obj: 0 for a world surface, else the
 * surface is an object's face (its plane has a centroid) and the value is 1 + the
 * object's number. Depths within OBJ_TIE_EPS tie, and a tie goes to the side of
 * the planes each surface lies on (a face whose centroid is on the eye's side of
 * the other's plane is in front: it rests on it or against it). Faces of two
 * objects lying in one plane (the tops or sides of two things of one height side
 * by side) go in a fixed order, the lower object number first, as
 * tools/refrender.py breaks exact ties; other surfaces in one plane fall back to
 * Abrash's rule, the larger 1/z gradient along the scan line (then down it), and
 * with one gradient too, the world goes before objects. A plane with d = 0 is in
 * front. */
int objd_front(const objd_plane *s, int s_obj, const objd_plane *p, int p_obj, int look, int px, int py);


/* The bounding box of the leaf's floor polygon (BOX_* sides; left > right:
 * no polygon). */
void objd_leaf_box(const scene *s, const scn_leaf *f, int32_t box[BOX_SIDES]);

/* Does the object's box (origin +- its model's radius) reach into the leaf's
 * convex floor polygon (box: objd_leaf_box's)? A box within the rounding of an
 * edge counts as touching: the renderers that ask (direct, painter) only take
 * an object in a leaf early by it. */
int objd_touches_leaf(const scene *s, const obj_state *o, const scn_leaf *f, const int32_t box[BOX_SIDES]);

/* The depth in the tree (the root: 0) of the deepest subtree whose region holds
 * the object's box with a unit to spare on every side: every leaf the box
 * touches, and every point of the object, lies in that subtree. A front-to-back
 * walk that has left the subtree (bsp_walk.h's back_to) reaches nothing more
 * that can be in front of the object. */
uint32_t objd_subtree_depth(const scene *s, const obj_state *o);

/* 0 if the object's bounding cylinder is wholly outside the near, left or right plane. */
int objd_in_view(const scene *s, const obj_state *o, const view_xform *v);

/* The pixels the object can cover: columns [x0, x1) and rows [y0, y1), a pixel
 * wider than the projection of the part of its box (origin +- its model's
 * radius, its model's heights) in front of the near plane, unclamped. 1 if
 * found; 0 if the box reaches past the coordinate box, where it has no such
 * bound; -1 if it covers nothing (no vertices, or wholly behind the near plane). */
int objd_screen_box(const scene *s, const obj_state *o, const view_xform *v, int *x0, int *x1, int *y0, int *y1);

/* The view depth of the object's origin (view units), for painter's order. */
int32_t objd_depth(const obj_state *o, const view_xform *v);

/* The model's vertices, yawed and placed at the object's origin, in view space.
 * Heights go through the same arithmetic as view_point's, so a vertex at a
 * floor's height lies exactly in that floor's plane. */
void objd_transform(const scene *s, const obj_state *o, const view_xform *v, view_pt out[CFG_MODEL_VERTS]);

/* Face f (an index into s->faces) of model m, its vertices transformed: its
 * plane, if it faces the eye by more than OBJ_BACKFACE_EPS (returns 1), else 0. */
int objd_face_plane(const scene *s, const scn_model *m, uint32_t f, const view_pt *verts, objd_plane *pl);

/* The same for any convex polygon of n view-space points (at most
 * SCN_MAX_FACE_VERTS) running counter-clockwise seen from its front. */
int objd_points_plane(const view_pt *pts, int n, objd_plane *pl);

/* Face f clipped and projected: its screen vertices, clockwise, into out; returns
 * their number, or 0 if nothing is left. */
int objd_face_screen(const scene *s, const scn_model *m, uint32_t f, const view_pt *verts, const view_xform *v,
                     screen_pt out[CLIP_MAX_VERTS]);

/* The same for n view-space points (at most CLIP_MAX_VERTS - 5) that run
 * clockwise on screen. */
int objd_points_screen(const view_pt *pts, int n, const view_xform *v, screen_pt out[CLIP_MAX_VERTS]);

#endif
