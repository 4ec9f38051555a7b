/* test_boot.c - the display board's bootloader checks, on the host under ASan and
 * UBSan: boot_vectors_refusal (hal/board/boot_vectors.c) at each of its bounds, the
 * largest value it takes and one past it. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>

#include <cmocka.h>

#include "board/board_layout.h"
#include "board/boot_vectors.h"

#define APP BOARD_SLOT_ADDR
#define LEN 5000u
#define SP_OK (BOARD_RAM_ORIGIN + 0x8000u)
#define RESET_OK (APP + 0x100u + 1u)

static int ok(uint32_t sp, uint32_t reset, uint32_t len)
{
    return boot_vectors_refusal(sp, reset, APP, len) == NULL;
}

static void test_stack_pointer_bounds(void **state)
{
    (void)state;
    assert_true(ok(SP_OK, RESET_OK, LEN));
    assert_true(ok(BOARD_RAM_END, RESET_OK, LEN));          /* the RAM's end: the largest */
    assert_false(ok(BOARD_RAM_END + 4u, RESET_OK, LEN));    /* one word past it */
    assert_true(ok(BOARD_RAM_ORIGIN + 4u, RESET_OK, LEN));  /* the smallest: one word of stack */
    assert_false(ok(BOARD_RAM_ORIGIN, RESET_OK, LEN));      /* no stack at all */
    assert_false(ok(BOARD_RAM_ORIGIN + 2u, RESET_OK, LEN)); /* not a word address */
    assert_false(ok(0, RESET_OK, LEN));
    assert_false(ok(0xFFFFFFFCu, RESET_OK, LEN));
    assert_false(ok(APP + 0x100u, RESET_OK, LEN)); /* in flash, not RAM */
}

static void test_reset_vector_bounds(void **state)
{
    (void)state;
    assert_true(ok(SP_OK, APP + 1u, LEN));             /* the first halfword */
    assert_false(ok(SP_OK, APP - 2u + 1u, LEN));       /* one halfword before the image */
    assert_true(ok(SP_OK, APP + LEN - 2u + 1u, LEN));  /* the last halfword: the largest */
    assert_false(ok(SP_OK, APP + LEN + 1u, LEN));      /* just past the image */
    assert_false(ok(SP_OK, APP + LEN - 1u + 1u, LEN)); /* a halfword cut by the end */
    assert_false(ok(SP_OK, RESET_OK - 1u, LEN));       /* no Thumb bit */
    assert_false(ok(SP_OK, 0xFFFFFFFFu, LEN));
    assert_false(ok(SP_OK, 1u, LEN));
}

static void test_length_bounds(void **state)
{
    (void)state;
    assert_true(ok(SP_OK, APP + 6u + 1u, 8u)); /* a vector table alone, its reset in its second word */
    assert_false(ok(SP_OK, APP + 1u, 7u));     /* too short for two words */
    assert_false(ok(SP_OK, APP + 1u, 0u));
}

/* 5,000 random bytes with a good CRC (the case): almost never both words
 * pass; over many such images the check takes only those that do. */
static void test_random_images(void **state)
{
    (void)state;
    uint32_t x = 12345, taken = 0;
    for (int i = 0; i < 100000; i++) {
        x = x * 1103515245u + 12345u;
        uint32_t sp = x;
        x = x * 1103515245u + 12345u;
        uint32_t reset = x;
        if (ok(sp, reset, LEN)) {
            taken++;
            assert_true(sp > BOARD_RAM_ORIGIN && sp <= BOARD_RAM_END && (reset & 1u));
        }
    }
    assert_true(taken < 10);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_stack_pointer_bounds),
        cmocka_unit_test(test_reset_vector_bounds),
        cmocka_unit_test(test_length_bounds),
        cmocka_unit_test(test_random_images),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
