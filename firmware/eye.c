/* eye.c - whether the eye stands inside the world (see eye.h).
 *
 * The eye may stand exactly on a partition, a wall's line or a vertex (a player
 * start on a grid point often does). The descent therefore takes both sides of
 * every partition the eye lies on, and every leaf it reaches must hold the eye.
 * Sides are decided on offsets shifted right by 3 (as scene_node_side does);
 * the rounding of the shifted terms is bounded below, and a point within that
 * bound of a line counts as on it, which only ever takes in one leaf more. */
#include "eye.h"

#define EYE_STACK (CFG_MAX_DEPTH + 2)

static int64_t abs64(int64_t v) { return v < 0 ? -v : v; }

/* Cross product of (dx, dy) with the eye's offset from (px, py), both shifted
 * as the products need, and its rounding bound: the offset's shifted terms are
 * floored (error < 1 each) and the direction's shifted terms lose under 1 each,
 * so the product is off by less than |dx| + |dy| + |ex| + |ey| + 2. Returns 1
 * left of the direction, -1 right of it, 0 on it within the bound. */
static int side_of(int64_t px, int64_t py, int64_t dx_raw, int64_t dy_raw, int64_t x, int64_t y)
{
    int64_t dx = fx_asr64(dx_raw, 1), dy = fx_asr64(dy_raw, 1);
    int64_t ex = fx_asr64(x - px, 3), ey = fx_asr64(y - py, 3);
    int64_t cross = dx * ey - dy * ex;
    int64_t slack = abs64(dx) + abs64(dy) + abs64(ex) + abs64(ey) + 2;
    return cross > slack ? 1 : (cross < -slack ? -1 : 0);
}

int eye_clearly_in_front(const view_xform *v, const scn_vertex *a, const scn_vertex *b)
{
    int64_t dx = fx_asr64((int64_t)b->x - a->x, 1), dy = fx_asr64((int64_t)b->y - a->y, 1);
    int64_t ex = fx_asr64(v->cx - a->x, 3), ey = fx_asr64(v->cy - a->y, 3);
    int64_t len = abs64(dx) + abs64(dy) + 2;
    int64_t slack = len + abs64(ex) + abs64(ey) + EYE_WALL_MARGIN * len;
    return dy * ex - dx * ey > slack;
}

/* 1 if the eye is clearly in front of every one-sided wall of the leaf: an eye
 * that side_of takes to be on the leaf's edge may lie a little outside the
 * world, and see into it past the backs of its walls. */
static int clear_of_walls(const scene *sc, const scn_leaf *f, const view_xform *v)
{
    for (uint32_t i = 0; i < f->num_segs; i++) {
        const scn_seg *g = &sc->segs[f->first_seg + i];
        if (sc->lines[g->line].sector[g->side ^ 1u] != SCN_NONE) continue;
        if (!eye_clearly_in_front(v, &sc->verts[g->v1], &sc->verts[g->v2])) return 0;
    }
    return 1;
}

/* 1 if the eye is inside the leaf's floor polygon or on its boundary
 * (counter-clockwise: inside is left of every edge). */
static int holds(const scene *sc, const scn_leaf *f, int64_t x, int64_t y)
{
    for (uint32_t i = 0; i < f->num_pverts; i++) {
        const scn_vertex *a = &sc->pverts[f->first_pvert + i];
        const scn_vertex *b = &sc->pverts[f->first_pvert + (i + 1 == f->num_pverts ? 0 : i + 1)];
        if (side_of(a->x, a->y, (int64_t)b->x - a->x, (int64_t)b->y - a->y, x, y) < 0) return 0;
    }
    return 1;
}

int eye_in_world(const scene *sc, const world_state *w, const view_xform *v)
{
    uint32_t stack[EYE_STACK];
    int top = 0, found = 0;
    stack[top++] = sc->root;
    while (top > 0) {
        uint32_t n = stack[--top];
        if (n & SCN_LEAF_BIT) {
            const scn_leaf *f = &sc->leaves[n & ~SCN_LEAF_BIT];
            if (f->sector == SCN_NONE || f->num_pverts < 3 || !holds(sc, f, v->cx, v->cy)) return 0;
            if (!clear_of_walls(sc, f, v)) return 0;
            const scn_sector *sec = &sc->sectors[f->sector];
            if (v->cz <= sec->floor_h || v->cz >= obj_ceil(w, sc, f->sector)) return 0;
            found = 1;
            continue;
        }
        const scn_node *node = &sc->nodes[n];
        /* front is the right of the partition's direction: side -1; back: +1 */
        int side = side_of(node->x, node->y, node->dx, node->dy, v->cx, v->cy);
        if (side <= 0) stack[top++] = node->child[0];
        if (side >= 0) {
            if (top == EYE_STACK) return 0; /* cannot happen for a loaded scene: depth is checked */
            stack[top++] = node->child[1];
        }
    }
    return found;
}
