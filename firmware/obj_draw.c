/* obj_draw.c - objects in the tree, in view space, on screen, and their 1/z order
 * against the world (see obj_draw.h for the 1/z format and its ranges).
 *
 * Ranges of the geometry. An object's origin lies in the box (|x|, |y| <= 32767
 * units, |z| <= 16383) and its vertices within 1024 sqrt 2 = 1449 units of it
 * horizontally and 1024 vertically (the loader's limits), so a vertex is within
 * |x|, |y| <= 34216 units and |z| <= 17407: an eye offset below 66,983 units
 * (2^32.03 raw 16.16), a rotated sum bounded by the offset's length (< 2^62.53
 * with 2.30 sine and cosine), a view coordinate below 2^30.53 raw (18.14), and a
 * height difference below 33,790 units (2^31.04 raw 16.16). */
#include "obj_draw.h"

#include "raster.h"
#include "wide128.h"

_Static_assert(!CFG_OBJECTS || CFG_FACE_VERTS + 5 <= CLIP_MAX_VERTS, "a clipped face must fit a clip_poly");

#define NORM_LO ((int64_t)1 << 29)
#define NORM_HI ((int64_t)1 << 30)
#define SIDE_EPS ((int64_t)OBJ_TIE_EPS << 30) /* OBJ_TIE_EPS times a normal's length, about */
#define TIE_FACTOR (320 / OBJ_TIE_EPS)        /* see objd_front */

/* Bits below the leading one, plus one (0 for 0). */
static int bits(uint64_t v)
{
    return v ? 64 - __builtin_clzll(v) : 0;
}

/* ---- planes ---------------------------------------------------------------------- */

/* Scale (x, y, z) so its largest component lies in [2^29, 2^30). Returns 0 for
 * the zero vector. */
static int normalise(int64_t *x, int64_t *y, int64_t *z)
{
    uint64_t m = w128_uabs(*x) | w128_uabs(*y) | w128_uabs(*z); /* the same leading bit as the largest */
    if (m == 0) return 0;
    int top = 63 - __builtin_clzll(m); /* the largest component's leading bit: wanted at 29 */
    if (top > 29) {
        *x = fx_asr64(*x, (unsigned)(top - 29));
        *y = fx_asr64(*y, (unsigned)(top - 29));
        *z = fx_asr64(*z, (unsigned)(top - 29));
    } else if (top < 29) { /* |v| < 2^29: shifting up by at most 29 stays below 2^59 */
        *x *= (int64_t)1 << (29 - top);
        *y *= (int64_t)1 << (29 - top);
        *z *= (int64_t)1 << (29 - top);
    }
    return 1;
}

/* n . p with |n| components < 2^30 and |p| < 2^30.6: below 2^61.4, and so is each
 * partial sum. */
static int64_t dot(const objd_plane *pl, int64_t x, int64_t y, int64_t z)
{
    return (int64_t)pl->nx * x + (int64_t)pl->ny * y + (int64_t)pl->nz * z;
}

void objd_plane_flat(const view_xform *v, int32_t h, objd_plane *p)
{
    /* view_point's height arithmetic; |y| < 2^29.05, so d < 2^58.05 */
    int32_t y = (int32_t)fx_asr64((int64_t)h - v->cz, 16 - VIEW_SHIFT);
    *p = (objd_plane){0, y < 0 ? -(int32_t)NORM_LO : (int32_t)NORM_LO, 0, 0, 0, 0, (int64_t)(y < 0 ? -y : y) * NORM_LO};
}

void objd_plane_wall(const view_xform *v, const scn_vertex *a, const scn_vertex *b, objd_plane *p)
{
    view_pt pa = view_point(v, a->x, a->y, 0), pb = view_point(v, b->x, b->y, 0);
    int64_t nx = (int64_t)pb.z - pa.z, ny = 0, nz = (int64_t)pa.x - pb.x; /* across the wall */
    *p = (objd_plane){0, 0, 0, 0, 0, 0, 0};
    if (!normalise(&nx, &ny, &nz)) return;
    int64_t d = nx * pa.x + nz * pa.z; /* < 2^30 * 2^30.5 * 2 */
    if (d < 0) {
        nx = -nx;
        nz = -nz;
        d = -d;
    }
    p->nx = (int32_t)nx;
    p->nz = (int32_t)nz;
    p->d = d;
}

/* 320 d / z at the pixel centre: the numerator M of obj_draw.h, < 2^41. */
static int64_t numerator(const objd_plane *p, int look, int px, int py)
{
    return (int64_t)p->nx * (2 * px + 1 - VIEW_W) + (int64_t)p->ny * (2 * (VIEW_CY + look) - 1 - 2 * py) +
           (int64_t)p->nz * VIEW_W;
}

/* Where point (x, y, z) lies against plane p: 1 on the eye's side, -1 beyond, 0
 * within about OBJ_TIE_EPS of it. */
static int side(const objd_plane *p, int32_t x, int32_t y, int32_t z)
{
    int64_t s = p->d - dot(p, x, y, z);
    return s > SIDE_EPS ? 1 : (s < -SIDE_EPS ? -1 : 0);
}

int objd_front(const objd_plane *s, int s_obj, const objd_plane *p, int p_obj, int look, int px, int py)
{
    if (p->d <= 0) return 0;
    if (s->d <= 0) return 1;
    px = px < 0 ? 0 : (px >= VIEW_W ? VIEW_W - 1 : px);
    py = py < 0 ? 0 : (py >= VIEW_H ? VIEW_H - 1 : py);
    int64_t ms = numerator(s, look, px, py), mp = numerator(p, look, px, py);
    /* 1/z_s - 1/z_p = (ms dp - mp ds) / (320 ds dp); the depths differ by less than
     * OBJ_TIE_EPS when 320 |ms dp - mp ds| < OBJ_TIE_EPS ms mp (both in front of the eye) */
    w128 diff = w128_sub(w128_mul(ms, p->d), w128_mul(mp, s->d)); /* < 2^102.5 */
    int sg = w128_sign(diff);
    if (ms > 0 && mp > 0) {
        w128 mag = sg < 0 ? w128_neg(diff) : diff;
        /* 20 mag >= 2^(bits(mag) + 3) and ms mp < 2^(bits(ms) + bits(mp)): most pairs
         * are told apart by their lengths alone */
        int mb = mag.hi ? 64 + bits(mag.hi) : bits(mag.lo);
        if (mb + 3 >= bits((uint64_t)ms) + bits((uint64_t)mp)) return sg > 0;
        /* mag * TIE_FACTOR (< 2^107) by 32-bit parts, against ms mp (< 2^80.2) */
        uint64_t l0 = (mag.lo & 0xFFFFFFFFu) * TIE_FACTOR, l1 = (mag.lo >> 32) * TIE_FACTOR + (l0 >> 32);
        w128 scaled = {mag.hi * TIE_FACTOR + (l1 >> 32), (l1 << 32) | (l0 & 0xFFFFFFFFu)};
        if (w128_sign(w128_sub(scaled, w128_mul(ms, mp))) >= 0) return sg > 0;
    } else {
        return sg > 0;
    }
    /* a tie: the surfaces abut here */
    if (s_obj) {
        int a = side(p, s->cx, s->cy, s->cz); /* s on the eye's side of p: s in front */
        if (a) return a > 0;
    }
    if (p_obj) {
        int b = side(s, p->cx, p->cy, p->cz); /* p on the eye's side of s: p in front */
        if (b) return b < 0;
    }
    /* two objects' faces in one plane (things of one height side by side): their
     * planes differ only by rounding, so a fixed order, as the reference's */
    if (s_obj && p_obj && s_obj != p_obj) return s_obj < p_obj;
    /* in one plane: the one nearing the eye faster along the line, then down it */
    int g = w128_sign_diff(s->nx, p->d, p->nx, s->d);
    if (g) return g > 0;
    g = w128_sign_diff(p->ny, s->d, s->ny, p->d);
    if (g) return g > 0;
    /* one plane, one gradient: the same depth at every pixel, so a fixed order */
    return s_obj == 0 ? p_obj != 0 : (p_obj != 0 && s_obj < p_obj);
}

/* ---- the object in the tree ------------------------------------------------------ */

void objd_leaf_box(const scene *sc, const scn_leaf *f, int32_t box[BOX_SIDES])
{
    const scn_vertex *p = &sc->pverts[f->first_pvert];
    box[BOX_LEFT] = box[BOX_BOTTOM] = INT32_MAX;
    box[BOX_RIGHT] = box[BOX_TOP] = INT32_MIN;
    for (uint32_t i = 0; i < f->num_pverts; i++) {
        if (p[i].x < box[BOX_LEFT]) box[BOX_LEFT] = p[i].x;
        if (p[i].y < box[BOX_BOTTOM]) box[BOX_BOTTOM] = p[i].y;
        if (p[i].x > box[BOX_RIGHT]) box[BOX_RIGHT] = p[i].x;
        if (p[i].y > box[BOX_TOP]) box[BOX_TOP] = p[i].y;
    }
}

/* Its bounding box first, then each edge of the leaf as a separating line.
 * Offsets are shifted (edges by 1, corners by 3) so the cross products stay
 * below 2^60.03 (box offsets below 2^32.03 raw, shifted by 3; edge directions
 * below 2^32 raw, shifted by 1). */
int objd_touches_leaf(const scene *sc, const obj_state *o, const scn_leaf *f, const int32_t box[BOX_SIDES])
{
    int64_t r = sc->models[o->model].radius;
    int64_t bx0 = (int64_t)o->x - r, by0 = (int64_t)o->y - r, bx1 = (int64_t)o->x + r, by1 = (int64_t)o->y + r;
    const scn_vertex *p = &sc->pverts[f->first_pvert];
    uint32_t n = f->num_pverts;
    if (n < 3 || box[BOX_LEFT] > bx1 || box[BOX_RIGHT] < bx0 || box[BOX_BOTTOM] > by1 || box[BOX_TOP] < by0) return 0;
    for (uint32_t i = 0; i < n; i++) {
        const scn_vertex *a = &p[i], *b = &p[i + 1 == n ? 0 : i + 1];
        int64_t dx = fx_asr64((int64_t)b->x - a->x, 1), dy = fx_asr64((int64_t)b->y - a->y, 1);
        /* the corner farthest to the left of a -> b (the polygon runs counter-clockwise) */
        int64_t cx = fx_asr64((dy > 0 ? bx0 : bx1) - a->x, 3), cy = fx_asr64((dx > 0 ? by1 : by0) - a->y, 3);
        int64_t slack = (dx < 0 ? -dx : dx) + (dy < 0 ? -dy : dy);
        if (dx * cy - dy * cx < -slack) return 0; /* the whole box is to the right: outside */
    }
    return 1;
}

/* Which side of the node's partition the box [x0, x1] x [y0, y1] lies on: 0
 * front, 1 back, -1 both (or on the line). As scene_node_side, to 1/8192 unit. */
static int box_side(const scn_node *n, int64_t x0, int64_t y0, int64_t x1, int64_t y1)
{
    int front = 0, back = 0;
    for (int c = 0; c < 4; c++) {
        int64_t ex = fx_asr64(((c & 1) ? x1 : x0) - n->x, 3), ey = fx_asr64(((c & 2) ? y1 : y0) - n->y, 3);
        int64_t cross = (int64_t)n->dx * ey - (int64_t)n->dy * ex;
        front |= cross < 0;
        back |= cross > 0;
        if (cross == 0) return -1;
    }
    return front == back ? -1 : back;
}

uint32_t objd_subtree_depth(const scene *s, const obj_state *o)
{
    int64_t r = (int64_t)s->models[o->model].radius + FX_ONE;
    int64_t x0 = (int64_t)o->x - r, y0 = (int64_t)o->y - r, x1 = (int64_t)o->x + r, y1 = (int64_t)o->y + r;
    uint32_t n = s->root, depth = 0;
    while (!(n & SCN_LEAF_BIT) && depth < SCN_MAX_DEPTH + 1u) {
        int side = box_side(&s->nodes[n], x0, y0, x1, y1);
        if (side < 0) break;
        n = s->nodes[n].child[side];
        depth++;
    }
    return depth;
}

/* The horizontal offset of the origin from the eye, rotated into view axes (16.16,
 * int64): z forward, x right. */
static void origin_view(const obj_state *o, const view_xform *v, int64_t *vx, int64_t *vz)
{
    int64_t dx = (int64_t)o->x - v->cx, dy = (int64_t)o->y - v->cy; /* < 2^32 */
    *vz = fx_asr64(dx * v->cos + dy * v->sin, FX_TRIG_SHIFT);
    *vx = fx_asr64(dx * v->sin - dy * v->cos, FX_TRIG_SHIFT);
}

int objd_in_view(const scene *s, const obj_state *o, const view_xform *v)
{
    int64_t vx, vz, r = s->models[o->model].radius + FX_ONE; /* a unit for the rounding */
    origin_view(o, v, &vx, &vz);
    if (vz + r < 0) return 0;
    /* left (z + x >= 0) and right (z - x >= 0): the distance from each is the sum
     * over sqrt 2, so the cylinder is outside when the sum is below -r sqrt 2
     * (1.4143 > sqrt 2: a little generous) */
    if ((vz + vx) * 10000 < -r * 14143 || (vz - vx) * 10000 < -r * 14143) return 0;
    return 1;
}

int32_t objd_depth(const obj_state *o, const view_xform *v)
{
    int64_t vx, vz;
    origin_view(o, v, &vx, &vz);
    return (int32_t)fx_asr64(vz, 16 - VIEW_SHIFT);
}

/* ---- faces -------------------------------------------------------------------------- */

void objd_transform(const scene *s, const obj_state *o, const view_xform *v, view_pt out[CFG_MODEL_VERTS])
{
    const scn_model *m = &s->models[o->model];
    fx_ang_t a = fx_ang_from_deg(o->yaw_deg);
    int64_t c = fx_cos(a), sn = fx_sin(a);
    for (uint32_t i = 0; i < m->num_verts && i < CFG_MODEL_VERTS; i++) {
        const scn_mvert *mv = &s->mverts[m->first_vert + i];
        /* model x forward, y left: yawed, |coordinate| < 2^26 raw times 2^30 */
        int64_t wx = (int64_t)o->x + fx_asr64(mv->x * c - mv->y * sn, FX_TRIG_SHIFT);
        int64_t wy = (int64_t)o->y + fx_asr64(mv->x * sn + mv->y * c, FX_TRIG_SHIFT);
        int64_t dx = wx - v->cx, dy = wy - v->cy;
        out[i].z = (int32_t)fx_asr64(dx * v->cos + dy * v->sin, 46 - VIEW_SHIFT);
        out[i].x = (int32_t)fx_asr64(dx * v->sin - dy * v->cos, 46 - VIEW_SHIFT);
        out[i].y = (int32_t)fx_asr64((int64_t)o->z + mv->z - v->cz, 16 - VIEW_SHIFT);
    }
}

int objd_face_plane(const scene *s, const scn_model *m, uint32_t f, const view_pt *verts, objd_plane *pl)
{
    const scn_face *fc = &s->faces[f];
    const uint32_t *ix = &s->findex[fc->first_index];
    view_pt pts[SCN_MAX_FACE_VERTS];
    int n = fc->num_index;
    (void)m;
    for (int k = 0; k < n && k < SCN_MAX_FACE_VERTS; k++) pts[k] = verts[ix[k]];
    return objd_points_plane(pts, n < SCN_MAX_FACE_VERTS ? n : SCN_MAX_FACE_VERTS, pl);
}

int objd_points_plane(const view_pt *pts, int n, objd_plane *pl)
{
    int64_t sx = 0, sy = 0, sz = 0;
    for (int k = 0; k < n; k++) {
        const view_pt *p = &pts[k];
        sx += p->x;
        sy += p->y;
        sz += p->z;
    }
    int32_t cx = (int32_t)(sx / n), cy = (int32_t)(sy / n), cz = (int32_t)(sz / n);
    /* Newell's sum about the centroid: offsets below 2^26.8 raw (a model spans at
     * most 2 * 1024 sqrt 3 units), products below 2^53.6, 16 terms below 2^57.6.
     * View space is left-handed (x right, y up, z forward), so for vertices running
     * counter-clockwise seen from outside the sum points into the part. */
    int64_t nx = 0, ny = 0, nz = 0;
    for (int k = 0; k < n; k++) {
        const view_pt *p = &pts[k], *q = &pts[k + 1 == n ? 0 : k + 1];
        int64_t px = (int64_t)p->x - cx, py = (int64_t)p->y - cy, pz = (int64_t)p->z - cz;
        int64_t qx = (int64_t)q->x - cx, qy = (int64_t)q->y - cy, qz = (int64_t)q->z - cz;
        nx += (py - qy) * (pz + qz);
        ny += (pz - qz) * (px + qx);
        nz += (px - qx) * (py + qy);
    }
    if (!normalise(&nx, &ny, &nz)) return 0;
    *pl = (objd_plane){(int32_t)nx, (int32_t)ny, (int32_t)nz, cx, cy, cz, 0};
    /* the inward normal at the centroid: positive when the eye is outside. The
     * normal's length is below 2^30.8, so beyond 2^31 eps no root is needed. */
    int64_t d = dot(pl, cx, cy, cz);
    if (d <= 0) return 0;
    if (d <= ((int64_t)OBJ_BACKFACE_EPS << 31) &&
        d <= (int64_t)fx_isqrt64((uint64_t)(nx * nx + ny * ny + nz * nz)) * OBJ_BACKFACE_EPS)
        return 0;
    pl->d = d;
    return 1;
}

int objd_face_screen(const scene *s, const scn_model *m, uint32_t f, const view_pt *verts, const view_xform *v,
                     screen_pt out[CLIP_MAX_VERTS])
{
    const scn_face *fc = &s->faces[f];
    const uint32_t *ix = &s->findex[fc->first_index];
    view_pt pts[CLIP_MAX_VERTS];
    int n = fc->num_index;
    (void)m;
    if (n > CLIP_MAX_VERTS - 5) return 0; /* the loader refuses such a face for this build */
    /* counter-clockwise seen from outside runs counter-clockwise on screen too (as a
     * floor does): reversed, it is the clockwise order the fill expects */
    for (int k = 0; k < n; k++) pts[k] = verts[ix[n - 1 - k]];
    return objd_points_screen(pts, n, v, out);
}

int objd_points_screen(const view_pt *pts, int n, const view_xform *v, screen_pt out[CLIP_MAX_VERTS])
{
    clip_poly p;
    if (n > CLIP_MAX_VERTS - 5) return 0;
    p.n = n;
    for (int k = 0; k < n; k++) p.v[k] = pts[k];
    if (!clip_polygon(&p, v, CLIP_ALL)) return 0;
    clip_project(v, &p, out);
    return p.n;
}

int objd_screen_box(const scene *s, const obj_state *os, const view_xform *v, int *x0, int *x1, int *y0, int *y1)
{
    const scn_model *m = &s->models[os->model];
    int32_t zlo = INT32_MAX, zhi = INT32_MIN;
    for (uint32_t i = 0; i < m->num_verts; i++) {
        int32_t z = s->mverts[m->first_vert + i].z;
        if (z < zlo) zlo = z;
        if (z > zhi) zhi = z;
    }
    if (zlo > zhi) return -1;
    int64_t r = m->radius, bx0 = (int64_t)os->x - r, bx1 = (int64_t)os->x + r, by0 = (int64_t)os->y - r,
            by1 = (int64_t)os->y + r;
    if (bx0 < INT32_MIN || bx1 > INT32_MAX || by0 < INT32_MIN || by1 > INT32_MAX) return 0; /* at the box's edge */
    int32_t xs[2] = {(int32_t)bx0, (int32_t)bx1}, ys[2] = {(int32_t)by0, (int32_t)by1};
    int32_t zs[2] = {os->z + zlo, os->z + zhi};
    view_pt corner[8];
    for (int c = 0; c < 8; c++) corner[c] = view_point(v, xs[c & 1], ys[(c >> 1) & 1], zs[c >> 2]);
    /* the box's part in front of the near plane: its corners there, and where its
     * edges cross the plane (projections are clamped to the screen) */
    int32_t xmin = INT32_MAX, xmax = INT32_MIN, ymin = INT32_MAX, ymax = INT32_MIN;
    for (int c = 0; c < 8; c++) {
        view_pt a = corner[c];
        for (int k = -1; k < 3; k++) {
            view_pt p = a;
            if (k >= 0) { /* the edge to the corner across bit k, taken once, from its end in front */
                view_pt b = corner[c ^ (1 << k)];
                if (a.z < VIEW_ZNEAR || b.z >= VIEW_ZNEAR) continue;
                int64_t dz = (int64_t)a.z - b.z, t = (int64_t)a.z - VIEW_ZNEAR; /* 0 <= t < dz */
                p.x = (int32_t)(a.x + ((int64_t)b.x - a.x) * t / dz);           /* |.| < 2^32 * 2^32: fits */
                p.y = (int32_t)(a.y + ((int64_t)b.y - a.y) * t / dz);
                p.z = VIEW_ZNEAR;
            } else if (a.z < VIEW_ZNEAR) {
                continue;
            }
            screen_pt q = view_project(v, p);
            if (q.x < xmin) xmin = q.x;
            if (q.x > xmax) xmax = q.x;
            if (q.y < ymin) ymin = q.y;
            if (q.y > ymax) ymax = q.y;
        }
    }
    if (xmin > xmax) return -1; /* wholly behind the near plane */
    *x0 = rast_first_sample(xmin) - 1;
    *x1 = rast_first_sample(xmax) + 1;
    *y0 = rast_first_sample(ymin) - 1;
    *y1 = rast_first_sample(ymax) + 1;
    return 1;
}
