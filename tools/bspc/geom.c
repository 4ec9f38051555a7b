/* geom.c - exact line set-up and line-line intersection for the BSP compiler
 * (see geom.h for the tolerance model). */
#include "geom.h"

#include <math.h>

uint64_t bs_isqrt(bs_u128 v)
{
    uint64_t r = (uint64_t)sqrtl((long double)v);
    /* correct the floating estimate by a few steps either way */
    while (r > 0 && (bs_u128)r * r > v) r--;
    while ((bs_u128)(r + 1) * (r + 1) <= v) r++;
    return r;
}

static int64_t abs64(int64_t v)
{
    return v < 0 ? -v : v;
}

static int64_t gcd64(int64_t a, int64_t b)
{
    a = abs64(a);
    b = abs64(b);
    while (b) {
        int64_t t = a % b;
        a = b;
        b = t;
    }
    return a;
}

void bs_pline_set(bs_pline *L, int32_t x, int32_t y, int64_t dx, int64_t dy)
{
    if (abs64(dx) > INT32_MAX || abs64(dy) > INT32_MAX) {
        int64_t g = gcd64(dx, dy);
        if (g > 1) {
            dx /= g;
            dy /= g;
        }
        /* still too wide (only for walls longer than 32767 units with odd raw
         * deltas): halve, rounding; the direction moves by under 2^-31 rad */
        while (abs64(dx) > INT32_MAX || abs64(dy) > INT32_MAX) {
            dx = (dx >= 0) ? (dx + 1) / 2 : -((-dx + 1) / 2);
            dy = (dy >= 0) ? (dy + 1) / 2 : -((-dy + 1) / 2);
        }
    }
    L->x = x;
    L->y = y;
    L->dx = (int32_t)dx;
    L->dy = (int32_t)dy;
    int64_t g = gcd64(dx, dy);
    int64_t rdx = dx / g, rdy = dy / g;
    L->rdx = (int32_t)rdx;
    L->rdy = (int32_t)rdy;
    L->small = abs64(rdx) < ((int64_t)1 << 29) && abs64(rdy) < ((int64_t)1 << 29);
    L->thr = (int64_t)bs_isqrt((bs_u128)(BS_EPS * BS_EPS) * ((bs_u128)(rdx * rdx) + (bs_u128)(rdy * rdy)));
}

/* round(n / d) to nearest, ties toward +infinity; d != 0 */
static bs_i128 rdiv(bs_i128 n, bs_i128 d)
{
    if (d < 0) {
        n = -n;
        d = -d;
    }
    bs_i128 num = 2 * n + d, den = 2 * d;
    bs_i128 q = num / den;
    if ((num % den != 0) && (num < 0)) q -= 1; /* floor */
    return q;
}

static int32_t clamp32(bs_i128 v)
{
    if (v > INT32_MAX) return INT32_MAX;
    if (v < INT32_MIN) return INT32_MIN;
    return (int32_t)v;
}

int bs_intersect(const bs_pline *lines, uint32_t a, uint32_t b, int32_t *x, int32_t *y)
{
    if (a > b) {
        uint32_t t = a;
        a = b;
        b = t;
    }
    const bs_pline *A = &lines[a], *B = &lines[b];
    /* A + t dA on B: t = ((B - A) x dB) / (dA x dB) with u x v = ux vy - uy vx */
    bs_i128 den = (bs_i128)A->rdx * B->rdy - (bs_i128)A->rdy * B->rdx;
    if (den == 0) return -1;
    bs_i128 num = (bs_i128)((int64_t)B->x - A->x) * B->rdy - (bs_i128)((int64_t)B->y - A->y) * B->rdx;
    /* |num| < 2^65, |dA| < 2^31: products < 2^96 */
    *x = clamp32((bs_i128)A->x + rdiv(num * A->rdx, den));
    *y = clamp32((bs_i128)A->y + rdiv(num * A->rdy, den));
    return 0;
}
