/* direct.c - render mode "direct" (see direct.h): the walk, world polygon rows
 * filled where free, objects held back where they are nearer. */
#include "direct.h"

#include "bsp_walk.h"
#include "cover.h"
#include "eye.h"
#include "obj_draw.h"
#include "obj_list.h"
#include "sprite.h"
#include "surfaces.h"

#define BACKGROUND_COLOUR 0

/* Pools for the faces of the active objects (and their edges). An object whose
 * faces do not fit is worked out again wherever it is needed: slower, never
 * wrong. A build may size them (build_config.h). */
#define DIRECT_FACE_POOL CFG_DIRECT_FACES
#define DIRECT_EDGE_POOL CFG_DIRECT_EDGES
#define FACE_EDGES CLIP_MAX_VERTS /* a clipped face's edges */
/* Depths farther apart than this decide "in front" everywhere along every ray
 * the two share: view depth grows along a ray, and objd_front's ties are closer. */
#define DEPTH_APART (2 * OBJ_TIE_EPS)

typedef struct {
    rast_edge e;     /* set up at its first row; stepped to any row by edge_x */
    uint8_t leading; /* a left edge */
} dr_edge;

typedef struct {
    objd_plane pl;
    int16_t top, bottom; /* rows [top, bottom) */
    uint16_t first_edge; /* into the edge pool (or the scratch face's own) */
    uint8_t nedges, colour;
    uint32_t obj,
        model_face;     /* whose face it is: the object, and the face in the scene's faces (SCN_NONE: its sprite) */
    int32_t zmin, zmax; /* the view depths of its vertices */
#if CFG_TEXTURES
    spr_view spr; /* a sprite: its image, placement and light */
#endif
} dr_face;

typedef struct {
    objl_entry e; /* the object, the west edge of its box (obj_list.h); e.nfaces: faces facing the eye and on
                   * screen (SCN_MAX_MODEL_FACES fits) */
    /* screen box of its faces: pixels [x0, x1) x [y0, y1); stored: its faces are in the pools; drew: it wrote a
     * pixel */
    uint32_t x0 : 9, x1 : 9, y0 : 8, stored : 1, drew : 1;
    uint8_t y1;
    uint8_t subtree;     /* objd_subtree_depth, at most 255: the walk is done with it once back_to is no deeper */
    uint16_t first_face; /* stored: its faces in the pool */
} dr_obj;

_Static_assert(SCN_MAX_MODEL_FACES <= 255 && VIEW_H <= 255 && VIEW_W < 512 && sizeof(dr_obj) == 16, "dr_obj's fields");

typedef struct {
    const scene *sc;
    const world_state *w;
    const view_xform *v;
    const rast_target *t;
    render_stats *st;
    surf_sink sink;
    cov_mask *cov; /* the pixels written: after the state (direct_render) or the caller's (direct_render_within) */
    occ_columns occ;
    int use_occ;
    dr_obj *objs;     /* objects in view, by the west edge of their boxes */
    uint16_t *active; /* the ones the walk has met that show faces, as indices into objs */
    uint32_t nobjs, nactive, nfaces, nedges;
    int32_t reach; /* the widest box in view, whole units */
    dr_face *faces;
    dr_edge *edges;
    dr_face scratch_face; /* a face of an object the pools could not hold */
    dr_edge scratch_edges[FACE_EDGES];
    const walk_stats *walk;      /* the walk's, for back_to */
    int faces_only;              /* direct_render_within's objects given: the world matters only in front of them */
    int32_t low, high;           /* faces_only: the lowest and highest point of the objects listed */
    uint32_t face_cap, edge_cap; /* the pools' sizes */
} dr_state;

static uint32_t align8(uint64_t n)
{
    return (uint32_t)((n + 7u) & ~(uint64_t)7u);
}

/* The work memory: the state, the objects' records and pools, and the mask
 * unless the caller lends one. */
static uint32_t work_bytes(const world_state *w, int own_mask)
{
    uint32_t n = objl_capacity(w);
    if (n > SCN_MAX_OBJECTS) return 0; /* more than the format allows (an object record holds 16 bits): refuse */
    uint64_t total = align8(sizeof(dr_state)) + (own_mask ? align8(sizeof(cov_mask)) : 0);
    if (n)
        total += align8((uint64_t)n * sizeof(dr_obj)) + align8((uint64_t)n * sizeof(uint16_t)) +
                 align8((uint64_t)DIRECT_FACE_POOL * sizeof(dr_face)) +
                 align8((uint64_t)DIRECT_EDGE_POOL * sizeof(dr_edge));
    return total > 0xFFFFFFF0u ? 0 : (uint32_t)total;
}

uint32_t direct_work_bytes(const scene *s, const world_state *w)
{
    (void)s;
    return work_bytes(w, 1);
}

uint32_t direct_work_bytes_within(const scene *s, const world_state *w)
{
    (void)s;
    return work_bytes(w, 0);
}

/* ---- object faces on screen ---------------------------------------------------------- */

/* x (16.16) of edge e at row y, as rast_edge_step would reach it: the whole steps
 * and the carries of the remainder at once. rem + k srem < (k + 1) dy <= 200 *
 * 2^23.7, which fits 32 bits unsigned; the whole steps wrap as the stepping does. */
static int32_t edge_x(const rast_edge *e, int y)
{
    uint32_t k = (uint32_t)(y - e->row);
    uint32_t x = (uint32_t)e->x + k * (uint32_t)e->step;
#if RAST_STEP_BITS == 0
    x += ((uint32_t)e->rem + k * (uint32_t)e->srem) / (uint32_t)e->dy;
#endif
    return (int32_t)x;
}

/* The face's pixels on row y: [*a, *b). 0 if none. */
static int face_row(const dr_face *f, const dr_edge *edges, int y, int *a, int *b)
{
    int lo = VIEW_W, hi = 0;
    if (y < f->top || y >= f->bottom) return 0;
    for (int i = 0; i < f->nedges; i++) {
        const dr_edge *e = &edges[i];
        if (y < e->e.row || y >= e->e.end_row) continue;
        int col = rast_first_sample(edge_x(&e->e, y));
        col = col < 0 ? 0 : (col > VIEW_W ? VIEW_W : col);
        if (e->leading)
            lo = col;
        else
            hi = col;
    }
    *a = lo;
    *b = hi;
    return lo < hi;
}

/* A face's rows and edges (into edges[], at most FACE_EDGES) from its n screen
 * points; its box grows box. 0 if it covers no row. */
static int face_edges(const screen_pt *pts, int n, dr_face *f, dr_edge *edges, screen_pt box[2])
{
    int ne = 0, top = VIEW_H, bottom = 0;
    for (int i = 0; i < n; i++) {
        screen_pt a = pts[i], b = pts[(i + 1 == n) ? 0 : i + 1];
        if (a.x < box[0].x) box[0].x = a.x;
        if (a.x > box[1].x) box[1].x = a.x;
        if (a.y < box[0].y) box[0].y = a.y;
        if (a.y > box[1].y) box[1].y = a.y;
        if (a.y == b.y) continue;
        dr_edge *e = &edges[ne];
        e->leading = a.y > b.y; /* going up the screen: a left edge (raster.c) */
        if (!(e->leading ? rast_edge_setup(&e->e, b.x, b.y, a.x, a.y) : rast_edge_setup(&e->e, a.x, a.y, b.x, b.y)))
            continue;
        if (e->e.row < top) top = e->e.row;
        if (e->e.end_row > bottom) bottom = e->e.end_row;
        ne++;
    }
    if (top >= bottom) return 0;
    f->top = (int16_t)top;
    f->bottom = (int16_t)bottom;
    f->nedges = (uint8_t)ne;
    return 1;
}

/* Face fi of the object's model, if it faces the eye and shows: its plane, rows
 * and edges (into edges[], at most FACE_EDGES). */
static int face_build(const scene *sc, const view_xform *v, const scn_model *m, uint32_t obj, const view_pt *verts,
                      uint32_t fi, dr_face *f, dr_edge *edges, screen_pt box[2])
{
    screen_pt pts[CLIP_MAX_VERTS];
    if (!objd_face_plane(sc, m, fi, verts, &f->pl)) return 0;
    int n = objd_face_screen(sc, m, fi, verts, v, pts);
    if (!n || !face_edges(pts, n, f, edges, box)) return 0;
    const uint32_t *ix = &sc->findex[sc->faces[fi].first_index];
    f->zmin = INT32_MAX;
    f->zmax = INT32_MIN;
    for (uint32_t k = 0; k < sc->faces[fi].num_index; k++) {
        if (verts[ix[k]].z < f->zmin) f->zmin = verts[ix[k]].z;
        if (verts[ix[k]].z > f->zmax) f->zmax = verts[ix[k]].z;
    }
    f->colour = sc->faces[fi].colour;
    f->obj = obj;
    f->model_face = fi;
    return 1;
}

#if CFG_TEXTURES
/* Object obj's sprite (set sprset) as one face, if it shows (sprite.h). */
static int sprite_face_build(const scene *sc, const world_state *w, const view_xform *v, uint32_t obj, uint32_t sprset,
                             dr_face *f, dr_edge *edges, screen_pt box[2])
{
    view_pt quad[4];
    screen_pt pts[CLIP_MAX_VERTS];
    if (!spr_view_of(sc, &w->objs[obj], sprset, v, &f->spr, quad)) return 0;
    view_pt front[4] = {quad[3], quad[2], quad[1], quad[0]}; /* counter-clockwise seen from the eye */
    if (!objd_points_plane(front, 4, &f->pl)) return 0;
    int n = objd_points_screen(quad, 4, v, pts);
    if (!n || !face_edges(pts, n, f, edges, box)) return 0;
    const scn_model *m = &sc->models[w->objs[obj].model];
    f->zmin = f->zmax = f->spr.zc;
    f->colour = sc->faces[m->first_face].colour; /* a flat-shaded target's colour */
    f->obj = obj;
    f->model_face = SCN_NONE;
    return 1;
}
#endif

/* The faces of one object that face the eye and show, one at a time: its
 * sprite's, or its model's. */
typedef struct {
    const scene *sc;
    const world_state *w;
    const view_xform *v;
    const scn_model *m;
    uint32_t obj, sprset, fi, end;
    view_pt verts[CFG_MODEL_VERTS];
} face_iter;

static void faces_begin(face_iter *it, const scene *sc, const world_state *w, const view_xform *v, uint32_t obj)
{
    it->sc = sc;
    it->w = w;
    it->v = v;
    it->obj = obj;
    it->m = &sc->models[w->objs[obj].model];
    it->sprset = obj_sprset(w, obj);
    if (it->sprset != SCN_NONE) {
        it->fi = 0;
        it->end = 1;
        return;
    }
    it->fi = it->m->first_face;
    it->end = it->m->first_face + it->m->num_faces;
    objd_transform(sc, &w->objs[obj], v, it->verts);
}

static int faces_next(face_iter *it, dr_face *f, dr_edge *edges, screen_pt box[2])
{
    while (it->fi < it->end) {
        uint32_t fi = it->fi++;
#if CFG_TEXTURES
        if (it->sprset != SCN_NONE) {
            if (sprite_face_build(it->sc, it->w, it->v, it->obj, it->sprset, f, edges, box)) return 1;
            continue;
        }
#endif
        if (face_build(it->sc, it->v, it->m, it->obj, it->verts, fi, f, edges, box)) return 1;
    }
    return 0;
}

/* The opaque pixels of [a, b) on row y of a face with holes (a sprite, or a
 * see-through middle texture) into op (cleared by the caller); 0 for a face
 * opaque all over. */
static int face_opaque(const scene *sc, const world_state *w, const view_xform *v, const dr_face *f, int y, int a,
                       int b, uint32_t *op)
{
#if CFG_TEXTURES
    if (f->model_face == SCN_NONE) {
        spr_opaque(sc, &f->spr, VIEW_LOOK(v), y, a, b, op);
        return 1;
    }
    uint32_t side = obj_mid_side(w, f->obj);
    return side != SCN_NONE && tex_mid_opaque(sc, v, side, w->objs[f->obj].z, y, a, b, op);
#else
    (void)sc, (void)w, (void)v, (void)f, (void)y, (void)a, (void)b, (void)op;
    return 0;
#endif
}

/* What a face's pixels are: its sprite, its middle texture, or its colour. */
static tex_paint face_paint(const scene *sc, const world_state *w, const view_xform *v, const dr_face *f)
{
#if CFG_TEXTURES
    if (f->model_face == SCN_NONE) return tex_sprite(sc, &f->spr, VIEW_LOOK(v), f->colour);
    uint32_t side = obj_mid_side(w, f->obj);
    if (side != SCN_NONE) return tex_mid(sc, v, side, w->objs[f->obj].z, 0);
#else
    (void)sc, (void)w, (void)v;
#endif
    return tex_flat(f->colour);
}

/* Calls visit(S, o, face, its edges, ctx) for each face of the active object o
 * that shows: from the pools, or worked out again into the scratch face. */
typedef void (*face_visit)(dr_state *S, dr_obj *o, const dr_face *f, const dr_edge *edges, void *ctx);

static void each_face(dr_state *S, dr_obj *o, face_visit visit, void *ctx)
{
    if (o->stored) {
        for (uint32_t k = 0; k < o->e.nfaces; k++) {
            const dr_face *f = &S->faces[o->first_face + k];
            visit(S, o, f, &S->edges[f->first_edge], ctx);
        }
        return;
    }
    face_iter it;
    screen_pt box[2];
    faces_begin(&it, S->sc, S->w, S->v, o->e.index);
    while (faces_next(&it, &S->scratch_face, S->scratch_edges, box))
        visit(S, o, &S->scratch_face, S->scratch_edges, ctx);
}

void direct_object_rows(const scene *sc, const world_state *w, const view_xform *v, uint32_t obj,
                        void (*row)(void *ctx, int y, int x0, int x1), void *ctx)
{
    face_iter it;
    screen_pt box[2] = {{0, 0}, {0, 0}};
    dr_face f;
    dr_edge edges[FACE_EDGES];
    faces_begin(&it, sc, w, v, obj);
    while (faces_next(&it, &f, edges, box)) {
        for (int y = f.top; y < f.bottom; y++) {
            int a, b;
            uint32_t op[COV_WORDS] = {0};
            if (!face_row(&f, edges, y, &a, &b)) continue;
            if (!face_opaque(sc, w, v, &f, y, a, b, op)) {
                row(ctx, y, a, b);
                continue;
            }
            for (int x = a, x0; spr_next_run(op, &x, b, &x0);) row(ctx, y, x0, x); /* the opaque runs */
        }
    }
}

/* Room in the pools: an active object whose screen box is wholly drawn can show
 * nothing more, so it leaves the active list and its faces leave the pools; the
 * faces of the others are packed down (the list is in the pools' order). */
static void reclaim(dr_state *S)
{
    uint32_t na = 0, nf = 0, ne = 0;
    for (uint32_t i = 0; i < S->nactive; i++) {
        dr_obj *o = &S->objs[S->active[i]];
        if (cov_box_covered(S->cov, o->y0, o->y1, o->x0, o->x1)) {
            o->e.nfaces = 0;
            o->stored = 0;
            continue;
        }
        S->active[na++] = S->active[i];
        if (!o->stored) continue;
        for (uint32_t k = 0; k < o->e.nfaces; k++) {
            dr_face f = S->faces[o->first_face + k];
            for (int e = 0; e < f.nedges; e++) S->edges[ne + (uint32_t)e] = S->edges[f.first_edge + (uint32_t)e];
            f.first_edge = (uint16_t)ne;
            ne += f.nedges;
            S->faces[nf + k] = f;
        }
        o->first_face = (uint16_t)nf;
        nf += o->e.nfaces;
    }
    S->nactive = na;
    S->nfaces = nf;
    S->nedges = ne;
}

/* The object's faces into the pools if they fit (else it is worked out again
 * where needed), and its screen box. */
static void activate(dr_state *S, dr_obj *o)
{
    face_iter it;
    screen_pt box[2] = {{INT32_MAX, INT32_MAX}, {INT32_MIN, INT32_MIN}};
    uint32_t nf = 0, ne = S->nedges, stored = 1;
    dr_face *f = &S->scratch_face;
    faces_begin(&it, S->sc, S->w, S->v, o->e.index);
    while (faces_next(&it, f, S->scratch_edges, box)) {
        /* into the pools if the face and its own edges fit, after making room if
         * the first face does not */
        if (nf == 0 && !(S->nfaces < S->face_cap && ne + f->nedges <= S->edge_cap)) {
            reclaim(S);
            ne = S->nedges;
        }
        stored &= (uint32_t)(S->nfaces + nf < S->face_cap && ne + f->nedges <= S->edge_cap);
        if (stored) {
            f->first_edge = (uint16_t)ne;
            for (int i = 0; i < f->nedges; i++) S->edges[ne + (uint32_t)i] = S->scratch_edges[i];
            S->faces[S->nfaces + nf] = *f;
            ne += f->nedges;
        }
        nf++;
    }
    o->e.nfaces = (uint8_t)nf;
    o->stored = stored != 0;
    if (nf && !stored) S->st->flushes++;
    if (stored) {
        o->first_face = (uint16_t)S->nfaces;
        S->nfaces += nf;
        S->nedges = ne;
    }
    if (!nf) return;
    int x0 = rast_first_sample(box[0].x) - 1, x1 = rast_first_sample(box[1].x) + 1;
    int y0 = rast_first_sample(box[0].y) - 1, y1 = rast_first_sample(box[1].y) + 1;
    o->x0 = (uint32_t)(x0 < 0 ? 0 : (x0 > VIEW_W ? VIEW_W : x0));
    o->x1 = (uint32_t)(x1 > VIEW_W ? VIEW_W : x1);
    o->y0 = (uint32_t)(y0 < 0 ? 0 : (y0 > VIEW_H ? VIEW_H : y0));
    o->y1 = (uint8_t)(y1 > VIEW_H ? VIEW_H : y1);
}

/* ---- objects against the leaves ---------------------------------------------------- */

/* Is the object wholly behind what is drawn already? Drawn pixels stay drawn,
 * so such an object can never show and is never set up. */
static int object_hidden(const dr_state *S, const obj_state *os)
{
    int x0, x1, y0, y1;
    int r = objd_screen_box(S->sc, os, S->v, &x0, &x1, &y0, &y1);
    if (r < 0) return 1;
    return r && cov_box_covered(S->cov, y0, y1, x0, x1);
}

/* An object the walk takes in (obj_list.h) becomes active and is set up, unless
 * already hidden: looked at once, hidden now stays hidden. */
static void take_object(void *ctx, uint32_t i)
{
    dr_state *S = ctx;
    dr_obj *o = &S->objs[i];
    const obj_state *os = &S->w->objs[o->e.index];
    if (object_hidden(S, os)) return;
    uint32_t depth = objd_subtree_depth(S->sc, os);
    o->subtree = (uint8_t)(depth > 255 ? 255 : depth); /* shallower: done later, never early */
    activate(S, o);
    if (o->e.nfaces) S->active[S->nactive++] = (uint16_t)i;
}

/* With the objects' faces only, a subtree the walk skips (its columns hold no
 * pixel to draw) may hold the leaf where an object would have been met: the
 * objects its box meets are taken in now, so that the walls met before the
 * object's next leaf are still weighed against it. Early is exact, only slower. */
static void take_in_hidden(void *ctx, const int32_t box[BOX_SIDES])
{
    dr_state *S = ctx;
    if (S->nactive < S->nobjs) objl_take_in_box(S->w, box, S->objs, S->nobjs, sizeof(dr_obj), S->reach, take_object, S);
}

/* ---- which surface is nearer ------------------------------------------------------------ */

/* Set in keep the pixels of [a, b) on row y where surface s is in front of p
 * (objd_front's numbering: 0 the world, 1 + an object's index). 1/z is linear
 * along a row, so "in front" changes at most once between the ends; the change
 * is found by bisection. */
static void mark_in_front(uint32_t *keep, const objd_plane *s, int sn, const objd_plane *p, int pn, int look, int y,
                          int a, int b)
{
    int fa = objd_front(s, sn, p, pn, look, a, y), fb = objd_front(s, sn, p, pn, look, b - 1, y);
    if (fa == fb) {
        if (fa) cov_line_set(keep, a, b);
        return;
    }
    int lo = a, hi = b - 1; /* in front at lo differs from at hi */
    while (hi - lo > 1) {
        int mid = lo + (hi - lo) / 2;
        if (objd_front(s, sn, p, pn, look, mid, y) == fa)
            lo = mid;
        else
            hi = mid;
    }
    if (fa)
        cov_line_set(keep, a, hi);
    else
        cov_line_set(keep, hi, b);
}

/* ---- drawing the objects' faces ---------------------------------------------------------- */

typedef struct {
    const dr_face *self; /* the face being drawn (a copy: the scratch face may be rebuilt) */
    uint32_t *keep;
    int y, x0, x1;
} near_ctx;

/* Mark where another face g is in front of the face being drawn. */
static void keep_nearer_face(dr_state *S, dr_obj *o, const dr_face *g, const dr_edge *edges, void *ctx)
{
    (void)o;
    near_ctx *k = ctx;
    if (g->obj == k->self->obj && g->model_face == k->self->model_face) return;
    int a, b;
    if (!face_row(g, edges, k->y, &a, &b)) return;
    if (a < k->x0) a = k->x0;
    if (b > k->x1) b = k->x1;
    if (a >= b || g->zmin > k->self->zmax + DEPTH_APART) return; /* g lies wholly behind */
    uint32_t front[COV_WORDS] = {0}, op[COV_WORDS] = {0};
    if (g->zmax + DEPTH_APART < k->self->zmin)
        cov_line_set(front, a, b); /* wholly in front */
    else
        mark_in_front(front, &g->pl, 1 + (int)g->obj, &k->self->pl, 1 + (int)k->self->obj, VIEW_LOOK(S->v), k->y, a, b);
    int holes = face_opaque(S->sc, S->w, S->v, g, k->y, a, b, op); /* g hides nothing through its holes */
    for (int w = 0; w < COV_WORDS; w++) k->keep[w] |= holes ? front[w] & op[w] : front[w];
}

/* Fill [a, b) of row y with face (a copy: looking at the other faces may rebuild
 * the scratch face) where it is free, set in mine (NULL: everywhere) and no other
 * active face is nearer. */
static void draw_face_row(dr_state *S, dr_obj *o, const dr_face *face, int y, int a, int b, const uint32_t *mine)
{
    uint32_t keep[COV_WORDS], op[COV_WORDS] = {0};
    int holes = face_opaque(S->sc, S->w, S->v, face, y, a, b, op); /* its holes show what lies behind */
    for (int w = 0; w < COV_WORDS; w++) keep[w] = (mine ? ~mine[w] : 0) | (holes ? ~op[w] : 0);
    near_ctx k = {face, keep, y, a, b};
    for (uint32_t i = 0; i < S->nactive; i++) {
        dr_obj *p = &S->objs[S->active[i]];
        if (p->y0 <= y && p->y1 > y && p->x0 < b && p->x1 > a) each_face(S, p, keep_nearer_face, &k);
    }
    tex_paint paint = face_paint(S->sc, S->w, S->v, face);
    if (cov_fill(S->cov, S->t, y, a, b, keep, &paint, RAST_ID(RAST_KIND_OBJECT, o->e.index)) && !o->drew) {
        o->drew = 1;
        S->st->objects_visible++;
    }
}

/* After the walk: fill face f's rows where they are still free. */
static void draw_face(dr_state *S, dr_obj *o, const dr_face *f, const dr_edge *edges, void *ctx)
{
    (void)ctx;
    dr_face face = *f;
    dr_edge own[FACE_EDGES];
    for (int i = 0; i < f->nedges; i++) own[i] = edges[i];
    for (int y = face.top; y < face.bottom; y++) {
        int a, b;
        if (face_row(&face, own, y, &a, &b) && !cov_row_full(S->cov, y)) draw_face_row(S, o, &face, y, a, b, 0);
    }
    S->st->object_faces++;
}

/* Every active object's faces, where still free after the walk. (An object
 * counts as visible once it writes a pixel, then or during the walk.) */
static void draw_objects(dr_state *S)
{
    for (uint32_t i = 0; i < S->nactive; i++) each_face(S, &S->objs[S->active[i]], draw_face, 0);
}

typedef struct {
    const objd_plane *world; /* the world surface of the row */
    int32_t zmin, zmax;      /* and the view depths it spans */
    int y, x0, x1;
} row_ctx;

/* During the walk: fill face f on a world row where it is nearer than the world
 * surface (and the nearest of the active faces). */
static void draw_face_over_world(dr_state *S, dr_obj *o, const dr_face *f, const dr_edge *edges, void *ctx)
{
    row_ctx *k = ctx;
    int a, b;
    if (!face_row(f, edges, k->y, &a, &b)) return;
    if (a < k->x0) a = k->x0;
    if (b > k->x1) b = k->x1;
    if (a >= b || cov_all(S->cov, k->y, a, b)) return; /* nothing of it left to decide */
    if (k->zmax + DEPTH_APART < f->zmin) return;       /* the world surface is nearer all over */
    uint32_t mine[COV_WORDS] = {0};
    if (k->zmin > f->zmax + DEPTH_APART)
        cov_line_set(mine, a, b); /* the face is nearer all over */
    else
        mark_in_front(mine, &f->pl, 1 + (int)f->obj, k->world, 0, VIEW_LOOK(S->v), k->y, a, b);
    uint32_t op[COV_WORDS] = {0};
    if (face_opaque(S->sc, S->w, S->v, f, k->y, a, b, op)) /* the world shows through its holes */
        for (int w = 0; w < COV_WORDS; w++) mine[w] &= op[w];
    uint32_t any = 0;
    for (int w = 0; w < COV_WORDS; w++) any |= mine[w];
    if (!any) return;
    dr_face face = *f;
    draw_face_row(S, o, &face, k->y, a, b, mine);
}

/* ---- world polygons -------------------------------------------------------------------- */

static void world_plane(const dr_state *S, uint32_t id, uint32_t seg, objd_plane *p)
{
    if (seg == SCN_NONE) {
        uint32_t sec = id & 0xFFFFFFu;
        int32_t h = (id >> 24) == RAST_KIND_FLOOR ? S->sc->sectors[sec].floor_h : obj_ceil(S->w, S->sc, sec);
        objd_plane_flat(S->v, h, p);
    } else {
        const scn_seg *g = &S->sc->segs[seg];
        objd_plane_wall(S->v, &S->sc->verts[g->v1], &S->sc->verts[g->v2], p);
    }
}

/* Active objects whose screen box meets [x0, x1) x [y0, y1). */
static int objects_meet(const dr_state *S, int x0, int x1, int y0, int y1)
{
    for (uint32_t i = 0; i < S->nactive; i++) {
        const dr_obj *o = &S->objs[S->active[i]];
        if (o->x0 < x1 && o->x1 > x0 && o->y0 < y1 && o->y1 > y0) return 1;
    }
    return 0;
}

/* A world row with active objects about: where a face is nearer than the world
 * surface, the pixel is the objects', and the nearest active face fills it now.
 * No object met later can be nearer there: it lies in leaves the walk reaches
 * later, behind this surface. The world surface fills the rest. */
static uint32_t fill_row_behind_objects(dr_state *S, int y, int x0, int x1, const objd_plane *world, int32_t zmin,
                                        int32_t zmax, const tex_paint *paint, uint32_t id)
{
    row_ctx k = {world, zmin, zmax, y, x0, x1};
    for (uint32_t i = 0; i < S->nactive; i++) {
        dr_obj *o = &S->objs[S->active[i]];
        if (o->y0 <= y && o->y1 > y && o->x0 < x1 && o->x1 > x0) each_face(S, o, draw_face_over_world, &k);
    }
    return cov_fill(S->cov, S->t, y, x0, x1, 0, paint, id);
}

static void add_polygon(void *ctx, const screen_pt *pts, int n, const tex_paint *paint, uint32_t id, uint32_t seg,
                        int32_t zmin, int32_t zmax)
{
    dr_state *S = ctx;
    rast_box box = rast_bounds(pts, n);
    int top = box.y0, bottom = box.y1, c0 = box.x0, c1 = box.x1;
    if (top < 0) top = 0;
    if (bottom > VIEW_H) bottom = VIEW_H;
    if (top >= bottom || cov_box_covered(S->cov, top, bottom, c0, c1)) {
        S->st->occluded++;
        return;
    }
    int16_t lo[VIEW_H], hi[VIEW_H];
    rast_rows(pts, n, top, bottom, lo, hi);
    uint32_t drawn = 0;
    if (CFG_OBJECTS && S->nactive && objects_meet(S, c0, c1, top, bottom)) {
        objd_plane world;
        world_plane(S, id, seg, &world);
        for (int y = top; y < bottom; y++)
            if (lo[y] < hi[y]) drawn += fill_row_behind_objects(S, y, lo[y], hi[y], &world, zmin, zmax, paint, id);
    } else {
        drawn = cov_fill_rows(S->cov, S->t, top, bottom, lo, hi, paint, id);
    }
    if (drawn)
        S->st->surfaces_drawn++;
    else
        S->st->occluded++;
}

/* The sink's question before clipping: is the points' box already drawn? */
static int box_hidden(void *ctx, const screen_pt *pts, int n)
{
    const dr_state *S = ctx;
    rast_box b = rast_bounds(pts, n);
    return cov_box_covered(S->cov, b.y0 - 1, b.y1 + 1, b.x0 - 1, b.x1 + 1);
}

/* A leaf, with the objects' faces only to draw. Its floor may be in front of
 * an object met later, if the object reaches below it (mode columns closes a
 * floor's rows only at the seg beyond it), and so may its ceiling, if an object
 * reaches above it; its walls cannot be (columns drew them in the tree's order),
 * so they matter only near the objects met and not yet done. */
static void faces_only_leaf(dr_state *S, uint32_t leaf, unsigned clip_mask)
{
    const scn_leaf *f = &S->sc->leaves[leaf];
    S->st->leaves++;
    unsigned which = 0;
    if (f->sector != SCN_NONE) {
        which |= S->sc->sectors[f->sector].floor_h > S->low ? SURF_FLOOR : 0u;
        which |= surf_ceil_now(S->sc, S->w ? S->w->ceil : 0, f->sector) < S->high ? SURF_CEILING : 0u;
    }
    if (which) surf_leaf_planes(S->sc, S->w, S->v, leaf, clip_mask, &S->sink, S->st, which);
    if (S->nactive) surf_leaf_walls(S->sc, S->w, S->v, leaf, clip_mask, &S->sink, S->use_occ ? &S->occ : 0, S->st);
}

/* Objects whose subtree the walk has left (obj_draw.h: objd_subtree_depth): no
 * leaf to come holds anything in front of them, so their faces fill what is
 * still free of them now, and they leave the active list (the pools drop their
 * faces at the next reclaim). What they leave free another active object's face
 * is nearer at: that one fills it when its turn comes. */
static void retire_objects(dr_state *S, uint32_t back_to)
{
    for (uint32_t i = 0; i < S->nactive;) {
        dr_obj *o = &S->objs[S->active[i]];
        /* only once its subtree is known to be the walk's (a box may take it in early, from outside) */
        if (back_to > o->subtree || !(o->e.taken & OBJL_AT_LEAF)) {
            i++;
            continue;
        }
        each_face(S, o, draw_face, 0);
        /* out of the list, the others kept in order (the pools' order, for reclaim) */
        S->nactive--;
        for (uint32_t k = i; k < S->nactive; k++) S->active[k] = S->active[k + 1];
    }
}

static int visit_leaf(void *ctx, uint32_t leaf, unsigned clip_mask)
{
    dr_state *S = ctx;
    if (CFG_OBJECTS && S->nactive) {
        retire_objects(S, S->walk->back_to);
        if (cov_full(S->cov)) return 1;
    }
    if (CFG_OBJECTS && S->nactive < S->nobjs)
        objl_take_in_leaf(S->sc, S->w, leaf, S->objs, S->nobjs, sizeof(dr_obj), S->reach, take_object, S);
    if (S->faces_only) {
        faces_only_leaf(S, leaf, clip_mask);
        return cov_full(S->cov);
    }
    surf_leaf(S->sc, S->w, S->v, leaf, clip_mask, &S->sink, S->use_occ ? &S->occ : 0, S->st);
    return cov_full(S->cov);
}

/* ---- the frame ---------------------------------------------------------------------- */

/* The objects in the view frustum, sorted by the west edges of their boxes;
 * only those set in `only` if given. */
static void list_objects_in_view(dr_state *S, const uint32_t *only)
{
    S->nactive = S->nfaces = S->nedges = 0;
    S->nobjs = objl_in_view(S->sc, S->w, S->v, S->objs, sizeof(dr_obj), &S->reach);
    S->low = INT32_MAX;
    S->high = INT32_MIN;
    if (!only) return;
    uint32_t n = 0;
    for (uint32_t i = 0; i < S->nobjs; i++) {
        uint32_t k = S->objs[i].e.index;
        if (!((only[k >> 5] >> (k & 31)) & 1u)) continue;
        S->objs[n++] = S->objs[i];
        const obj_state *o = &S->w->objs[k];
        const scn_model *m = &S->sc->models[o->model];
        int64_t lo = (int64_t)o->z + m->zmin, hi = (int64_t)o->z + m->zmax;
        if (lo < S->low) S->low = lo < INT32_MIN ? INT32_MIN : (int32_t)lo;
        if (hi > S->high) S->high = hi > INT32_MAX ? INT32_MAX : (int32_t)hi;
    }
    S->nobjs = n;
}

/* With the objects' faces only, the list holds just the objects that claimed
 * pixels, often few of the n it has room for: the pools take the rest of that
 * room (end: where the pools end), a face to every four edges. */
static void widen_pools(dr_state *S, uint32_t n, uint8_t *end)
{
    uint8_t *p = (uint8_t *)S->objs + align8((uint64_t)S->nobjs * sizeof(dr_obj));
    uint16_t *active = (uint16_t *)(void *)p;
    p += align8((uint64_t)S->nobjs * sizeof(uint16_t));
    uint64_t room = (uint64_t)(end - p), faces = room / (sizeof(dr_face) + 4u * sizeof(dr_edge));
    if (S->nobjs >= n || faces <= DIRECT_FACE_POOL) return; /* no more than the fixed pools */
    if (faces > 65535u) faces = 65535u;                     /* their indices are 16 bits */
    uint64_t edges = (room - align8(faces * sizeof(dr_face))) / sizeof(dr_edge);
    S->active = active;
    S->faces = (dr_face *)(void *)p;
    S->edges = (dr_edge *)(void *)(p + align8(faces * sizeof(dr_face)));
    S->face_cap = (uint32_t)faces;
    S->edge_cap = (uint32_t)(edges > 65535u ? 65535u : edges);
}

void direct_render(const scene *sc, const world_state *w, const view_xform *v, const rast_target *t, render_stats *st,
                   void *work, uint32_t bytes)
{
    direct_render_within(sc, w, v, t, st, work, bytes, 0, 0);
}

/* Columns where mask has no pixel set: closed. */
static void close_empty_columns(occ_columns *occ, const cov_mask *mask)
{
    uint32_t any[COV_WORDS] = {0};
    for (int y = 0; y < VIEW_H; y++)
        for (int i = 0; i < COV_WORDS; i++) any[i] |= mask->bits[y][i];
    for (int x = 0; x < VIEW_W;) {
        int end = x;
        while (end < VIEW_W && !((any[end >> 5] >> (end & 31)) & 1u)) end++;
        if (end > x) occ_close(occ, x, end);
        x = end + 1;
    }
}

void direct_render_within(const scene *sc, const world_state *w, const view_xform *v, const rast_target *t,
                          render_stats *st, void *work, uint32_t bytes, cov_mask *only, const uint32_t *objects)
{
    uint32_t need = work_bytes(w, only == 0);
    if (!work || need == 0 || bytes < need) {
        st->refused = 1; /* the caller did not provide the memory this frame needs */
        tex_paint background = tex_flat(BACKGROUND_COLOUR);
        for (int y = 0; y < VIEW_H; y++) rast_span(t, y, 0, VIEW_W, &background, RAST_ID(RAST_KIND_NONE, 0));
        return;
    }
    uint8_t *mem = work;
    dr_state *S = (dr_state *)(void *)mem;
    mem += align8(sizeof(dr_state));
    uint32_t n = objl_capacity(w);
    S->objs = (dr_obj *)(void *)mem;
    mem += n ? align8((uint64_t)n * sizeof(dr_obj)) : 0;
    S->active = (uint16_t *)(void *)mem;
    mem += n ? align8((uint64_t)n * sizeof(uint16_t)) : 0;
    S->faces = (dr_face *)(void *)mem;
    mem += n ? align8((uint64_t)DIRECT_FACE_POOL * sizeof(dr_face)) : 0;
    S->edges = (dr_edge *)(void *)mem;
    mem += n ? align8((uint64_t)DIRECT_EDGE_POOL * sizeof(dr_edge)) : 0;
    S->face_cap = DIRECT_FACE_POOL;
    S->edge_cap = DIRECT_EDGE_POOL;
    S->cov = only ? only : (cov_mask *)(void *)mem;
    S->sc = sc;
    S->w = w;
    S->v = v;
    S->t = t;
    S->st = st;
    S->sink.polygon = add_polygon;
    S->sink.hidden = box_hidden;
    S->sink.ctx = S;
    S->sink.flat = t->flat;
    walk_stats ws;
    S->walk = &ws;
    occ_reset(&S->occ);
    if (only) { /* only these pixels: the rest counts as drawn */
        close_empty_columns(&S->occ, only);
        cov_complement(only, only);
    } else {
        cov_clear(S->cov);
    }
    S->faces_only = only && objects;
    list_objects_in_view(S, only ? objects : 0);
    if (S->faces_only) widen_pools(S, n, mem);
    st->object_pass = S->nobjs != 0;
    /* solid walls close columns only for an eye inside the world (spans.c says why) */
    S->use_occ = eye_in_world(sc, w, v);
    walk_tree_hidden(sc, v, WALK_FRONT_TO_BACK, visit_leaf, S, (S->use_occ || only) ? &S->occ : 0, &ws,
                     S->faces_only ? take_in_hidden : 0);
    st->nodes = ws.nodes;
    st->boxes_culled = ws.boxes_culled + ws.boxes_hidden;
    if (CFG_OBJECTS && S->nactive) draw_objects(S);
    tex_paint background = tex_flat(BACKGROUND_COLOUR);
    for (int y = 0; y < VIEW_H; y++) /* what no surface claimed: the background */
        cov_fill(S->cov, t, y, 0, VIEW_W, 0, &background, RAST_ID(RAST_KIND_NONE, 0));
}
