/* occlusion.h - screen columns closed by solid walls (prefix occ_), Doom's
 * "solid segs" idea for the front-to-back walk: a wall with no opening, seen from
 * its front, hides everything farther in the columns it spans (the floor and
 * ceiling in front of it fill the rest of each column), so subtrees and wall
 * pieces wholly inside closed columns are skipped before any clipping, and the
 * walk can stop once every column is closed. */
#ifndef OCCLUSION_H
#define OCCLUSION_H

#include <stdint.h>
#include "scene.h"
#include "view.h"

#define OCC_MAX_RANGES (VIEW_W / 2 + 2)

typedef struct {
    int n;
    int16_t r[OCC_MAX_RANGES][2]; /* closed columns [x0, x1), sorted, disjoint, not touching */
} occ_columns;

void occ_reset(occ_columns *o);
int occ_full(const occ_columns *o);
/* 1 if every column of [x0, x1) is closed. */
int occ_hidden(const occ_columns *o, int x0, int x1);
void occ_close(occ_columns *o, int x0, int x1);

/* Columns a map segment a -> b, given in view space (its x and z), can cover on
 * screen, conservatively (may be wider than the truth). Returns 0 if the segment
 * is wholly outside the view. */
int occ_seg_columns(view_pt p, view_pt q, int *x0, int *x1);

/* Columns a map box (BOX_* sides) can cover, conservatively. */
void occ_box_columns(const view_xform *v, const int32_t box[BOX_SIDES], int *x0, int *x1);

#endif
