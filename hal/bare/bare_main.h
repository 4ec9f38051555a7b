/* bare_main.h - the start-up and frame loop the bare-metal targets share
 * (prefix bare_), with per-target hooks, as doomgeneric splits its Create and
 * Tick from the DG_ functions a port provides.
 *
 * bare_main runs: the options (args.h), the camera path, eng_init and the
 * refusal message, the work memory, the render and present modes, the target's
 * start, then each frame of the path (or of a fixed view: fixed_view.h) between
 * the target's frame hooks, then the target's finish. It returns the exit
 * status; what the target does with it (return from main, an exit port) is its
 * own. A target's entry does its board set-up and finds its command line first.
 *
 * The built-in scene comes from the generated scene file of each target's
 * build (mk/mps2.mk, mk/pcvga.mk).
 */
#ifndef BARE_MAIN_H
#define BARE_MAIN_H

#include <stdint.h>

#include "args.h"
#include "campath.h"
#include "engine.h"

/* Exit statuses both targets give (each may add its own above these). */
#define BARE_EXIT_OK 0
#define BARE_EXIT_SCENE 2 /* the built-in scene is invalid */
#define BARE_EXIT_WORK 4  /* not enough work memory for the scene */
#define BARE_EXIT_ARGS 5  /* bad run-time options */

/* ---- from the generated scene file -------------------------------------- */
extern const uint8_t fw_scene[];
extern const uint32_t fw_scene_len;
extern const char fw_scene_name[];
extern const char fw_campath_name[];

/* The run as the hooks see it, set up before the target's start. */
typedef struct {
    engine e;
    fw_args args;
    const campath *path; /* the options' or the build's; its name is in the start line */
    int fixed_view;      /* nonzero: no path input, the same camera every frame */
    uint32_t frames;     /* to render */
    uint32_t need;       /* work bytes the scene needs */
    uint32_t avail;      /* work bytes the target has (bare_work's avail) */
    uint32_t t0;         /* hal_ticks_ms before the first frame */
} bare_run;

/* Where the work area is: mem and the bytes handed to the engine; avail, the
 * bytes there are, for the messages. */
typedef struct {
    uint8_t *mem;
    uint32_t bytes, avail;
} bare_work;

typedef struct {
    const char *name; /* the prefix of every message: "firmware: ..." */
    unsigned offered; /* the ARGS_* options this target has */
    /* The log sink: one line, or part of one, by format.h's printf. */
    void (*log)(const char *fmt, ...) __attribute__((format(printf, 1, 2)));
    /* After the options are read and the path found (e.g. stop the tick). NULL: none. */
    void (*options)(const fw_args *a);
    void (*fault)(void); /* --fault: cause a processor fault */
    bare_work (*work)(uint32_t need);
    /* The line saying the work area is too small, and what to do about it. */
    void (*work_refused)(uint32_t need, uint32_t avail);
    /* With the engine ready: the target's set-up, the start line. Returns 0 or an exit status. */
    int (*start)(const bare_run *r);
    /* Right before and right after each frame's engine step (hal/mps2's
     * instruction-count markers). frame_end may be NULL. */
    void (*frame_begin)(uint32_t frame);
    void (*frame_end)(uint32_t frame);
    /* After each frame: show or send it. Returns 0, or an exit status that ends the run. */
    int (*frame_out)(const bare_run *r, uint32_t frame);
    /* After the last frame: the done line and any wait. Returns the exit status. */
    int (*finish)(const bare_run *r);
} bare_target;

/* Run the built-in scene on target t with the options in cmdline (modified in
 * place: args_parse). Returns the exit status. */
int bare_main(const bare_target *t, char *cmdline);

#endif
