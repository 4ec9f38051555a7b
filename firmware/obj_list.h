/* obj_list.h - the objects in view, sorted by the west edges of their boxes,
 * and those whose boxes may reach a leaf (prefix objl_). The front-to-back
 * modes take an object in at the first leaf of the walk its box touches
 * (docs/objects.md); a leaf looks only at the stretch of the list whose boxes
 * can reach its west-east extent.
 *
 * A mode keeps its own record per object: any struct whose first member is an
 * objl_entry, in an array of records of `size` bytes (a multiple of 4). */
#ifndef OBJ_LIST_H
#define OBJ_LIST_H

#include <stdint.h>
#include "objects.h"
#include "scene.h"
#include "view.h"

typedef struct {
    int32_t left;   /* west edge of its box, whole units (the list is sorted by it) */
    uint16_t index; /* the object (its id; SCN_MAX_OBJECTS fits) */
    uint8_t taken;  /* OBJL_* bits (0 from objl_in_view) */
    uint8_t nfaces; /* the mode's: faces it shows, for a mode that keeps them (0 from objl_in_view) */
} objl_entry;

_Static_assert(SCN_MAX_OBJECTS <= 65536, "objl_entry.index");

/* objl_entry.taken: OBJL_SEEN once handed to the mode's take (by a leaf or a
 * box), OBJL_AT_LEAF once the walk has reached a leaf its box touches. */
enum { OBJL_SEEN = 1, OBJL_AT_LEAF = 2 };

static inline objl_entry *objl_at(void *list, uint32_t i, uint32_t size)
{
    return (objl_entry *)(void *)((uint8_t *)list + (uint64_t)i * size);
}

/* The most objects a frame may list: all of w's. A world state of n objects
 * with no states yet (objs NULL: a build sizing its work memory) counts as n. */
static inline uint32_t objl_capacity(const world_state *w)
{
    return (CFG_OBJECTS && w && (w->objs || w->n)) ? w->n : 0;
}

/* The objects of w in the view frustum into list (records of size bytes, zero
 * but for their objl_entry, room for w->n), sorted by west edge; returns how
 * many. *reach: the widest box's half width in whole units (0 if none). */
uint32_t objl_in_view(const scene *sc, const world_state *w, const view_xform *v, void *list, uint32_t size,
                      int32_t *reach);

/* The walk has reached leaf: marks OBJL_AT_LEAF in each record i of list[0 ..
 * n) whose object's box touches the leaf (objd_touches_leaf), and calls take(ctx,
 * i) for those not yet seen, after marking them seen: an object is taken in once,
 * at the first leaf its box touches (or earlier, by objl_take_in_box). */
void objl_take_in_leaf(const scene *sc, const world_state *w, uint32_t leaf, void *list, uint32_t n, uint32_t size,
                       int32_t reach, void (*take)(void *ctx, uint32_t i), void *ctx);

/* The walk skips a subtree whose box (BOX_* sides) holds leaves an object's box
 * may touch: calls take(ctx, i) for each record not yet seen whose object's box
 * meets it, after marking it seen (not OBJL_AT_LEAF). */
void objl_take_in_box(const world_state *w, const int32_t box[BOX_SIDES], void *list, uint32_t n, uint32_t size,
                      int32_t reach, void (*take)(void *ctx, uint32_t i), void *ctx);

#endif
