/* painter.c - render mode "painter": the Listing 62.1 pipeline. Walk the BSP tree
 * back to front (data recursion, bsp_walk.c), turn each leaf into its floor,
 * ceiling and front-facing wall polygons (surfaces.c), and fill each one as it
 * comes; nearer polygons overdraw farther ones. Kept as the baseline the
 * zero-overdraw span renderer is measured against.
 *
 * Objects are drawn with the leaves: each one right after the nearest leaf its
 * box touches that the walk visits, so every leaf nearer than that overdraws it
 * and none behind it does; objects of one leaf farthest origin first, faces
 * farthest centroid first (Chapter 65's z-sorted objects). A first walk, front
 * to back, finds each object's nearest leaf (the first one it touches); the
 * second, back to front, draws. Not exact, by
 * design: an object still overdraws the surfaces of its own leaf that are in
 * front of it, and two objects are ordered by their origins only. */
#include "painter.h"

#include "bsp_walk.h"
#include "cover.h"
#include "obj_draw.h"
#include "sprite.h"
#include "surfaces.h"

#define PAINTER_BACKGROUND 0

typedef struct {
    uint32_t key;  /* objects: the front-to-back number of the leaf they are drawn after; faces: unused */
    int32_t depth; /* view z of the origin (objects) or the centroid (faces) */
    uint32_t index;
    uint32_t leaf; /* objects: that leaf */
    int32_t left;  /* objects: the west edge of the box, whole units (the first walk's order) */
} pt_order;

typedef struct {
    const scene *sc;
    const world_state *w;
    const view_xform *v;
    const rast_target *t;
    render_stats *st;
    surf_sink sink;
    pt_order *objs; /* objects in view; the first walk finds their leaves, the second draws them in order */
    uint32_t nobjs, at;
    uint32_t visits;   /* first walk: leaves visited so far */
    uint32_t unplaced; /* first walk: objects whose leaf is not found yet */
    int32_t reach;     /* first walk: the widest box, whole units */
} painter;

uint32_t painter_work_bytes(const scene *s, const world_state *w)
{
    /* the objects' order and a merge buffer: 2 * 4096 * 20 bytes at most */
    (void)s;
    uint32_t n = (CFG_OBJECTS && w && w->objs) ? w->n : 0;
    return (uint32_t)(2u * (uint64_t)n * sizeof(pt_order));
}

static void fill_polygon(void *ctx, const screen_pt *pts, int n, const tex_paint *paint, uint32_t id, uint32_t seg,
                         int32_t zmin, int32_t zmax)
{
    (void)seg;
    (void)zmin;
    (void)zmax;
    const painter *p = ctx;
    rast_convex(p->t, pts, n, paint, id);
}

static void draw_object(const scene *sc, uint32_t i, const obj_state *o, const view_xform *v, const rast_target *t,
                        render_stats *st);
#if CFG_TEXTURES
static void draw_sprite(const scene *sc, uint32_t i, uint32_t sprset, const obj_state *o, const view_xform *v,
                        const rast_target *t, render_stats *st);
static void draw_mid(const scene *sc, uint32_t i, uint32_t side, const obj_state *o, const view_xform *v,
                     const rast_target *t, render_stats *st);
#endif

/* First walk, front to back: each object's nearest leaf is the first it touches.
 * The objects are in west-edge order, so a leaf looks only at those whose boxes
 * can reach its west-east extent. */
static int place_objects(void *ctx, uint32_t leaf, unsigned clip_mask)
{
    painter *p = ctx;
    (void)clip_mask;
    const scn_leaf *f = &p->sc->leaves[leaf];
    int32_t box[BOX_SIDES];
    objd_leaf_box(p->sc, f, box);
    p->visits++;
    if (box[BOX_LEFT] > box[BOX_RIGHT]) return 0;
    int32_t west = (box[BOX_LEFT] >> 16) - 2 * p->reach - 1, east = box[BOX_RIGHT] >> 16;
    uint32_t lo = 0, hi = p->nobjs;
    while (lo < hi) { /* the first object whose west edge is at or east of west */
        uint32_t mid = lo + (hi - lo) / 2;
        if (p->objs[mid].left < west)
            lo = mid + 1;
        else
            hi = mid;
    }
    for (uint32_t k = lo; k < p->nobjs && p->objs[k].left <= east; k++) {
        pt_order *o = &p->objs[k];
        if (o->key || !objd_touches_leaf(p->sc, &p->w->objs[o->index], f, box)) continue;
        o->key = p->visits;
        o->leaf = leaf;
        p->unplaced--;
    }
    return p->unplaced == 0;
}

static int draw_leaf(void *ctx, uint32_t leaf, unsigned clip_mask)
{
    painter *p = ctx;
    surf_leaf(p->sc, p->w, p->v, leaf, clip_mask, &p->sink, 0, p->st);
    if (CFG_OBJECTS && p->objs) {
        for (; p->at < p->nobjs && p->objs[p->at].leaf == leaf; p->at++) {
            uint32_t i = p->objs[p->at].index;
#if CFG_TEXTURES
            uint32_t set = obj_sprset(p->w, i), side = obj_mid_side(p->w, i);
            if (set != SCN_NONE) {
                draw_sprite(p->sc, i, set, &p->w->objs[i], p->v, p->t, p->st);
                continue;
            }
            if (side != SCN_NONE) {
                draw_mid(p->sc, i, side, &p->w->objs[i], p->v, p->t, p->st);
                continue;
            }
#endif
            draw_object(p->sc, i, &p->w->objs[i], p->v, p->t, p->st);
        }
    }
    return 0;
}

/* Drawing order, 1 if a is drawn before b: the leaf drawn first (larger key)
 * first, then farthest first (larger depth), then by index: a stable, total
 * order. */
static int draws_before(const pt_order *a, const pt_order *b)
{
    if (a->key != b->key) return a->key > b->key;
    return a->depth != b->depth ? a->depth > b->depth : a->index < b->index;
}

/* The first walk's order: by the boxes' west edges. */
static int west_of(const pt_order *a, const pt_order *b)
{
    return a->left < b->left;
}

/* Merge sort, stable: b goes before a where less(b, a). */
static void sort_by(pt_order *a, pt_order *tmp, uint32_t n, int (*less)(const pt_order *, const pt_order *))
{
    for (uint32_t width = 1; width < n; width *= 2) {
        for (uint32_t lo = 0; lo < n; lo += 2 * width) {
            uint32_t mid = lo + width < n ? lo + width : n, hi = lo + 2 * width < n ? lo + 2 * width : n;
            uint32_t i = lo, j = mid, k = lo;
            while (i < mid && j < hi) tmp[k++] = less(&a[j], &a[i]) ? a[j++] : a[i++];
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
        for (uint32_t k = nf++; k > 0 && draws_before(&faces[k], &faces[k - 1]); k--) {
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
        tex_paint paint = tex_flat(sc->faces[f].colour);
        rast_convex(t, pts, n, &paint, RAST_ID(RAST_KIND_OBJECT, i));
    }
}

#if CFG_TEXTURES
/* A face with holes: a sprite (sv), or a see-through middle texture (side, its row 0 at top). */
typedef struct {
    const scene *sc;
    const view_xform *v;
    const spr_view *sv;
    uint32_t side;
    int32_t top;
} holes;

/* The face's opaque pixels of the polygon pts over what is drawn. */
static void fill_with_holes(const holes *h, const screen_pt *pts, int n, const tex_paint *paint, uint32_t id,
                            const rast_target *t)
{
    int16_t lo[VIEW_H], hi[VIEW_H];
    rast_rows(pts, n, 0, VIEW_H, lo, hi);
    for (int y = 0; y < VIEW_H; y++) {
        uint32_t op[COV_WORDS] = {0};
        if (lo[y] >= hi[y]) continue;
        if (h->sv)
            spr_opaque(h->sc, h->sv, VIEW_LOOK(h->v), y, lo[y], hi[y], op);
        else if (!tex_mid_opaque(h->sc, h->v, h->side, h->top, y, lo[y], hi[y], op))
            cov_line_set(op, lo[y], hi[y]);
        for (int x = lo[y], x0; spr_next_run(op, &x, hi[y], &x0);) rast_span(t, y, x0, x, paint, id);
    }
}

/* A sprite over what is drawn: its opaque pixels. */
static void draw_sprite(const scene *sc, uint32_t i, uint32_t sprset, const obj_state *o, const view_xform *v,
                        const rast_target *t, render_stats *st)
{
    spr_view sv;
    view_pt quad[4];
    screen_pt pts[CLIP_MAX_VERTS];
    if (!spr_view_of(sc, o, sprset, v, &sv, quad)) return;
    int n = objd_points_screen(quad, 4, v, pts);
    if (!n) return;
    st->object_faces++;
    tex_paint paint = tex_sprite(sc, &sv, VIEW_LOOK(v), sc->faces[sc->models[o->model].first_face].colour);
    holes h = {sc, v, &sv, SCN_NONE, 0};
    fill_with_holes(&h, pts, n, &paint, RAST_ID(RAST_KIND_OBJECT, i), t);
}

/* A see-through middle texture (its model's one face) over what is drawn. */
static void draw_mid(const scene *sc, uint32_t i, uint32_t side, const obj_state *o, const view_xform *v,
                     const rast_target *t, render_stats *st)
{
    const scn_model *m = &sc->models[o->model];
    view_pt verts[CFG_MODEL_VERTS];
    screen_pt pts[CLIP_MAX_VERTS];
    objd_plane pl;
    objd_transform(sc, o, v, verts);
    if (!objd_face_plane(sc, m, m->first_face, verts, &pl)) return;
    int n = objd_face_screen(sc, m, m->first_face, verts, v, pts);
    if (!n) return;
    st->object_faces++;
    tex_paint paint = tex_mid(sc, v, side, o->z, 0);
    holes h = {sc, v, 0, side, o->z};
    fill_with_holes(&h, pts, n, &paint, RAST_ID(RAST_KIND_OBJECT, i), t);
}
#endif

void painter_render(const scene *sc, const world_state *w, const view_xform *v, const rast_target *t, render_stats *st,
                    void *work, uint32_t work_bytes)
{
    painter p = {sc, w, v, t, st, {fill_polygon, 0}, 0, 0, 0, 0, 0};
    walk_stats ws;
    uint32_t nobj = (CFG_OBJECTS && w && w->objs) ? w->n : 0;
    if (nobj && (!work || work_bytes < painter_work_bytes(sc, w))) {
        st->refused = 1; /* no room to order the objects */
        rast_clear(t, PAINTER_BACKGROUND);
        return;
    }
    p.sink.ctx = &p;
    p.sink.flat = t->flat;
    rast_clear(t, PAINTER_BACKGROUND);
    if (nobj) {
        pt_order *order = work, *tmp = order + nobj;
        uint32_t n = 0;
        for (uint32_t i = 0; i < nobj; i++) {
            const obj_state *o = &w->objs[i];
            if (o->model >= sc->nmodels || !objd_in_view(sc, o, v)) continue;
            int32_t r = (sc->models[o->model].radius >> 16) + 1; /* whole units, rounded up */
            if (r > p.reach) p.reach = r;
            order[n++] = (pt_order){0, objd_depth(o, v), i, 0, (int32_t)((o->x >> 16) - r)};
        }
        sort_by(order, tmp, n, west_of);
        p.objs = order;
        p.nobjs = p.unplaced = n;
        if (n) walk_tree(sc, v, WALK_FRONT_TO_BACK, place_objects, &p, 0, &ws);
        uint32_t placed = 0; /* objects in no visited leaf are not drawn */
        for (uint32_t k = 0; k < n; k++)
            if (order[k].key) order[placed++] = order[k];
        sort_by(order, tmp, placed, draws_before);
        st->objects_visible = placed;
        p.nobjs = placed;
    }
    walk_tree(sc, v, WALK_BACK_TO_FRONT, draw_leaf, &p, 0, &ws);
    st->nodes = ws.nodes;
    st->boxes_culled = ws.boxes_culled;
}
