/* test_fixed.c - 16.16 arithmetic and trig tables against a double-precision
 * reference, over the whole input range with the extremes included. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <cmocka.h>
#include <math.h>

#include "fixed.h"

/* Deterministic sample of the int32 range: every small value, powers of two and
 * their neighbours, the extremes, and a pseudo-random spread. */
static int32_t sample(uint32_t i)
{
    static const int32_t edges[] = {0,
                                    1,
                                    -1,
                                    2,
                                    -2,
                                    65535,
                                    65536,
                                    65537,
                                    -65536,
                                    -65537,
                                    32768,
                                    -32768,
                                    INT32_MAX,
                                    INT32_MIN,
                                    INT32_MAX - 1,
                                    INT32_MIN + 1,
                                    46340 << 16,
                                    181 << 16,
                                    -(181 << 16),
                                    0x7FFF0000,
                                    -0x7FFF0000,
                                    0x00010001,
                                    3,
                                    100};
    uint32_t n = sizeof edges / sizeof edges[0];
    if (i < n) return edges[i];
    uint32_t x = i * 2654435761u;
    x ^= x >> 15;
    x *= 2246822519u;
    x ^= x >> 13;
    switch (i % 4) {
    case 0: return (int32_t)x;       /* anywhere */
    case 1: return (int32_t)x >> 8;  /* |v| < 128 */
    case 2: return (int32_t)x >> 16; /* |v| < 1/2 */
    default: return (int32_t)(1u << (x % 31)) * ((x & 1u) ? -1 : 1);
    }
}

static double clampd(double v)
{
    if (v > INT32_MAX) return INT32_MAX;
    if (v < INT32_MIN) return INT32_MIN;
    return v;
}

static void test_mul(void **state)
{
    (void)state;
    for (uint32_t i = 0; i < 3000; i++)
        for (uint32_t j = 0; j < 300; j++) {
            int32_t a = sample(i), b = sample(j * 7 + 1);
            double ref = clampd(floor((double)a * (double)b / 65536.0));
            assert_int_equal(fx_mul(a, b), (int32_t)ref);
        }
}

static void test_div(void **state)
{
    (void)state;
    for (uint32_t i = 0; i < 3000; i++)
        for (uint32_t j = 0; j < 300; j++) {
            int32_t a = sample(i), b = sample(j * 5 + 3);
            int32_t got = fx_div(a, b);
            if (b == 0) {
                assert_int_equal(got, a >= 0 ? FX_MAX : FX_MIN);
                continue;
            }
            double ref = clampd(trunc((double)a * 65536.0 / (double)b));
            assert_int_equal(got, (int32_t)ref);
        }
}

static void test_recip(void **state)
{
    (void)state;
    assert_int_equal(fx_recip(FX_ONE), FX_ONE);
    assert_int_equal(fx_recip(2 * FX_ONE), FX_HALF);
    assert_int_equal(fx_recip(0), FX_MAX);
    assert_int_equal(fx_recip(1), FX_MAX); /* 65536: saturates */
    assert_int_equal(fx_recip(-1), FX_MIN);
    assert_int_equal(fx_recip(INT32_MIN), -2); /* 1 / -32768 = -2^-15 = -2 raw */
    assert_int_equal(fx_recip(2), FX_MAX);     /* 2^31 does not fit */
    for (uint32_t i = 0; i < 100000; i++) {
        int32_t a = sample(i);
        if (a == 0) continue;
        double ref = clampd(trunc(4294967296.0 / (double)a));
        assert_int_equal(fx_recip(a), (int32_t)ref);
    }
}

static void test_floor_and_shift(void **state)
{
    (void)state;
    for (uint32_t i = 0; i < 200000; i++) {
        int32_t a = sample(i);
        assert_int_equal(fx_floor_int(a), (int32_t)floor((double)a / 65536.0));
        int64_t big = (int64_t)a * 77777 - 12345;
        for (unsigned s = 0; s < 40; s += 7)
            assert_true(fx_asr64(big, s) == (int64_t)floor((double)big / ldexp(1.0, (int)s)));
    }
    assert_int_equal(fx_from_int(32767), 32767 << 16);
    assert_int_equal(fx_from_int(-32768), INT32_MIN);
    assert_int_equal(fx_from_int(40000), FX_MAX);
    assert_int_equal(fx_from_int(-40000), FX_MIN);
    assert_int_equal(fx_sat32((int64_t)1 << 40), INT32_MAX);
    assert_int_equal(fx_sat32(-((int64_t)1 << 40)), INT32_MIN);
}

/* The 32-bit long division (FX_DIV32 targets) against the 64-bit divide, over
 * divisors of every size and quotients up to 2^32 - 1, both normalisation
 * corrections included (divisors just above a power of two, dividends just
 * below a multiple), and its signed floor form. */
static void test_udiv64_32(void **state)
{
    (void)state;
    uint64_t x = 0x9E3779B97F4A7C15ull;
    for (uint32_t i = 0; i < 2000000; i++) {
        x ^= x << 13;
        x ^= x >> 7;
        x ^= x << 17;
        uint32_t d = (uint32_t)(x >> 32) >> (i % 32);
        if (i % 5 == 0) d = (1u << (i % 32)) + (uint32_t)(i & 3u) - 1u;
        if (d == 0) d = 1;
        uint32_t q = (uint32_t)x >> ((i >> 5) % 32);
        if (i % 7 == 0) q = 0xFFFFFFFFu - (i & 7u);
        uint64_t r = (uint64_t)(x % d);
        if (i % 3 == 0) r = d - 1u;
        uint64_t n = (uint64_t)q * d + r; /* < d * 2^32 */
        uint32_t got_r, got_q = fx_udiv64_32(n, d, &got_r);
        if (got_q != n / d || got_r != n % d) fail_msg("%llu / %u: %u rem %u", (unsigned long long)n, d, got_q, got_r);
        int64_t sn = (int64_t)(n >> 2) * ((i & 1u) ? -1 : 1);
        if (d >= 2u && (uint64_t)(sn < 0 ? -sn : sn) / d < 0x7FFFFFFEu) {
            int64_t want = sn / d - ((sn % (int64_t)d) < 0);
            int32_t sq = fx_floordiv64_32(sn, d, &got_r);
            if (sq != want || (int64_t)got_r != sn - want * (int64_t)d)
                fail_msg("floor %lld / %u: %d rem %u", (long long)sn, d, sq, got_r);
        }
    }
    uint32_t r;
    assert_int_equal(fx_udiv64_32(0, 7, &r), 0);
    assert_int_equal(fx_udiv64_32(0xFFFFFFFEFFFFFFFFull, 0xFFFFFFFFu, &r), 0xFFFFFFFFu); /* the largest quotient */
    assert_int_equal(r, 0xFFFFFFFEu);
    assert_int_equal(fx_udiv64_32((uint64_t)1 << 32, 1, &r), 0xFFFFFFFFu); /* outside the contract: defined */
    assert_int_equal(fx_udiv64_32(5, 0, &r), 0xFFFFFFFFu);
}

static void test_trig(void **state)
{
    (void)state;
    const double two_pi = 6.283185307179586;
    double worst = 0;
    for (uint64_t k = 0; k < (1ull << 32); k += 9973) {
        fx_ang_t a = (fx_ang_t)k;
        double ang = (double)a / 4294967296.0 * two_pi;
        double es = fabs(fx_sin(a) / 1073741824.0 - sin(ang));
        double ec = fabs(fx_cos(a) / 1073741824.0 - cos(ang));
        if (es > worst) worst = es;
        if (ec > worst) worst = ec;
    }
    assert_true(worst <= ldexp(1.0, -24));
    /* quadrant angles are exact */
    assert_int_equal(fx_sin(0), 0);
    assert_int_equal(fx_cos(0), 1 << 30);
    assert_int_equal(fx_sin(0x40000000u), 1 << 30);
    assert_int_equal(fx_cos(0x40000000u), 0);
    assert_int_equal(fx_sin(0x80000000u), 0);
    assert_int_equal(fx_cos(0x80000000u), -(1 << 30));
    assert_int_equal(fx_sin(0xC0000000u), -(1 << 30));
    assert_int_equal(fx_sin(0xFFFFFFFFu) <= 0, 1);
}

static void test_angles(void **state)
{
    (void)state;
    assert_int_equal(fx_ang_from_deg(0), 0u);
    assert_int_equal(fx_ang_from_deg(90 << 16), 0x40000000u);
    assert_int_equal(fx_ang_from_deg(180 << 16), 0x80000000u);
    assert_int_equal(fx_ang_from_deg(-90 * 65536), 0xC0000000u);
    assert_int_equal(fx_ang_from_deg(360 << 16), 0u);
    assert_int_equal(fx_ang_from_deg(INT32_MAX) != 0, 1);
    for (uint32_t i = 0; i < 100000; i++) {
        int32_t d = sample(i);
        double turns = (double)d / 65536.0 / 360.0;
        double ref = floor(turns * 4294967296.0 + 0.5);
        uint32_t want = (uint32_t)(int64_t)fmod(ref, 4294967296.0);
        uint32_t got = fx_ang_from_deg(d);
        int32_t diff = (int32_t)(got - want);
        assert_true(diff >= -1 && diff <= 1); /* double rounding of the reference */
    }
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_mul),       cmocka_unit_test(test_div),
        cmocka_unit_test(test_recip),     cmocka_unit_test(test_floor_and_shift),
        cmocka_unit_test(test_udiv64_32), cmocka_unit_test(test_trig),
        cmocka_unit_test(test_angles),
    };
    return cmocka_run_group_tests_name("fixed", tests, NULL, NULL);
}
