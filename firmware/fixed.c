/* fixed.c - 16.16 multiply, divide, reciprocal and table-driven sine/cosine.
 * The sine table (fx_sin_quarter) is generated at build time by tools/gen_tables.c. */
#include "fixed.h"

/* 4097 entries: sin(i * pi/2 / 4096) in 2.30 for i = 0..4096 (build/gen/fx_tables.c). */
extern const int32_t fx_sin_quarter[4097];

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

/* sin over the first quadrant for p in [0, 2^30] (a quarter turn), linearly
 * interpolated between table entries 2^18 angle units apart. */
static int32_t sin_quadrant(uint32_t p)
{
    uint32_t i = p >> 18;
    if (i >= 4096) return fx_sin_quarter[4096];
    int32_t a = fx_sin_quarter[i];
    int32_t d = fx_sin_quarter[i + 1] - a;
    return a + (int32_t)fx_asr64((int64_t)d * (int64_t)(p & 0x3FFFFu), 18);
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
