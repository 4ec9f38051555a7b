/* eye.c - whether the eye stands inside the world (see eye.h).
 *
 * Column occlusion rests on one fact: every ray from the eye meets a surface
 * before it can leave the world, so the floor and ceiling in front of a solid
 * wall fill its column above and below it. Two things break that fact next to
 * the world's boundary: a surface nearer than the near plane is clipped away
 * (the ray passes through it into the void), and a wall seen exactly edge-on is
 * culled. Both happen only within EYE_MARGIN of a wall, floor or ceiling, so the
 * eye counts as inside only with that much room around it; otherwise the frame
 * is drawn without occlusion, which is always right, only slower.
 *
 * The eye may stand exactly on a partition (a player start on a grid point
 * often does): the descent takes both sides of every partition the eye lies
 * within EYE_MARGIN of, so every leaf that holds the eye, and every leaf with a
 * wall near it, is reached. Sides are decided on offsets shifted right by 3 (as
 * scene_node_side does); the rounding of the shifted terms is bounded below,
 * and a point within that bound of a line counts as on it, which only ever
 * takes in one leaf more. */
#include "eye.h"

#include "bsp_walk.h" /* WALK_STACK_MAX */

/* Room the eye needs from the boundary, in 16.16 map units: twice the near
 * plane's distance plus one view-space step. Within the 90-degree field of
 * view a wall point nearer than the near plane lies within sqrt(2) of its
 * distance from the eye, and with the largest look a floor or ceiling point
 * within 1.25 of it. */
#define EYE_MARGIN (((int64_t)VIEW_ZNEAR + 1) << (17 - VIEW_SHIFT))
/* The same in the units of the cross products below (offsets shifted by 3). */
#define EYE_MARGIN_X (EYE_MARGIN >> 3)

static int64_t abs64(int64_t v)
{
    return v < 0 ? -v : v;
}

/* Side of the eye (x, y) relative to the line through (px, py) along (dx_raw,
 * dy_raw), within a band of `band` (EYE_MARGIN_X units) either side.
 * The direction is halved and the offset shifted by 3, so the products stay
 * below 2^61; the shifted terms lose under 1 each, so the product is off by less
 * than |dx| + |dy| + |ex| + |ey| + 2. A band of b units widens that bound by
 * b * (|dx| + |dy|), at least b times the direction's length. Returns 1 left of
 * the direction, -1 right of it, 0 within the bound. */
static int side_of(int64_t px, int64_t py, int64_t dx_raw, int64_t dy_raw, int64_t x, int64_t y, int64_t band)
{
    int64_t dx = fx_asr64(dx_raw, 1), dy = fx_asr64(dy_raw, 1);
    int64_t ex = fx_asr64(x - px, 3), ey = fx_asr64(y - py, 3);
    int64_t cross = dx * ey - dy * ex;
    int64_t slack = (abs64(dx) + abs64(dy)) * (band + 1) + abs64(ex) + abs64(ey) + 2;
    return cross > slack ? 1 : (cross < -slack ? -1 : 0);
}

/* 1 unless the eye is certainly farther than EYE_MARGIN from segment a -> b:
 * beyond its line's band, or beyond either end along it. */
static int near_segment(const scn_vertex *a, const scn_vertex *b, int64_t x, int64_t y)
{
    int64_t dxr = (int64_t)b->x - a->x, dyr = (int64_t)b->y - a->y;
    if (side_of(a->x, a->y, dxr, dyr, x, y, EYE_MARGIN_X) != 0) return 0;
    /* along the segment: the dot product with the direction, with the same
     * bounds; past a by the margin, or past b by it, is far */
    int64_t dx = fx_asr64(dxr, 1), dy = fx_asr64(dyr, 1);
    int64_t slack = (abs64(dx) + abs64(dy)) * (EYE_MARGIN_X + 1) + 2;
    int64_t ea = dx * fx_asr64(x - a->x, 3) + dy * fx_asr64(y - a->y, 3);
    int64_t eb = dx * fx_asr64(x - b->x, 3) + dy * fx_asr64(y - b->y, 3);
    return ea >= -(slack + abs64(fx_asr64(x - a->x, 3)) + abs64(fx_asr64(y - a->y, 3))) &&
           eb <= slack + abs64(fx_asr64(x - b->x, 3)) + abs64(fx_asr64(y - b->y, 3));
}

/* 1 if the eye's height has EYE_MARGIN of room above floor and below ceiling. */
static int between(int32_t floor_h, int32_t ceil_h, int64_t z)
{
    return z - floor_h > EYE_MARGIN && (int64_t)ceil_h - z > EYE_MARGIN;
}

int eye_clearly_in_front(const view_xform *v, const scn_vertex *a, const scn_vertex *b)
{
    int64_t dx = fx_asr64((int64_t)b->x - a->x, 1), dy = fx_asr64((int64_t)b->y - a->y, 1);
    int64_t ex = fx_asr64(v->cx - a->x, 3), ey = fx_asr64(v->cy - a->y, 3);
    int64_t len = abs64(dx) + abs64(dy) + 2;
    int64_t slack = len + abs64(ex) + abs64(ey) + EYE_WALL_MARGIN * len;
    return dy * ex - dx * ey > slack;
}

/* 1 if the eye is inside the leaf's floor polygon or on its boundary
 * (counter-clockwise: inside is left of every edge). */
static int holds(const scene *sc, const scn_leaf *f, int64_t x, int64_t y)
{
    for (uint32_t i = 0; i < f->num_pverts; i++) {
        const scn_vertex *a = &sc->pverts[f->first_pvert + i];
        const scn_vertex *b = &sc->pverts[f->first_pvert + (i + 1 == f->num_pverts ? 0 : i + 1)];
        if (side_of(a->x, a->y, (int64_t)b->x - a->x, (int64_t)b->y - a->y, x, y, 0) < 0) return 0;
    }
    return 1;
}

/* 1 if no wall of the leaf stands near the eye, except a line whose opening
 * has room around the eye's height (the eye may stand in a doorway). */
static int clear_of_walls(const scene *sc, const world_state *w, const scn_leaf *f, const view_xform *v)
{
    for (uint32_t i = 0; i < f->num_segs; i++) {
        const scn_seg *g = &sc->segs[f->first_seg + i];
        if (!near_segment(&sc->verts[g->v1], &sc->verts[g->v2], v->cx, v->cy)) continue;
        const scn_line *l = &sc->lines[g->line];
        uint32_t s0 = l->sector[0], s1 = l->sector[1];
        if (s0 == SCN_NONE || s1 == SCN_NONE) return 0;
        int32_t fl0 = sc->sectors[s0].floor_h, fl1 = sc->sectors[s1].floor_h;
        int32_t c0 = obj_ceil(w, sc, s0), c1 = obj_ceil(w, sc, s1);
        if (!between(fl0 > fl1 ? fl0 : fl1, c0 < c1 ? c0 : c1, v->cz)) return 0;
    }
    return 1;
}

int eye_in_world(const scene *sc, const world_state *w, const view_xform *v)
{
    uint32_t stack[WALK_STACK_MAX];
    int top = 0, found = 0;
    stack[top++] = sc->root;
    while (top > 0) {
        uint32_t n = stack[--top];
        if (n & SCN_LEAF_BIT) {
            const scn_leaf *f = &sc->leaves[n & ~SCN_LEAF_BIT];
            if (f->num_pverts >= 3 && holds(sc, f, v->cx, v->cy)) {
                if (f->sector == SCN_NONE) return 0;
                if (!between(sc->sectors[f->sector].floor_h, obj_ceil(w, sc, f->sector), v->cz)) return 0;
                found = 1;
            }
            if (!clear_of_walls(sc, w, f, v)) return 0;
            continue;
        }
        const scn_node *node = &sc->nodes[n];
        /* front is the right of the partition's direction: side -1; back: +1 */
        int side = side_of(node->x, node->y, node->dx, node->dy, v->cx, v->cy, EYE_MARGIN_X);
        if (side <= 0) stack[top++] = node->child[0];
        if (side >= 0) {
            if (top == WALK_STACK_MAX) return 0; /* cannot happen for a loaded scene: depth is checked */
            stack[top++] = node->child[1];
        }
    }
    return found;
}
