/* painter.c - render mode "painter": the Listing 62.1 pipeline. Walk the BSP tree
 * back to front with an explicit stack (data recursion), cull back-facing wall
 * pieces, build each visible part (one-sided: floor to ceiling; two-sided: the
 * upper and lower steps between the two sectors) as a view-space quad, clip it
 * to the frustum, project and fill it. Farther walls are overdrawn by nearer ones. */
#include "clip.h"
#include "render.h"

#define PAINTER_BACKGROUND 0

/* Front-facing: the eye strictly on the right of v1 -> v2 (edge-on is culled). */
static int seg_faces_eye(const view_xform *v, const scn_vertex *a, const scn_vertex *b)
{
    /* |b - a| < 2^32 and |eye - a| < 2^33 raw: shifted to 2^31 and 2^30 the
     * products stay below 2^61. */
    int64_t dx = fx_asr64((int64_t)b->x - a->x, 1), dy = fx_asr64((int64_t)b->y - a->y, 1);
    int64_t ex = fx_asr64(v->cx - a->x, 3), ey = fx_asr64(v->cy - a->y, 3);
    return dx * ey - dy * ex < 0;
}

/* One wall part between heights bottom..top (16.16) along a -> b. */
static void draw_part(const view_xform *v, const rast_target *t, const scn_vertex *a, const scn_vertex *b,
                      int32_t bottom, int32_t top, uint8_t colour, uint32_t id, render_stats *st)
{
    if (top <= bottom) return;
    clip_poly p;
    p.n = 4;
    p.v[0] = view_point(v, a->x, a->y, top);
    p.v[1] = view_point(v, b->x, b->y, top);
    p.v[2] = view_point(v, b->x, b->y, bottom);
    p.v[3] = view_point(v, a->x, a->y, bottom);
    if (!clip_polygon(&p, v, CLIP_ALL)) {
        st->clipped_away++;
        return;
    }
    screen_pt s[CLIP_MAX_VERTS];
    for (int i = 0; i < p.n; i++) s[i] = view_project(v, p.v[i]);
    st->polygons++;
    rast_convex(t, s, p.n, colour, id);
}

static void draw_seg(const scene *sc, const view_xform *v, const rast_target *t, const scn_seg *g, render_stats *st)
{
    const scn_vertex *a = &sc->verts[g->v1], *b = &sc->verts[g->v2];
    st->segs++;
    if (!seg_faces_eye(v, a, b)) {
        st->culled++;
        return;
    }
    const scn_line *l = &sc->lines[g->line];
    const scn_sector *front = &sc->sectors[l->sector[g->side]];
    uint32_t back_index = l->sector[g->side ^ 1u];
    uint32_t id = RAST_ID(RAST_KIND_WALL, g->line * 2u + g->side);
    const uint8_t *colour = l->color[g->side];
    if (back_index == SCN_NONE) {
        draw_part(v, t, a, b, front->floor_h, front->ceil_h, colour[SCN_PART_MIDDLE], id, st);
        return;
    }
    const scn_sector *back = &sc->sectors[back_index];
    int both_sky = (front->flags & back->flags & SCN_SECTOR_SKY) != 0;
    if (!both_sky && back->ceil_h < front->ceil_h) {
        int32_t low = back->ceil_h > front->floor_h ? back->ceil_h : front->floor_h;
        draw_part(v, t, a, b, low, front->ceil_h, colour[SCN_PART_UPPER], id, st);
    }
    if (back->floor_h > front->floor_h) {
        int32_t high = back->floor_h < front->ceil_h ? back->floor_h : front->ceil_h;
        draw_part(v, t, a, b, front->floor_h, high, colour[SCN_PART_LOWER], id, st);
    }
}

static void draw_leaf(const scene *sc, const view_xform *v, const rast_target *t, uint32_t leaf, render_stats *st)
{
    const scn_leaf *f = &sc->leaves[leaf];
    st->leaves++;
    for (uint32_t i = 0; i < f->num_segs; i++) draw_seg(sc, v, t, &sc->segs[f->first_seg + i], st);
}

void painter_render(const scene *sc, const view_xform *v, const rast_target *t, render_stats *st)
{
    /* A validated tree is at most SCN_MAX_DEPTH nodes deep, and this walk holds at
     * most one pending sibling per level plus the one being expanded. */
    uint32_t stack[SCN_MAX_DEPTH + 2];
    int sp = 0;
    render_clear(t, PAINTER_BACKGROUND);
    if (sc->nleaves == 0) return;
    stack[sp++] = sc->root;
    while (sp > 0) {
        uint32_t n = stack[--sp];
        if (n & SCN_LEAF_BIT) {
            draw_leaf(sc, v, t, n & ~SCN_LEAF_BIT, st);
            continue;
        }
        const scn_node *node = &sc->nodes[n];
        int near = scene_node_side(node, (int32_t)v->cx, (int32_t)v->cy);
        st->nodes++;
        if (sp + 2 > SCN_MAX_DEPTH + 2) break; /* unreachable for a validated scene */
        stack[sp++] = node->child[near];     /* drawn last */
        stack[sp++] = node->child[near ^ 1]; /* drawn first: the far side */
    }
}
