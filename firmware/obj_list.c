/* obj_list.c - the objects in view by the west edges of their boxes (see obj_list.h). */
#include "obj_list.h"

#include "obj_draw.h"

/* Swap two records, a word at a time (they are a few words). */
static void swap(void *list, uint32_t i, uint32_t j, uint32_t size)
{
    uint32_t *a = (uint32_t *)(void *)objl_at(list, i, size), *b = (uint32_t *)(void *)objl_at(list, j, size);
    for (uint32_t k = 0; k < size / 4; k++) {
        uint32_t t = a[k];
        a[k] = b[k];
        b[k] = t;
    }
}

/* Sorting by west edge, in place (no memory beyond the list and a few hundred
 * bytes of stack): the records are first dealt into SORT_BUCKETS buckets by
 * their edge's place between the smallest and largest (American flag sort),
 * then an insertion sort puts each bucket in order. Things spread over a map,
 * so a bucket holds a few: about linear, where a heap sort was n log n. */
#define SORT_BUCKETS 64

static uint32_t bucket(void *list, uint32_t i, uint32_t size, int32_t lo, unsigned shift)
{
    return (uint32_t)((int64_t)objl_at(list, i, size)->left - lo) >> shift;
}

static void sort_by_west(void *list, uint32_t n, uint32_t size)
{
    if (n < 2) return;
    int32_t lo = INT32_MAX, hi = INT32_MIN;
    for (uint32_t i = 0; i < n; i++) {
        int32_t l = objl_at(list, i, size)->left;
        lo = l < lo ? l : lo;
        hi = l > hi ? l : hi;
    }
    unsigned shift = 0;
    while (((uint64_t)((int64_t)hi - lo) >> shift) >= SORT_BUCKETS) shift++;
    uint16_t next[SORT_BUCKETS] = {0}, end[SORT_BUCKETS]; /* n <= SCN_MAX_OBJECTS */
    for (uint32_t i = 0; i < n; i++) next[bucket(list, i, size, lo, shift)]++;
    for (uint32_t b = 0, at = 0; b < SORT_BUCKETS; b++) {
        at += next[b];
        end[b] = (uint16_t)at;
        next[b] = (uint16_t)(at - next[b]);
    }
    for (uint32_t b = 0; b < SORT_BUCKETS; b++)
        while (next[b] < end[b]) { /* each swap puts one record in its bucket for good */
            uint32_t c = bucket(list, next[b], size, lo, shift);
            if (c == b)
                next[b]++;
            else
                swap(list, next[b], next[c]++, size);
        }
    for (uint32_t i = 1; i < n; i++)
        for (uint32_t j = i; j > 0 && objl_at(list, j - 1, size)->left > objl_at(list, j, size)->left; j--)
            swap(list, j - 1, j, size);
}

_Static_assert(SCN_MAX_OBJECTS <= 65535, "sort_by_west's counters");

/* A see-through middle texture shows only to an eye in front of its side (its
 * one face is culled from behind), which this finds before any projection. */
static int mid_faces_eye(const scene *sc, uint32_t side, const view_xform *v)
{
    const scn_line *l = &sc->lines[side >> 1];
    const scn_vertex *a = &sc->verts[l->v1], *b = &sc->verts[l->v2];
    /* differences below 2^33 raw, shifted to 2^25: the cross product fits 64 bits */
    int64_t dx = ((int64_t)b->x - a->x) >> 8, dy = ((int64_t)b->y - a->y) >> 8;
    int64_t ex = (v->cx - a->x) >> 8, ey = (v->cy - a->y) >> 8;
    int64_t cross = dx * ey - dy * ex; /* < 0: the eye on the right, the front side */
    return (side & 1) ? cross > 0 : cross < 0;
}

uint32_t objl_in_view(const scene *sc, const world_state *w, const view_xform *v, void *list, uint32_t size,
                      int32_t *reach)
{
    uint32_t n = 0;
    *reach = 0;
    if (!CFG_OBJECTS || !w || !w->objs) return 0;
    for (uint32_t i = 0; i < w->n; i++) {
        const obj_state *o = &w->objs[i];
        if (o->model >= sc->nmodels || !objd_in_view(sc, o, v)) continue;
        uint32_t side = obj_mid_side(w, i);
        if (side != SCN_NONE && !mid_faces_eye(sc, side, v)) continue;
        int32_t r = (sc->models[o->model].radius >> 16) + 1; /* whole units, rounded up */
        if (r > *reach) *reach = r;
        uint32_t *rec = (uint32_t *)(void *)objl_at(list, n++, size);
        for (uint32_t k = 0; k < size / 4; k++) rec[k] = 0;
        *(objl_entry *)(void *)rec = (objl_entry){(int32_t)((o->x >> 16) - r), (uint16_t)i, 0, 0};
    }
    sort_by_west(list, n, size);
    return n;
}

/* The first record whose west edge is at or east of x (the list is sorted by it). */
static uint32_t first_at_or_east(void *list, uint32_t n, uint32_t size, int32_t x)
{
    uint32_t lo = 0, hi = n;
    while (lo < hi) {
        uint32_t mid = lo + (hi - lo) / 2;
        if (objl_at(list, mid, size)->left < x)
            lo = mid + 1;
        else
            hi = mid;
    }
    return lo;
}

/* The first record whose box can reach a map box's west-east extent; *east: past
 * which west edge no later record can. */
static uint32_t stretch_start(void *list, uint32_t n, uint32_t size, const int32_t box[BOX_SIDES], int32_t reach,
                              int32_t *east)
{
    int64_t west = ((int64_t)box[BOX_LEFT] >> 16) - 2 * (int64_t)reach - 1;
    *east = box[BOX_RIGHT] >> 16;
    return first_at_or_east(list, n, size, west < INT32_MIN ? INT32_MIN : (int32_t)west);
}

void objl_take_in_leaf(const scene *sc, const world_state *w, uint32_t leaf, void *list, uint32_t n, uint32_t size,
                       int32_t reach, void (*take)(void *ctx, uint32_t i), void *ctx)
{
    const scn_leaf *f = &sc->leaves[leaf];
    int32_t box[BOX_SIDES];
    objd_leaf_box(sc, f, box);
    if (box[BOX_LEFT] > box[BOX_RIGHT]) return;
    int32_t east; /* only the stretch of the list whose boxes can reach the leaf's west-east extent */
    for (uint32_t i = stretch_start(list, n, size, box, reach, &east); i < n && objl_at(list, i, size)->left <= east;
         i++) {
        objl_entry *e = objl_at(list, i, size);
        if ((e->taken & OBJL_AT_LEAF) || !objd_touches_leaf(sc, &w->objs[e->index], f, box)) continue;
        int seen = e->taken & OBJL_SEEN;
        e->taken = OBJL_SEEN | OBJL_AT_LEAF;
        if (!seen) take(ctx, i);
    }
}

void objl_take_in_box(const world_state *w, const int32_t box[BOX_SIDES], void *list, uint32_t n, uint32_t size,
                      int32_t reach, void (*take)(void *ctx, uint32_t i), void *ctx)
{
    int32_t east;
    for (uint32_t i = stretch_start(list, n, size, box, reach, &east); i < n && objl_at(list, i, size)->left <= east;
         i++) {
        objl_entry *e = objl_at(list, i, size);
        if (e->taken) continue;
        /* the object's box: its origin +- the widest half width, in whole units rounded out */
        const obj_state *o = &w->objs[e->index];
        int64_t x = (int64_t)o->x >> 16, y = (int64_t)o->y >> 16, r = reach + 1;
        if (x + r < ((int64_t)box[BOX_LEFT] >> 16) || y + r < ((int64_t)box[BOX_BOTTOM] >> 16) ||
            y - r > ((int64_t)box[BOX_TOP] >> 16) + 1)
            continue;
        e->taken = OBJL_SEEN;
        take(ctx, i);
    }
}
