/* campath.h - scripted camera paths: the firmware's input (prefix campath_).
 *
 * A path is a list of steps, each holding a set of HAL_KEY_* bits for a number
 * of frames, starting from the scene's player start. Every frame advances the
 * clock by a fixed 1000/35 ms (a 35 Hz tic, the remainder carried so that 35
 * frames are exactly 1000 ms, as hal/null does), never by the SysTick, so a
 * path renders the same frames on every run and every machine; the frame link
 * reports the camera each frame was rendered from, so the host can reproduce
 * any frame with build/render.
 *
 * Paths (campath.c):
 *   default  tests/scenes/default.scene (204 frames): from the hall through the
 *            corridor (one step up) into the sky-lit court, a look up at the sky
 *            while turning, and a turn back toward the corridor.
 *   map01    freedoom2.wad:MAP01 (165 frames): along the corridor east from the
 *            player start and down its stairs, a turn to the north, a walk north
 *            through the rooms there, and a look to the right.
 * mk/mps2.mk picks one with CAMPATH= (default: map01 for a MAP01 scene, else
 * default).
 */
#ifndef MPS2_CAMPATH_H
#define MPS2_CAMPATH_H

#include <stdint.h>

typedef struct {
    uint32_t keys;   /* HAL_KEY_* bits held */
    uint32_t frames; /* for this many frames */
} campath_step;

typedef struct {
    const char *name;
    const campath_step *steps;
    uint32_t nsteps;
} campath;

extern const campath campath_default;
extern const campath campath_map01;

#define CAMPATH_TIC_HZ 35u

uint32_t campath_frames(const campath *p);               /* frames in the whole path */
uint32_t campath_keys(const campath *p, uint32_t frame); /* keys held at frame (0 past the end) */
uint32_t campath_dt_ms(uint32_t frame);                  /* ms frame advances the clock: 28 or 29 */
const campath *campath_find(const char *name);           /* by name, or NULL */

#endif
