/* eye.h - where the eye stands relative to the world (prefix eye_). */
#ifndef EYE_H
#define EYE_H

#include "objects.h"
#include "scene.h"
#include "view.h"

/* 1 if the eye stands inside the world: inside the floor polygon of every leaf
 * whose region holds it (a point on a partition belongs to the leaves on both
 * sides), and strictly between the floor and the current ceiling of each of
 * their sectors. Only then does a solid wall hide everything behind it, so only
 * then may walls close screen columns. w may be NULL (ceilings as compiled). */
int eye_in_world(const scene *sc, const world_state *w, const view_xform *v);

#endif
