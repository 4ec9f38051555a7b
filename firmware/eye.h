/* eye.h - where the eye stands relative to the world (prefix eye_). */
#ifndef EYE_H
#define EYE_H

#include "objects.h"
#include "scene.h"
#include "view.h"

/* 1 if the eye stands inside the world: inside the floor polygon of every leaf
 * whose region holds it (a point on a partition belongs to the leaves on both
 * sides), clear of their walls and strictly between the floor and the current
 * ceiling of each of their sectors (eye.c gives the margins). Only then does a
 * solid wall hide everything behind it, so only then may walls close screen
 * columns. w may be NULL (ceilings as compiled). */
int eye_in_world(const scene *sc, const world_state *w, const view_xform *v);

/* How far the eye must be in front of a wall to be clearly in front of it, in
 * units of 8 raw (16.16): 64 is 512 raw, 1/128 map unit, far beyond the 2^-14
 * unit the view rounds positions to. */
#define EYE_WALL_MARGIN 64

/* 1 if the eye is in front of (right of) the line a -> b by more than
 * 8 * EYE_WALL_MARGIN raw, for certain. The cross product is formed on offsets
 * shifted as faces_eye (surfaces.c) and side_of shift them, so it is off by
 * less than the sum of the shifted terms' sizes plus 2; past that it is at least
 * |b - a| / 16 times the distance (raw), and |b - a| <= 2 (|dx| + |dy| + 2) in
 * shifted terms, so EYE_WALL_MARGIN (|dx| + |dy| + 2) more puts the eye over
 * 8 * EYE_WALL_MARGIN raw away. Nearer, the view's rounding can leave the wall
 * seen edge-on or from behind. */
int eye_clearly_in_front(const view_xform *v, const scn_vertex *a, const scn_vertex *b);

#endif
