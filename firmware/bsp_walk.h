/* bsp_walk.h - walking the BSP tree (prefix walk_): the one explicit-stack
 * walk over the nodes whose child boxes pass a caller's test (walk_boxes),
 * and on it the walk in visibility order, with node bounding boxes culled
 * against the view frustum (walk_tree). The frustum walk hands each leaf to
 * the visitor with the clip planes its polygons may still cross: a box found
 * trivially inside a plane passes that plane's bit down cleared, so the
 * polygons below skip clipping against it (Quake's node clipping). */
#ifndef BSP_WALK_H
#define BSP_WALK_H

#include <stdint.h>
#include "build_config.h"
#include "scene.h"
#include "occlusion.h"
#include "view.h"

/* Entries a walk stack needs: one pending sibling per level of a validated
 * tree (depth <= CFG_MAX_DEPTH) and the two children of the node in hand. */
#define WALK_STACK_MAX (CFG_MAX_DEPTH + 2)

typedef enum { WALK_FRONT_TO_BACK, WALK_BACK_TO_FRONT } walk_order;

/* Return nonzero to stop the walk (e.g. the screen is full). state: what the
 * box tests handed down to the leaf (walk_tree: the clip planes still to
 * test, clip.h's CLIP_* bits). */
typedef int (*walk_visit)(void *ctx, uint32_t leaf, unsigned state);

typedef struct {
    uint32_t nodes;        /* nodes visited */
    uint32_t boxes_culled; /* subtrees rejected by their bounding box */
    uint32_t boxes_hidden; /* subtrees behind closed columns (walk_tree) */
    /* Set before each leaf is handed to the visitor: the shallowest tree depth
     * (the root's children: 1) of the subtrees the walk entered since the leaf
     * before. A walk visits a subtree's leaves one after another, so a subtree
     * whose root is at depth d is done once a leaf comes with back_to <= d. */
    uint32_t back_to;
} walk_stats;

/* What a walk_boxes walk asks its caller: first, box and stop get the ctx
 * given to walk_boxes, leaf its own leaf_ctx. */
typedef struct {
    /* The child of node to walk first, 0 or 1. NULL: child 0. */
    int (*first)(void *ctx, const scn_node *node);
    /* A child's box (BOX_* sides) under a subtree walked with state: -1 to
     * skip the subtree, else the state (0..255) for it. Asked for the child
     * walked second, then the first. */
    int (*box)(void *ctx, const int32_t box[BOX_SIDES], unsigned state);
    walk_visit leaf; /* called with leaf_ctx */
    void *leaf_ctx;
    /* May be NULL. Asked before each entry taken off the stack while others
     * still wait: nonzero ends the walk (nothing more can show). */
    int (*stop)(void *ctx);
} walk_rules;

/* Walk from the root (with state) down to every leaf under boxes that pass
 * rules->box; st (may be NULL) counts nodes and subtrees skipped. Returns 1
 * if rules->leaf or rules->stop ended the walk. */
int walk_boxes(const scene *s, const walk_rules *rules, void *ctx, unsigned state, walk_stats *st);

/* Walk every leaf that may be visible, in the order asked for. occ (may be NULL,
 * front to back only): subtrees whose boxes fall in closed columns are skipped. */
void walk_tree(const scene *s, const view_xform *v, walk_order order, walk_visit visit, void *ctx,
               const occ_columns *occ, walk_stats *st);

/* walk_tree, also telling hidden(ctx, box) of each subtree skipped behind closed
 * columns, no later than its leaves would have come (the sibling walked second
 * is told of before the first is walked). */
void walk_tree_hidden(const scene *s, const view_xform *v, walk_order order, walk_visit visit, void *ctx,
                      const occ_columns *occ, walk_stats *st, void (*hidden)(void *ctx, const int32_t box[BOX_SIDES]));

#endif
