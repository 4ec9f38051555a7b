/* campath.c - the scripted camera paths (see campath.h). */
#include "campath.h"

#include "hal.h"

#define FWD HAL_KEY_FORWARD
#define LEFT HAL_KEY_TURN_LEFT
#define RIGHT HAL_KEY_TURN_RIGHT
#define UP HAL_KEY_LOOK_UP
#define DOWN HAL_KEY_LOOK_DOWN

/* Turning is 120 degrees a second and walking 256 units a second
 * (firmware/camera.c), so 7 frames turn about 24 degrees and 35 frames walk
 * 256 units. */
static const campath_step default_steps[] = {
    {0, 2},     /* the player start: (96, 160), 20 degrees */
    {RIGHT, 7}, /* face the corridor (about -4 degrees) */
    {FWD, 86},  /* across the hall, up the step, through the corridor */
    {LEFT, 12}, /* in the sky-lit court, turn left (about 40 degrees) */
    {UP, 20},   /* look up at the sky */
    {LEFT, 30}, /* turn, still looking up */
    {DOWN, 20}, /* level again */
    {LEFT, 24}, /* turn toward the window and the gallery */
    {0, 3},     /* stand: identical frames */
};

static const campath_step map01_steps[] = {
    {0, 2},      /* the player start: (-192, -160), facing east */
    {FWD, 74},   /* along the corridor east, down the stairs */
    {LEFT, 26},  /* turn to the north (about 90 degrees) */
    {FWD, 40},   /* into the alcove */
    {RIGHT, 20}, /* and a look to the right */
    {0, 3},      /* stand: identical frames */
};

const campath campath_default = {"default", default_steps, sizeof default_steps / sizeof default_steps[0]};
const campath campath_map01 = {"map01", map01_steps, sizeof map01_steps / sizeof map01_steps[0]};

uint32_t campath_frames(const campath *p)
{
    uint32_t n = 0;
    for (uint32_t i = 0; i < p->nsteps; i++) n += p->steps[i].frames;
    return n;
}

uint32_t campath_keys(const campath *p, uint32_t frame)
{
    for (uint32_t i = 0; i < p->nsteps; i++) {
        if (frame < p->steps[i].frames) return p->steps[i].keys;
        frame -= p->steps[i].frames;
    }
    return 0;
}

uint32_t campath_dt_ms(uint32_t frame)
{
    return (frame + 1u) * 1000u / CAMPATH_TIC_HZ - frame * 1000u / CAMPATH_TIC_HZ;
}

static int same(const char *a, const char *b)
{
    while (*a && *a == *b) a++, b++;
    return *a == *b;
}

const campath *campath_find(const char *name)
{
    if (same(name, campath_default.name)) return &campath_default;
    if (same(name, campath_map01.name)) return &campath_map01;
    return 0;
}
