/* palette.c - the default 256-colour palette and colour choice for Doom maps.
 *
 * 16 ramps of 16 shades, index = ramp * 16 + shade, shade 0 darkest. Ramp 0 is
 * grey, ramps 1-10 saturated hues for walls, ramps 11-15 muted earth and slate
 * tones for floors and ceilings, so a flat-shaded view tells walls from flats
 * at a glance. Doom textures pick a ramp by a hash of their name (the same
 * texture always gets the same hue) and a shade from the sector light level.
 */
#include <ctype.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "bspc_int.h"

static const struct {
    const char *name;
    unsigned char r, g, b;
} ramps[BS_RAMP_COUNT] = {
    {"grey", 210, 210, 210}, {"red", 224, 48, 40},     {"orange", 238, 132, 30},  {"yellow", 232, 212, 48},
    {"lime", 150, 214, 40},  {"green", 44, 180, 72},   {"teal", 36, 168, 150},    {"cyan", 60, 196, 232},
    {"blue", 64, 96, 236},   {"violet", 136, 80, 224}, {"magenta", 208, 60, 184}, {"brown", 156, 104, 60},
    {"sand", 196, 174, 120}, {"moss", 112, 136, 80},   {"slate", 104, 124, 156},  {"plum", 146, 100, 134},
};

void bs_palette(uint8_t pal[768])
{
    for (int r = 0; r < BS_RAMP_COUNT; r++) {
        for (int s = 0; s < 16; s++) {
            /* brightness from 1/16 to full, the top three shades lifted toward white */
            double k = (double)(s + 1) / 16.0;
            double w = (s >= 13) ? 0.1 * (s - 12) : 0.0;
            const unsigned char base[3] = {ramps[r].r, ramps[r].g, ramps[r].b};
            for (int c = 0; c < 3; c++) {
                double v = base[c] * k;
                v = v + (255.0 - v) * w;
                long iv = lround(v);
                if (iv < 0) iv = 0;
                if (iv > 255) iv = 255;
                pal[(r * 16 + s) * 3 + c] = (uint8_t)iv;
            }
        }
    }
}

const char *bs_ramp_name(int ramp)
{
    return (ramp >= 0 && ramp < BS_RAMP_COUNT) ? ramps[ramp].name : "?";
}

int bs_color_by_name(const char *s)
{
    char name[16];
    size_t n = 0;
    while (s[n] && s[n] != ':' && n < sizeof name - 1) {
        name[n] = (char)tolower((unsigned char)s[n]);
        n++;
    }
    name[n] = 0;
    int shade = 10;
    if (s[n] == ':') {
        const char *p = s + n + 1;
        if (!isdigit((unsigned char)p[0])) return -1;
        char *end;
        long v = strtol(p, &end, 10);
        if (*end || v < 0 || v > 15) return -1;
        shade = (int)v;
    } else if (s[n]) {
        return -1;
    }
    for (int r = 0; r < BS_RAMP_COUNT; r++)
        if (strcmp(name, ramps[r].name) == 0) return r * 16 + shade;
    return -1;
}

/* FNV-1a over the upper-cased name (at most 8 characters). */
static uint32_t name_hash(const char t[8])
{
    uint32_t h = 2166136261u;
    for (int i = 0; i < 8 && t[i]; i++) {
        h ^= (uint8_t)toupper((unsigned char)t[i]);
        h *= 16777619u;
    }
    return h;
}

/* Doom light 0..255 to a shade: 0 -> 3, 160 -> 10, 255 -> 14 */
static int light_shade(int light)
{
    if (light < 0) light = 0;
    if (light > 255) light = 255;
    return 3 + light * 12 / 256;
}

static uint8_t pick(int ramp, int shade)
{
    if (shade < 0) shade = 0;
    if (shade > 15) shade = 15;
    return (uint8_t)(ramp * 16 + shade);
}

uint8_t bs_wall_color(const char tex[8], int light, int contrast)
{
    int ramp = 1 + (int)(name_hash(tex) % 10u); /* red .. magenta */
    return pick(ramp, light_shade(light) + contrast);
}

uint8_t bs_flat_color(const char flat[8], int light, int ceiling)
{
    int ramp = 11 + (int)(name_hash(flat) % 5u); /* brown .. plum */
    return pick(ramp, light_shade(light) - (ceiling ? 3 : 1));
}

uint8_t bs_sky_color(void)
{
    return pick(BS_RAMP_CYAN, 13);
}

uint8_t bs_neutral_color(int light)
{
    return pick(BS_RAMP_GREY, light_shade(light) - 1);
}
