/* camera.h - placing and moving the eye through a scene (prefix cam_). */
#ifndef CAMERA_H
#define CAMERA_H

#include <stdint.h>
#include "scene.h"
#include "view.h"

#define CAM_EYE_HEIGHT (41 * FX_ONE) /* above the floor of the eye's sector */

typedef struct {
    camera view;      /* what the renderer uses */
    fx_t fly;         /* height above floor + CAM_EYE_HEIGHT, changed by fly keys */
} cam_state;

/* The player start of the scene, eye at floor + 41. */
void cam_start(cam_state *c, const scene *s);

/* Eye height for a map point: its sector's floor + 41 (+ fly); unchanged if the
 * point is in no sector. */
void cam_follow_floor(cam_state *c, const scene *s);

/* Apply one step of input (HAL_KEY_* bits) over dt milliseconds. */
void cam_move(cam_state *c, const scene *s, uint32_t input, uint32_t dt_ms);

#endif
