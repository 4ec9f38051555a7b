/* bsp_walk.h - walking the BSP tree in visibility order (prefix walk_), with node
 * bounding boxes culled against the view frustum. Each leaf is handed to the
 * visitor with the clip planes its polygons may still cross: a box found
 * trivially inside a plane passes that plane's bit down cleared, so the
 * polygons below skip clipping against it (Quake's node clipping). */
#ifndef BSP_WALK_H
#define BSP_WALK_H

#include <stdint.h>
#include "scene.h"
#include "occlusion.h"
#include "view.h"

typedef enum { WALK_FRONT_TO_BACK, WALK_BACK_TO_FRONT } walk_order;

/* Return nonzero to stop the walk (e.g. the screen is full). */
typedef int (*walk_visit)(void *ctx, uint32_t leaf, unsigned clip_mask);

typedef struct {
    uint32_t nodes;        /* nodes visited */
    uint32_t boxes_culled; /* subtrees rejected by their bounding box */
    uint32_t boxes_hidden; /* subtrees behind closed columns */
} walk_stats;

/* Walk every leaf that may be visible, in the order asked for. occ (may be NULL,
 * front to back only): subtrees whose boxes fall in closed columns are skipped. */
void walk_tree(const scene *s, const view_xform *v, walk_order order, walk_visit visit, void *ctx,
               const occ_columns *occ, walk_stats *st);

#endif
