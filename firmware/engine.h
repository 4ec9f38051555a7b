/* engine.h - the firmware's entry points (prefix eng_). The target owns the main
 * loop and calls eng_step once per frame; the engine owns no globals. */
#ifndef ENGINE_H
#define ENGINE_H

#include <stdint.h>
#include "camera.h"
#include "hal.h"
#include "objects.h"
#include "render.h"
#include "scene.h"
#include "texture.h"

typedef struct {
    scene sc;
    cam_state cam;
    render_mode mode;
    hal_present_mode present;
    uint8_t flat;              /* 1: a textured scene is drawn in its flat colours */
    uint32_t frame;            /* frames rendered since eng_init */
    render_stats stats;        /* of the last frame */
    render_work work;          /* given by the target: eng_set_work */
    render_work renderer_work; /* the renderer's part of it (after the world state) */
    world_state world;         /* objects and doors now, in the work area; unset (NULL arrays) before eng_set_work */
    uint32_t t_ms;             /* time since eng_init: the sum of eng_step's dt */
} engine;

/* 1 if frames are drawn textured: the scene has a look, the build has the
 * texture code, and flat colours were not asked for. */
static inline int eng_textured(const engine *e)
{
    return CFG_TEXTURES && e->sc.look && !e->flat;
}

/* Validate the compiled scene, load its palette, put the eye at the player start.
 * Returns SCENE_OK or the loader's status (details in err, which may be NULL). */
scene_status eng_init(engine *e, const void *blob, uint32_t len, scene_error *err);

/* Work memory the loaded scene needs (the world state of its objects and doors,
 * then the renderer's work for drawing them: render_work_bytes), and handing it
 * over: returns 0, or -1 if bytes is smaller than eng_work_bytes (the scene
 * needs more than this build provides: refuse it). eng_set_work puts the
 * objects and doors at time 0 (obj_init). Until then the static world is drawn
 * without objects, and mode spans draws only the background and reports
 * stats.refused. */
uint32_t eng_work_bytes(const engine *e);
int eng_set_work(engine *e, void *mem, uint32_t bytes);

/* Render the current view (and the world state as it is) into the surface for
 * the present mode and present it. ids may be NULL. Does not call hal_frame_done. */
void eng_render(engine *e, uint32_t *ids);

/* One frame: apply input over dt milliseconds (mode and present keys included;
 * the walk collides with the doors as they are), advance the time by dt and move
 * the objects and doors to it (doors seeing the player where the walk left it),
 * render, present, and tell the target the frame is done. */
void eng_step(engine *e, uint32_t input, uint32_t dt_ms);

#endif
