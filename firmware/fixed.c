/* fixed.c - 16.16 multiply, divide, reciprocal and table-driven sine/cosine.
 * The sine table (fx_sin_quarter) is generated at build time by tools/gen_tables.c. */
#include "fixed.h"

/* sin(i * pi/2 / 2^FX_SIN_BITS) in 2.30 for i = 0..2^FX_SIN_BITS (build/gen/fx_tables.c). */
#define SIN_N (1u << FX_SIN_BITS)
extern const int32_t fx_sin_quarter[SIN_N + 1];

fx_t fx_mul(fx_t a, fx_t b)
{
    return fx_sat32(fx_asr64((int64_t)a * b, FX_SHIFT));
}

fx_t fx_div(fx_t a, fx_t b)
{
    if (b == 0) return (a >= 0) ? FX_MAX : FX_MIN;
    /* |a| * 2^16 < 2^47 and the quotient's magnitude is at most that: no overflow. */
    return fx_sat32(((int64_t)a * FX_ONE) / b);
}

fx_t fx_recip(fx_t a)
{
    return fx_div(FX_ONE, a);
}

fx_ang_t fx_ang_from_deg(fx_t deg)
{
    /* turns = deg / 360; angle = turns * 2^32 = deg_raw * 2^16 / 360, rounded to
     * nearest. |deg_raw * 2^16| < 2^47: fits. Floor division keeps negatives exact. */
    int64_t n = (int64_t)deg * 65536 + 180;
    int64_t q = n / 360;
    if (n % 360 < 0) q -= 1;
    return (fx_ang_t)(uint64_t)q;
}

/* sin over the first quadrant for p in [0, 2^30] (a quarter turn); entries are
 * 2^(30 - FX_SIN_BITS) angle units apart. */
#define SIN_GAP (30 - FX_SIN_BITS)
static int32_t sin_quadrant(uint32_t p)
{
#if FX_SIN_LERP
    uint32_t i = p >> SIN_GAP;
    if (i >= SIN_N) return fx_sin_quarter[SIN_N];
    int32_t a = fx_sin_quarter[i];
    int32_t d = fx_sin_quarter[i + 1] - a;
    /* |d| < 2^30 * pi / 32 and the fraction < 2^26: the product is below 2^53 */
    return a + (int32_t)fx_asr64((int64_t)d * (int64_t)(p & ((1u << SIN_GAP) - 1u)), SIN_GAP);
#else
    return fx_sin_quarter[(p + (1u << (SIN_GAP - 1))) >> SIN_GAP]; /* p <= 2^30: at most SIN_N */
#endif
}

int32_t fx_sin(fx_ang_t a)
{
    uint32_t quadrant = a >> 30;
    uint32_t p = a & 0x3FFFFFFFu;
    int32_t v = (quadrant & 1u) ? sin_quadrant(0x40000000u - p) : sin_quadrant(p);
    return (quadrant & 2u) ? -v : v;
}

int32_t fx_cos(fx_ang_t a)
{
    return fx_sin(a + 0x40000000u);
}

uint64_t fx_isqrt64(uint64_t v)
{
    uint64_t r = 0, bit = (uint64_t)1 << 62;
    while (bit > v) bit >>= 2;
    while (bit) {
        if (v >= r + bit) {
            v -= r + bit;
            r = (r >> 1) + bit;
        } else {
            r >>= 1;
        }
        bit >>= 2;
    }
    return r;
}
