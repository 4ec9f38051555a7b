/* fixed.h - 16.16 fixed-point arithmetic and angle tables (prefix fx_).
 *
 * Owns the number formats every other part of the renderer relies on:
 *   fx_t     signed 16.16 in an int32_t: range [-32768, 32768 - 2^-16], step 2^-16.
 *   fx_ang_t binary angle: a full turn is 2^32, so wrap-around is free (uint32_t).
 * Products that can exceed 32 bits go through 64-bit intermediates. Every
 * routine saturates to [FX_MIN, FX_MAX] instead of overflowing, so no input
 * causes undefined behaviour; the ranges over which each result is exact
 * (correctly rounded toward negative infinity unless stated) are documented
 * beside it and checked by tests/unit/test_fixed.c against a double reference.
 */
#ifndef FX_FIXED_H
#define FX_FIXED_H

#include <stdint.h>

typedef int32_t fx_t;
typedef uint32_t fx_ang_t;

#define FX_SHIFT 16
#define FX_ONE ((fx_t)1 << FX_SHIFT)
#define FX_HALF ((fx_t)1 << (FX_SHIFT - 1))
#define FX_MAX INT32_MAX
#define FX_MIN INT32_MIN

/* Whole number to 16.16. Exact for |i| <= 32767; saturates outside. */
static inline fx_t fx_from_int(int32_t i)
{
    if (i > 32767) return FX_MAX;
    if (i < -32768) return FX_MIN;
    return (fx_t)((uint32_t)i << FX_SHIFT);
}

/* Floor of a 16.16 value as a whole number (arithmetic shift, defined for all inputs). */
static inline int32_t fx_floor_int(fx_t a)
{
    return (a >= 0) ? (a >> FX_SHIFT) : (int32_t)(-(int64_t)((((uint64_t)(-(int64_t)a)) + 0xFFFFu) >> FX_SHIFT));
}

/* Saturate a 64-bit value into the 32-bit range. */
static inline int32_t fx_sat32(int64_t v)
{
    if (v > INT32_MAX) return INT32_MAX;
    if (v < INT32_MIN) return INT32_MIN;
    return (int32_t)v;
}

/* Arithmetic right shift of a signed 64-bit value, floor semantics, defined for
 * negative values (C leaves >> of negatives implementation-defined). 0 <= s < 63. */
static inline int64_t fx_asr64(int64_t v, unsigned s)
{
    return (v >= 0) ? (v >> s) : -(int64_t)(((uint64_t)(-(v + 1)) >> s) + 1);
}

/* a*b in 16.16, rounded toward negative infinity. Any inputs; the result
 * saturates when |a*b| >= 32768. */
fx_t fx_mul(fx_t a, fx_t b);

/* a/b in 16.16, truncated toward zero. b == 0 gives FX_MAX (a >= 0) or FX_MIN
 * (a < 0); a quotient outside the 16.16 range saturates. */
fx_t fx_div(fx_t a, fx_t b);

/* 1/a in 16.16 (= fx_div(FX_ONE, a)), truncated toward zero. |a| <= 2 raw (a
 * quotient of 2^31 or more) saturates; a == 0 gives FX_MAX. */
fx_t fx_recip(fx_t a);

/* 64-bit by 32-bit multiply-shift used by the transform: (a*b) >> s with floor
 * semantics; a may use up to 48 significant bits and b 16.16 or 2.30. The
 * caller guarantees |a*b| < 2^63 (documented at each use). */
static inline int64_t fx_mul64(int64_t a, int32_t b, unsigned s)
{
    return fx_asr64(a * (int64_t)b, s);
}

/* FX_DIV32: 1 where a 64-bit divide is a library call (32-bit cores: the
 * Cortex-M3's libgcc divide was 12% of its frame), so the per-frame divides
 * whose quotient provably fits 32 bits go through fx_udiv64_32 and its two
 * 32-bit hardware divides instead; 0 where the core divides 64 bits in one
 * instruction. Either way the same quotients (docs/ranges.md). */
#ifndef FX_DIV32
#define FX_DIV32 (UINTPTR_MAX <= 0xFFFFFFFFu)
#endif

/* floor(n / d) for d > 0 and n < d * 2^32 (the quotient fits 32 bits), with two
 * 32-bit divides (Knuth's algorithm D on 16-bit digits, Hacker's Delight
 * divlu); *rem gets n - q * d. Outside the contract the result is unspecified
 * but defined. */
static inline uint32_t fx_udiv64_32(uint64_t n, uint32_t d, uint32_t *rem)
{
    uint32_t u1 = (uint32_t)(n >> 32), u0 = (uint32_t)n;
    if (d == 0 || u1 >= d) { /* outside the contract */
        *rem = 0;
        return 0xFFFFFFFFu;
    }
    int s = __builtin_clz(d); /* normalise: the divisor's top bit set */
    uint32_t v = d << s;
    uint32_t vn1 = v >> 16, vn0 = v & 0xFFFFu;
    uint32_t un32 = s ? (u1 << s) | (u0 >> (32 - s)) : u1;
    uint32_t un10 = u0 << s;
    uint32_t un1 = un10 >> 16, un0 = un10 & 0xFFFFu;
    uint32_t q1 = un32 / vn1, rhat = un32 - q1 * vn1;
    while (q1 >= 0x10000u || q1 * vn0 > ((rhat << 16) | un1)) {
        q1--;
        rhat += vn1;
        if (rhat >= 0x10000u) break;
    }
    uint32_t un21 = (un32 << 16) + un1 - q1 * v;
    uint32_t q0 = un21 / vn1;
    rhat = un21 - q0 * vn1;
    while (q0 >= 0x10000u || q0 * vn0 > ((rhat << 16) | un0)) {
        q0--;
        rhat += vn1;
        if (rhat >= 0x10000u) break;
    }
    *rem = ((un21 << 16) + un0 - q0 * v) >> s;
    return (q1 << 16) | q0;
}

/* floor(n / d) for d > 0 and |floor(n / d)| < 2^31 - 1, by fx_udiv64_32; *rem
 * gets n - q * d, in [0, d). */
static inline int32_t fx_floordiv64_32(int64_t n, uint32_t d, uint32_t *rem)
{
    if (n >= 0) return (int32_t)fx_udiv64_32((uint64_t)n, d, rem);
    uint32_t r, q = fx_udiv64_32((uint64_t)0 - (uint64_t)n, d, &r); /* -n = q d + r */
    *rem = r ? d - r : 0;
    return r ? -(int32_t)q - 1 : -(int32_t)q;
}

/* floor(sqrt(v)) for any 64-bit v (bit-by-bit, no division). */
uint64_t fx_isqrt64(uint64_t v);

/* Angles. fx_ang_from_deg takes degrees in 16.16 (any value: it wraps). */
fx_ang_t fx_ang_from_deg(fx_t deg);
/* sin/cos as 2.30 fixed point (1.0 = 1 << 30), from a quarter-wave table of
 * 2^FX_SIN_BITS intervals generated at build time (tools/gen_tables.c); exact 0
 * and +-1 at the quadrant angles.
 *
 * Precision knobs: they trade the table's memory (4 * (2^FX_SIN_BITS + 1)
 * bytes) and, for FX_SIN_LERP, a multiply per call against the accuracy of the
 * view's rotation; sin and cos are taken once per frame, so run time hardly
 * moves. An angle error of e radians turns the whole view by e: up to 160 * e
 * pixels at the screen's sides.
 *   FX_SIN_BITS  4..12 (default 12: 4097 entries).
 *   FX_SIN_LERP  1 (default): interpolate linearly between entries, max error
 *                about (pi / 2^(FX_SIN_BITS + 1))^2 / 8 (2^-24 or so at 12 bits);
 *                0: take the nearest entry, max error pi / 2^(FX_SIN_BITS + 2). */
#ifndef FX_SIN_BITS
#define FX_SIN_BITS 12
#endif
#ifndef FX_SIN_LERP
#define FX_SIN_LERP 1
#endif
#if FX_SIN_BITS < 4 || FX_SIN_BITS > 12
#error "FX_SIN_BITS: 4..12"
#endif
#if FX_SIN_LERP != 0 && FX_SIN_LERP != 1
#error "FX_SIN_LERP: 0 or 1"
#endif
#define FX_TRIG_SHIFT 30
int32_t fx_sin(fx_ang_t a);
int32_t fx_cos(fx_ang_t a);

#endif
