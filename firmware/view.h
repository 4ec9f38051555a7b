/* view.h - the camera and the world-to-view transform (prefix view_).
 *
 * View space: x right, y up, z forward, in "view units": 18.14 fixed point in an
 * int32_t (VIEW_SHIFT). World coordinates lie inside +-32767 and heights inside
 * +-16383 (scene_format.h) and view_setup clamps the eye into that box, so a view
 * coordinate is at most 65534 * sqrt(2) < 2^16.5 units = 2^30.5 raw: it fits.
 * Screen: 320x200, focal length 160 px on both axes, centre (160, 100 + look),
 * pixel (px, py) sampled at its centre (px + 0.5, py + 0.5); screen coordinates
 * are 16.16.
 */
#ifndef VIEW_VIEW_H
#define VIEW_VIEW_H

#include <stdint.h>
#include "fixed.h"

#define VIEW_SHIFT 14
#define VIEW_ONE (1 << VIEW_SHIFT)
#define VIEW_ZNEAR 16            /* near plane: 16 / 2^14 = 1/1024 unit */
#define VIEW_FOCAL 160           /* pixels */
#define VIEW_CX 160
#define VIEW_CY 100
#define VIEW_LOOK_MAX 100        /* |look| in pixels: the horizon stays on screen */
#define VIEW_W 320
#define VIEW_H 200
#define VIEW_W_FX (VIEW_W << 16)
#define VIEW_H_FX (VIEW_H << 16)

typedef struct {
    fx_t x, y, z;      /* eye position, 16.16 map units (z absolute) */
    fx_t angle_deg;    /* view angle in degrees, 16.16; 0 = east, counter-clockwise */
    int32_t look;      /* vertical shear in pixels: positive looks up */
} camera;

typedef struct {
    int64_t cx, cy, cz;  /* eye, 16.16 */
    int32_t sin, cos;    /* of the view angle, 2.30 */
    int32_t look;        /* clamped shear, pixels */
} view_xform;

typedef struct {
    int32_t x, y, z;     /* view space, 18.14 */
} view_pt;

typedef struct {
    int32_t x, y;        /* screen, 16.16 */
} screen_pt;

/* Set up the transform for a camera (clamps the eye into the world box and look). */
void view_setup(view_xform *v, const camera *cam);

/* World (x, y) at height h (all 16.16) to view space. */
static inline view_pt view_point(const view_xform *v, int32_t wx, int32_t wy, int32_t h)
{
    int64_t dx = (int64_t)wx - v->cx, dy = (int64_t)wy - v->cy;
    view_pt p;
    /* |dx|,|dy| < 2^32 raw and |sin|,|cos| <= 2^30: each product < 2^62 and the
     * rotated sum is bounded by the vector length (< 2^62.5): no overflow.
     * 16.16 * 2.30 has 46 fraction bits; >> 32 leaves 14. */
    p.z = (int32_t)fx_asr64(dx * v->cos + dy * v->sin, 32);
    p.x = (int32_t)fx_asr64(dx * v->sin - dy * v->cos, 32);
    p.y = (int32_t)fx_asr64((int64_t)h - v->cz, 2);
    return p;
}

/* Project a view point with z >= VIEW_ZNEAR that lies inside the frustum; the
 * result is clamped to the screen rectangle [0,320] x [0,200] (16.16). */
screen_pt view_project(const view_xform *v, view_pt p);

#endif
