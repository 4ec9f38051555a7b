/* columns.c - render mode "columns" (see columns.h): the world down screen
 * columns, floors and ceilings from visplanes. */
#include "columns.h"

#include "anim.h"
#include "bsp_walk.h"
#include "clip.h"
#include "cover.h"
#include "direct.h"
#include "eye.h"
#include "obj_draw.h"
#include "obj_list.h"
#include "surfaces.h"

#define BACKGROUND_COLOUR 0
#define NO_ROW 0xFFu /* a visplane column with no rows */

/* A sector's floor or ceiling rows, one run per column (Doom's visplane); or
 * a wall's rows where it is drawn in a flat colour, which row spans fill a
 * dword at a time. */
typedef struct {
    uint32_t id;            /* the surface: RAST_ID of the floor, ceiling or wall side */
    uint8_t colour;         /* a wall's flat colour */
    int16_t minx, maxx;     /* the columns used lie in [minx, maxx]; none while minx > maxx */
    uint8_t top[VIEW_W];    /* first row of each column of [minx, maxx], NO_ROW if none */
    uint8_t bottom[VIEW_W]; /* one past its last */
} cols_plane;

enum { ROW_CEIL, ROW_FLOOR, ROW_LOW, ROW_HIGH, ROW_LINES };

/* The pixels objects may show in, which mode direct draws after the walk: the
 * pixels of an object's faces still open when the walk reaches the first leaf
 * its box touches. The walls drawn before are in front of it (the tree's order,
 * as in mode direct); what is left open there is the objects' and direct's, with
 * whatever of the world comes in front of them. */
typedef struct {
    cov_mask mask;               /* set: left to direct */
    uint32_t col_any[COV_WORDS]; /* the columns it has set in, a bit each */
    uint8_t any;
} cols_region;


typedef struct {
    const scene *sc;
    const view_xform *v;
    const rast_target *t;
    render_stats *st;
    const fx_t *ceil; /* the ceilings now (doors), or NULL */
    int textured;
    occ_columns occ;                            /* columns with no row open */
    uint8_t open_top[VIEW_W], open_bot[VIEW_W]; /* rows [top, bot) of each column still open */
    uint8_t rows[ROW_LINES][VIEW_W];            /* the seg in hand: where its lines cross each column */
    cols_region *region;                        /* what is left to the objects */
    const world_state *w;
    objl_entry *objs; /* the objects in view, by west edge (obj_list.h) */
    uint32_t nobjs;
    int32_t reach;
    uint32_t *claimed; /* a bit per object of w: it claimed a pixel (the rest are hidden) */
    int claimed_any;   /* the object in hand claimed a pixel */
    int whole_rows;    /* an object claimed whole rows, not its faces */
    uint32_t nplanes;
    cols_plane planes[CFG_COLS_PLANES];
} cols_state;

static uint32_t align8(uint64_t n)
{
    return (uint32_t)((n + 7u) & ~(uint64_t)7u);
}

/* The objects that claimed pixels: a bit per object of w. */
static uint32_t claimed_bytes(const world_state *w)
{
    return align8(((uint64_t)objl_capacity(w) + 31u) / 32u * 4u);
}

/* The work memory: the objects' region and which objects claimed pixels, then
 * this mode's state and its list of objects, or direct's. */
uint32_t cols_work_bytes(const scene *s, const world_state *w)
{
    uint64_t direct = direct_work_bytes_within(s, w), own = align8(sizeof(cols_state));
    if (direct == 0 || direct_work_bytes(s, w) == 0) return 0;
    own += align8((uint64_t)objl_capacity(w) * sizeof(objl_entry));
    uint64_t total = align8(sizeof(cols_region)) + claimed_bytes(w) + (direct > own ? direct : own);
    return total > 0xFFFFFFF0u ? 0 : (uint32_t)total;
}

/* ---- rows of a wall's lines in each column ------------------------------------------- */

static inline int64_t floor_div(int64_t a, int64_t b)
{
    int64_t q = a / b;
    return (a % b < 0) ? q - 1 : q;
}

static inline int clamp_row(int64_t r)
{
    return r < 0 ? 0 : (r > VIEW_H ? VIEW_H : (int)r);
}

/* rows[c]: the first row whose centre lies at or below the screen edge a -> b
 * (a.x < b.x), at the centre of each column c of [c0, c1) that the edge spans:
 * the edge's y there by an exact DDA (floor, 16.16), sampled as the fill rule
 * samples rows. Screen points are inside [0, 320] x [0, 200] (clip.h), so the
 * products stay below 2^50. */
static void edge_rows(screen_pt a, screen_pt b, int c0, int c1, uint8_t *rows)
{
    int c = rast_first_sample(a.x), end = rast_first_sample(b.x);
    if (c < c0) c = c0;
    if (end > c1) end = c1;
    if (c >= end) return;
    int64_t dx = (int64_t)b.x - a.x, dy = (int64_t)b.y - a.y;
    int64_t num = (((int64_t)c << 16) + 32768 - a.x) * dy;
    int32_t y, step;
    uint32_t rem, srem; /* in [0, dx) */
#if FX_DIV32
    if (dx > 65536) { /* wider than a column: |step| < |dy| < 2^25, and the first y lies on the edge */
        y = a.y + fx_floordiv64_32(num, (uint32_t)dx, &rem);
        step = fx_floordiv64_32(dy * 65536, (uint32_t)dx, &srem);
    } else
#endif
    {
        int64_t q = floor_div(num, dx), s = floor_div(dy * 65536, dx);
        y = (int32_t)(a.y + q);
        rem = (uint32_t)(num - q * dx);
        step = (int32_t)s; /* over at most one column, whatever it is, it is not used again */
        srem = (uint32_t)(dy * 65536 - s * dx);
    }
    for (; c < end; c++) {
        rows[c] = (uint8_t)clamp_row(fx_asr64((int64_t)y + 32767, 16));
        y = (int32_t)((uint32_t)y + (uint32_t)step);
        rem += srem;
        if (rem >= (uint32_t)dx) {
            rem -= (uint32_t)dx;
            y++;
        }
    }
}

/* Where the wall quad from height hb to ht over view points pa, pb meets each
 * column of [c0, c1): top[c] its first row, bot[c] one past its last (clipped
 * and projected as every mode clips it, its upper chain walked into top and its
 * lower chain into bot; either may be NULL: not needed). A column the clipped
 * quad misses lies wholly above the screen (a quad above the eye) or below it. */
static void quad_rows(cols_state *S, view_pt pa, view_pt pb, int32_t hb, int32_t ht, unsigned mask, int c0, int c1,
                      uint8_t *top, uint8_t *bot)
{
    const view_xform *v = S->v;
    uint8_t miss = (uint8_t)(hb >= v->cz ? 0 : (ht <= v->cz ? VIEW_H : clamp_row(VIEW_CY + VIEW_LOOK(v))));
    for (int c = c0; c < c1; c++) {
        if (top) top[c] = miss;
        if (bot) bot[c] = miss;
    }
    if (ht <= hb) return;
    clip_poly p;
    surf_wall_quad(v, pa, pb, hb, ht, &p);
    if (!clip_polygon(&p, v, mask)) return;
    S->st->polygons++;
    screen_pt s[CLIP_MAX_VERTS];
    clip_project(v, &p, s);
    for (int i = 0; i < p.n; i++) { /* clockwise on screen: rightwards along the top, leftwards along the bottom */
        screen_pt a = s[i], b = s[i + 1 == p.n ? 0 : i + 1];
        if (a.x < b.x && top)
            edge_rows(a, b, c0, c1, top);
        else if (a.x > b.x && bot)
            edge_rows(b, a, c0, c1, bot);
    }
}

/* ---- drawing ----------------------------------------------------------------------- */

/* Rows [y0, y1) of column x in a paint, counted as the byte writes they are. */
static void put_column(const cols_state *S, int x, int y0, int y1, const tex_paint *paint, uint32_t id)
{
    if (y0 >= y1) return;
    const rast_target *t = S->t;
    int textured = rast_textured_paint(t, paint);
    uint32_t n = (uint32_t)(y1 - y0);
    if (t->tally) {
        uint8_t *dst = t->surf->pixels + (uint32_t)y0 * HAL_WIDTH + (uint32_t)x;
#if CFG_TEXTURES
        if (textured)
            tex_column(paint, x, y0, y1, dst, HAL_WIDTH);
        else
#endif
            for (uint32_t k = 0; k < n; k++) dst[k * HAL_WIDTH] = paint->colour;
        t->tally->w[0] += n;
        t->tally->pixels += n;
    } else {
        uint8_t col[VIEW_H];
#if CFG_TEXTURES
        if (textured)
            tex_column(paint, x, y0, y1, col, 1);
        else
#endif
            for (uint32_t k = 0; k < n; k++) col[k] = paint->colour;
        for (uint32_t k = 0; k < n; k++) hal_fill_span(t->surf, y0 + (int)k, x, 1, col[k]);
    }
    (void)textured;
    if (t->ids)
        for (int y = y0; y < y1; y++) t->ids[y * VIEW_W + x] = id;
}

/* put_column, leaving out the pixels left to the objects. */
static void draw_column(const cols_state *S, int x, int y0, int y1, const tex_paint *paint, uint32_t id)
{
    const cols_region *r = S->region;
    uint32_t bit = 1u << (x & 31);
    int w = x >> 5;
    if (!(r->col_any[w] & bit)) {
        put_column(S, x, y0, y1, paint, id);
        return;
    }
    for (int y = y0; y < y1;) {
        int end = y;
        while (end < y1 && !(r->mask.bits[end][w] & bit)) end++;
        put_column(S, x, y, end, paint, id);
        while (end < y1 && (r->mask.bits[end][w] & bit)) end++;
        y = end;
    }
}

static tex_paint plane_paint(const cols_state *S, const cols_plane *p)
{
    if (p->id >> 24 == RAST_KIND_WALL) return tex_flat(p->colour);
    uint32_t sector = p->id & 0xFFFFFFu;
    int ceiling = p->id >> 24 == RAST_KIND_CEILING;
    const scn_sector *sec = &S->sc->sectors[sector];
    uint8_t colour = ceiling ? sec->ceil_color : sec->floor_color;
#if CFG_TEXTURES
    if (S->textured) {
        if (ceiling && CFG_SKY && (sec->flags & SCN_SECTOR_SKY)) return tex_sky(S->sc, S->v, colour);
        const scn_plane *pl = &S->sc->planes[sector];
        int32_t h = ceiling ? surf_ceil_now(S->sc, S->ceil, sector) : sec->floor_h;
        uint32_t tex = anim_tex(S->sc, anim_tic(S->w), ceiling ? pl->ceil_tex : pl->floor_tex);
        return tex_plane(S->sc, S->v, tex, h, sec->light, colour);
    }
#endif
    return tex_flat(colour);
}

/* A row span of a floor or ceiling, leaving out the pixels objects may cover. */
static inline void plane_span(cols_state *S, int y, int x0, int x1, const tex_paint *paint, uint32_t id)
{
    const cols_region *r = S->region;
    uint32_t any = 0;
    if (r->any)
        for (int i = x0 >> 5; i <= (x1 - 1) >> 5; i++) any |= r->mask.bits[y][i];
    if (!any) {
        rast_span(S->t, y, x0, x1, paint, id);
        return;
    }
    const cov_mask *m = &r->mask;
    for (int x = cov_next_clear(m, y, x0, x1); x < x1;) {
        int end = cov_next_set(m, y, x, x1);
        rast_span(S->t, y, x, end, paint, id);
        x = cov_next_clear(m, y, end, x1);
    }
}

/* A visplane's column runs as row spans (Doom's R_MakeSpans): a row's span
 * starts where the row enters the columns' runs and ends where it leaves. */
static void draw_plane(cols_state *S, const cols_plane *p)
{
    if (p->minx > p->maxx) return;
    tex_paint paint = plane_paint(S, p);
    uint32_t id = p->id;
    int16_t start[VIEW_H];
    int t1 = 0, b1 = 0; /* the previous column's rows [t1, b1) */
    for (int x = p->minx; x <= p->maxx + 1; x++) {
        int t2 = 0, b2 = 0;
        if (x <= p->maxx && p->top[x] != NO_ROW) {
            t2 = p->top[x];
            b2 = p->bottom[x];
        }
        for (int y = t1; y < b1 && y < t2; y++) plane_span(S, y, start[y], x, &paint, id);
        for (int y = b2 > t1 ? b2 : t1; y < b1; y++) plane_span(S, y, start[y], x, &paint, id);
        for (int y = t2; y < b2 && y < t1; y++) start[y] = (int16_t)x;
        for (int y = b1 > t2 ? b1 : t2; y < b2; y++) start[y] = (int16_t)x;
        t1 = t2;
        b1 = b2;
    }
}

/* Every visplane drawn, the pool emptied. */
static void flush_planes(cols_state *S)
{
    for (uint32_t i = 0; i < S->nplanes; i++) draw_plane(S, &S->planes[i]);
    S->nplanes = 0;
}

/* The newest visplane of a surface (and colour) if none of columns [c0, c1) is
 * used in it yet, else a new one (Doom's R_CheckPlane). The caller has made
 * room for it. */
static cols_plane *plane_for(cols_state *S, uint32_t id, uint8_t colour, int c0, int c1)
{
    for (uint32_t i = S->nplanes; i-- > 0;) {
        cols_plane *p = &S->planes[i];
        if (p->id != id || p->colour != colour) continue;
        int lo = c0 > p->minx ? c0 : p->minx, hi = c1 - 1 < p->maxx ? c1 - 1 : p->maxx;
        int x = lo;
        while (x <= hi && p->top[x] == NO_ROW) x++;
        if (x > hi) return p;
        break;
    }
    cols_plane *p = &S->planes[S->nplanes++];
    p->id = id;
    p->colour = colour;
    p->minx = VIEW_W;
    p->maxx = -1;
    return p;
}

/* Column x of a visplane gets rows [y0, y1). Only columns in [minx, maxx] are
 * ever read, so those the range takes in on the way are marked empty then. */
static inline void plane_rows(cols_plane *p, int x, int y0, int y1)
{
    if (p->minx > p->maxx) {
        p->minx = p->maxx = (int16_t)x;
    } else if (x > p->maxx) {
        for (int i = p->maxx + 1; i < x; i++) p->top[i] = NO_ROW;
        p->maxx = (int16_t)x;
    } else if (x < p->minx) {
        for (int i = x + 1; i < p->minx; i++) p->top[i] = NO_ROW;
        p->minx = (int16_t)x;
    }
    p->top[x] = (uint8_t)y0;
    p->bottom[x] = (uint8_t)y1;
}

/* ---- a seg ------------------------------------------------------------------------- */

typedef struct {
    uint32_t sector;     /* the front sector */
    int two_sided;       /* 0: the wall fills the column between floor and ceiling */
    int upper, lower;    /* two-sided: an upper wall (or sky step), a lower wall */
    int sky_step;        /* the upper part is more sky (Doom's sky rule) */
    tex_paint paint[3];  /* SCN_PART_* */
    uint8_t as_plane[3]; /* the part is a flat colour: row spans fill it (a visplane) */
    cols_plane *wall_plane[3];
    uint32_t id;
    cols_plane *ceil_plane, *floor_plane;
} seg_look;

/* Rows [y0, y1) of column c of a wall part: down the column, or into its visplane. */
static inline void wall_rows(cols_state *S, seg_look *k, int part, int c, int c0, int c1, int y0, int y1)
{
    if (y0 >= y1) return;
    if (!k->as_plane[part]) {
        draw_column(S, c, y0, y1, &k->paint[part], k->id);
        return;
    }
    if (!k->wall_plane[part]) k->wall_plane[part] = plane_for(S, k->id, k->paint[part].colour, c0, c1);
    plane_rows(k->wall_plane[part], c, y0, y1);
}

static inline int clamp_in(int r, int lo, int hi)
{
    return r < lo ? lo : (r > hi ? hi : r);
}

/* Split the open rows of columns [c0, c1) by the seg's lines, draw its walls,
 * give the floor and ceiling rows to the front sector's visplanes, and leave
 * open only the opening. */
static void seg_columns(cols_state *S, seg_look *k, int c0, int c1)
{
    int closed_from = -1;
    for (int c = c0; c <= c1; c++) {
        int closed = c < c1 && S->open_top[c] >= S->open_bot[c];
        if (c < c1 && !closed) {
            int t = S->open_top[c], b = S->open_bot[c];
            int fc = clamp_in(S->rows[ROW_CEIL][c], t, b), ff = clamp_in(S->rows[ROW_FLOOR][c], fc, b);
            int low = k->upper ? clamp_in(S->rows[ROW_LOW][c], fc, ff) : fc;
            int high = k->lower ? clamp_in(S->rows[ROW_HIGH][c], low, ff) : ff;
            if (!k->two_sided) low = high = ff;
            int ceil_end = k->sky_step ? low : fc;
            if (ceil_end > t) {
                if (!k->ceil_plane) k->ceil_plane = plane_for(S, RAST_ID(RAST_KIND_CEILING, k->sector), 0, c0, c1);
                plane_rows(k->ceil_plane, c, t, ceil_end);
            }
            if (ff < b) {
                if (!k->floor_plane) k->floor_plane = plane_for(S, RAST_ID(RAST_KIND_FLOOR, k->sector), 0, c0, c1);
                plane_rows(k->floor_plane, c, ff, b);
            }
            if (!k->two_sided) {
                wall_rows(S, k, SCN_PART_MIDDLE, c, c0, c1, fc, ff);
            } else {
                if (!k->sky_step) wall_rows(S, k, SCN_PART_UPPER, c, c0, c1, fc, low);
                wall_rows(S, k, SCN_PART_LOWER, c, c0, c1, high, ff);
            }
            S->open_top[c] = (uint8_t)low;
            S->open_bot[c] = (uint8_t)high;
            closed = low >= high;
        }
        if (closed && closed_from < 0) closed_from = c;
        if (!closed && closed_from >= 0) {
            occ_close(&S->occ, closed_from, c);
            closed_from = -1;
        }
    }
}

static tex_paint part(const cols_state *S, const scn_seg *g, int part, int32_t ff, int32_t fc, int32_t bf, int32_t bc,
                      uint8_t light, uint8_t colour)
{
    return S->textured ? surf_part_paint(S->sc, S->v, g, part, ff, fc, bf, bc, light, colour, anim_tic(S->w))
                       : tex_flat(colour);
}

static void seg(cols_state *S, uint32_t gi, unsigned mask)
{
    const scene *sc = S->sc;
    const view_xform *v = S->v;
    const scn_seg *g = &sc->segs[gi];
    const scn_vertex *a = &sc->verts[g->v1], *b = &sc->verts[g->v2];
    S->st->segs++;
    if (!surf_faces_eye(v, a, b)) {
        S->st->culled++;
        return;
    }
    view_pt pa = view_point(v, a->x, a->y, 0), pb = view_point(v, b->x, b->y, 0);
    int32_t xa, xb;
    if (!clip_wall_x(v, pa, pb, mask, &xa, &xb)) {
        S->st->clipped_away++;
        return;
    }
    int c0 = rast_first_sample(xa), c1 = rast_first_sample(xb);
    c0 = c0 < 0 ? 0 : c0;
    c1 = c1 > VIEW_W ? VIEW_W : c1;
    if (c0 >= c1 || occ_hidden(&S->occ, c0, c1)) {
        S->st->occluded++;
        return;
    }
    const scn_line *l = &sc->lines[g->line];
    uint32_t fi = l->sector[g->side], bi = l->sector[g->side ^ 1u];
    const scn_sector *front = &sc->sectors[fi];
    int32_t ff = front->floor_h, fc = surf_ceil_now(sc, S->ceil, fi), bf = ff, bc = fc;
    const uint8_t *colour = l->color[g->side];
    seg_look k = {0};
    k.sector = fi;
    k.id = RAST_ID(RAST_KIND_WALL, g->line * 2u + g->side);
    quad_rows(S, pa, pb, ff, fc, mask, c0, c1, S->rows[ROW_CEIL], S->rows[ROW_FLOOR]);
    if (CFG_TWO_SIDED && bi != SCN_NONE) {
        const scn_sector *back = &sc->sectors[bi];
        k.two_sided = 1;
        bf = back->floor_h;
        bc = surf_ceil_now(sc, S->ceil, bi);
        if (CFG_HEIGHTS && bc < fc) {
            k.upper = 1;
            k.sky_step = CFG_SKY && (front->flags & back->flags & SCN_SECTOR_SKY);
            int32_t low = bc > ff ? bc : ff;
            quad_rows(S, pa, pb, low, fc, mask, c0, c1, 0, S->rows[ROW_LOW]);
            k.paint[SCN_PART_UPPER] = part(S, g, SCN_PART_UPPER, ff, fc, bf, bc, front->light, colour[SCN_PART_UPPER]);
        }
        if (CFG_HEIGHTS && bf > ff) {
            k.lower = 1;
            int32_t high = bf < fc ? bf : fc;
            quad_rows(S, pa, pb, ff, high, mask, c0, c1, S->rows[ROW_HIGH], 0);
            k.paint[SCN_PART_LOWER] = part(S, g, SCN_PART_LOWER, ff, fc, bf, bc, front->light, colour[SCN_PART_LOWER]);
        }
    } else {
        k.paint[SCN_PART_MIDDLE] = part(S, g, SCN_PART_MIDDLE, ff, fc, bf, bc, front->light, colour[SCN_PART_MIDDLE]);
    }
    for (int i = 0; i < 3; i++) k.as_plane[i] = !rast_textured_paint(S->t, &k.paint[i]);
    if (S->nplanes + 4 > CFG_COLS_PLANES) { /* room for this seg's floor, ceiling and two flat walls */
        flush_planes(S);
        S->st->flushes++;
    }
    seg_columns(S, &k, c0, c1);
}

/* One row of an object's face: the pixels of it still open are left to the objects. */
static void claim_row(void *ctx, int y, int x0, int x1)
{
    cols_state *S = ctx;
    cols_region *r = S->region;
    for (int x = x0; x < x1; x++) {
        if (y < S->open_top[x] || y >= S->open_bot[x]) continue;
        uint32_t bit = 1u << (x & 31);
        r->mask.bits[y][x >> 5] |= bit;
        r->col_any[x >> 5] |= bit;
        r->any = 1;
        S->claimed_any = 1;
    }
}

/* Is a pixel of [x0, x1) x [y0, y1) still open? */
static int box_open(const cols_state *S, int x0, int x1, int y0, int y1)
{
    x0 = x0 < 0 ? 0 : x0;
    x1 = x1 > VIEW_W ? VIEW_W : x1;
    for (int x = x0; x < x1; x++)
        if ((y0 > S->open_top[x] ? y0 : S->open_top[x]) < (y1 < S->open_bot[x] ? y1 : S->open_bot[x])) return 1;
    return 0;
}

/* An object the walk takes in (obj_list.h: at the first leaf its box touches)
 * claims the pixels of its faces whose rows are still open: mode direct draws
 * them after the walk, the object or whatever of the world is in front of it.
 * Nothing behind it shows there, so direct's walk ends at the object. An object
 * whose box reaches past the coordinate box claims every open row instead. */
static void take_object(void *ctx, uint32_t i)
{
    cols_state *S = ctx;
    int x0, x1, y0, y1;
    uint32_t obj = S->objs[i].index;
    int got = objd_screen_box(S->sc, &S->w->objs[obj], S->v, &x0, &x1, &y0, &y1);
    if (got < 0 || (got > 0 && !box_open(S, x0, x1, y0, y1))) return;
    S->claimed_any = 0;
    if (got > 0) {
        direct_object_rows(S->sc, S->w, S->v, obj, claim_row, S);
    } else {
        for (int y = 0; y < VIEW_H; y++) claim_row(S, y, 0, VIEW_W);
        S->whole_rows = 1;
    }
    if (S->claimed_any) S->claimed[obj >> 5] |= 1u << (obj & 31);
}

static int visit_leaf(void *ctx, uint32_t leaf, unsigned clip_mask)
{
    cols_state *S = ctx;
    const scn_leaf *f = &S->sc->leaves[leaf];
    S->st->leaves++;
    if (S->nobjs) objl_take_in_leaf(S->sc, S->w, leaf, S->objs, S->nobjs, sizeof(objl_entry), S->reach, take_object, S);
    for (uint32_t i = 0; i < f->num_segs && !occ_full(&S->occ); i++) seg(S, f->first_seg + i, clip_mask);
    return occ_full(&S->occ);
}

/* ---- the frame ---------------------------------------------------------------------- */

static void region_clear(cols_region *r)
{
    for (int y = 0; y < VIEW_H; y++)
        for (int i = 0; i < COV_WORDS; i++) r->mask.bits[y][i] = 0;
    for (int i = 0; i < COV_WORDS; i++) r->col_any[i] = 0;
    r->any = 0;
}

void cols_render(const scene *sc, const world_state *w, const view_xform *v, const rast_target *t, render_stats *st,
                 void *work, uint32_t work_bytes)
{
    uint32_t need = cols_work_bytes(sc, w);
    if (!work || need == 0 || work_bytes < need || !eye_in_world(sc, w, v)) {
        /* an eye outside the world may see a wall from behind, and columns do not close */
        st->fallback = work && need && work_bytes >= need;
        direct_render(sc, w, v, t, st, work, work_bytes);
        return;
    }
    uint8_t *mem = work;
    cols_region *region = work;
    mem += align8(sizeof(cols_region));
    uint32_t *claimed = (uint32_t *)(void *)mem, nclaimed = claimed_bytes(w);
    for (uint32_t i = 0; i < nclaimed / 4u; i++) claimed[i] = 0;
    mem += nclaimed;
    cols_state *S = (cols_state *)(void *)mem;
    S->sc = sc;
    S->w = w;
    S->v = v;
    S->t = t;
    S->st = st;
    S->ceil = w ? w->ceil : 0;
    S->textured = CFG_TEXTURES && sc->look && !t->flat;
    S->region = region;
    S->claimed = claimed;
    S->whole_rows = 0;
    region_clear(region);
    S->objs = (objl_entry *)(void *)(mem + align8(sizeof(cols_state)));
    S->nobjs = objl_in_view(sc, w, v, S->objs, sizeof(objl_entry), &S->reach);
    S->nplanes = 0;
    occ_reset(&S->occ);
    for (int c = 0; c < VIEW_W; c++) {
        S->open_top[c] = 0;
        S->open_bot[c] = VIEW_H;
    }
    walk_stats ws;
    walk_tree(sc, v, WALK_FRONT_TO_BACK, visit_leaf, S, &S->occ, &ws);
    flush_planes(S);
    tex_paint background = tex_flat(BACKGROUND_COLOUR);
    for (int c = 0; c < VIEW_W; c++) /* what no wall's column reached: the background */
        draw_column(S, c, S->open_top[c], S->open_bot[c], &background, RAST_ID(RAST_KIND_NONE, 0));
    uint32_t nodes = ws.nodes, culled = ws.boxes_culled + ws.boxes_hidden;
    if (region->any) /* the objects, and the world in front of them, exactly, by mode direct */
        direct_render_within(sc, w, v, t, st, mem, work_bytes - (uint32_t)(mem - (uint8_t *)work), &region->mask,
                             S->whole_rows ? 0 : claimed);
    st->nodes += nodes;
    st->boxes_culled += culled;
}
