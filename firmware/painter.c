/* painter.c - render mode "painter": the Listing 62.1 pipeline. Walk the BSP tree
 * back to front (data recursion, bsp_walk.c), turn each leaf into its floor,
 * ceiling and front-facing wall polygons (surfaces.c), and fill each one as it
 * comes; nearer polygons overdraw farther ones. Kept as the baseline the
 * zero-overdraw span renderer is measured against.
 *
 * Objects are drawn with the leaves: each one right after the nearest leaf its
 * box touches that the walk visits, so every leaf nearer than that overdraws it
 * and none behind it does; objects of one leaf farthest origin first, faces
 * farthest centroid first (Chapter 65's z-sorted objects). A first walk numbers
 * the leaves (objd_locate needs their keys); the second draws. Not exact, by
 * design: an object still overdraws the surfaces of its own leaf that are in
 * front of it, and two objects are ordered by their origins only. */
#include "bsp_walk.h"
#include "obj_draw.h"
#include "render.h"
#include "surfaces.h"

#define PAINTER_BACKGROUND 0

typedef struct {
    uint32_t key;  /* objects: the key of the leaf they are drawn after; faces: unused */
    int32_t depth; /* view z of the origin (objects) or the centroid (faces) */
    uint32_t index;
} pt_order;

typedef struct {
    const scene *sc;
    const world_state *w;
    const view_xform *v;
    const rast_target *t;
    render_stats *st;
    surf_sink sink;
    uint32_t *leaf_key;   /* first walk: nleaves - visit number (nearer leaves smaller), 0 unvisited */
    uint32_t next_key;
    const pt_order *objs; /* second walk: objects in drawing order, and the next one to draw */
    uint32_t nobjs, at;
} painter;

uint32_t painter_work_bytes(const scene *s, const world_state *w)
{
    /* the leaves' keys, then the order and a merge buffer: 2 * 4096 * 12 bytes at most */
    uint32_t n = (CFG_OBJECTS && w && w->objs) ? w->n : 0;
    if (!n) return 0;
    return (uint32_t)((uint64_t)s->nleaves * sizeof(uint32_t) + 2u * (uint64_t)n * sizeof(pt_order));
}

static void fill_polygon(void *ctx, const screen_pt *pts, int n, uint8_t colour, uint32_t id, uint32_t seg)
{
    (void)seg;
    const painter *p = ctx;
    rast_convex(p->t, pts, n, colour, id);
}

static void draw_object(const scene *sc, uint32_t i, const obj_state *o, const view_xform *v, const rast_target *t,
                        render_stats *st);

static int number_leaf(void *ctx, uint32_t leaf, unsigned clip_mask)
{
    painter *p = ctx;
    (void)clip_mask;
    p->leaf_key[leaf] = p->next_key--;
    return 0;
}

static int draw_leaf(void *ctx, uint32_t leaf, unsigned clip_mask)
{
    painter *p = ctx;
    surf_leaf(p->sc, p->w, p->v, leaf, clip_mask, &p->sink, 0, p->st);
    if (CFG_OBJECTS && p->leaf_key) {
        uint32_t key = p->leaf_key[leaf];
        for (; p->at < p->nobjs && p->objs[p->at].key == key; p->at++) {
            uint32_t i = p->objs[p->at].index;
            draw_object(p->sc, i, &p->w->objs[i], p->v, p->t, p->st);
        }
    }
    return 0;
}

/* Drawing order: the leaf drawn first (larger key) first, then farthest first
 * (larger depth), then by index: a stable, total order. */
static int before(const pt_order *a, const pt_order *b)
{
    if (a->key != b->key) return a->key > b->key;
    return a->depth != b->depth ? a->depth > b->depth : a->index < b->index;
}

static void sort_far_first(pt_order *a, pt_order *tmp, uint32_t n)
{
    for (uint32_t width = 1; width < n; width *= 2) {
        for (uint32_t lo = 0; lo < n; lo += 2 * width) {
            uint32_t mid = lo + width < n ? lo + width : n, hi = lo + 2 * width < n ? lo + 2 * width : n;
            uint32_t i = lo, j = mid, k = lo;
            while (i < mid && j < hi) tmp[k++] = before(&a[j], &a[i]) ? a[j++] : a[i++];
            while (i < mid) tmp[k++] = a[i++];
            while (j < hi) tmp[k++] = a[j++];
        }
        for (uint32_t i = 0; i < n; i++) a[i] = tmp[i];
    }
}

static void draw_object(const scene *sc, uint32_t i, const obj_state *o, const view_xform *v, const rast_target *t,
                        render_stats *st)
{
    const scn_model *m = &sc->models[o->model];
    view_pt verts[CFG_MODEL_VERTS];
    pt_order faces[SCN_MAX_MODEL_FACES];
    uint32_t nf = 0;
    objd_transform(sc, o, v, verts);
    for (uint32_t f = m->first_face; f < m->first_face + m->num_faces && nf < SCN_MAX_MODEL_FACES; f++) {
        objd_plane pl;
        if (!objd_face_plane(sc, m, f, verts, &pl)) continue;
        faces[nf].key = 0;
        faces[nf].depth = pl.cz;
        faces[nf].index = f;
        for (uint32_t k = nf++; k > 0 && before(&faces[k], &faces[k - 1]); k--) {
            pt_order x = faces[k];
            faces[k] = faces[k - 1];
            faces[k - 1] = x;
        }
    }
    screen_pt pts[CLIP_MAX_VERTS];
    for (uint32_t k = 0; k < nf; k++) {
        uint32_t f = faces[k].index;
        int n = objd_face_screen(sc, m, f, verts, v, pts);
        if (!n) continue;
        st->object_faces++;
        rast_convex(t, pts, n, sc->faces[f].colour, RAST_ID(RAST_KIND_OBJECT, i));
    }
}

void painter_render(const scene *sc, const world_state *w, const view_xform *v, const rast_target *t,
                    const render_work *work, render_stats *st)
{
    painter p = {sc, w, v, t, st, {fill_polygon, 0}, 0, 0, 0, 0, 0};
    walk_stats ws;
    uint32_t nobj = (CFG_OBJECTS && w && w->objs) ? w->n : 0;
    if (nobj && (!work || !work->mem || work->bytes < painter_work_bytes(sc, w))) {
        st->refused = 1; /* no room to order the objects */
        render_clear(t, PAINTER_BACKGROUND);
        return;
    }
    p.sink.ctx = &p;
    render_clear(t, PAINTER_BACKGROUND);
    if (nobj) {
        p.leaf_key = work->mem;
        for (uint32_t i = 0; i < sc->nleaves; i++) p.leaf_key[i] = 0;
        p.next_key = sc->nleaves;
        walk_tree(sc, v, WALK_BACK_TO_FRONT, number_leaf, &p, 0, &ws);
        pt_order *order = (pt_order *)(void *)(p.leaf_key + sc->nleaves), *tmp = order + nobj;
        uint32_t n = 0;
        for (uint32_t i = 0; i < nobj; i++) {
            const obj_state *o = &w->objs[i];
            uint32_t kmin, kmax;
            if (o->model >= sc->nmodels || !objd_in_view(sc, o, v) || !objd_locate(sc, o, p.leaf_key, &kmin, &kmax))
                continue;
            order[n].key = kmin; /* the nearest of its visited leaves */
            order[n].depth = objd_depth(o, v);
            order[n++].index = i;
        }
        sort_far_first(order, tmp, n);
        st->objects_visible = n;
        p.objs = order;
        p.nobjs = n;
    }
    walk_tree(sc, v, WALK_BACK_TO_FRONT, draw_leaf, &p, 0, &ws);
    st->nodes = ws.nodes;
    st->boxes_culled = ws.boxes_culled;
}
