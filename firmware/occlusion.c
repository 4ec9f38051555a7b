/* occlusion.c - closed-column ranges and conservative screen extents. */
#include "occlusion.h"

void occ_reset(occ_columns *o)
{
    o->n = 0;
}

int occ_full(const occ_columns *o)
{
    return o->n == 1 && o->r[0][0] <= 0 && o->r[0][1] >= VIEW_W;
}

int occ_hidden(const occ_columns *o, int x0, int x1)
{
    if (x1 <= x0) return 1;
    for (int i = 0; i < o->n; i++) {
        if (o->r[i][0] > x0) return 0;
        if (o->r[i][1] >= x1) return 1;
    }
    return 0;
}

void occ_close(occ_columns *o, int x0, int x1)
{
    if (x0 < 0) x0 = 0;
    if (x1 > VIEW_W) x1 = VIEW_W;
    if (x1 <= x0) return;
    int i = 0;
    while (i < o->n && o->r[i][1] < x0) i++;
    int j = i;
    while (j < o->n && o->r[j][0] <= x1) j++;
    if (j > i) {
        if (o->r[i][0] < x0) x0 = o->r[i][0];
        if (o->r[j - 1][1] > x1) x1 = o->r[j - 1][1];
        int gone = j - i - 1;
        for (int k = j; k < o->n; k++) {
            o->r[k - gone][0] = o->r[k][0];
            o->r[k - gone][1] = o->r[k][1];
        }
        o->n -= gone;
    } else {
        /* disjoint ranges of at least one column with gaps between them: at most
         * VIEW_W / 2 + 1 exist, so there is always room */
        if (o->n >= OCC_MAX_RANGES) return;
        for (int k = o->n; k > i; k--) {
            o->r[k][0] = o->r[k - 1][0];
            o->r[k][1] = o->r[k - 1][1];
        }
        o->n++;
    }
    o->r[i][0] = (int16_t)x0;
    o->r[i][1] = (int16_t)x1;
}

/* Screen x (16.16) of view point (x, z), z >= VIEW_ZNEAR, |x| <= z, projected
 * as view_project projects a vertex (the same precision knobs apply), so the
 * columns a wall closes stay within the columns it is drawn in. */
static int32_t screen_x(int64_t x, int64_t z)
{
    int64_t sx = ((int64_t)VIEW_CX << 16) + view_persp((int32_t)x, (int32_t)z);
    return view_subpixel(sx < 0 ? 0 : (sx > VIEW_W_FX ? VIEW_W_FX : (int32_t)sx));
}

static int column(int32_t sx)
{
    return (sx + 32767) >> 16;
}

/* Clip the view-space segment p -> q (x, z) to near, left and right with the
 * parametric form; t in 2.30. Returns 0 if nothing is left. */
int occ_seg_columns(view_pt p, view_pt q, int *x0, int *x1)
{
    int64_t t0 = 0, t1 = (int64_t)1 << 30;
    /* plane distances d = A*x + B*z + C for near (z - zn), left (z + x), right (z - x) */
    int64_t dp[3] = {(int64_t)p.z - VIEW_ZNEAR, (int64_t)p.z + p.x, (int64_t)p.z - p.x};
    int64_t dq[3] = {(int64_t)q.z - VIEW_ZNEAR, (int64_t)q.z + q.x, (int64_t)q.z - q.x};
    for (int i = 0; i < 3; i++) {
        if (dp[i] < 0 && dq[i] < 0) return 0;
        if (dp[i] >= 0 && dq[i] >= 0) continue;
        /* crossing at t = dp / (dp - dq): |d| < 2^32, so d << 30 fits */
        int64_t t = (dp[i] * ((int64_t)1 << 30)) / (dp[i] - dq[i]);
        if (dp[i] < 0) {
            if (t > t0) t0 = t;
        } else if (t < t1) {
            t1 = t;
        }
    }
    if (t0 >= t1) return 0;
    int64_t dx = (int64_t)q.x - p.x, dz = (int64_t)q.z - p.z;
    int64_t xa = p.x + fx_asr64(dx * t0, 30), za = p.z + fx_asr64(dz * t0, 30);
    int64_t xb = p.x + fx_asr64(dx * t1, 30), zb = p.z + fx_asr64(dz * t1, 30);
    if (za < VIEW_ZNEAR) za = VIEW_ZNEAR;
    if (zb < VIEW_ZNEAR) zb = VIEW_ZNEAR;
    int ca = column(screen_x(xa, za)), cb = column(screen_x(xb, zb));
    *x0 = ca < cb ? ca : cb;
    *x1 = ca < cb ? cb : ca;
    return 1;
}

void occ_box_columns(const view_xform *v, const int32_t box[BOX_SIDES], int *x0, int *x1)
{
    const int32_t xs[2] = {box[BOX_LEFT], box[BOX_RIGHT]}, ys[2] = {box[BOX_BOTTOM], box[BOX_TOP]};
    int lo = VIEW_W, hi = 0;
    for (int i = 0; i < 4; i++) {
        view_pt p = view_point(v, xs[i & 1], ys[i >> 1], 0);
        if (p.z <= VIEW_ZNEAR) { /* a corner at or behind the eye: any column */
            *x0 = 0;
            *x1 = VIEW_W;
            return;
        }
        int64_t x = p.x < -p.z ? -p.z : (p.x > p.z ? p.z : p.x);
        int c = column(screen_x(x, p.z));
        if (c < lo) lo = c;
        if (c > hi) hi = c;
    }
    *x0 = lo > 0 ? lo - 1 : 0; /* one column of margin for rounding */
    *x1 = hi < VIEW_W ? hi + 1 : VIEW_W;
}
