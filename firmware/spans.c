/* spans.c - edge lists, the surface stack, span collection and coverage. */
#include "spans.h"

#include "bsp_walk.h"
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
    uint32_t key;              /* BSP order of its leaf: smaller is nearer */
    uint32_t id;
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
    const view_xform *v;
    const rast_target *t;
    render_stats *st;
    surf_sink sink;
    sp_edge *edges;
    uint32_t nedges, max_edges;
    sp_surf *surfs;
    uint32_t nsurfs, max_surfs;
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

static uint64_t max_edges(const scene *s)
{
    /* A polygon with n vertices has at most n + 5 after clipping (one more per
     * plane), each an edge. Floors and ceilings: two per leaf. Walls: at most two
     * parts per seg (upper and lower, or the middle), 4 + 5 edges each. */
    uint64_t e = 0;
    for (uint32_t i = 0; i < s->nleaves; i++) e += 2u * ((uint64_t)s->leaves[i].num_pverts + 5u);
    return e + (uint64_t)s->nsegs * 2u * 9u;
}

static uint64_t max_surfs(const scene *s)
{
    return 2u * (uint64_t)s->nleaves + 2u * (uint64_t)s->nsegs;
}

static uint32_t align8(uint64_t n)
{
    return (uint32_t)((n + 7u) & ~(uint64_t)7u);
}

uint32_t span_work_bytes(const scene *s)
{
    uint64_t total = align8(sizeof(span_state)) + align8(max_edges(s) * sizeof(sp_edge)) +
                     align8(max_surfs(s) * sizeof(sp_surf));
    return total > 0xFFFFFFF0u ? 0 : (uint32_t)total;
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

static void add_polygon(void *ctx, const screen_pt *pts, int n, uint8_t colour, uint32_t id)
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
    if (S->nsurfs >= S->max_surfs || S->nedges + (uint32_t)n > S->max_edges) return; /* bound proven: unreachable */
    sp_surf *s = &S->surfs[S->nsurfs++];
    s->key = S->key;
    s->id = id;
    s->colour = colour;
    s->state = 0;
    s->span_head = -1;
    s->next_drawn = 0;
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
    for (int y = top; y < top + rows; y++) cover(S, y, lo[y], hi[y]);
}

static int visit_leaf(void *ctx, uint32_t leaf, unsigned clip_mask)
{
    span_state *S = ctx;
    S->key++;
    surf_leaf(S->sc, S->v, leaf, clip_mask, &S->sink, S->use_occ ? &S->occ : 0, S->st);
    return S->full_rows == VIEW_H; /* the screen is full: nothing farther can show */
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

/* One scan line: walk the active edges left to right, keeping the stack of
 * surfaces under the current x sorted by key; the top one owns the pixels. */
static void scan_line(span_state *S, sp_edge *active, int y)
{
    sp_surf *top = &S->background;
    int cur = 0;
    for (sp_edge *e = active; e; e = e->next) {
        int col = rast_first_sample(e->d.x);
        if (col < 0) col = 0;
        if (col > VIEW_W) col = VIEW_W;
        sp_surf *s = e->surf;
        if (e->leading) {
            if (++s->state != 1) continue;
            if (s->key < top->key) {            /* nearer than the top: it takes over */
                emit_span(S, top, y, cur, col);
                cur = col;
                s->below = top;
                s->above = 0;
                top->above = s;
                top = s;
            } else {                            /* slot it in below, by key */
                sp_surf *p = top;
                while (p->below->key <= s->key) p = p->below;
                s->below = p->below;
                s->above = p;
                p->below->above = s;
                p->below = s;
            }
        } else {
            if (--s->state != 0) continue;
            if (s == top) {                     /* the top ends: the next one shows */
                emit_span(S, s, y, cur, col);
                cur = col;
                top = s->below;
                top->above = 0;
            } else if (s->below || s->above) {  /* leaves from inside the stack */
                s->above->below = s->below;
                s->below->above = s->above;
            }
            s->below = s->above = 0;
        }
    }
    emit_span(S, top, y, cur, VIEW_W);
    /* every surface starts the next line closed, even one whose edges crossed */
    for (sp_edge *e = active; e; e = e->next) {
        e->surf->state = 0;
        e->surf->above = e->surf->below = 0;
    }
}

static void scan(span_state *S)
{
    sp_edge *active = 0;
    for (int y = 0; y < VIEW_H; y++) {
        /* merge the edges starting on this line (both lists sorted by x) */
        sp_edge **link = &active;
        sp_edge *n = S->new_edges[y];
        while (n) {
            while (*link && (*link)->d.x < n->d.x) link = &(*link)->next;
            sp_edge *next = n->next;
            n->next = *link;
            *link = n;
            link = &n->next;
            n = next;
        }
        scan_line(S, active, y);
        /* drop finished edges, step the rest, and restore x order: stepping
         * reorders only edges that cross, so an edge is moved back only when it
         * passed the one before it */
        sp_edge **link2 = &active, *prev = 0;
        while (*link2) {
            sp_edge *e = *link2;
            if (e->d.end_row <= y + 1) {
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

/* 1 if the eye stands inside its leaf's floor polygon (leaf regions also take in
 * void behind walls) and between its sector's floor and ceiling, strictly: an eye
 * on a wall's line sees into the sector beyond as well, where its height may be
 * below that sector's floor and a solid wall there hides nothing. The shifted
 * products are within |dx| + |dy| + |ex| + |ey| + 2 of the exact cross product
 * (scaled by 1/16); a point nearer the edge than that counts as on it, which only
 * costs the occlusion shortcut. */
static int eye_in_world(const scene *sc, const view_xform *v)
{
    const scn_leaf *f = &sc->leaves[scene_leaf_at(sc, (int32_t)v->cx, (int32_t)v->cy)];
    if (f->sector == SCN_NONE || f->num_pverts < 3) return 0;
    const scn_sector *sec = &sc->sectors[f->sector];
    if (v->cz <= sec->floor_h || v->cz >= sec->ceil_h) return 0;
    for (uint32_t i = 0; i < f->num_pverts; i++) {
        const scn_vertex *a = &sc->pverts[f->first_pvert + i];
        const scn_vertex *b = &sc->pverts[f->first_pvert + (i + 1 == f->num_pverts ? 0 : i + 1)];
        /* counter-clockwise polygon: inside is on the left of every edge; the
         * shifts keep both products below 2^61 (as in surfaces.c) */
        int64_t dx = fx_asr64((int64_t)b->x - a->x, 1), dy = fx_asr64((int64_t)b->y - a->y, 1);
        int64_t ex = fx_asr64(v->cx - a->x, 3), ey = fx_asr64(v->cy - a->y, 3);
        int64_t slack = (dx < 0 ? -dx : dx) + (dy < 0 ? -dy : dy) + (ex < 0 ? -ex : ex) + (ey < 0 ? -ey : ey) + 2;
        if (dx * ey - dy * ex <= slack) return 0;
    }
    return 1;
}

void spans_render(const scene *sc, const view_xform *v, const rast_target *t, render_stats *st, void *work,
                  uint32_t work_bytes)
{
    if (!work || work_bytes < span_work_bytes(sc) || span_work_bytes(sc) == 0) {
        st->refused = 1; /* the caller did not provide the memory this scene needs */
        render_clear(t, BACKGROUND_COLOUR);
        return;
    }
    uint8_t *mem = work;
    span_state *S = (span_state *)(void *)mem;
    mem += align8(sizeof(span_state));
    S->edges = (sp_edge *)(void *)mem;
    S->max_edges = (uint32_t)max_edges(sc);
    mem += align8(max_edges(sc) * sizeof(sp_edge));
    S->surfs = (sp_surf *)(void *)mem;
    S->max_surfs = (uint32_t)max_surfs(sc);
    S->sc = sc;
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
    S->background = (sp_surf){0xFFFFFFFFu, RAST_ID(RAST_KIND_NONE, 0), 0, BACKGROUND_COLOUR, 0, 0, -1, 0};
    for (int y = 0; y < VIEW_H; y++) {
        S->new_edges[y] = 0;
        S->cover[y].n = 0;
    }
    walk_stats ws;
    /* Solid walls close columns only for an eye inside the world: from outside
     * every sector, or above or below its own sector, one sees past them. */
    occ_columns *occ = eye_in_world(sc, v) ? &S->occ : 0;
    occ_reset(&S->occ);
    S->use_occ = occ != 0;
    walk_tree(sc, v, WALK_FRONT_TO_BACK, visit_leaf, S, occ, &ws);
    st->nodes = ws.nodes;
    st->boxes_culled = ws.boxes_culled + ws.boxes_hidden;
    st->edges = S->nedges;
    scan(S);
    flush_spans(S);
}
