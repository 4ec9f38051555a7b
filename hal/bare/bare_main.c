/* bare_main.c - the bare-metal targets' start-up and frame loop (see bare_main.h). */
#include "bare_main.h"

#include "fixed_view.h"
#include "hal.h"
#include "scene_refusal.h"

/* The options and the camera path. Returns 0 or an exit status. */
static int bare_options(const bare_target *t, bare_run *r, char *cmdline)
{
    static char err[128];
    if (args_parse(&r->args, cmdline, t->offered, err, sizeof err) != 0) {
        t->log("%s: %s\n", t->name, err);
        return BARE_EXIT_ARGS;
    }
    const char *name = r->args.path ? r->args.path : fw_campath_name;
    r->path = campath_find(name);
    if (!r->path) {
        t->log("%s: no camera path named '%s' (default, map01)\n", t->name, name);
        return BARE_EXIT_ARGS;
    }
    if (t->options) t->options(&r->args);
    if (r->args.fault) t->fault();
    r->fixed_view = fixed_view_wanted(&r->args);
    return 0;
}

/* The built-in scene checked, and its work area. Returns 0 or an exit status. */
static int bare_engine(const bare_target *t, bare_run *r)
{
    scene_error se;
    scene_status st = eng_init(&r->e, fw_scene, fw_scene_len, &se);
    if (st != SCENE_OK) {
        static char why[240]; /* with the prefix, within a log line (256) */
        scene_refusal_format(why, sizeof why, fw_scene_name, st, &se);
        t->log("%s: %s\n", t->name, why);
        return BARE_EXIT_SCENE;
    }
    r->need = eng_work_bytes(&r->e);
    bare_work w = t->work(r->need);
    r->avail = w.avail;
    if (eng_set_work(&r->e, w.mem, w.bytes) != 0) {
        t->work_refused(r->need, w.avail);
        return BARE_EXIT_WORK;
    }
    return 0;
}

/* The modes and the view the options ask for. */
static void bare_modes(bare_run *r)
{
    const fw_args *a = &r->args;
    if (a->mode >= 0) r->e.mode = (render_mode)a->mode;
    r->e.flat = (uint8_t)a->flat;
    if (a->present >= 0) r->e.present = (hal_present_mode)a->present;
    if (r->fixed_view) fixed_view_apply(&r->e, a);
    r->frames = a->frames >= 0 ? (uint32_t)a->frames : campath_frames(r->path);
}

/* The frames, each between the target's frame hooks. Returns 0 or an exit status.
 * What the loop reads is held in locals, so that between hal/mps2's markers
 * the loop adds to the step only register tests, no loads (make count-m3). */
static int bare_frames(const bare_target *t, bare_run *r)
{
    void (*begin)(uint32_t) = t->frame_begin, (*end)(uint32_t) = t->frame_end;
    int (*out)(const bare_run *, uint32_t) = t->frame_out;
    const int fixed = r->fixed_view;
    const uint32_t frames = r->frames;
    r->t0 = hal_ticks_ms();
    for (uint32_t f = 0; f < frames; f++) {
        uint32_t input = hal_input();
        begin(f);
        if (fixed) {
            eng_render(&r->e, 0);
            hal_frame_done();
        } else {
            eng_step(&r->e, input, campath_dt_ms(f));
        }
        if (end) end(f);
        int st = out(r, f);
        if (st != 0) return st;
    }
    return 0;
}

int bare_main(const bare_target *t, char *cmdline)
{
    static bare_run run;
    int st = bare_options(t, &run, cmdline);
    if (st == 0) st = bare_engine(t, &run);
    if (st != 0) return st;
    bare_modes(&run);
    st = t->start(&run);
    if (st == 0) st = bare_frames(t, &run);
    return st != 0 ? st : t->finish(&run);
}
