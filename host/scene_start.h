/* scene_start.h - a scene started in the engine, for the host programs
 * (build/render, build/emu, build/fltool; prefix scene_start_): the scene read
 * or compiled (scene_file_load), validated by eng_init with the loader's verdict
 * put into words, and the engine given the work memory the scene needs. */
#ifndef SCENE_START_H
#define SCENE_START_H

#include <stddef.h>
#include <stdint.h>

#include "engine.h"
#include "scene_file.h"

typedef struct {
    const char *name; /* for messages: the spec, or "built-in scene" */
    const void *data; /* the compiled scene the engine runs */
    size_t len;
    uint8_t *blob; /* data when it was read or compiled (malloc'd), else NULL */
    void *work;    /* the engine's work memory (malloc'd) */
} scene_start;

/* Reads or compiles spec (with opt) or, when spec is NULL, takes the built-in
 * scene builtin[0..builtin_len), and eng_inits e with it. Returns 0, or -1 with
 * a message naming the scene and the problem in err (nothing left to free). */
int scene_start_open(scene_start *st, engine *e, const char *spec, const bspc_options *opt, const void *builtin,
                     size_t builtin_len, char *err, size_t errlen);

/* Gives e the work memory its scene needs, or more when objs (NULL: the scene's
 * own objects) are to be drawn instead. Returns 0, or -1 with a message in err. */
int scene_start_work(scene_start *st, engine *e, const world_state *objs, char *err, size_t errlen);

/* scene_start_open, then scene_start_work for the scene's own objects. */
int scene_start_load(scene_start *st, engine *e, const char *spec, const bspc_options *opt, const void *builtin,
                     size_t builtin_len, char *err, size_t errlen);

/* Frees what scene_start_open and scene_start_work took (the engine must not
 * run after). */
void scene_start_close(scene_start *st);

#endif
