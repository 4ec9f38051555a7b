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

static scn_texture tex[NTEX];
static scene sc;

/* The flat and its taller copies in one scene with light tables that keep the
 * texel (the pixels are the texels read); every texel below 0x80. */
static int setup(void **state)
{
    (void)state;
    for (int t = 0; t < SCN_LIGHT_MAPS; t++)
        for (int c = 0; c < 256; c++) lights[t * 256 + c] = (uint8_t)c;
    uint32_t first = 0;
    for (size_t k = 0; k < NTEX; k++) {
        tex[k] = (scn_texture){first, FLAT_BITS, TALL_BITS[k], 0, 0, (uint16_t)(1u << TALL_BITS[k]), 0};
        for (uint32_t u = 0; u < 1u << FLAT_BITS; u++)
            for (uint32_t v = 0; v < 1u << TALL_BITS[k]; v++) /* rows repeat every 64 */
                texels[first + (u << TALL_BITS[k] | v)] = (uint8_t)((((v & 63) * 64 + u) * 37 >> 5) & 0x7F);
        first += 1u << (FLAT_BITS + TALL_BITS[k]);
    }
    memset(&sc, 0, sizeof sc);
    sc.lights = lights;
    sc.nlights = SCN_LIGHT_MAPS;
    sc.textures = tex;
    sc.ntextures = NTEX;
    sc.texels = texels;
    sc.ntexels = first;
    return 0;
}

static void test_floor_texels_follow_the_format(void **state)
{
    (void)state;
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

/* tex_span fills pixels [x0, x1) of the row and no other, for spans that start
 * and end anywhere within the subdivisions a wall is sampled at. */
static void test_span_writes_only_its_pixels(void **state)
{
    (void)state;
    camera cam = {U(3) + 777, U(-5) + 4321, U(41), U(10), 0};
    view_xform v;
    view_setup(&v, &cam);
    /* a wall 200 units east of the eye, across the view (its front faces west) */
    scn_vertex a = {U(200), U(1000)};
    scn_side sd = {0, -(1 << 30), 0, 0, {0, 0, 0}, 0, 0};
    static const int starts[] = {0, 1, 5, 7, 8, 13, 100, 155, 312, 317, 319};
    for (size_t k = 0; k < NTEX; k++) {
        tex_paint paints[2] = {tex_wall(&sc, &v, &sd, (uint32_t)k, &a, U(128), 160, 0),
                               tex_plane(&sc, &v, (uint32_t)k, 0, 160, 0)};
        for (int pi = 0; pi < 2; pi++)
            for (int y = VIEW_H / 2 + 3; y < VIEW_H; y += 17)
                for (size_t i = 0; i < sizeof starts / sizeof starts[0]; i++)
                    for (int x1 = starts[i] + 1; x1 <= VIEW_W; x1 += 1 + x1 / 16) {
                        int x0 = starts[i];
                        uint8_t row[VIEW_W + 16];
                        memset(row, 0xFF, sizeof row);
                        tex_span(&paints[pi], y, x0, x1, row);
                        for (int x = 0; x < VIEW_W + 16; x++)
                            if (x < x0 || x >= x1) {
                                if (row[x] != 0xFF) fprintf(stderr, "paint %d: [%d, %d) wrote %d\n", pi, x0, x1, x);
                                assert_int_equal(row[x], 0xFF);
                            } else {
                                assert_true(row[x] < 0x80);
                            }
                    }
    }
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_floor_texels_follow_the_format),
        cmocka_unit_test(test_span_writes_only_its_pixels),
    };
    return cmocka_run_group_tests(tests, setup, NULL);
}
