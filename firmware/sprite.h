/* sprite.h - WAD things drawn as Doom's sprites (prefix spr_; docs/objects.md,
 * "Sprites"): which image a thing shows from the eye, where its upright
 * rectangle lies in view space, and which of its pixels are opaque.
 *
 * The rectangle is parallel to the screen at the thing's view depth zc, so a
 * pixel's texel follows from exact integer arithmetic: through the centre of
 * pixel (px, py) the ray meets depth zc at lateral X = (2 px + 1 - 320) zc / 320
 * and height Y = (200 + 2 look - 2 py - 1) zc / 320 (view units), whence the
 * column u = floor((X - xl) / 1 unit) and the row v = floor((yt - Y) / 1 unit).
 * Both are stepped along a row without a division per pixel. */
#ifndef SPRITE_H
#define SPRITE_H

#include <stdint.h>
#include "objects.h"
#include "scene.h"
#include "view.h"

#define SPR_MIN_DEPTH (4 * VIEW_ONE) /* view units: a nearer thing is not drawn (Doom's) */

typedef struct {
    uint16_t image;        /* scn_sprite */
    uint8_t mirror, table; /* drawn mirrored; its light table (0 brightest) */
    int32_t zc;            /* the rectangle's view depth, view units */
    int32_t xl, yt;        /* view x of column 0's left edge, view y of row 0's top */
} spr_view;

/* Object o (scene object index i) drawn as sprite set sprset: its image, light
 * and placement from the eye, and the rectangle's corners in view space in the
 * clockwise screen order the fill takes (top left, top right, bottom right,
 * bottom left). 0 if it is not drawn (too near, or wholly below its floor). */
int spr_view_of(const scene *s, const obj_state *o, uint32_t sprset, const view_xform *v, spr_view *sv,
                view_pt quad[4]);

/* The texel column under pixel x: a stepper along a row. */
typedef struct {
    int32_t u, du;          /* column, whole columns per pixel */
    int64_t rem, drem, den; /* remainder in [0, den), its step */
} spr_cols;

static inline void spr_cols_at(spr_cols *c, const spr_view *sv, int x)
{
    int64_t den = 320 * (int64_t)VIEW_ONE;
    int64_t n = (int64_t)(2 * x + 1 - VIEW_W) * sv->zc - 320 * (int64_t)sv->xl;
    int64_t q = n / den, r = n % den;
    if (r < 0) q--, r += den;
    int64_t step = 2 * (int64_t)sv->zc;
    c->u = (int32_t)q;
    c->rem = r;
    c->du = (int32_t)(step / den);
    c->drem = step % den;
    c->den = den;
}

static inline void spr_cols_next(spr_cols *c)
{
    c->u += c->du;
    c->rem += c->drem;
    if (c->rem >= c->den) c->rem -= c->den, c->u++;
}

/* The texel row under row y of the screen, or -1 outside the image. */
static inline int spr_row(const spr_view *sv, int look, int y, int height)
{
    int64_t den = 320 * (int64_t)VIEW_ONE;
    int64_t n = 320 * (int64_t)sv->yt - (int64_t)(2 * (VIEW_CY + look) - 2 * y - 1) * sv->zc;
    if (n < 0) return -1;
    int64_t v = n / den;
    return v < height ? (int)v : -1;
}

/* The next run of set bits of a row's bits at or after *x, before b: [*x0, *x).
 * 0 when none is left. */
static inline int spr_next_run(const uint32_t *bits, int *x, int b, int *x0)
{
    int k = *x;
    while (k < b && !((bits[k >> 5] >> (k & 31)) & 1u)) k++;
    *x0 = k;
    while (k < b && ((bits[k >> 5] >> (k & 31)) & 1u)) k++;
    *x = k;
    return k > *x0;
}

/* Set in bits (a row's COV_WORDS words) the pixels of [a, b) on row y where
 * the sprite is opaque. */
void spr_opaque(const scene *s, const spr_view *sv, int look, int y, int a, int b, uint32_t *bits);

#endif
