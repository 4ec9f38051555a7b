/* test_scene.c - the compiled-scene loader never trusts its input: every header
 * field, offset, count and index is checked, and damaged blobs (with the CRC
 * recomputed, so the damage reaches the structural checks) are refused or, if
 * accepted, render without touching memory outside the blob (ASan watches). */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <cmocka.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "bspc.h"
#include "crc32.h"
#include "engine.h"
#include "hal_null.h"
#include "scene.h"

static uint8_t *blob;
static size_t blob_len;

static int setup(void **state)
{
    (void)state;
    char err[256];
    bspc_options opt = bspc_defaults();
    if (bspc_compile("tests/scenes/default.scene", &opt, &blob, &blob_len, NULL, err, sizeof err) != 0) {
        fprintf(stderr, "%s\n", err);
        return -1;
    }
    return 0;
}

static int teardown(void **state)
{
    (void)state;
    free(blob);
    return 0;
}

static void fix_crc(uint8_t *b, size_t len)
{
    uint32_t crc = crc_update(0, b + 16, len - 16);
    memcpy(b + 12, &crc, 4);
}

static scene_status load_copy(const uint8_t *src, size_t len, scene_error *err)
{
    uint32_t *aligned = malloc(len + 4);
    memcpy(aligned, src, len);
    scene s;
    scene_status st = scene_load(&s, aligned, (uint32_t)len, err);
    if (st == SCENE_OK) {
        /* accepted: it must render within bounds */
        static engine e;
        hal_null_reset();
        assert_int_equal(eng_init(&e, aligned, (uint32_t)len, NULL), SCENE_OK);
        uint32_t need = eng_work_bytes(&e);
        void *work = malloc(need ? need : 1);
        assert_int_equal(eng_set_work(&e, work, need), 0);
        for (int m = 0; m < RENDER_MODE_COUNT; m++) {
            e.mode = (render_mode)m;
            eng_render(&e, NULL);
        }
        free(work);
    }
    free(aligned);
    return st;
}

static void test_good_blob_loads(void **state)
{
    (void)state;
    scene_error err;
    assert_int_equal(load_copy(blob, blob_len, &err), SCENE_OK);
}

static void test_header_damage(void **state)
{
    (void)state;
    uint8_t *b = malloc(blob_len);
    scene_error err;
    /* truncated anywhere */
    for (size_t n = 0; n < blob_len; n += 1 + n / 8) assert_int_equal(load_copy(blob, n, &err) != SCENE_OK, 1);
    /* each header byte flipped (the CRC fixed where it does not cover the byte) */
    for (size_t i = 0; i < sizeof(scn_header); i++) {
        if (i >= 12 && i < 16) continue;
        memcpy(b, blob, blob_len);
        b[i] ^= 0x5A;
        fix_crc(b, blob_len);
        scene_status st = load_copy(b, blob_len, &err);
        /* magic, version, sizes and the reserved flags must match exactly; the
         * player start, the root and the depth may change to other valid values
         * (load_copy has then rendered a frame from them under ASan) */
        if (i < 20) assert_int_not_equal(st, SCENE_OK);
    }
    /* a bad CRC */
    memcpy(b, blob, blob_len);
    b[blob_len - 1] ^= 1;
    assert_int_equal(load_copy(b, blob_len, &err), SCENE_ERR_CRC);
    /* misaligned in memory */
    uint8_t *odd = malloc(blob_len + 1);
    memcpy(odd + 1, blob, blob_len);
    scene s;
    assert_int_equal(scene_load(&s, odd + 1, (uint32_t)blob_len, &err), SCENE_ERR_ALIGN);
    free(odd);
    free(b);
}

/* Every 32-bit word of the body replaced by hostile values, CRC recomputed:
 * the loader refuses or the renderer survives it. */
static void test_body_damage(void **state)
{
    (void)state;
    static const uint32_t hostile[] = {0xFFFFFFFFu, 0x80000000u, 0x7FFFFFFFu, 0, 1, 0x80000001u, 0x10000};
    uint8_t *b = malloc(blob_len);
    uint32_t refused = 0, total = 0;
    for (size_t off = 16; off + 4 <= blob_len; off += 4)
        for (size_t k = 0; k < sizeof hostile / sizeof hostile[0]; k++) {
            memcpy(b, blob, blob_len);
            memcpy(b + off, &hostile[k], 4);
            fix_crc(b, blob_len);
            scene_error err;
            refused += load_copy(b, blob_len, &err) != SCENE_OK;
            total++;
        }
    assert_true(refused > 0 && refused <= total);
    free(b);
}

static void test_tree_must_be_a_tree(void **state)
{
    (void)state;
    uint8_t *b = malloc(blob_len);
    memcpy(b, blob, blob_len);
    scn_header *h = (scn_header *)(void *)b;
    if (h->sec[SCN_SEC_NODES].count >= 2) {
        scn_node *nodes = (scn_node *)(void *)(b + h->sec[SCN_SEC_NODES].offset);
        /* point the root's children at the root itself: a cycle */
        nodes[h->root].child[0] = h->root;
        fix_crc(b, blob_len);
        scene_error err;
        assert_int_equal(load_copy(b, blob_len, &err), SCENE_ERR_TREE);
    }
    free(b);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_good_blob_loads),
        cmocka_unit_test(test_header_damage),
        cmocka_unit_test(test_body_damage),
        cmocka_unit_test(test_tree_must_be_a_tree),
    };
    return cmocka_run_group_tests_name("scene", tests, setup, teardown);
}
