/* test_texture.c - a floor's texels follow the format's addressing whatever the
 * texture's shape: texel (u, v) = texels[(u & wmask) << hbits | (v & hmask)]
 * (scene_format.h). A 64 x 64 flat and the same flat repeated down 128, 256 and
 * 512 rows address the same texel at every (u, v), so every span of a floor
 * drawn with any of them is the same pixels, though texture.c reads the common
 * shapes (64 x 64, 128 rows) through its own constant shifts and masks. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>
#include <string.h>

#include <cmocka.h>

#include "scene.h"
#include "texture.h"
#include "view.h"

#define U(v) ((fx_t)((int64_t)(v)*65536))
#define FLAT_BITS 6
static const uint8_t TALL_BITS[] = {FLAT_BITS, 7, 8, 9};
#define NTEX (sizeof TALL_BITS / sizeof TALL_BITS[0])

static uint8_t lights[SCN_LIGHT_MAPS * 256];
static uint8_t texels[NTEX << (FLAT_BITS + 9)];

static void test_floor_texels_follow_the_format(void **state)
{
    (void)state;
    /* light tables that keep the texel, so the pixels are the texels read */
    for (int t = 0; t < SCN_LIGHT_MAPS; t++)
        for (int c = 0; c < 256; c++) lights[t * 256 + c] = (uint8_t)c;
    scn_texture tex[NTEX];
    uint32_t first = 0;
    for (size_t k = 0; k < NTEX; k++) {
        tex[k] = (scn_texture){first, FLAT_BITS, TALL_BITS[k], 0, 0, (uint16_t)(1u << TALL_BITS[k]), 0};
        for (uint32_t u = 0; u < 1u << FLAT_BITS; u++)
            for (uint32_t v = 0; v < 1u << TALL_BITS[k]; v++) /* no two texels of the flat alike */
                texels[first + (u << TALL_BITS[k] | v)] = (uint8_t)(((v & 63) * 64 + u) * 37 >> 4);
        first += 1u << (FLAT_BITS + TALL_BITS[k]);
    }
    scene sc;
    memset(&sc, 0, sizeof sc);
    sc.lights = lights;
    sc.nlights = SCN_LIGHT_MAPS;
    sc.textures = tex;
    sc.ntextures = NTEX;
    sc.texels = texels;
    sc.ntexels = first;
    static const int32_t angles[] = {0, 33, 90, 200, 271};
    uint32_t differ = 0;
    for (size_t a = 0; a < sizeof angles / sizeof angles[0]; a++) {
        camera cam = {U(1000) + 12345, U(-77) + 999, U(41), U(angles[a]), 0};
        view_xform v;
        view_setup(&v, &cam);
        for (int y = VIEW_H / 2 + 1; y < VIEW_H; y++) {
            uint8_t want[VIEW_W], got[VIEW_W];
            tex_paint p = tex_plane(&sc, &v, 0, 0, 200, 0);
            tex_span(&p, y, 0, VIEW_W, want);
            for (uint32_t c = 1; c < VIEW_W; c++) differ += want[c] != want[0];
            for (size_t k = 1; k < NTEX; k++) {
                tex_paint q = tex_plane(&sc, &v, (uint32_t)k, 0, 200, 0);
                tex_span(&q, y, 0, VIEW_W, got);
                assert_memory_equal(got, want, VIEW_W);
            }
        }
    }
    assert_true(differ > 0); /* the floor shows the texture, not one colour */
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_floor_texels_follow_the_format),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
