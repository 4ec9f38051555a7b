/* texture.h - what a surface's pixels are (prefix tex_): a flat colour, or a
 * wall texture, a flat or the sky under Doom's light (docs/textures.md).
 *
 * surfaces.c describes each polygon's paint once (tex_wall, tex_plane,
 * tex_sky); whoever fills the polygon's spans, in whatever order, asks
 * tex_span for a span's pixels. Everything a span needs is in the paint, so a
 * render mode may keep paints (the span renderer's surfaces do) and fill their
 * spans long after the walk. Integer only; the same frame on every target.
 *
 * Precision knobs (compile-time; make report measures them against the
 * reference renderer):
 *   TEX_SUBDIV_BITS  walls: depth and texture column exact every 2^k pixels
 *                    of a span, interpolated linearly between (0..6, default 3).
 *   TEX_RECIP_BITS   0 (default): the depth divides are exact. 4..12: depth
 *                    from view.h's table of 2^k reciprocals and a multiply.
 *   TEX_LIGHT_BITS   light tables used: 2^k of the 32 (1..5, default 5).
 */
#ifndef TEXTURE_H
#define TEXTURE_H

#include <stdint.h>
#include "build_config.h"
#include "scene.h"
#include "sprite.h"
#include "view.h"


#ifndef TEX_SUBDIV_BITS
#define TEX_SUBDIV_BITS 3
#endif
#ifndef TEX_RECIP_BITS
#define TEX_RECIP_BITS 0
#endif
#ifndef TEX_LIGHT_BITS
#define TEX_LIGHT_BITS 5
#endif
#if TEX_SUBDIV_BITS < 0 || TEX_SUBDIV_BITS > 6
#error "TEX_SUBDIV_BITS: 0..6"
#endif
#if TEX_RECIP_BITS != 0 && (TEX_RECIP_BITS < 4 || TEX_RECIP_BITS > 12)
#error "TEX_RECIP_BITS: 0 (exact divide) or 4..12"
#endif
#if TEX_LIGHT_BITS < 1 || TEX_LIGHT_BITS > 5
#error "TEX_LIGHT_BITS: 1..5"
#endif

enum { TEX_FLAT, TEX_WALL, TEX_PLANE, TEX_SKY, TEX_SPRITE };

typedef struct {
    uint8_t kind;   /* TEX_* */
    uint8_t colour; /* TEX_FLAT's colour; for the others, the flat colour a flat-shaded target draws */
#if CFG_TEXTURES
    uint8_t hbits; /* rows 2^hbits; texel (u, v) = texels[(u & wmask) << hbits | (v & hmask)] */
    int8_t start;  /* the brightest light table the surface's light level allows */
    uint32_t wmask, hmask;
    const uint8_t *texels;
    const uint8_t *lights; /* the scene's light tables */
    int64_t dist;          /* walls: the eye's distance from the wall's line, 16.16, times 2^14 */
    int64_t dh;            /* planes: the plane's height above the eye, 16.16 */
    int32_t a, b;          /* walls: depth denominator a + sx * b; planes: cos, sin of the view; 2.30 */
    int32_t c, d;          /* walls: texture column slope c + sx * d (2.30); planes: sin, cos divided by 320 */
    uint32_t u0;           /* walls: texture column at the eye, 16.16; sky: the view angle */
    uint32_t v0;           /* walls: texture row at the eye's height, 16.16; planes: the eye's x, 16.16 */
    uint32_t w0;           /* planes: minus the eye's y, 16.16 */
    int32_t look;
    /* sprites (TEX_SPRITE): texels the image's, lights its light table, wmask and hmask its width and height,
     * hbits 1 if mirrored; a, b, c its spr_view's zc, xl, yt */
#endif
} tex_paint;

/* A flat paint (every build). */
static inline tex_paint tex_flat(uint8_t colour)
{
    tex_paint p;
    p.kind = TEX_FLAT;
    p.colour = colour;
    return p;
}

#if CFG_TEXTURES
/* Paints of a textured scene's surfaces. tex: an scn_texture index (the
 * loader has checked it), SCN_TEX_NONE gives the flat colour. light: the
 * sector's light level 0..255, adj Doom's fake contrast. */
/* A wall part through map points a, b (the seg's, for the line), of line side
 * sd, whose texture row 0 is at height top (16.16). */
tex_paint tex_wall(const scene *sc, const view_xform *v, const scn_side *sd, uint32_t tex, const scn_vertex *a,
                   int32_t top, uint8_t light, uint8_t colour);
/* A floor or ceiling at height h (16.16). */
tex_paint tex_plane(const scene *sc, const view_xform *v, uint32_t tex, int32_t h, uint8_t light, uint8_t colour);
/* The sky (a sky ceiling, or a step between two). */
tex_paint tex_sky(const scene *sc, const view_xform *v, uint8_t colour);

/* A sprite image as sprite.h places it (sv: a spr_view), look the view's shear. Only the pixels the
 * caller finds opaque (spr_opaque) may be asked for. */
tex_paint tex_sprite(const scene *sc, const spr_view *sv, int look, uint8_t colour);

/* A see-through middle texture: line side `side`'s middle texture with row 0 at
 * height top (16.16), under its sector's light; holes: instead its opacity map,
 * whose spans come out 1 where the texture is opaque and 0 in a hole (the side's
 * texture must have a mask). */
tex_paint tex_mid(const scene *sc, const view_xform *v, uint32_t side, int32_t top, int holes);
/* Set in op (a row's bits) the pixels of [a, b) on row y where that middle
 * texture is opaque; 0 if it has no holes (op untouched). */
int tex_mid_opaque(const scene *sc, const view_xform *v, uint32_t side, int32_t top, int y, int a, int b, uint32_t *op);

/* The height of a texture's rows as Doom counts them (its unpadded height). */
static inline int32_t tex_height(const scene *sc, uint32_t tex)
{
    return tex < sc->ntextures ? (int32_t)sc->textures[tex].height << 16 : 0;
}

/* Pixels [x0, x1) of row y of a textured paint into row[x0 .. x1). */
void tex_span(const tex_paint *p, int y, int x0, int x1, uint8_t *row);

/* Rows [y0, y1) of screen column x of a wall paint (TEX_WALL) into dst[0],
 * dst[pitch], ...: the depth, texture column and light exact at the column's
 * centre, the texture row stepped down it. */
void tex_column(const tex_paint *p, int x, int y0, int y1, uint8_t *dst, uint32_t pitch);
#endif

#endif
