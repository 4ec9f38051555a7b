/* spans.c - edge lists, the surface stack, span collection and coverage. */
#include "spans.h"

#include "bsp_walk.h"
#include "eye.h"
#include "obj_draw.h"
#include "surfaces.h"

#define SPAN_BUFFER 2048       /* spans collected before a flush */
#define COVER_MAX 24           /* covered intervals remembered per scan line */
#define BACKGROUND_COLOUR 0

typedef struct sp_edge {
    rast_edge d;               /* the DDA the fill rule is defined by (raster.h) */
    uint8_t leading;           /* left edge of its polygon: the surface starts here */
    struct sp_surf *surf;
    struct sp_edge *next;
} sp_edge;

typedef struct sp_surf {
    uint32_t key;              /* BSP order of its leaf: smaller is nearer (an object's face: kmin) */
    uint32_t id;
    uint32_t kmax;             /* an object's face: its key range is [key, kmax] */
    int32_t plane;             /* its 1/z plane in planes[], or -1 (a world surface's, until needed) */
    uint32_t seg;              /* a world surface's plane: a wall of this seg, or (SCN_NONE) the
                                * floor or ceiling its id names */
    uint8_t object;            /* 1: an object's face */
    int32_t state;             /* leading minus trailing edges seen on this line */
    uint8_t colour;
    struct sp_surf *below;     /* next surface down the stack */
    struct sp_surf *above;
    int32_t span_head;         /* this batch's spans, linked through sp_span.next */
    struct sp_surf *next_drawn;
} sp_surf;

typedef struct {
    int16_t y, x0, x1;
    int32_t next;
} sp_span;

typedef struct {
    int16_t n;                 /* intervals in use; -1 once the line is full */
    int16_t x[COVER_MAX][2];   /* sorted, disjoint, not touching: [x0, x1) */
} sp_cover;

typedef struct {
    const scene *sc;
    const world_state *w;
    const view_xform *v;
    const rast_target *t;
    render_stats *st;
    surf_sink sink;
    sp_edge *edges;
    uint32_t nedges, max_edges;
    sp_surf *surfs;
    uint32_t nsurfs, max_surfs;
    uint32_t *leaf_key;        /* with objects: the key each leaf was visited with, 0 if not */
    objd_plane *planes;        /* with objects: 1/z planes of object faces and of world surfaces */
    uint32_t nplanes, max_planes;
    uint32_t object_faces;     /* object faces on the edge lists */
    sp_edge *new_edges[VIEW_H];
    sp_cover cover[VIEW_H];
    occ_columns occ;
    int use_occ;
    int full_rows;
    uint32_t key;
    sp_span spans[SPAN_BUFFER];
    int nspans;
    sp_surf *drawn;            /* surfaces with spans in this batch */
    sp_surf background;
} span_state;

/* ---- memory ------------------------------------------------------------- */

/* Faces and their clipping-maximal edges of w's objects (0 without objects). */
static void object_bound(const scene *s, const world_state *w, uint64_t *faces, uint64_t *edges)
{
    *faces = *edges = 0;
    if (!CFG_OBJECTS || !w) return;
    for (uint32_t i = 0; i < w->n; i++) {
        uint32_t mi = w->objs ? w->objs[i].model : (i < s->nobjects ? s->objects[i].model : SCN_NONE);
        if (mi >= s->nmodels) continue; /* nothing to draw */
        *faces += s->models[mi].num_faces;
        *edges += scene_model_edges(s, &s->models[mi]);
    }
}

static uint32_t align8(uint64_t n)
{
    return (uint32_t)((n + 7u) & ~(uint64_t)7u);
}

typedef struct {
    uint64_t edges, surfs, planes, leaves; /* counts; leaves and planes 0 without objects */
    uint64_t total;                        /* bytes */
} span_layout;

static void layout(const scene *s, const world_state *w, span_layout *L)
{
    uint64_t faces, oedges;
    object_bound(s, w, &faces, &oedges);
    /* the world's part: the most one frame can take for any camera, as the
     * compiler proved it (docs/needs.md) */
    L->edges = (uint64_t)s->needs->edges + oedges;
    L->surfs = (uint64_t)s->needs->surfaces + faces;
    L->planes = faces ? L->surfs : 0;
    L->leaves = faces ? s->nleaves : 0;
    L->total = (uint64_t)align8(sizeof(span_state)) + align8(L->edges * sizeof(sp_edge)) +
               align8(L->surfs * sizeof(sp_surf)) + align8(L->leaves * sizeof(uint32_t)) +
               align8(L->planes * sizeof(objd_plane));
}

uint32_t span_work_bytes(const scene *s, const world_state *w)
{
    span_layout L;
    layout(s, w, &L);
    return L.total > 0xFFFFFFF0u ? 0 : (uint32_t)L.total;
}

/* ---- coverage ----------------------------------------------------------- */

/* 1 if [x0, x1) on row y is already covered by nearer polygons. */
static int covered(const sp_cover *c, int x0, int x1)
{
    if (c->n < 0) return 1;
    for (int i = 0; i < c->n; i++) {
        if (c->x[i][0] > x0) return 0;
        if (c->x[i][1] >= x1) return 1;
    }
    return 0;
}

/* Record [x0, x1) as covered. If the line has no room for another interval the
 * new one is forgotten: coverage then claims less than is true, which only
 * costs an early stop, never a hole. */
static void cover(span_state *S, int y, int x0, int x1)
{
    sp_cover *c = &S->cover[y];
    if (c->n < 0 || x1 <= x0) return;
    int i = 0;
    while (i < c->n && c->x[i][1] < x0) i++;          /* intervals wholly left */
    int j = i;
    while (j < c->n && c->x[j][0] <= x1) j++;         /* intervals touching [x0, x1) */
    if (j > i) {                                       /* merge i .. j-1 into one */
        if (c->x[i][0] < x0) x0 = c->x[i][0];
        if (c->x[j - 1][1] > x1) x1 = c->x[j - 1][1];
        c->x[i][0] = (int16_t)x0;
        c->x[i][1] = (int16_t)x1;
        int gone = j - i - 1;
        for (int k = j; k < c->n; k++) {
            c->x[k - gone][0] = c->x[k][0];
            c->x[k - gone][1] = c->x[k][1];
        }
        c->n = (int16_t)(c->n - gone);
    } else {
        if (c->n == COVER_MAX) return;
        for (int k = c->n; k > i; k--) {
            c->x[k][0] = c->x[k - 1][0];
            c->x[k][1] = c->x[k - 1][1];
        }
        c->x[i][0] = (int16_t)x0;
        c->x[i][1] = (int16_t)x1;
        c->n++;
    }
    if (c->n == 1 && c->x[0][0] == 0 && c->x[0][1] == VIEW_W) {
        c->n = -1;
        S->full_rows++;
    }
}

/* ---- edges ---------------------------------------------------------------- */

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
    int32_t ymin = INT32_MAX, ymax = INT32_MIN;
    for (int i = 0; i < n; i++) {
        if (pts[i].y < ymin) ymin = pts[i].y;
        if (pts[i].y > ymax) ymax = pts[i].y;
    }
    int top = rast_first_sample(ymin), bottom = rast_first_sample(ymax);
    if (top < 0) top = 0;
    if (bottom > VIEW_H) bottom = VIEW_H;
    for (int y = top; y < bottom; y++) {
        lo[y] = VIEW_W;
        hi[y] = 0;
    }
    for (int i = 0; i < n; i++) {
        screen_pt a = pts[i], b = pts[(i + 1 == n) ? 0 : i + 1];
        if (a.y == b.y) continue;
        int leading = a.y > b.y;
        rast_edge e;
        if (!(leading ? rast_edge_setup(&e, b.x, b.y, a.x, a.y) : rast_edge_setup(&e, a.x, a.y, b.x, b.y)))
            continue;
        for (; e.row < e.end_row; rast_edge_step(&e)) {
            int col = rast_first_sample(e.x);
            if (col < 0) col = 0;
            if (col > VIEW_W) col = VIEW_W;
            if (leading) lo[e.row] = (int16_t)col;
            else hi[e.row] = (int16_t)col;
        }
    }
    *top_out = (int16_t)top;
    return bottom - top;
}

/* Cheap first test: is the polygon's screen bounding box already covered on every
 * row it spans? (Exact per-row extents are only worked out when it is not.) */
static int box_covered(const span_state *S, const screen_pt *pts, int n)
{
    int32_t xmin = INT32_MAX, xmax = INT32_MIN, ymin = INT32_MAX, ymax = INT32_MIN;
    for (int i = 0; i < n; i++) {
        if (pts[i].x < xmin) xmin = pts[i].x;
        if (pts[i].x > xmax) xmax = pts[i].x;
        if (pts[i].y < ymin) ymin = pts[i].y;
        if (pts[i].y > ymax) ymax = pts[i].y;
    }
    int x0 = rast_first_sample(xmin), x1 = rast_first_sample(xmax);
    int y0 = rast_first_sample(ymin), y1 = rast_first_sample(ymax);
    if (y1 > VIEW_H) y1 = VIEW_H;
    for (int y = y0 < 0 ? 0 : y0; y < y1; y++)
        if (!covered(&S->cover[y], x0, x1)) return 0;
    return 1;
}

/* A new surface and its edges (the caller has checked the pools). */
static sp_surf *add_surface(span_state *S, const screen_pt *pts, int n, uint8_t colour, uint32_t id)
{
    sp_surf *s = &S->surfs[S->nsurfs++];
    s->key = S->key;
    s->id = id;
    s->colour = colour;
    s->state = 0;
    s->span_head = -1;
    s->next_drawn = 0;
    s->object = 0;
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

static void add_polygon(void *ctx, const screen_pt *pts, int n, uint8_t colour, uint32_t id, uint32_t seg)
{
    span_state *S = ctx;
    if (box_covered(S, pts, n)) {
        S->st->occluded++;
        return;
    }
    int16_t lo[VIEW_H], hi[VIEW_H], top;
    int rows = polygon_rows(pts, n, &top, lo, hi);
    int visible = 0;
    for (int y = top; y < top + rows && !visible; y++)
        visible = lo[y] < hi[y] && !covered(&S->cover[y], lo[y], hi[y]);
    if (!visible) {
        S->st->occluded++;
        return;
    }
    if (S->nsurfs >= S->max_surfs || S->nedges + (uint32_t)n > S->max_edges) { /* the proof says: never */
        S->st->overflow++;
        return;
    }
    sp_surf *s = add_surface(S, pts, n, colour, id);
    if (S->leaf_key) { /* objects may meet it: how to find its plane if they do */
        s->plane = -1;
        s->seg = seg;
    }
    for (int y = top; y < top + rows; y++) cover(S, y, lo[y], hi[y]);
}

static int visit_leaf(void *ctx, uint32_t leaf, unsigned clip_mask)
{
    span_state *S = ctx;
    S->key++;
    if (S->leaf_key) S->leaf_key[leaf] = S->key;
    surf_leaf(S->sc, S->w, S->v, leaf, clip_mask, &S->sink, S->use_occ ? &S->occ : 0, S->st);
    return S->full_rows == VIEW_H; /* the screen is full: nothing farther can show */
}

/* ---- objects -------------------------------------------------------------- */

/* Is any object in the view frustum? If not, the frame skips the object pass:
 * no leaf keys during the walk, no locating, no planes. */
static int any_in_view(const scene *sc, const world_state *w, const view_xform *v)
{
    for (uint32_t i = 0; i < w->n; i++)
        if (w->objs[i].model < sc->nmodels && objd_in_view(sc, &w->objs[i], v)) return 1;
    return 0;
}

/* Every object in a visited leaf and in view: its faces that face the eye, clipped
 * and projected, onto the edge lists (no coverage test: they are sorted in the
 * scan, against the world by key range and 1/z). */
static void add_objects(span_state *S)
{
    const scene *sc = S->sc;
    const world_state *w = S->w;
    view_pt verts[CFG_MODEL_VERTS];
    screen_pt pts[CLIP_MAX_VERTS];
    for (uint32_t i = 0; i < w->n; i++) {
        const obj_state *o = &w->objs[i];
        uint32_t kmin, kmax;
        if (o->model >= sc->nmodels || !objd_in_view(sc, o, S->v) || !objd_locate(sc, o, S->leaf_key, &kmin, &kmax))
            continue;
        S->st->objects_visible++;
        const scn_model *m = &sc->models[o->model];
        objd_transform(sc, o, S->v, verts);
        for (uint32_t f = m->first_face; f < m->first_face + m->num_faces; f++) {
            objd_plane pl;
            if (!objd_face_plane(sc, m, f, verts, &pl)) continue;
            int n = objd_face_screen(sc, m, f, verts, S->v, pts);
            if (!n) continue;
            if (S->nsurfs >= S->max_surfs || S->nedges + (uint32_t)n > S->max_edges || S->nplanes >= S->max_planes) {
                S->st->overflow++; /* bounded by the objects' faces: never */
                return;
            }
            S->st->object_faces++;
            sp_surf *s = add_surface(S, pts, n, sc->faces[f].colour, RAST_ID(RAST_KIND_OBJECT, i));
            s->key = kmin;
            s->kmax = kmax;
            s->object = 1;
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
    for (sp_surf *s = S->drawn; s; s = s->next_drawn) {
        for (int32_t i = s->span_head; i >= 0; i = S->spans[i].next)
            rast_span(S->t, S->spans[i].y, S->spans[i].x0, S->spans[i].x1, s->colour, s->id);
        s->span_head = -1;
        S->st->surfaces_drawn++;
    }
    S->drawn = 0;
    S->nspans = 0;
}

static void emit_span(span_state *S, sp_surf *s, int y, int x0, int x1)
{
    if (x1 <= x0) return;
    if (S->nspans == SPAN_BUFFER) flush_spans(S);
    sp_span *sp = &S->spans[S->nspans];
    sp->y = (int16_t)y;
    sp->x0 = (int16_t)x0;
    sp->x1 = (int16_t)x1;
    if (s->span_head < 0) {
        s->next_drawn = S->drawn;
        S->drawn = s;
    }
    sp->next = s->span_head;
    s->span_head = S->nspans++;
    S->st->spans++;
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
    int x;      /* first pixel where s is in front of the top, VIEW_W: none */
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
        if (mixed_front(S, p, top, mid, y)) hi = mid;
        else lo = mid;
    }
    return hi;
}

static void note(span_state *S, sp_next *n, sp_surf *top, sp_surf *p, int x, int y)
{
    int at = overtakes_at(S, top, p, x, y);
    if (at < n->x || (at == n->x && at < VIEW_W && in_front(S, p, n->s, at, y, 1))) {
        n->x = at;
        n->s = p;
    }
}

/* The next overtaking of top from pixel x on. */
static sp_next plan(span_state *S, sp_surf *top, int x, int y)
{
    sp_next n = {VIEW_W, 0};
    for (sp_surf *p = top->below; p; p = p->below) note(S, &n, top, p, x, y);
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
        *n = plan(S, top, at, y);
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
    int nobj = 0, mixed = 0;        /* object faces on the stack; any on this line so far */
    sp_next next = {VIEW_W, 0};     /* with objects: the next overtaking of the top */
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
                if (objects && nobj) next = plan(S, top, col, y);
            } else {                            /* slot it in below */
                sp_surf *p = top;
                while (!in_front(S, s, p->below, col, y, objects)) p = p->below;
                s->below = p->below;
                s->above = p;
                p->below->above = s;
                p->below = s;
                if (objects && nobj) note(S, &next, top, s, col, y);
            }
        } else {
            if (--s->state != 0) continue;
            if (objects && s->object) nobj--;
            if (s == top) {                     /* the top ends: the next one shows */
                emit_span(S, s, y, cur, col);
                cur = col;
                top = s->below;
                top->above = 0;
                if (objects && mixed) top = nearest(S, top, col, y);
                if (objects) next = nobj ? plan(S, top, col, y) : (sp_next){VIEW_W, 0};
            } else if (s->below || s->above) {  /* leaves from inside the stack */
                s->above->below = s->below;
                s->below->above = s->above;
                if (objects && s == next.s) next = nobj ? plan(S, top, col, y) : (sp_next){VIEW_W, 0};
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

void spans_render(const scene *sc, const world_state *w, const view_xform *v, const rast_target *t, render_stats *st,
                  void *work, uint32_t work_bytes)
{
    span_layout L;
    layout(sc, w, &L);
    if (!work || L.total > 0xFFFFFFF0u || work_bytes < L.total) {
        st->refused = 1; /* the caller did not provide the memory this frame needs */
        render_clear(t, BACKGROUND_COLOUR);
        return;
    }
    uint8_t *mem = work;
    span_state *S = (span_state *)(void *)mem;
    mem += align8(sizeof(span_state));
    S->edges = (sp_edge *)(void *)mem;
    S->max_edges = (uint32_t)L.edges;
    mem += align8(L.edges * sizeof(sp_edge));
    S->surfs = (sp_surf *)(void *)mem;
    S->max_surfs = (uint32_t)L.surfs;
    mem += align8(L.surfs * sizeof(sp_surf));
    /* objects need the leaves' keys, and planes for their faces and the world
     * surfaces they meet; a frame without them pays nothing for either */
    S->leaf_key = (CFG_OBJECTS && L.leaves && w->objs && any_in_view(sc, w, v)) ? (uint32_t *)(void *)mem : 0;
    st->object_pass = S->leaf_key != 0;
    mem += align8(L.leaves * sizeof(uint32_t));
    S->planes = (objd_plane *)(void *)mem;
    S->max_planes = (uint32_t)L.planes;
    S->nplanes = 0;
    S->object_faces = 0;
    S->sc = sc;
    S->w = w;
    S->v = v;
    S->t = t;
    S->st = st;
    S->sink.polygon = add_polygon;
    S->sink.ctx = S;
    S->nedges = S->nsurfs = 0;
    S->full_rows = 0;
    S->key = 0;
    S->nspans = 0;
    S->drawn = 0;
    S->background = (sp_surf){.key = 0xFFFFFFFFu, .id = RAST_ID(RAST_KIND_NONE, 0), .plane = -1, .seg = SCN_NONE,
                              .colour = BACKGROUND_COLOUR, .span_head = -1};
    for (int y = 0; y < VIEW_H; y++) {
        S->new_edges[y] = 0;
        S->cover[y].n = 0;
    }
    if (S->leaf_key)
        for (uint32_t i = 0; i < sc->nleaves; i++) S->leaf_key[i] = 0;
    walk_stats ws;
    /* Solid walls close columns only for an eye inside the world: from outside
     * every sector, or above or below its own sector, one sees past them. */
    occ_columns *occ = eye_in_world(sc, w, v) ? &S->occ : 0;
    occ_reset(&S->occ);
    S->use_occ = occ != 0;
    walk_tree(sc, v, WALK_FRONT_TO_BACK, visit_leaf, S, occ, &ws);
    st->nodes = ws.nodes;
    st->boxes_culled = ws.boxes_culled + ws.boxes_hidden;
    if (CFG_OBJECTS && S->leaf_key) add_objects(S);
    st->edges = S->nedges;
    scan(S, CFG_OBJECTS && S->object_faces > 0);
    flush_spans(S);
}
