/* surfaces.c - leaf floors, ceilings and wall parts to screen polygons.
 * Shared 3-D edges give bit-identical screen edges: a wall's bottom edge and the
 * floor polygon's edge along it are transformed from the same map points and
 * clipped with the same canonical intersections (clip.c), so the fill rule
 * leaves neither gap nor overlap between them. */
#include "surfaces.h"

#include "anim.h"
#include "clip.h"
#include "eye.h"
#include "raster.h"
#include "wide128.h"

/* The polygon's vertices projected as they are, if every one is in front of the
 * near plane (0 if not). Unclipped, the polygon's screen image lies within
 * their box; and where clipping then cuts nothing, these are the very points
 * clip_project would give. */
static int project_unclipped(const view_xform *v, const clip_poly *p, screen_pt *s)
{
    for (int i = 0; i < p->n; i++)
        if (p->v[i].z < VIEW_ZNEAR) return 0;
    for (int i = 0; i < p->n; i++) s[i] = view_project(v, p->v[i]);
    return 1;
}

/* How a polygon is painted, kept as the few values that say it: the paint
 * itself (tex_wall's and tex_plane's set-up) is worked out only for a polygon
 * that survives the hidden test and clipping. */
enum { LOOK_FLAT, LOOK_PART, LOOK_PLANE, LOOK_SKY };

typedef struct {
    uint8_t kind;           /* LOOK_* */
    uint8_t part;           /* LOOK_PART: SCN_PART_* */
    uint8_t colour;         /* the flat colour */
    uint8_t light;          /* the sector's light level */
    const scn_seg *g;       /* LOOK_PART */
    int32_t ff, fc, bf, bc; /* LOOK_PART: front floor and ceiling, back floor and ceiling, now */
    uint32_t tex;           /* LOOK_PLANE: the flat shown now (anim_tex) */
    int32_t h;              /* LOOK_PLANE: its height */
    uint32_t tic;           /* LOOK_PART: the level time (anim.h) */
} surf_look;

tex_paint surf_part_paint(const scene *sc, const view_xform *v, const scn_seg *g, int part, int32_t ff, int32_t fc,
                          int32_t bf, int32_t bc, uint8_t light, uint8_t colour, uint32_t tic)
{
#if CFG_TEXTURES
    const scn_side *sd = &sc->sides[g->line * 2u + g->side];
    uint32_t tex = sd->tex[part]; /* pegged by the side's own texture, as Doom does, drawn with the frame shown */
    int32_t top;
    if (part == SCN_PART_MIDDLE)
        top = (sd->flags & SCN_SIDE_UNPEG_BOTTOM) ? ff + tex_height(sc, tex) : fc;
    else if (part == SCN_PART_UPPER)
        top = (sd->flags & SCN_SIDE_UNPEG_TOP) ? fc : bc + tex_height(sc, tex);
    else
        top = (sd->flags & SCN_SIDE_UNPEG_BOTTOM) ? fc : bf;
    tex_paint p = tex_wall(sc, v, sd, anim_tex(sc, tic, tex), &sc->verts[g->v1], top, light, colour);
    if (p.kind == TEX_WALL) p.u0 += anim_scroll(sd, tic);
    return p;
#else
    (void)sc, (void)v, (void)g, (void)part, (void)ff, (void)fc, (void)bf, (void)bc, (void)light, (void)tic;
    return tex_flat(colour);
#endif
}

static tex_paint part_paint(const scene *sc, const view_xform *v, const surf_look *k)
{
    return surf_part_paint(sc, v, k->g, k->part, k->ff, k->fc, k->bf, k->bc, k->light, k->colour, k->tic);
}

static tex_paint paint_of(const scene *sc, const view_xform *v, const surf_sink *sink, const surf_look *k)
{
#if CFG_TEXTURES
    if (sc->look && !sink->flat) {
        if (k->kind == LOOK_PART) return part_paint(sc, v, k);
        if (k->kind == LOOK_PLANE) return tex_plane(sc, v, k->tex, k->h, k->light, k->colour);
        if (k->kind == LOOK_SKY) return tex_sky(sc, v, k->colour);
    }
#else
    (void)sc, (void)v, (void)sink;
#endif
    return tex_flat(k->colour);
}

static void emit(const scene *sc, const view_xform *v, clip_poly *p, unsigned mask, const surf_sink *sink,
                 const surf_look *look, uint32_t id, uint32_t seg, render_stats *st)
{
    screen_pt s[CLIP_MAX_VERTS];
    int projected = sink->hidden && p->n <= CLIP_MAX_VERTS - 5 && project_unclipped(v, p, s);
    if (projected && sink->hidden(sink->ctx, s, p->n)) {
        st->occluded++;
        return;
    }
    if (!clip_polygon(p, v, mask)) {
        st->clipped_away++;
        return;
    }
    if (!(p->cut & (CLIP_TOP | CLIP_BOTTOM))) st->yclip_skipped++;
    if (!projected || p->cut) clip_project(v, p, s);
    st->polygons++;
    int32_t zmin = p->v[0].z, zmax = p->v[0].z;
    for (int i = 1; i < p->n; i++) {
        if (p->v[i].z < zmin) zmin = p->v[i].z;
        if (p->v[i].z > zmax) zmax = p->v[i].z;
    }
    tex_paint paint = paint_of(sc, v, sink, look);
    sink->polygon(sink->ctx, s, p->n, &paint, id, seg, zmin, zmax);
}

int surf_faces_eye(const view_xform *v, const scn_vertex *a, const scn_vertex *b)
{
    return w128_sign_diff((int64_t)b->x - a->x, v->cy - a->y, (int64_t)b->y - a->y, v->cx - a->x) < 0;
}

void surf_wall_quad(const view_xform *v, view_pt a, view_pt b, int32_t bottom, int32_t top, clip_poly *p)
{
    p->n = 4;
    p->v[0] = view_at_height(v, a, top);
    p->v[1] = view_at_height(v, b, top);
    p->v[2] = view_at_height(v, b, bottom);
    p->v[3] = view_at_height(v, a, bottom);
}

/* The wall between view points a and b (rotated once per seg) from height
 * bottom to top. */
static void wall_part(const scene *sc, const view_xform *v, view_pt a, view_pt b, int32_t bottom, int32_t top,
                      unsigned mask, const surf_sink *sink, const surf_look *look, uint32_t id, uint32_t seg,
                      render_stats *st)
{
    if (top <= bottom) return;
    clip_poly p;
    surf_wall_quad(v, a, b, bottom, top, &p);
    emit(sc, v, &p, mask, sink, look, id, seg, st);
}

/* A wall with no opening hides everything behind it in the columns it covers,
 * whose other rows the floors, ceilings and walls in front of it fill. Those are
 * exactly the columns the fill rule gives its vertical edges (clip_wall_x), so
 * walls that meet at a vertex close neighbouring columns with no gap between. An
 * eye on or next to the wall's line closes nothing. */
static void close_columns(const view_xform *v, const scn_vertex *a, const scn_vertex *b, view_pt pa, view_pt pb,
                          unsigned mask, occ_columns *occ)
{
    int32_t xa, xb;
    if (!eye_clearly_in_front(v, a, b)) return;
    if (!clip_wall_x(v, view_at_height(v, pa, 0), view_at_height(v, pb, 0), mask, &xa, &xb)) return;
    occ_close(occ, rast_first_sample(xa), rast_first_sample(xb));
}

static void seg_parts(const scene *sc, const fx_t *ceil, uint32_t tic, const view_xform *v, uint32_t gi, unsigned mask,
                      const surf_sink *sink, occ_columns *occ, render_stats *st)
{
    const scn_seg *g = &sc->segs[gi];
    const scn_vertex *a = &sc->verts[g->v1], *b = &sc->verts[g->v2];
    st->segs++;
    if (!surf_faces_eye(v, a, b)) {
        st->culled++;
        return;
    }
    view_pt pa = view_point(v, a->x, a->y, 0), pb = view_point(v, b->x, b->y, 0); /* once for every part */
    int c0 = 0, c1 = VIEW_W;
    if (occ) {
        if (!occ_seg_columns(pa, pb, &c0, &c1) || occ_hidden(occ, c0 > 0 ? c0 - 1 : 0, c1 < VIEW_W ? c1 + 1 : VIEW_W)) {
            st->occluded++;
            return;
        }
    }
    const scn_line *l = &sc->lines[g->line];
    uint32_t front_index = l->sector[g->side], back_index = l->sector[g->side ^ 1u];
    const scn_sector *front = &sc->sectors[front_index];
    int32_t front_ceil = surf_ceil_now(sc, ceil, front_index);
    uint32_t id = RAST_ID(RAST_KIND_WALL, g->line * 2u + g->side);
    const uint8_t *colour = l->color[g->side];
    surf_look k = {LOOK_PART,
                   SCN_PART_MIDDLE,
                   colour[SCN_PART_MIDDLE],
                   front->light,
                   g,
                   front->floor_h,
                   front_ceil,
                   front->floor_h,
                   front_ceil,
                   0,
                   0,
                   tic};
    if (!CFG_TWO_SIDED || back_index == SCN_NONE) {
        wall_part(sc, v, pa, pb, front->floor_h, front_ceil, mask, sink, &k, id, gi, st);
        if (occ) close_columns(v, a, b, pa, pb, mask, occ);
        return;
    }
    const scn_sector *back = &sc->sectors[back_index];
    int32_t back_ceil = surf_ceil_now(sc, ceil, back_index);
    k.bf = back->floor_h;
    k.bc = back_ceil;
    if (CFG_HEIGHTS && back_ceil < front_ceil) {
        int32_t low = back_ceil > front->floor_h ? back_ceil : front->floor_h;
        /* Doom's sky rule: between two sky ceilings there is no upper wall but more
         * sky. The step is drawn as the front sector's sky ceiling, so the view
         * through it has no hole. */
        if (CFG_SKY && (front->flags & back->flags & SCN_SECTOR_SKY)) {
            surf_look sky = {LOOK_SKY, 0, front->ceil_color, 0, g, 0, 0, 0, 0, 0, 0};
            wall_part(sc, v, pa, pb, low, front_ceil, mask, sink, &sky, RAST_ID(RAST_KIND_CEILING, front_index), gi,
                      st);
        } else {
            k.part = SCN_PART_UPPER;
            k.colour = colour[SCN_PART_UPPER];
            wall_part(sc, v, pa, pb, low, front_ceil, mask, sink, &k, id, gi, st);
        }
    }
    if (CFG_HEIGHTS && back->floor_h > front->floor_h) {
        int32_t high = back->floor_h < front_ceil ? back->floor_h : front_ceil;
        k.part = SCN_PART_LOWER;
        k.colour = colour[SCN_PART_LOWER];
        wall_part(sc, v, pa, pb, front->floor_h, high, mask, sink, &k, id, gi, st);
    }
    /* closed door: no opening between the two sectors */
    int32_t top = back_ceil < front_ceil ? back_ceil : front_ceil;
    int32_t bottom = back->floor_h > front->floor_h ? back->floor_h : front->floor_h;
    if (occ && top <= bottom) close_columns(v, a, b, pa, pb, mask, occ);
}

/* A floor's or ceiling's look: its flat as shown at level time tic, or the sky. */
static surf_look plane_look(const scene *sc, uint32_t sector, int ceiling, int32_t h, uint32_t tic)
{
    const scn_sector *sec = &sc->sectors[sector];
    surf_look k = {LOOK_PLANE, 0, ceiling ? sec->ceil_color : sec->floor_color, sec->light, 0, 0, 0, 0, 0, SCN_TEX_NONE,
                   h,          0};
    if (ceiling && CFG_SKY && (sec->flags & SCN_SECTOR_SKY))
        k.kind = LOOK_SKY;
    else if (CFG_TEXTURES && sc->look)
        k.tex = anim_tex(sc, tic, ceiling ? sc->planes[sector].ceil_tex : sc->planes[sector].floor_tex);
    return k;
}

/* The leaf polygon at height h. Seen from above (floor) a counter-clockwise map
 * polygon runs counter-clockwise on screen, so floors are emitted reversed;
 * seen from below (ceiling) it runs clockwise as stored. */
static void plane(const scene *sc, const view_xform *v, const view_pt *pts, uint32_t n, int32_t h, int reverse,
                  unsigned mask, const surf_sink *sink, const surf_look *look, uint32_t id, render_stats *st)
{
    clip_poly p;
    p.n = (int)n;
    for (uint32_t i = 0; i < n; i++) p.v[i] = view_at_height(v, pts[reverse ? n - 1 - i : i], h);
    emit(sc, v, &p, mask, sink, look, id, SCN_NONE, st);
}

void surf_leaf_planes(const scene *sc, const world_state *w, const view_xform *v, uint32_t leaf, unsigned mask,
                      const surf_sink *sink, render_stats *st, unsigned which)
{
    const scn_leaf *f = &sc->leaves[leaf];
    if (f->sector == SCN_NONE) return;
    const scn_sector *sec = &sc->sectors[f->sector];
    int32_t top = surf_ceil_now(sc, w ? w->ceil : 0, f->sector);
    /* edge-on or from behind: no plane work */
    int floor = (which & SURF_FLOOR) && v->cz > sec->floor_h, ceiling = (which & SURF_CEILING) && v->cz < top;
    st->planes_skipped += (uint32_t)!floor + (uint32_t)!ceiling;
    uint32_t n = f->num_pverts;
    if (n < 3 || n > CLIP_MAX_VERTS - 5) return; /* degenerate; the loader refuses more than the build's */
    view_pt pts[CLIP_MAX_VERTS];
    if (floor || ceiling) /* the leaf polygon rotated once for both */
        for (uint32_t i = 0; i < n; i++) {
            const scn_vertex *q = &sc->pverts[f->first_pvert + i];
            pts[i] = view_point(v, q->x, q->y, 0);
        }
    if (floor) {
        surf_look k = plane_look(sc, f->sector, 0, sec->floor_h, anim_tic(w));
        plane(sc, v, pts, n, sec->floor_h, 1, mask, sink, &k, RAST_ID(RAST_KIND_FLOOR, f->sector), st);
    }
    if (ceiling) {
        surf_look k = plane_look(sc, f->sector, 1, top, anim_tic(w));
        plane(sc, v, pts, n, top, 0, mask, sink, &k, RAST_ID(RAST_KIND_CEILING, f->sector), st);
    }
}

void surf_leaf_walls(const scene *sc, const world_state *w, const view_xform *v, uint32_t leaf, unsigned mask,
                     const surf_sink *sink, occ_columns *occ, render_stats *st)
{
    const scn_leaf *f = &sc->leaves[leaf];
    const fx_t *ceil = w ? w->ceil : 0;
    uint32_t tic = anim_tic(w);
    for (uint32_t i = 0; i < f->num_segs; i++) seg_parts(sc, ceil, tic, v, f->first_seg + i, mask, sink, occ, st);
}

void surf_leaf(const scene *sc, const world_state *w, const view_xform *v, uint32_t leaf, unsigned mask,
               const surf_sink *sink, occ_columns *occ, render_stats *st)
{
    st->leaves++;
    surf_leaf_planes(sc, w, v, leaf, mask, sink, st, SURF_FLOOR | SURF_CEILING);
    surf_leaf_walls(sc, w, v, leaf, mask, sink, occ, st);
}
