/* engine.c - one frame of the target's loop: input, camera, objects and doors,
 * render, present. */
#include "engine.h"

scene_status eng_init(engine *e, const void *blob, uint32_t len, scene_error *err)
{
    scene_status st = scene_load(&e->sc, blob, len, err);
    if (st != SCENE_OK) return st;
    e->mode = render_mode_default();
    e->work.mem = e->renderer_work.mem = 0;
    e->work.bytes = e->renderer_work.bytes = 0;
    e->world = (world_state){0, 0, 0, 0};
    e->t_ms = 0;
    e->present = HAL_PRESENT_FLIP;
    e->flat = 0;
    e->frame = 0;
    e->stats = (render_stats){0};
    cam_start(&e->cam, &e->sc);
    hal_set_palette(e->sc.palette);
    return SCENE_OK;
}

/* The renderer's need for the scene's own objects (their models are fixed: the
 * state only moves them). */
static uint32_t render_bytes(const engine *e)
{
    world_state proto = {0, e->sc.nobjects, 0, 0};
    return render_work_bytes(&e->sc, &proto);
}

uint32_t eng_work_bytes(const engine *e)
{
    uint64_t world = obj_state_bytes(&e->sc), render = render_bytes(e);
    if (render == 0 || world + render > 0xFFFFFFF0u) return 0;
    return (uint32_t)(world + render);
}

int eng_set_work(engine *e, void *mem, uint32_t bytes)
{
    uint32_t need = eng_work_bytes(e), world = obj_state_bytes(&e->sc);
    if (need == 0 || bytes < need || !mem) return -1;
    if (obj_init(&e->world, &e->sc, mem, world) != 0) return -1;
    e->work.mem = mem;
    e->work.bytes = bytes;
    e->renderer_work.mem = (uint8_t *)mem + world; /* world is a multiple of 8: the rest stays aligned */
    e->renderer_work.bytes = bytes - world;
    e->t_ms = 0;
    return 0;
}

/* The world the renderer draws: NULL when it holds nothing but the compiled
 * scene (no objects, no doors, no level time for animated textures to follow). */
static const world_state *world_of(const engine *e)
{
    return (e->world.ceil || e->world.objs || (CFG_ANIM && (e->sc.needs->features & SCN_NEED_ANIM))) ? &e->world : 0;
}

void eng_render(engine *e, uint32_t *ids)
{
    hal_surface surf = hal_begin_frame(e->present);
    hal_tally tally = {{0, 0, 0}, 0};
    rast_target t = {&surf, ids, hal_surface_linear(&surf) ? &tally : 0, e->flat};
    render_frame(&e->sc, world_of(e), &e->cam.view, e->mode, &t, &e->renderer_work, &e->stats);
    if (t.tally) hal_add_tally(&surf, &tally);
    hal_present(e->present);
    e->frame++;
}

void eng_step(engine *e, uint32_t input, uint32_t dt_ms)
{
    if (input & HAL_KEY_NEXT_MODE) e->mode = render_mode_next(e->mode);
    if (input & HAL_KEY_NEXT_PRESENT) e->present = (hal_present_mode)((e->present + 1) % HAL_PRESENT_COUNT);
    cam_move(&e->cam, &e->sc, world_of(e), input, dt_ms);
    e->t_ms += dt_ms; /* wraps after 49.7 days (a jump along the paths; doors only see dt) */
    if (world_of(e)) obj_update(&e->world, &e->sc, e->t_ms, dt_ms, e->cam.view.x, e->cam.view.y);
    eng_render(e, 0);
    hal_frame_done();
}
