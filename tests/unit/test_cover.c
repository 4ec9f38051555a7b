/* test_cover.c - the coverage bit mask against a byte per pixel, over random runs
 * with every word boundary and both screen edges among them. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <cmocka.h>

#include "cover.h"

static cov_mask mask;
static uint8_t model[VIEW_H][VIEW_W];

static uint32_t rng_state = 12345u;
static uint32_t rnd(uint32_t n)
{
    rng_state = rng_state * 1664525u + 1013904223u;
    return (rng_state >> 8) % n;
}

/* A run end: often on or beside a word boundary or a screen edge. */
static int run_end(void)
{
    if (rnd(3) == 0) {
        int w = (int)rnd(COV_WORDS + 1) * 32 + (int)rnd(3) - 1;
        return w < 0 ? 0 : (w > VIEW_W ? VIEW_W : w);
    }
    return (int)rnd(VIEW_W + 1);
}

static void check_row(int y)
{
    int full = 1;
    for (int x = 0; x < VIEW_W; x++) full &= model[y][x];
    assert_int_equal(cov_row_full(&mask, y), full);
    for (int k = 0; k < 40; k++) {
        int a = run_end(), b = run_end();
        int all = 1, first_clear = b, first_set = b;
        for (int x = a; x < b; x++) {
            all &= model[y][x];
            if (!model[y][x] && first_clear == b) first_clear = x;
            if (model[y][x] && first_set == b) first_set = x;
        }
        if (b < a) first_clear = first_set = b; /* an empty run: nothing found */
        assert_int_equal(cov_all(&mask, y, a, b), all);
        assert_int_equal(cov_next_clear(&mask, y, a, b), a >= b ? b : first_clear);
        assert_int_equal(cov_next_set(&mask, y, a, b), a >= b ? b : first_set);
    }
}

static void test_against_model(void **state)
{
    (void)state;
    cov_clear(&mask);
    for (int y = 0; y < VIEW_H; y++)
        for (int x = 0; x < VIEW_W; x++) model[y][x] = 0;
    for (int round = 0; round < 60; round++) {
        for (int k = 0; k < 400; k++) {
            int y = (int)rnd(VIEW_H), a = run_end(), b = run_end();
            cov_set(&mask, y, a, b);
            for (int x = a; x < b; x++) model[y][x] = 1;
        }
        int rows = 0;
        for (int y = 0; y < VIEW_H; y++) {
            check_row(y);
            rows += cov_row_full(&mask, y);
        }
        assert_int_equal(mask.full_rows, rows);
        assert_int_equal(cov_full(&mask), rows == VIEW_H);
    }
}

static void test_whole_screen(void **state)
{
    (void)state;
    cov_clear(&mask);
    assert_int_equal(cov_next_set(&mask, 7, 0, VIEW_W), VIEW_W);
    assert_int_equal(cov_next_clear(&mask, 7, 0, VIEW_W), 0);
    for (int y = 0; y < VIEW_H; y++) {
        assert_false(cov_full(&mask));
        cov_set(&mask, y, 0, 31);
        cov_set(&mask, y, 31, VIEW_W);
        cov_set(&mask, y, 5, 9); /* again: a full row stays counted once */
    }
    assert_true(cov_full(&mask));
    assert_int_equal(mask.full_rows, VIEW_H);
    assert_true(cov_all(&mask, 199, 0, VIEW_W));
    assert_int_equal(cov_next_clear(&mask, 199, 0, VIEW_W), VIEW_W);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_against_model),
        cmocka_unit_test(test_whole_screen),
    };
    return cmocka_run_group_tests_name("cover", tests, NULL, NULL);
}
