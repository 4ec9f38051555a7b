/* wide128.h - exact 128-bit products of 64-bit integers (prefix w128_), for the
 * comparisons of products of products that collision and the 1/z sort decide
 * exactly. A host with a 128-bit type multiplies with it; a 32-bit core (the
 * Cortex-M3) builds the product from 32-bit parts, w128_mul_parts, which the
 * unit tests check against the 128-bit type. Static inline: these sit in the
 * span renderer's inner comparisons. */
#ifndef WIDE128_H
#define WIDE128_H

#include <stdint.h>

typedef struct {
    uint64_t hi, lo; /* two's complement */
} w128;

static inline uint64_t w128_uabs(int64_t a)
{
    return a < 0 ? (uint64_t)0 - (uint64_t)a : (uint64_t)a;
}

static inline w128 w128_neg(w128 a)
{
    w128 r;
    r.lo = ~a.lo + 1u;
    r.hi = ~a.hi + (r.lo == 0);
    return r;
}

/* a * b for any int64 a, b (the magnitude is below 2^126), from 32-bit parts. */
static inline w128 w128_mul_parts(int64_t a, int64_t b)
{
    uint64_t x = w128_uabs(a), y = w128_uabs(b);
    uint64_t xl = x & 0xFFFFFFFFu, xh = x >> 32, yl = y & 0xFFFFFFFFu, yh = y >> 32;
    uint64_t ll = xl * yl, lh = xl * yh, hl = xh * yl, hh = xh * yh;
    uint64_t mid = (ll >> 32) + (lh & 0xFFFFFFFFu) + (hl & 0xFFFFFFFFu); /* < 3 * 2^32 */
    w128 r;
    r.lo = (ll & 0xFFFFFFFFu) | (mid << 32);
    r.hi = hh + (lh >> 32) + (hl >> 32) + (mid >> 32);
    return ((a < 0) != (b < 0)) ? w128_neg(r) : r;
}

static inline w128 w128_mul(int64_t a, int64_t b)
{
#if defined(__SIZEOF_INT128__)
    __extension__ typedef __int128 i128;
    __extension__ typedef unsigned __int128 u128;
    u128 p = (u128)((i128)a * b);
    w128 r = {(uint64_t)(p >> 64), (uint64_t)p};
    return r;
#else
    return w128_mul_parts(a, b);
#endif
}

static inline w128 w128_sub(w128 a, w128 b)
{
    w128 r;
    r.lo = a.lo - b.lo;
    r.hi = a.hi - b.hi - (a.lo < b.lo);
    return r;
}

/* -1, 0 or 1. */
static inline int w128_sign(w128 a)
{
    if (a.hi >> 63) return -1;
    return (a.hi | a.lo) ? 1 : 0;
}

/* Sign of a b - c d, exactly, for any int64 values (the difference of two
 * products below 2^126 is below 2^127). */
static inline int w128_sign_diff(int64_t a, int64_t b, int64_t c, int64_t d)
{
    return w128_sign(w128_sub(w128_mul(a, b), w128_mul(c, d)));
}

/* The same from 32-bit parts only, whatever the host (for the tests). */
static inline int w128_sign_diff_parts(int64_t a, int64_t b, int64_t c, int64_t d)
{
    return w128_sign(w128_sub(w128_mul_parts(a, b), w128_mul_parts(c, d)));
}

#endif
