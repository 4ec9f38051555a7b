/* bsp_walk.c - data-recursive BSP traversal with frustum culling of node boxes.
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
    p[2] = (walk_plane){v->cos, v->sin, CLIP_NEAR};                                        /* z >= 0 */
}

/* Returns -1 if the box is outside some plane, else the mask with the planes
 * the box is wholly inside of removed. */
static int cull_box(const int32_t box[4], const view_xform *v, const walk_plane p[3], unsigned mask)
{
    /* box: top (ymax), bottom (ymin), left (xmin), right (xmax) */
    int64_t x0 = fx_asr64((int64_t)box[2] - v->cx, 3), x1 = fx_asr64((int64_t)box[3] - v->cx, 3);
    int64_t y0 = fx_asr64((int64_t)box[1] - v->cy, 3), y1 = fx_asr64((int64_t)box[0] - v->cy, 3);
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

void walk_tree(const scene *s, const view_xform *v, walk_order order, walk_visit visit, void *ctx,
               const occ_columns *occ, walk_stats *st)
{
    uint32_t stack[CFG_MAX_DEPTH + 2];
    uint8_t masks[CFG_MAX_DEPTH + 2];
    walk_plane planes[3];
    int sp = 0;
    walk_stats local = {0, 0};
    if (!st) st = &local;
    st->nodes = st->boxes_culled = st->boxes_hidden = 0;
    if (s->nleaves == 0) return;
    frustum_planes(v, planes);
    stack[sp] = s->root;
    masks[sp++] = CLIP_ALL;
    while (sp > 0) {
        sp--;
        uint32_t n = stack[sp];
        unsigned mask = masks[sp];
        if (occ && sp > 0 && occ_full(occ)) return; /* nothing more can show */
        if (n & SCN_LEAF_BIT) {
            if (visit(ctx, n & ~SCN_LEAF_BIT, mask)) return;
            continue;
        }
        const scn_node *node = &s->nodes[n];
        int near = scene_node_side(node, (int32_t)v->cx, (int32_t)v->cy);
        st->nodes++;
        /* push the child to visit second first */
        int first = (order == WALK_FRONT_TO_BACK) ? near : near ^ 1;
        int second = first ^ 1;
        int m2 = cull_box(node->bbox[second], v, planes, mask);
        int m1 = cull_box(node->bbox[first], v, planes, mask);
        if (occ) {
            int x0, x1;
            if (m2 >= 0 && (occ_box_columns(v, node->bbox[second], &x0, &x1), occ_hidden(occ, x0, x1))) {
                m2 = -1;
                st->boxes_hidden++;
            }
            if (m1 >= 0 && (occ_box_columns(v, node->bbox[first], &x0, &x1), occ_hidden(occ, x0, x1))) {
                m1 = -1;
                st->boxes_hidden++;
            }
        }
        if (sp + 2 > CFG_MAX_DEPTH + 2) return; /* unreachable for a validated scene */
        if (m2 >= 0) {
            stack[sp] = node->child[second];
            masks[sp++] = (uint8_t)m2;
        } else {
            st->boxes_culled++;
        }
        if (m1 >= 0) {
            stack[sp] = node->child[first];
            masks[sp++] = (uint8_t)m1;
        } else {
            st->boxes_culled++;
        }
    }
}
