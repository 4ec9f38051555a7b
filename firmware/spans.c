/* spans.c - edge lists, the surface stack, span collection, coverage, and the
 * batches that keep the pools a fixed size. */
#include "spans.h"

#include "bsp_walk.h"
#include "cover.h"
#include "eye.h"
#include "obj_draw.h"
#include "surfaces.h"

#define SPAN_BUFFER 2048 /* spans collected before they are filled */
#define BACKGROUND_COLOUR 0
#define POLY_EDGES (CFG_POLY_VERTS + 5) /* the most edges one clipped polygon can have */

typedef struct sp_edge {
    rast_edge d;     /* the DDA the fill rule is defined by (raster.h) */
    uint8_t leading; /* left edge of its polygon: the surface starts here */
    struct sp_surf *surf;
    struct sp_edge *next;
} sp_edge;

typedef struct sp_surf {
    uint32_t key; /* BSP order of its leaf: smaller is nearer (an object's face: kmin) */
    uint32_t id;
    uint32_t kmax;  /* an object's face: its key range is [key, kmax] */
    int32_t plane;  /* its 1/z plane in planes[], or -1 (a world surface's, until needed) */
    uint32_t seg;   /* a world surface's plane: a wall of this seg, or (SCN_NONE) the
                                * floor or ceiling its id names */
    uint8_t object; /* 1: an object's face */
    uint8_t silent; /* 1: owns its pixels but fills nothing (see spans_render) */
    int32_t state;  /* leading minus trailing edges seen on this line */
    tex_paint paint;
    struct sp_surf *below; /* next surface down the stack */
    struct sp_surf *above;
    int32_t span_head; /* this batch's spans, linked through sp_span.next */
    struct sp_surf *next_drawn;
} sp_surf;

typedef struct {
    int16_t y, x0, x1;
    int32_t next;
} sp_span;

/* An object in the view frustum, and the first visited leaf its box touches. */
typedef struct {
    int32_t x0, x1, y0, y1; /* its box (16.16), clamped to 32 bits */
    uint32_t index;         /* in w->objs */
    uint32_t kmin;          /* the key of that leaf, 0 while none */
} sp_obj;

typedef struct {
    const scene *sc;
    const world_state *w;
    const view_xform *v;
    const rast_target *t;
    render_stats *st;
    surf_sink sink;
    sp_edge *edges;
    uint32_t nedges, max_edges; /* max_edges: world edges in one batch (object faces come on top) */
    sp_surf *surfs;
    uint32_t nsurfs, max_surfs;
    uint32_t cap_edges, cap_surfs; /* the pools: world's part plus every face of every object */
    objd_plane *planes;            /* with objects: 1/z planes of object faces and of world surfaces */
    uint32_t nplanes;
    uint32_t object_faces;   /* object faces on the edge lists */
    sp_obj *objs;            /* with objects: those in the frustum, by x0 */
    uint32_t nobjs, pending; /* pending: not yet found in a visited leaf */
    int32_t obj_span;        /* the widest object box (x1 - x0) */
    int world_planes;        /* world surfaces keep what finds their plane */
    int final;               /* the batch being drawn is the frame's last */
    int flushed;             /* a batch was drawn before this one */
    uint32_t edges_total;
    sp_edge *new_edges[VIEW_H];
    cov_mask claimed; /* pixels some polygon on the lists (any batch) covers */
    cov_mask drawn;   /* pixels filled by an earlier batch */
    occ_columns occ;
    int use_occ;
    uint32_t key;
    sp_span spans[SPAN_BUFFER];
    int nspans;
    sp_surf *drawn_list; /* surfaces with spans in the span buffer */
    sp_surf background;
} span_state;

/* ---- memory ------------------------------------------------------------- */

/* Faces and their clipping-maximal edges of w's objects, and the objects (0
 * without objects). */
static void object_bound(const scene *s, const world_state *w, uint64_t *faces, uint64_t *edges, uint64_t *objs)
{
    *faces = *edges = *objs = 0;
    if (!CFG_OBJECTS || !w) return;
    for (uint32_t i = 0; i < w->n; i++) {
        uint32_t mi = w->objs ? w->objs[i].model : (i < s->nobjects ? s->objects[i].model : SCN_NONE);
        if (mi >= s->nmodels) continue; /* nothing to draw */
        *faces += s->models[mi].num_faces;
        *edges += scene_model_edges(s, &s->models[mi]);
        (*objs)++;
    }
}

static uint32_t align8(uint64_t n)
{
    return (uint32_t)((n + 7u) & ~(uint64_t)7u);
}

static uint64_t min_u64(uint64_t a, uint64_t b)
{
    return a < b ? a : b;
}

typedef struct {
    uint64_t world_edges, world_surfs;   /* one batch's world polygons */
    uint64_t edges, surfs, planes, objs; /* pool sizes; planes and objs 0 without objects */
    uint64_t total;                      /* bytes */
} span_layout;

static void layout(const scene *s, const world_state *w, span_layout *L)
{
    uint64_t faces, oedges, objs;
    object_bound(s, w, &faces, &oedges, &objs);
    /* the world's part: what the build allows, or less when the compiler proved
     * that no frame of this scene needs more (docs/needs.md); at least one polygon */
    L->world_edges = min_u64(s->needs->edges, SPANS_POOL_EDGES);
    L->world_surfs = min_u64(s->needs->surfaces, SPANS_POOL_SURFACES);
    if (L->world_edges < POLY_EDGES) L->world_edges = POLY_EDGES;
    if (L->world_surfs < 1) L->world_surfs = 1;
    L->edges = L->world_edges + oedges;
    L->surfs = L->world_surfs + faces;
    L->planes = faces ? L->surfs : 0;
    L->objs = faces ? objs : 0;
    L->total = (uint64_t)align8(sizeof(span_state)) + align8(L->edges * sizeof(sp_edge)) +
               align8(L->surfs * sizeof(sp_surf)) + align8(L->planes * sizeof(objd_plane)) +
               align8(L->objs * sizeof(sp_obj));
}

uint32_t spans_work_bytes(const scene *s, const world_state *w)
{
    span_layout L;
    layout(s, w, &L);
    return L.total > 0xFFFFFFF0u ? 0 : (uint32_t)L.total;
}

/* ---- coverage of polygons ------------------------------------------------- */

/* Insert into a list kept sorted by x. */
static void insert_sorted(sp_edge **list, sp_edge *e)
{
    while (*list && (*list)->d.x < e->d.x) list = &(*list)->next;
    e->next = *list;
    *list = e;
}

/* The polygon's per-row extent, exactly as the scan will produce it; used to
 * test it against coverage and then to extend coverage. Returns the rows. */
static int polygon_rows(const screen_pt *pts, int n, int16_t *top_out, int16_t lo[VIEW_H], int16_t hi[VIEW_H])
{
    rast_box b = rast_bounds(pts, n);
    int top = b.y0 < 0 ? 0 : b.y0, bottom = b.y1 > VIEW_H ? VIEW_H : b.y1;
    rast_rows(pts, n, top, bottom, lo, hi);
    *top_out = (int16_t)top;
    return bottom - top;
}

/* Cheap first test: is the polygon's screen bounding box already covered on every
 * row it spans? (Exact per-row extents are only worked out when it is not.) */
static int box_covered(const span_state *S, const screen_pt *pts, int n)
{
    rast_box b = rast_bounds(pts, n);
    int x0 = b.x0, x1 = b.x1, y0 = b.y0, y1 = b.y1;
    if (x0 < 0) x0 = 0;
    if (x1 > VIEW_W) x1 = VIEW_W;
    if (y1 > VIEW_H) y1 = VIEW_H;
    for (int y = y0 < 0 ? 0 : y0; y < y1; y++)
        if (!cov_all(&S->claimed, y, x0, x1)) return 0;
    return 1;
}

/* ---- edges ---------------------------------------------------------------- */

/* A new surface and its edges (the caller has checked the pools). */
static sp_surf *add_surface(span_state *S, const screen_pt *pts, int n, const tex_paint *paint, uint32_t id)
{
    sp_surf *s = &S->surfs[S->nsurfs++];
    s->key = S->key;
    s->id = id;
    s->paint = *paint;
    s->state = 0;
    s->span_head = -1;
    s->next_drawn = 0;
    s->object = 0;
    s->silent = 0;
    s->below = s->above = 0;
    for (int i = 0; i < n; i++) {
        screen_pt a = pts[i], b = pts[(i + 1 == n) ? 0 : i + 1];
        if (a.y == b.y) continue;
        sp_edge *e = &S->edges[S->nedges];
        int leading = a.y > b.y; /* going up the screen: a left edge (raster.c) */
        if (!(leading ? rast_edge_setup(&e->d, b.x, b.y, a.x, a.y) : rast_edge_setup(&e->d, a.x, a.y, b.x, b.y)))
            continue;
        e->leading = (uint8_t)leading;
        e->surf = s;
        S->nedges++;
        insert_sorted(&S->new_edges[e->d.row], e);
    }
    return s;
}

static void draw_batch(span_state *S, int final);

static void add_polygon(void *ctx, const screen_pt *pts, int n, const tex_paint *paint, uint32_t id, uint32_t seg,
                        int32_t zmin, int32_t zmax)
{
    (void)zmin;
    (void)zmax;
    span_state *S = ctx;
    if (box_covered(S, pts, n)) {
        S->st->occluded++;
        return;
    }
    int16_t lo[VIEW_H], hi[VIEW_H], top;
    int rows = polygon_rows(pts, n, &top, lo, hi);
    int visible = 0;
    for (int y = top; y < top + rows && !visible; y++)
        visible = lo[y] < hi[y] && !cov_all(&S->claimed, y, lo[y], hi[y]);
    if (!visible) {
        S->st->occluded++;
        return;
    }
    /* The pools are full: what they hold is drawn now, and the walk goes on
     * behind it (see spans_render). */
    if (S->nsurfs >= S->max_surfs || S->nedges + (uint32_t)n > S->max_edges) draw_batch(S, 0);
    if (S->nsurfs >= S->max_surfs || S->nedges + (uint32_t)n > S->max_edges) { /* n > CFG_POLY_VERTS + 5: never */
        S->st->overflow++;
        return;
    }
    sp_surf *s = add_surface(S, pts, n, paint, id);
    if (S->world_planes) { /* objects may meet it: how to find its plane if they do */
        s->plane = -1;
        s->seg = seg;
    }
    for (int y = top; y < top + rows; y++) cov_set(&S->claimed, y, lo[y], hi[y]);
}

/* ---- objects -------------------------------------------------------------- */

static int32_t clamp32(int64_t v)
{
    return v < INT32_MIN ? INT32_MIN : (v > INT32_MAX ? INT32_MAX : (int32_t)v);
}

/* The objects in the frustum, by the left side of their boxes. Returns how many. */
static uint32_t collect_objects(span_state *S)
{
    const scene *sc = S->sc;
    const world_state *w = S->w;
    uint32_t n = 0;
    S->obj_span = 0;
    for (uint32_t i = 0; i < w->n; i++) {
        const obj_state *o = &w->objs[i];
        if (o->model >= sc->nmodels || !objd_in_view(sc, o, S->v)) continue;
        int64_t r = sc->models[o->model].radius;
        sp_obj b = {clamp32((int64_t)o->x - r),
                    clamp32((int64_t)o->x + r),
                    clamp32((int64_t)o->y - r),
                    clamp32((int64_t)o->y + r),
                    i,
                    0};
        if (b.x1 - b.x0 > S->obj_span) S->obj_span = b.x1 - b.x0;
        uint32_t k = n++;
        for (; k > 0 && S->objs[k - 1].x0 > b.x0; k--) S->objs[k] = S->objs[k - 1];
        S->objs[k] = b;
    }
    return n;
}

static void box_add(int32_t box[BOX_SIDES], const scn_vertex *p)
{
    if (p->y > box[BOX_TOP]) box[BOX_TOP] = p->y;
    if (p->y < box[BOX_BOTTOM]) box[BOX_BOTTOM] = p->y;
    if (p->x < box[BOX_LEFT]) box[BOX_LEFT] = p->x;
    if (p->x > box[BOX_RIGHT]) box[BOX_RIGHT] = p->x;
}

/* The objects whose box touches the leaf's bounding box (the compiler's: its
 * floor polygon and its segs) and that no earlier
 * leaf touched: this leaf's key is their kmin. */
static void find_objects(span_state *S, uint32_t leaf)
{
    const scene *sc = S->sc;
    const scn_leaf *f = &sc->leaves[leaf];
    int32_t box[BOX_SIDES] = {INT32_MIN, INT32_MAX, INT32_MAX, INT32_MIN}; /* empty */
    for (uint32_t i = 0; i < f->num_pverts; i++) box_add(box, &sc->pverts[f->first_pvert + i]);
    for (uint32_t i = 0; i < f->num_segs; i++) {
        const scn_seg *g = &sc->segs[f->first_seg + i];
        box_add(box, &sc->verts[g->v1]);
        box_add(box, &sc->verts[g->v2]);
    }
    if (box[BOX_LEFT] > box[BOX_RIGHT]) return; /* no geometry */
    /* the first object that can reach the leaf from the left, by bisection */
    int64_t from = (int64_t)box[BOX_LEFT] - S->obj_span;
    uint32_t lo = 0, hi = S->nobjs;
    while (lo < hi) {
        uint32_t mid = lo + (hi - lo) / 2;
        if (S->objs[mid].x0 < from)
            lo = mid + 1;
        else
            hi = mid;
    }
    for (uint32_t i = lo; i < S->nobjs && S->objs[i].x0 <= box[BOX_RIGHT]; i++) {
        sp_obj *o = &S->objs[i];
        if (o->kmin || o->x1 < box[BOX_LEFT] || o->y0 > box[BOX_TOP] || o->y1 < box[BOX_BOTTOM]) continue;
        o->kmin = S->key;
        S->pending--;
    }
}

static int visit_leaf(void *ctx, uint32_t leaf, unsigned clip_mask)
{
    span_state *S = ctx;
    S->key++;
    if (CFG_OBJECTS && S->pending) find_objects(S, leaf);
    surf_leaf(S->sc, S->w, S->v, leaf, clip_mask, &S->sink, S->use_occ ? &S->occ : 0, S->st);
    return cov_full(&S->claimed); /* the screen is full: nothing farther can show */
}

/* Every object found in a visited leaf: its faces that face the eye, clipped and
 * projected, onto the edge lists (no coverage test: they are sorted in the scan,
 * against the world by kmin and 1/z). silent: a batch before the last, where
 * they only keep world surfaces behind them from being filled. */
static void add_objects(span_state *S, int silent)
{
    const scene *sc = S->sc;
    const world_state *w = S->w;
    view_pt verts[CFG_MODEL_VERTS];
    screen_pt pts[CLIP_MAX_VERTS];
    for (uint32_t k = 0; k < S->nobjs; k++) {
        if (!S->objs[k].kmin) continue;
        uint32_t i = S->objs[k].index;
        const obj_state *o = &w->objs[i];
        if (!silent) S->st->objects_visible++;
        const scn_model *m = &sc->models[o->model];
        objd_transform(sc, o, S->v, verts);
        for (uint32_t f = m->first_face; f < m->first_face + m->num_faces; f++) {
            objd_plane pl;
            if (!objd_face_plane(sc, m, f, verts, &pl)) continue;
            int n = objd_face_screen(sc, m, f, verts, S->v, pts);
            if (!n) continue;
            if (S->nsurfs >= S->cap_surfs || S->nedges + (uint32_t)n > S->cap_edges) {
                S->st->overflow++; /* beyond the world's part, the pools hold every face of every object: never */
                return;
            }
            if (!silent) S->st->object_faces++;
            tex_paint paint = tex_flat(sc->faces[f].colour);
            sp_surf *s = add_surface(S, pts, n, &paint, RAST_ID(RAST_KIND_OBJECT, i));
            s->key = S->objs[k].kmin;
            s->kmax = OBJD_KEY_OPEN;
            s->object = 1;
            s->silent = (uint8_t)silent;
            s->plane = (int32_t)S->nplanes;
            S->planes[S->nplanes++] = pl;
            S->object_faces++;
        }
    }
}

static const objd_plane *plane_of(span_state *S, sp_surf *s)
{
    if (s->plane < 0) { /* a world surface met by an object: its plane, once */
        objd_plane *p = &S->planes[S->nplanes];
        if (s->seg == SCN_NONE) {
            uint32_t sec = s->id & 0xFFFFFFu;
            int32_t h = (s->id >> 24) == RAST_KIND_FLOOR ? S->sc->sectors[sec].floor_h : obj_ceil(S->w, S->sc, sec);
            objd_plane_flat(S->v, h, p);
        } else {
            const scn_seg *g = &S->sc->segs[s->seg];
            objd_plane_wall(S->v, &S->sc->verts[g->v1], &S->sc->verts[g->v2], p);
        }
        s->plane = (int32_t)S->nplanes++; /* one per surface at most: the pool holds them all */
    }
    return &S->planes[s->plane];
}

/* objd_front's name for a surface: 0 for the world's, 1 + the object's number. */
static int obj_number(const sp_surf *s)
{
    return s->object ? (int)(s->id & 0xFFFFFFu) + 1 : 0;
}

/* Is s (being inserted) in front of p at pixel x of row y? World surfaces by key;
 * an object's face against the world by key outside its range, else by 1/z; and
 * faces of objects against each other by 1/z (docs/objects.md). */
static int mixed_front(span_state *S, sp_surf *s, sp_surf *p, int x, int y)
{
    if (!s->object) {
        if (s->key < p->key) return 1;
        if (s->key > p->kmax) return 0;
    } else if (!p->object) {
        if (p->key < s->key) return 0;
        if (p->key > s->kmax) return 1;
    }
    return objd_front(plane_of(S, s), obj_number(s), plane_of(S, p), obj_number(p), VIEW_LOOK(S->v), x, y);
}

static inline __attribute__((always_inline)) int in_front(span_state *S, sp_surf *s, sp_surf *p, int x, int y,
                                                          int objects)
{
    return (objects && (s->object | p->object)) ? mixed_front(S, s, p, x, y) : s->key < p->key;
}


/* ---- spans ---------------------------------------------------------------- */

static void flush_spans(span_state *S)
{
    for (sp_surf *s = S->drawn_list; s; s = s->next_drawn) {
        for (int32_t i = s->span_head; i >= 0; i = S->spans[i].next)
            rast_span(S->t, S->spans[i].y, S->spans[i].x0, S->spans[i].x1, &s->paint, s->id);
        s->span_head = -1;
        S->st->surfaces_drawn++;
    }
    S->drawn_list = 0;
    S->nspans = 0;
}

static inline __attribute__((always_inline)) void push_span(span_state *S, sp_surf *s, int y, int x0, int x1)
{
    if (S->nspans == SPAN_BUFFER) flush_spans(S);
    sp_span *sp = &S->spans[S->nspans];
    sp->y = (int16_t)y;
    sp->x0 = (int16_t)x0;
    sp->x1 = (int16_t)x1;
    if (s->span_head < 0) {
        s->next_drawn = S->drawn_list;
        S->drawn_list = s;
    }
    sp->next = s->span_head;
    s->span_head = S->nspans++;
    S->st->spans++;
}

/* Fill [x0, x1) of row y with s in a batch before the last: later batches leave these pixels alone. */
static void push_marked(span_state *S, sp_surf *s, int y, int x0, int x1)
{
    push_span(S, s, y, x0, x1);
    cov_set(&S->drawn, y, x0, x1);
}

/* s owns [x0, x1) of row y. In a batch before the last, the background and
 * silent surfaces (object faces) fill nothing there: the pixels stay open for
 * the surfaces behind that later batches bring. After the first batch, pixels an
 * earlier batch filled belong to nearer surfaces than any of this batch. */
static void emit_span(span_state *S, sp_surf *s, int y, int x0, int x1)
{
    if (x1 <= x0) return;
    if (!S->final && (s == &S->background || s->silent)) return;
    if (S->final && !S->flushed) { /* the frame in one batch */
        push_span(S, s, y, x0, x1);
        return;
    }
    for (int x = cov_next_clear(&S->drawn, y, x0, x1); x < x1;) {
        int end = cov_next_set(&S->drawn, y, x, x1);
        if (S->final)
            push_span(S, s, y, x, end);
        else
            push_marked(S, s, y, x, end);
        x = cov_next_clear(&S->drawn, y, end, x1);
    }
}

/* ---- the stack with objects: intersecting spans --------------------------- */

/* Pairs sorted by 1/z can change order along a line: a Doom thing whose box
 * reaches into a wall, two objects that interpenetrate. The order found when a
 * surface is inserted (independent sorting) would then hold for the rest of the
 * span; instead, on lines with an object on the stack the top stays the nearest
 * surface at every pixel (Black Book ch. 67's intersecting span sorting). The
 * first pixel where another surface overtakes the top is found by bisection
 * (1/z is linear along the line, so "in front" flips at most once) and kept as
 * the line's next event beside the edges; it is found again whenever the top
 * changes, and a surface slotted in below is checked against the top. When the
 * top ends, the nearest of the rest takes over, wherever it sat in the stack. */
#define OVERTAKES_MAX 32 /* at one pixel: only orders that are no depth could need more */

typedef struct {
    int x; /* first pixel where s is in front of the top, VIEW_W: none */
    sp_surf *s;
} sp_next;

static int may_cross(const sp_surf *s, const sp_surf *p)
{
    if (!(s->object | p->object)) return 0;
    if (s->object && p->object) return 1;
    const sp_surf *o = s->object ? s : p, *w = s->object ? p : s;
    return w->key >= o->key && w->key <= o->kmax;
}

/* Put s, somewhere below top, on top. */
static sp_surf *raise_surf(sp_surf *top, sp_surf *s)
{
    s->above->below = s->below;
    if (s->below) s->below->above = s->above;
    s->below = top;
    s->above = 0;
    top->above = s;
    return s;
}

/* The first pixel from x on where p is in front of top (VIEW_W: none). */
static int overtakes_at(span_state *S, sp_surf *top, sp_surf *p, int x, int y)
{
    if (x >= VIEW_W || !may_cross(p, top) || !mixed_front(S, p, top, VIEW_W - 1, y)) return VIEW_W;
    int lo = x - 1, hi = VIEW_W - 1; /* in front at hi; lo is before the range */
    while (hi - lo > 1) {
        int mid = lo + (hi - lo) / 2;
        if (mixed_front(S, p, top, mid, y))
            hi = mid;
        else
            lo = mid;
    }
    return hi;
}

/* Keep p's overtaking of top in *n if it comes before the one *n holds (at the
 * same pixel: if p is nearer there than n's surface). */
static void keep_sooner_overtake(span_state *S, sp_next *n, sp_surf *top, sp_surf *p, int x, int y)
{
    int at = overtakes_at(S, top, p, x, y);
    if (at < n->x || (at == n->x && at < VIEW_W && in_front(S, p, n->s, at, y, 1))) {
        n->x = at;
        n->s = p;
    }
}

/* The next overtaking of top from pixel x on. */
static sp_next next_overtake(span_state *S, sp_surf *top, int x, int y)
{
    sp_next n = {VIEW_W, 0};
    for (sp_surf *p = top->below; p; p = p->below) keep_sooner_overtake(S, &n, top, p, x, y);
    return n;
}

/* The nearest surface of the stack at x, on top. */
static sp_surf *nearest(span_state *S, sp_surf *top, int x, int y)
{
    sp_surf *best = top;
    for (sp_surf *p = top->below; p; p = p->below)
        if (in_front(S, p, best, x, y, 1)) best = p;
    return best == top ? top : raise_surf(top, best);
}

/* Overtakings before pixel col: each ends the top's span and puts the nearer on top. */
static sp_surf *overtake(span_state *S, sp_surf *top, sp_next *n, int *cur, int col, int y)
{
    for (int k = 0; n->x < col && k < OVERTAKES_MAX; k++) {
        int at = n->x < *cur ? *cur : n->x;
        emit_span(S, top, y, *cur, at);
        *cur = at;
        top = raise_surf(top, n->s);
        *n = next_overtake(S, top, at, y);
    }
    return top;
}

/* One scan line: walk the active edges left to right, keeping the stack of
 * surfaces under the current x sorted front to back; the top one owns the
 * pixels. Without objects the order is the key alone. */
static inline __attribute__((always_inline)) void scan_line(span_state *S, sp_edge *active, int y, int objects)
{
    sp_surf *top = &S->background;
    int cur = 0;
    int nobj = 0, mixed = 0;    /* object faces on the stack; any on this line so far */
    sp_next next = {VIEW_W, 0}; /* with objects: the next overtaking of the top */
    for (sp_edge *e = active; e; e = e->next) {
        int col = rast_first_sample(e->d.x);
        if (col < 0) col = 0;
        if (col > VIEW_W) col = VIEW_W;
        sp_surf *s = e->surf;
        if (objects && next.x < col) top = overtake(S, top, &next, &cur, col, y);
        if (e->leading) {
            if (++s->state != 1) continue;
            if (objects && s->object) nobj++, mixed = 1;
            if (in_front(S, s, top, col, y, objects)) { /* nearer than the top: it takes over */
                emit_span(S, top, y, cur, col);
                cur = col;
                s->below = top;
                s->above = 0;
                top->above = s;
                top = s;
                if (objects && nobj) next = next_overtake(S, top, col, y);
            } else { /* slot it in below */
                sp_surf *p = top;
                while (!in_front(S, s, p->below, col, y, objects)) p = p->below;
                s->below = p->below;
                s->above = p;
                p->below->above = s;
                p->below = s;
                if (objects && nobj) keep_sooner_overtake(S, &next, top, s, col, y);
            }
        } else {
            if (--s->state != 0) continue;
            if (objects && s->object) nobj--;
            if (s == top) { /* the top ends: the next one shows */
                emit_span(S, s, y, cur, col);
                cur = col;
                top = s->below;
                top->above = 0;
                if (objects && mixed) top = nearest(S, top, col, y);
                if (objects) next = nobj ? next_overtake(S, top, col, y) : (sp_next){VIEW_W, 0};
            } else if (s->below || s->above) { /* leaves from inside the stack */
                s->above->below = s->below;
                s->below->above = s->above;
                if (objects && s == next.s) next = nobj ? next_overtake(S, top, col, y) : (sp_next){VIEW_W, 0};
            }
            s->below = s->above = 0;
        }
    }
    if (objects && next.x < VIEW_W) top = overtake(S, top, &next, &cur, VIEW_W, y);
    emit_span(S, top, y, cur, VIEW_W);
    /* every surface starts the next line closed, even one whose edges crossed */
    for (sp_edge *e = active; e; e = e->next) {
        e->surf->state = 0;
        e->surf->above = e->surf->below = 0;
    }
}

/* With objects, a line is scanned the object way only while an object's edge is
 * on it: no object face can be on the stack of any other line. */
static inline __attribute__((always_inline)) void scan_lines(span_state *S, int objects)
{
    sp_edge *active = 0;
    int object_edges = 0; /* active edges of object faces */
    for (int y = 0; y < VIEW_H; y++) {
        /* merge the edges starting on this line (both lists sorted by x) */
        sp_edge **link = &active;
        sp_edge *n = S->new_edges[y];
        while (n) {
            while (*link && (*link)->d.x < n->d.x) link = &(*link)->next;
            sp_edge *next = n->next;
            if (objects) object_edges += n->surf->object;
            n->next = *link;
            *link = n;
            link = &n->next;
            n = next;
        }
        if (objects && object_edges)
            scan_line(S, active, y, 1);
        else
            scan_line(S, active, y, 0);
        /* drop finished edges, step the rest, and restore x order: stepping
         * reorders only edges that cross, so an edge is moved back only when it
         * passed the one before it */
        sp_edge **link2 = &active, *prev = 0;
        while (*link2) {
            sp_edge *e = *link2;
            if (e->d.end_row <= y + 1) {
                if (objects) object_edges -= e->surf->object;
                *link2 = e->next;
                continue;
            }
            rast_edge_step(&e->d);
            if (prev && e->d.x < prev->d.x) {
                *link2 = e->next;
                insert_sorted(&active, e);
                continue;
            }
            prev = e;
            link2 = &e->next;
        }
    }
}

static void scan(span_state *S, int objects)
{
    if (objects)
        scan_lines(S, 1);
    else
        scan_lines(S, 0);
}

/* Draw what the lists hold (final: the frame's last batch), then empty them. */
static void draw_batch(span_state *S, int final)
{
    if (!final && !S->flushed) cov_clear(&S->drawn);
    S->final = final;
    S->object_faces = 0;
    if (CFG_OBJECTS && S->nobjs) add_objects(S, !final);
    S->edges_total += S->nedges;
    scan(S, CFG_OBJECTS && S->object_faces > 0);
    flush_spans(S);
    for (int y = 0; y < VIEW_H; y++) S->new_edges[y] = 0;
    S->nedges = S->nsurfs = S->nplanes = 0;
    if (!final) {
        S->flushed = 1;
        S->st->flushes++;
    }
}

void spans_render(const scene *sc, const world_state *w, const view_xform *v, const rast_target *t, render_stats *st,
                  void *work, uint32_t work_bytes)
{
    span_layout L;
    layout(sc, w, &L);
    if (!work || L.total > 0xFFFFFFF0u || work_bytes < L.total) {
        st->refused = 1; /* the caller did not provide the memory this frame needs */
        rast_clear(t, BACKGROUND_COLOUR);
        return;
    }
    uint8_t *mem = work;
    span_state *S = (span_state *)(void *)mem;
    mem += align8(sizeof(span_state));
    S->edges = (sp_edge *)(void *)mem;
    S->max_edges = (uint32_t)L.world_edges;
    S->cap_edges = (uint32_t)L.edges;
    mem += align8(L.edges * sizeof(sp_edge));
    S->surfs = (sp_surf *)(void *)mem;
    S->max_surfs = (uint32_t)L.world_surfs;
    S->cap_surfs = (uint32_t)L.surfs;
    mem += align8(L.surfs * sizeof(sp_surf));
    S->planes = (objd_plane *)(void *)mem;
    mem += align8(L.planes * sizeof(objd_plane));
    S->objs = (sp_obj *)(void *)mem;
    S->sc = sc;
    S->w = w;
    S->v = v;
    S->t = t;
    S->st = st;
    /* objects need the objects in the frustum found in the walk's leaves, and
     * planes for their faces and the world surfaces they meet; a frame without
     * any pays for neither */
    S->nobjs = (CFG_OBJECTS && L.objs && w->objs) ? collect_objects(S) : 0;
    S->pending = S->nobjs;
    S->world_planes = S->nobjs != 0;
    st->object_pass = S->nobjs != 0;
    S->nplanes = 0;
    S->object_faces = 0;
    S->sink.polygon = add_polygon;
    S->sink.hidden = 0;
    S->sink.ctx = S;
    S->sink.flat = t->flat;
    S->nedges = S->nsurfs = 0;
    S->edges_total = 0;
    S->final = S->flushed = 0;
    S->key = 0;
    S->nspans = 0;
    S->drawn_list = 0;
    S->background = (sp_surf){.key = 0xFFFFFFFFu,
                              .id = RAST_ID(RAST_KIND_NONE, 0),
                              .plane = -1,
                              .seg = SCN_NONE,
                              .paint = {.kind = TEX_FLAT, .colour = BACKGROUND_COLOUR},
                              .span_head = -1};
    for (int y = 0; y < VIEW_H; y++) S->new_edges[y] = 0;
    cov_clear(&S->claimed); /* S->drawn: cleared before the first batch that is not the last */
    walk_stats ws;
    /* Solid walls close columns only for an eye inside the world: from outside
     * every sector, or above or below its own sector, one sees past them. */
    occ_columns *occ = eye_in_world(sc, w, v) ? &S->occ : 0;
    occ_reset(&S->occ);
    S->use_occ = occ != 0;
    walk_tree(sc, v, WALK_FRONT_TO_BACK, visit_leaf, S, occ, &ws);
    st->nodes = ws.nodes;
    st->boxes_culled = ws.boxes_culled + ws.boxes_hidden;
    draw_batch(S, 1);
    st->edges = S->edges_total;
}
