/* engine.c - one frame of the target's loop: input, camera, render, present. */
#include "engine.h"

scene_status eng_init(engine *e, const void *blob, uint32_t len, scene_error *err)
{
    scene_status st = scene_load(&e->sc, blob, len, err);
    if (st != SCENE_OK) return st;
    e->mode = RENDER_SPANS;
    e->work.mem = 0;
    e->work.bytes = 0;
    e->present = HAL_PRESENT_FLIP;
    e->frame = 0;
    e->stats = (render_stats){0};
    cam_start(&e->cam, &e->sc);
    hal_set_palette(e->sc.palette);
    return SCENE_OK;
}

uint32_t eng_work_bytes(const engine *e)
{
    return render_work_bytes(&e->sc);
}

int eng_set_work(engine *e, void *mem, uint32_t bytes)
{
    uint32_t need = render_work_bytes(&e->sc);
    if (need == 0 || bytes < need) return -1;
    e->work.mem = mem;
    e->work.bytes = bytes;
    return 0;
}

void eng_render(engine *e, uint32_t *ids)
{
    hal_surface surf = hal_begin_frame(e->present);
    rast_target t = {&surf, ids};
    render_frame(&e->sc, &e->cam.view, e->mode, &t, &e->work, &e->stats);
    hal_present(e->present);
    e->frame++;
}

void eng_step(engine *e, uint32_t input, uint32_t dt_ms)
{
    if (input & HAL_KEY_NEXT_MODE) e->mode = (render_mode)((e->mode + 1) % RENDER_MODE_COUNT);
    if (input & HAL_KEY_NEXT_PRESENT) e->present = (hal_present_mode)((e->present + 1) % HAL_PRESENT_COUNT);
    cam_move(&e->cam, &e->sc, input, dt_ms);
    eng_render(e, 0);
    hal_frame_done();
}
