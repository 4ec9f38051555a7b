/* bsp_walk.c - data-recursive BSP traversal over the boxes a caller's test
 * passes, and on it the walk with frustum culling of node boxes.
 *
 * The horizontal frustum planes (left, right, near) are tested against each
 * child's box in map space: for each plane, the box corner farthest along the
 * plane's inward normal decides "all outside", the nearest corner "all inside".
 * Distances: box offsets from the eye reach 2^33 raw; shifted right by 3 they
 * stay below 2^30, and the normals are below 2^31 (sums of two 2.30 values), so
 * each product is below 2^61. */
#include "bsp_walk.h"
#include "clip.h"

typedef struct {
    int64_t nx, ny; /* inward normal in map space, 2.30 scale */
    unsigned bit;
} walk_plane;

static void frustum_planes(const view_xform *v, walk_plane p[3])
{
    /* view z = dx*cos + dy*sin, view x = dx*sin - dy*cos (view.h) */
    p[0] = (walk_plane){(int64_t)v->cos + v->sin, (int64_t)v->sin - v->cos, CLIP_LEFT};  /* z + x >= 0 */
    p[1] = (walk_plane){(int64_t)v->cos - v->sin, (int64_t)v->sin + v->cos, CLIP_RIGHT}; /* z - x >= 0 */
    p[2] = (walk_plane){v->cos, v->sin, CLIP_NEAR};                                      /* z >= 0 */
}

/* Returns -1 if the box is outside some plane, else the mask with the planes
 * the box is wholly inside of removed. */
static int cull_box(const int32_t box[BOX_SIDES], const view_xform *v, const walk_plane p[3], unsigned mask)
{
    int64_t x0 = fx_asr64((int64_t)box[BOX_LEFT] - v->cx, 3), x1 = fx_asr64((int64_t)box[BOX_RIGHT] - v->cx, 3);
    int64_t y0 = fx_asr64((int64_t)box[BOX_BOTTOM] - v->cy, 3), y1 = fx_asr64((int64_t)box[BOX_TOP] - v->cy, 3);
    for (int i = 0; i < 3; i++) {
        if (!(mask & p[i].bit)) continue;
        int64_t far = (p[i].nx >= 0 ? x1 : x0) * p[i].nx + (p[i].ny >= 0 ? y1 : y0) * p[i].ny;
        if (far < 0) return -1;
        int64_t near = (p[i].nx >= 0 ? x0 : x1) * p[i].nx + (p[i].ny >= 0 ? y0 : y1) * p[i].ny;
        /* the near plane sits at z = VIEW_ZNEAR, not 0: only call a box inside it
         * with a margin that covers that distance (view units to map 16.16 >> 3,
         * times the 2.30 normal) */
        int64_t margin = (p[i].bit == CLIP_NEAR) ? ((int64_t)VIEW_ZNEAR << (30 + (16 - VIEW_SHIFT) - 3)) * 2 : 0;
        if (near > margin) mask &= ~p[i].bit;
    }
    return (int)mask;
}

/* The walk itself. Inlined whole into walk_boxes and walk_tree: with the
 * frustum's rules constant there, the compiler calls its tests directly (the
 * frame's walk pays no call through a pointer per box). */
static inline __attribute__((always_inline)) int walk(const scene *s, const walk_rules *rules, void *ctx,
                                                      unsigned state, walk_stats *st)
{
    uint32_t stack[WALK_STACK_MAX];
    uint8_t states[WALK_STACK_MAX];
    uint16_t depths[WALK_STACK_MAX]; /* each entry's depth in the tree */
    int sp = 0;
    walk_stats local;
    if (!st) st = &local;
    st->nodes = st->boxes_culled = st->boxes_hidden = 0;
    if (s->nleaves == 0) return 0;
    stack[sp] = s->root;
    depths[sp] = 0;
    states[sp++] = (uint8_t)state;
    uint32_t back_to = 0;
    while (sp > 0) {
        sp--;
        uint32_t n = stack[sp];
        unsigned in = states[sp], depth = depths[sp];
        if (depth < back_to) back_to = depth;
        if (rules->stop && sp > 0 && rules->stop(ctx)) return 1;
        if (n & SCN_LEAF_BIT) {
            st->back_to = back_to;
            back_to = UINT32_MAX;
            if (rules->leaf(rules->leaf_ctx, n & ~SCN_LEAF_BIT, in)) return 1;
            continue;
        }
        const scn_node *node = &s->nodes[n];
        /* push the child to walk second first */
        int first = rules->first ? rules->first(ctx, node) : 0;
        int second = first ^ 1;
        st->nodes++;
        int m2 = rules->box(ctx, node->bbox[second], in);
        int m1 = rules->box(ctx, node->bbox[first], in);
        if (sp + 2 > WALK_STACK_MAX) return 0; /* unreachable for a validated scene */
        if (m2 >= 0) {
            stack[sp] = node->child[second];
            depths[sp] = (uint16_t)(depth + 1);
            states[sp++] = (uint8_t)m2;
        } else {
            st->boxes_culled++;
        }
        if (m1 >= 0) {
            stack[sp] = node->child[first];
            depths[sp] = (uint16_t)(depth + 1);
            states[sp++] = (uint8_t)m1;
        } else {
            st->boxes_culled++;
        }
    }
    return 0;
}

int walk_boxes(const scene *s, const walk_rules *rules, void *ctx, unsigned state, walk_stats *st)
{
    return walk(s, rules, ctx, state, st);
}

/* ---- the frustum walk ---- */

typedef struct {
    const view_xform *v;
    walk_plane planes[3];
    walk_order order;
    const occ_columns *occ; /* may be NULL */
    walk_stats *st;
    void (*hidden)(void *ctx, const int32_t box[BOX_SIDES]); /* may be NULL */
    void *ctx;
} frustum_walk;

static int frustum_first(void *ctx, const scn_node *node)
{
    const frustum_walk *f = ctx;
    int near = scene_node_side(node, (int32_t)f->v->cx, (int32_t)f->v->cy);
    return (f->order == WALK_FRONT_TO_BACK) ? near : near ^ 1;
}

static int frustum_box(void *ctx, const int32_t box[BOX_SIDES], unsigned mask)
{
    frustum_walk *f = ctx;
    int m = cull_box(box, f->v, f->planes, mask);
    if (m >= 0 && f->occ) {
        int x0, x1;
        occ_box_columns(f->v, box, &x0, &x1);
        if (occ_hidden(f->occ, x0, x1)) {
            f->st->boxes_hidden++;
            if (f->hidden) f->hidden(f->ctx, box);
            return -1;
        }
    }
    return m;
}

static int frustum_full(void *ctx)
{
    const frustum_walk *f = ctx;
    return occ_full(f->occ);
}

void walk_tree(const scene *s, const view_xform *v, walk_order order, walk_visit visit, void *ctx,
               const occ_columns *occ, walk_stats *st)
{
    walk_tree_hidden(s, v, order, visit, ctx, occ, st, 0);
}

void walk_tree_hidden(const scene *s, const view_xform *v, walk_order order, walk_visit visit, void *ctx,
                      const occ_columns *occ, walk_stats *st, void (*hidden)(void *ctx, const int32_t box[BOX_SIDES]))
{
    walk_stats local;
    frustum_walk f = {v, {{0}}, order, occ, st ? st : &local, hidden, ctx};
    const walk_rules rules = {frustum_first, frustum_box, visit, ctx, occ ? frustum_full : 0};
    frustum_planes(v, f.planes);
    walk(s, &rules, &f, CLIP_ALL, f.st);
}
