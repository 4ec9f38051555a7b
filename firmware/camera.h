/* camera.h - placing and moving the eye through a scene (prefix cam_).
 * Walking collides with the walls (firmware/collide.h: Doom's player, radius 16,
 * height 56, step 24); the eye is the floor under it + 41, eased over steps. */
#ifndef CAMERA_H
#define CAMERA_H

#include <stdint.h>
#include "objects.h"
#include "scene.h"
#include "view.h"

#define CAM_EYE_HEIGHT (41 * FX_ONE)              /* above the floor of the eye's sector */
#define CAM_EASE_MS 60                            /* time constant of the eye's easing over steps */
#define CAM_FLY_MAX (2 * SCN_HEIGHT_MAX * FX_ONE) /* highest fly offset */

typedef struct {
    camera view;    /* what the renderer uses */
    fx_t fly;       /* height above floor + CAM_EYE_HEIGHT, changed by fly keys, 0..CAM_FLY_MAX */
    fx_t eye_floor; /* the floor the eye is at (eased toward the floor under the eye) */
    fx_t feet;      /* the floor the player stands on (collide.h: highest under its circle) */
    int noclip;     /* nonzero: walk through walls (free movement); 0 after cam_start */
} cam_state;

/* The player start of the scene, eye at floor + 41. */
void cam_start(cam_state *c, const scene *s);

/* Eye height for the eye's map point, at once (no easing): its sector's floor + 41
 * (+ fly); unchanged if the point is in no sector. */
void cam_follow_floor(cam_state *c, const scene *s);

/* Apply one step of input (HAL_KEY_* bits) over dt milliseconds: turn, look, walk
 * (colliding and sliding unless noclip), fly (raises the eye above the floor;
 * walking still collides), and ease the eye toward the floor under it + 41.
 * w: the ceilings now (doors block when closed; NULL: as compiled). */
void cam_move(cam_state *c, const scene *s, const world_state *w, uint32_t input, uint32_t dt_ms);

#endif
