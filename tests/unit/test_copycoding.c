/* test_copycoding.c - the COPY picture coding (hal/serial/fl_copy.c) on its own:
 * round trips of pictures that exercise every kind of copy, the bound on a
 * coded picture's size, and the decoder's every check on untrusted data at its
 * bound (the largest valid value and one past it), written token by token with
 * the coder's own primitives. The file includes fl_copy.c to reach them; the
 * encoder's output is caught before COBS (fl_writer_direct below). */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#include <cmocka.h>

#define fl_writer_direct catch_bytes
#include "../../hal/serial/fl_copy.c"
#undef fl_writer_direct

static uint8_t caught[FL_FRAME_BYTES + 4096];
static uint32_t ncaught;

void catch_bytes(fl_writer *w, const uint8_t *p, uint32_t n)
{
    (void)w;
    assert_true(ncaught + n <= sizeof caught);
    memcpy(caught + ncaught, p, n);
    ncaught += n;
}

static uint32_t rng = 1;
static uint32_t rnd(void)
{
    rng = rng * 1103515245u + 12345u;
    return rng >> 8;
}

static fl_copy_model model;
static int32_t hash[FL_CP_HASH];
static _Alignas(4) uint8_t pic[FL_FRAME_BYTES], base[FL_FRAME_BYTES], out[FL_FRAME_BYTES];

static uint32_t encode(const uint8_t *px, const uint8_t *b, int with_hash)
{
    fl_writer w;
    ncaught = 0;
    uint32_t n = fl_copy_encode(&model, px, b, with_hash ? hash : NULL, &w);
    assert_int_equal(n, ncaught);
    assert_true(n <= FL_FRAME_BYTES + FL_CP_SLACK + 16);
    return n;
}

static void round_trip(const uint8_t *px, const uint8_t *b)
{
    for (int h = 0; h < 2; h++) {
        uint32_t n = encode(px, b, h);
        memset(out, 0xA5, sizeof out);
        assert_int_equal(fl_copy_decode(&model, caught, n, b, out), 0);
        assert_memory_equal(out, px, FL_FRAME_BYTES);
    }
}

/* Pictures of every shape: one colour, noise (the escape), stripes both ways,
 * a checkerboard, a gradient, and the base moved (a copy from the base that
 * runs on into this frame) for a delta. */
static void test_round_trips(void **state)
{
    (void)state;
    for (int kind = 0; kind < 7; kind++) {
        rng = (uint32_t)kind + 1u;
        for (uint32_t i = 0; i < FL_FRAME_BYTES; i++) {
            uint32_t x = i % FL_W, y = i / FL_W;
            uint8_t v = kind == 0   ? 17
                        : kind == 1 ? (uint8_t)rnd()
                        : kind == 2 ? (uint8_t)(x / 3 * 7)
                        : kind == 3 ? (uint8_t)(y * 5)
                        : kind == 4 ? (uint8_t)((x ^ y) & 1 ? 200 : 3)
                        : kind == 5 ? (uint8_t)(x + y)
                                    : (uint8_t)(rnd() % 6 == 0 ? rnd() : x / 4 + y / 2);
            pic[i] = v;
            base[i] = (uint8_t)(kind == 1 ? rnd() : v ^ (uint8_t)(rnd() % 16 == 0));
        }
        round_trip(pic, NULL);
        round_trip(pic, base);
        /* the base moved by 7 rows and 5 columns */
        for (uint32_t i = 0; i < FL_FRAME_BYTES; i++) base[i] = pic[(i + 7u * FL_W + 5u) % FL_FRAME_BYTES];
        round_trip(pic, base);
    }
}

/* Noise costs at most its raw size and the slack: it goes through the escape. */
static void test_noise_bound(void **state)
{
    (void)state;
    rng = 77;
    for (uint32_t i = 0; i < FL_FRAME_BYTES; i++) pic[i] = (uint8_t)rnd();
    uint32_t n = encode(pic, NULL, 1);
    assert_true(n > FL_FRAME_BYTES);
    assert_true(n <= FL_FRAME_BYTES + FL_CP_SLACK + 16);
    assert_int_equal(fl_copy_decode(&model, caught, n, NULL, out), 0);
    assert_memory_equal(out, pic, FL_FRAME_BYTES);
}

/* Damaged data never writes outside the picture and never decodes silently to
 * a different picture under the same pixel hash: every bit of a coded
 * picture's first bytes flipped, and every truncation of it. */
static void test_damage(void **state)
{
    (void)state;
    rng = 5;
    for (uint32_t i = 0; i < FL_FRAME_BYTES; i++) pic[i] = (uint8_t)(i % FL_W / 9 * 3 + (rnd() % 50 == 0));
    uint32_t n = encode(pic, NULL, 1);
    uint32_t h = fl_pixel_hash(pic);
    static uint8_t dmg[FL_FRAME_BYTES + 4096];
    memcpy(dmg, caught, n);
    uint32_t lim = n < 400 ? n : 400;
    for (uint32_t i = 0; i < lim * 8; i++) {
        dmg[i / 8] ^= (uint8_t)(1u << (i % 8));
        if (fl_copy_decode(&model, dmg, n, NULL, out) == 0)
            assert_true(memcmp(out, pic, FL_FRAME_BYTES) == 0 || fl_pixel_hash(out) != h);
        dmg[i / 8] ^= (uint8_t)(1u << (i % 8));
    }
    for (uint32_t k = 0; k < n; k++) assert_int_equal(fl_copy_decode(&model, caught, k, NULL, out), -1);
    /* a byte too many */
    caught[n] = 0;
    assert_int_equal(fl_copy_decode(&model, caught, n + 1, NULL, out), -1);
}

/* ---- streams written token by token, to reach each check at its bound ---- */

typedef struct {
    rc_enc r;
    fl_copy_model m;
    fl_writer w;
    uint32_t state;
} tok;

static void tok_begin(tok *t, int delta)
{
    memset(t, 0, sizeof *t);
    t->r.range = 0xFFFFFFFFu;
    t->r.pending = 1;
    t->r.w = &t->w;
    t->state = K_LIT;
    model_reset(&t->m, delta);
    ncaught = 0;
}

static void tok_lit(tok *t, uint8_t v, uint8_t left)
{
    enc_bit(&t->r, t->m.p + P_IS_COPY + t->state, 0);
    enc_tree(&t->r, t->m.p + LIT_CTX(left), v, 8);
    t->state = K_LIT;
}

/* a copy with a new offset: in_base, the zigzag row and column codes as sent */
static void tok_new(tok *t, uint32_t in_base, uint32_t zy, uint32_t zx, uint32_t len, int32_t off)
{
    enc_bit(&t->r, t->m.p + P_IS_COPY + t->state, 1);
    enc_bit(&t->r, t->m.p + P_IS_REP0 + t->state, 0);
    enc_bit(&t->r, t->m.p + P_IS_REP + t->state, 0);
    enc_bit(&t->r, t->m.p + P_IS_NEAR + t->state, 0);
    enc_bit(&t->r, t->m.p + P_IN_BASE + t->state, in_base);
    enc_gamma(&t->r, t->m.p + P_DY, 4, t->m.p + P_DY_HI, zy + 1u);
    enc_gamma(&t->r, t->m.p + P_DX, 4, t->m.p + P_DX_HI, zx + 1u);
    if (len) {
        rep_push(&t->m, off);
        enc_gamma(&t->r, t->m.p + P_LEN + 32 * (K_NEW - 1), 5, t->m.p + P_LEN_HI + 64 * (K_NEW - 1), len);
        t->state = K_NEW;
    }
}

/* a copy from the left neighbour (offset 1, a "near" copy) */
static void tok_left(tok *t, uint32_t len)
{
    enc_bit(&t->r, t->m.p + P_IS_COPY + t->state, 1);
    enc_bit(&t->r, t->m.p + P_IS_REP0 + t->state, 0);
    enc_bit(&t->r, t->m.p + P_IS_REP + t->state, 0);
    enc_bit(&t->r, t->m.p + P_IS_NEAR + t->state, 1);
    enc_tree(&t->r, t->m.p + P_NEAR_TREE + 4 * t->state, 0, 2);
    rep_push(&t->m, 1);
    enc_gamma(&t->r, t->m.p + P_LEN + 32 * (K_NEAR - 1), 5, t->m.p + P_LEN_HI + 64 * (K_NEAR - 1), len);
    t->state = K_NEAR;
}

static uint32_t tok_end(tok *t)
{
    enc_flush(&t->r);
    return ncaught;
}

static int tok_decode(tok *t, const uint8_t *b)
{
    return fl_copy_decode(&model, caught, tok_end(t), b, out);
}

/* A copy's length: to the picture's end exactly, and one more. */
static void test_length_bound(void **state)
{
    (void)state;
    for (uint32_t extra = 0; extra < 2; extra++) {
        tok t;
        tok_begin(&t, 0);
        tok_lit(&t, 9, 0);
        tok_left(&t, FL_FRAME_BYTES - 1u + extra);
        assert_int_equal(tok_decode(&t, NULL), extra ? -1 : 0);
        if (!extra)
            for (uint32_t i = 0; i < FL_FRAME_BYTES; i++) assert_int_equal(out[i], 9);
    }
}

/* A new offset into this frame reaching back to pixel 0 exactly, and one
 * further; into the base, to the base's first pixel exactly, and one further;
 * and a keyframe, which has no base, refuses the same copy. */
static void test_offset_bounds(void **state)
{
    (void)state;
    memset(base, 4, sizeof base);
    for (uint32_t over = 0; over < 2; over++) {
        /* this frame: 321 literals, then a copy from 321 + over pixels back
         * (1 row and 1 + over columns: zigzag 2 * (1 + over)) */
        tok t;
        tok_begin(&t, 0);
        for (uint32_t i = 0; i < FL_W + 1; i++) tok_lit(&t, (uint8_t)(i + 1), (uint8_t)i);
        uint32_t pos = FL_W + 1, zx = 2u * (1u + over);
        tok_new(&t, 0, 1, zx, FL_FRAME_BYTES - pos, (int32_t)(FL_W + 1 + over));
        int rc = tok_decode(&t, NULL);
        assert_int_equal(rc, over ? -1 : 0);
        if (!over) assert_int_equal(out[pos], 1);
    }
    for (uint32_t over = 0; over < 2; over++) {
        /* the base: at pixel 0, the motion -over (dy 0, dx -over: zigzag 2 * over - 1 or 0) */
        for (int delta = 1; delta >= 0; delta--) {
            tok t;
            tok_begin(&t, delta);
            tok_new(&t, 1, 0, over ? 1u : 0u, FL_FRAME_BYTES, OFF_BASE + (int32_t)over);
            int rc = tok_decode(&t, delta ? base : NULL);
            assert_int_equal(rc, delta && !over ? 0 : -1);
        }
    }
}

/* A new offset's codes: rows up to 2 * 200 and columns up to 320 are read (and
 * the copy judged by where it lands); one more is refused outright. */
static void test_code_bounds(void **state)
{
    (void)state;
    memset(base, 6, sizeof base);
    static const struct {
        uint32_t zy, zx;
        int ok;
    } cases[] = {
        {2 * FL_H, 0, 0},     /* 200 rows down in the base: outside the picture */
        {2 * FL_H + 1, 0, 0}, /* past the code's bound */
        {0, FL_W, 1},         /* 160 columns right in the base, a copy of 1 */
        {0, FL_W + 1, 0},     /* past the code's bound */
    };
    for (uint32_t k = 0; k < sizeof cases / sizeof cases[0]; k++) {
        tok t;
        tok_begin(&t, 1);
        tok_new(&t, 1, cases[k].zy, cases[k].zx, 1, 0);
        tok_left(&t, FL_FRAME_BYTES - 1u);
        assert_int_equal(tok_decode(&t, base), cases[k].ok ? 0 : -1);
    }
}

/* The escape: exactly the rest of the picture plain after it, not a byte more
 * or less. */
static void test_escape_bound(void **state)
{
    (void)state;
    for (int diff = -1; diff <= 1; diff++) {
        tok t;
        tok_begin(&t, 0);
        tok_lit(&t, 1, 0);
        tok_new(&t, 0, 0, 0, 0, 0); /* offset 0 in this frame: the escape */
        uint32_t n = tok_end(&t);
        uint32_t rest = (uint32_t)((int)(FL_FRAME_BYTES - 1) + diff);
        memset(caught + n, 2, rest);
        assert_int_equal(fl_copy_decode(&model, caught, n + rest, NULL, out), diff ? -1 : 0);
        if (!diff) assert_int_equal(out[FL_FRAME_BYTES - 1], 2);
    }
}

/* The first byte of a coded picture is always 0 (the coder's start). */
static void test_first_byte(void **state)
{
    (void)state;
    memset(pic, 3, sizeof pic);
    uint32_t n = encode(pic, NULL, 0);
    assert_int_equal(caught[0], 0);
    assert_int_equal(fl_copy_decode(&model, caught, n, NULL, out), 0);
    caught[0] = 1;
    assert_int_equal(fl_copy_decode(&model, caught, n, NULL, out), -1);
    assert_int_equal(fl_copy_decode(&model, caught, 0, NULL, out), -1);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_round_trips),  cmocka_unit_test(test_noise_bound),   cmocka_unit_test(test_damage),
        cmocka_unit_test(test_length_bound), cmocka_unit_test(test_offset_bounds), cmocka_unit_test(test_code_bounds),
        cmocka_unit_test(test_escape_bound), cmocka_unit_test(test_first_byte),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
