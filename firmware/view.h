/* view.h - the camera and the world-to-view transform (prefix view_).
 *
 * View space: x right, y up, z forward, in "view units": fixed point with
 * VIEW_SHIFT fraction bits in an int32_t (18.14 by default). World coordinates
 * lie inside +-32767 and heights inside +-16383 (scene_format.h) and view_setup
 * clamps the eye into that box, so a view coordinate is at most 65534 * sqrt(2)
 * < 2^16.5 units = 2^(16.5 + VIEW_SHIFT) raw: it fits for VIEW_SHIFT <= 14.
 * Screen: 320x200, focal length 160 px on both axes, centre (160, 100 + look),
 * pixel (px, py) sampled at its centre (px + 0.5, py + 0.5); screen coordinates
 * are 16.16.
 *
 * Precision knobs (compile-time; make report measures each against the
 * reference renderer). The defaults are the exact arithmetic the golden frames
 * were recorded with; every other allowed value draws a slightly different,
 * still gap-free frame, because a shared vertex still maps to one screen point.
 *
 *   VIEW_SHIFT          fraction bits of view space, 4..14 (default 14). Fewer
 *                       bits quantise vertices to 2^-VIEW_SHIFT map units before
 *                       projection, which moves edges near the eye most (an
 *                       error of 2^-VIEW_SHIFT units at depth z is 160 / z
 *                       times that in pixels). It changes no instruction on a
 *                       64-bit host; a narrower target could keep the transform
 *                       in fewer bits.
 *   VIEW_SUBPIXEL_BITS  fraction bits kept of each projected screen coordinate,
 *                       0..16 (default 16: all of 16.16). Below 16 x and y are
 *                       rounded to the nearest 1/2^k pixel, as a renderer with
 *                       k-bit subpixel vertices would see them: edges move by up
 *                       to half of 1/2^k pixel at their ends.
 *   VIEW_RECIP_BITS     0 (default): the perspective divide is an exact 64-bit
 *                       division. 4..12: 1/z comes from a table of
 *                       2^VIEW_RECIP_BITS reciprocals indexed by the bits of z
 *                       below its leading one, then a multiply - what a core
 *                       without a 64-bit divide (the Cortex-M3) wants. The
 *                       relative error of 1/z is below 2^-(VIEW_RECIP_BITS + 1),
 *                       i.e. up to 160 / 2^(VIEW_RECIP_BITS + 1) pixels at the
 *                       screen's sides.
 */
#ifndef VIEW_VIEW_H
#define VIEW_VIEW_H

#include <stdint.h>
#include "build_config.h"
#include "fixed.h"

#ifndef VIEW_SHIFT
#define VIEW_SHIFT 14
#endif
#ifndef VIEW_SUBPIXEL_BITS
#define VIEW_SUBPIXEL_BITS 16
#endif
#ifndef VIEW_RECIP_BITS
#define VIEW_RECIP_BITS 0
#endif
#if VIEW_SHIFT < 4 || VIEW_SHIFT > 14
#error "VIEW_SHIFT: 4..14 (view coordinates must fit an int32_t)"
#endif
#if VIEW_SUBPIXEL_BITS < 0 || VIEW_SUBPIXEL_BITS > 16
#error "VIEW_SUBPIXEL_BITS: 0..16"
#endif
#if VIEW_RECIP_BITS != 0 && (VIEW_RECIP_BITS < 4 || VIEW_RECIP_BITS > 12)
#error "VIEW_RECIP_BITS: 0 (exact divide) or 4..12"
#endif

#define VIEW_ONE (1 << VIEW_SHIFT)
/* The near plane at 1/1024 unit (16 raw by default); with fewer than 10 view
 * bits, at one raw unit, the nearest plane they can express. */
#define VIEW_ZNEAR (VIEW_SHIFT >= 10 ? 1 << (VIEW_SHIFT - 10) : 1)
#define VIEW_FOCAL 160 /* pixels */
#define VIEW_CX 160
#define VIEW_CY 100
#define VIEW_LOOK_MAX 100 /* |look| in pixels: the horizon stays on screen */
#define VIEW_W 320
#define VIEW_H 200
#define VIEW_W_FX (VIEW_W << 16)
#define VIEW_H_FX (VIEW_H << 16)

typedef struct {
    fx_t x, y, z;   /* eye position, 16.16 map units (z absolute) */
    fx_t angle_deg; /* view angle in degrees, 16.16; 0 = east, counter-clockwise */
    int32_t look;   /* vertical shear in pixels: positive looks up */
} camera;

typedef struct {
    int64_t cx, cy, cz; /* eye, 16.16 */
    int32_t sin, cos;   /* of the view angle, 2.30 */
    int32_t look;       /* clamped shear, pixels */
    fx_ang_t angle;     /* the view angle */
} view_xform;

typedef struct {
    int32_t x, y, z; /* view space, VIEW_SHIFT fraction bits */
} view_pt;

typedef struct {
    int32_t x, y; /* screen, 16.16 */
} screen_pt;

/* The vertical shear in use: always 0 in a build without look up/down. */
#define VIEW_LOOK(v) (CFG_LOOK ? (v)->look : 0)

/* Set up the transform for a camera (clamps the eye into the world box and look). */
void view_setup(view_xform *v, const camera *cam);

/* The view height of world height h (16.16): view_point's y. */
static inline int32_t view_height(const view_xform *v, int32_t h)
{
    return (int32_t)fx_asr64((int64_t)h - v->cz, 16 - VIEW_SHIFT);
}

/* World (x, y) at height h (all 16.16) to view space. A point's x and z do not
 * depend on h: the polygons of a leaf rotate each map point once and set the
 * height of each use with view_height. */
static inline view_pt view_point(const view_xform *v, int32_t wx, int32_t wy, int32_t h)
{
    int64_t dx = (int64_t)wx - v->cx, dy = (int64_t)wy - v->cy;
    view_pt p;
    /* |dx|,|dy| < 2^32 raw and |sin|,|cos| <= 2^30: each product < 2^62 and the
     * rotated sum is bounded by the vector length (< 2^62.5): no overflow.
     * 16.16 * 2.30 has 46 fraction bits; VIEW_SHIFT of them are kept. */
    p.z = (int32_t)fx_asr64(dx * v->cos + dy * v->sin, 46 - VIEW_SHIFT);
    p.x = (int32_t)fx_asr64(dx * v->sin - dy * v->cos, 46 - VIEW_SHIFT);
    p.y = view_height(v, h);
    return p;
}

/* p at height h: the same as view_point(v, x, y, h) for the map point p was rotated from. */
static inline view_pt view_at_height(const view_xform *v, view_pt p, int32_t h)
{
    p.y = view_height(v, h);
    return p;
}

#if VIEW_RECIP_BITS
/* view_recip[j] = 2^(k + 32) / (2m + 1) rounded, m = 2^k + j, k = VIEW_RECIP_BITS:
 * 2^(k + 31) / m at the middle of the bucket of z values that share those top
 * k + 1 bits, in (2^30, 2^31). Generated by tools/gen_tables.c. */
extern const uint32_t view_recip[1 << VIEW_RECIP_BITS];
#endif

/* a * VIEW_FOCAL / z in 16.16 pixels, for 1 <= z < 2^31: the perspective divide
 * every projection goes through, so that the polygons and the column estimates
 * of occlusion.c see the same screen positions. Both clamp it to the screen; a
 * quotient of 2^30 or more may come back as 2^30 (its sign kept). */
static inline int64_t view_persp(int32_t a, int32_t z)
{
#if VIEW_RECIP_BITS
    /* z = m * 2^(b - k) with m's leading one at bit k; 1/z ~ r / 2^(31 + b).
     * |a| * r < 2^62; a quarter of that times 160 < 2^62. */
    int b = 31 - __builtin_clz((uint32_t)z);
    uint32_t m = b >= VIEW_RECIP_BITS ? (uint32_t)z >> (b - VIEW_RECIP_BITS) : (uint32_t)z << (VIEW_RECIP_BITS - b);
    int64_t r = view_recip[m - (1u << VIEW_RECIP_BITS)];
    return fx_asr64(fx_asr64((int64_t)a * r, 8) * VIEW_FOCAL, (unsigned)(7 + b));
#elif FX_DIV32
    /* A quotient of 2^30 or more is clamped off the screen by every caller
     * (docs/ranges.md): stop it there, and divide the rest in 32 bits. */
    uint64_t n = (uint64_t)(a < 0 ? -(int64_t)a : a) * ((uint64_t)VIEW_FOCAL << 16);
    uint32_t r;
    int64_t q = n >= (uint64_t)z << 30 ? (int64_t)1 << 30 : (int64_t)fx_udiv64_32(n, (uint32_t)z, &r);
    return a < 0 ? -q : q;
#else
    /* |a| < 2^31 and focal * 2^16 < 2^24: the product is below 2^55. */
    return (int64_t)a * ((int64_t)VIEW_FOCAL << 16) / z;
#endif
}

/* A projected 16.16 coordinate in [0, 320 << 16] rounded to VIEW_SUBPIXEL_BITS
 * fraction bits; the bounds are whole pixels, so it stays inside them. */
static inline int32_t view_subpixel(int32_t s)
{
#if VIEW_SUBPIXEL_BITS < 16
    const int32_t unit = (int32_t)1 << (16 - VIEW_SUBPIXEL_BITS);
    return (s + unit / 2) & ~(unit - 1);
#else
    return s;
#endif
}

/* Project a view point with z >= VIEW_ZNEAR that lies inside the frustum; the
 * result is clamped to the screen rectangle [0,320] x [0,200] (16.16). */
screen_pt view_project(const view_xform *v, view_pt p);

/* view_project's x alone. */
int32_t view_project_x(view_pt p);

#endif
