/* scene_start.c - a scene from any source started in the engine (scene_start.h). */
#include "scene_start.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "objects.h"
#include "render.h"

int scene_start_open(scene_start *st, engine *e, const char *spec, const bspc_options *opt, const void *builtin,
                     size_t builtin_len, char *err, size_t errlen)
{
    memset(st, 0, sizeof *st);
    st->name = spec ? spec : "built-in scene";
    st->data = builtin;
    st->len = builtin_len;
    if (spec) {
        if (scene_file_load(spec, opt, &st->blob, &st->len, err, errlen) != 0) return -1;
        st->data = st->blob;
    }
    if (st->len > UINT32_MAX) { /* scene_file_load reads at most 256 MiB; a built-in scene is smaller */
        snprintf(err, errlen, "%s: larger than 4 GiB", st->name);
        scene_start_close(st);
        return -1;
    }
    scene_error se;
    if (eng_init(e, st->data, (uint32_t)st->len, &se) != SCENE_OK) {
        scene_file_describe_error(st->name, st->data, st->len, &se, err, errlen);
        scene_start_close(st);
        return -1;
    }
    return 0;
}

int scene_start_work(scene_start *st, engine *e, const world_state *objs, char *err, size_t errlen)
{
    /* The renderer's work memory depends on the objects drawn: others than the
     * scene's own may need more than eng_work_bytes provides for. */
    uint32_t need = eng_work_bytes(e);
    if (objs && need) {
        uint64_t r = render_work_bytes(&e->sc, objs), total = (uint64_t)obj_state_bytes(&e->sc) + r;
        if (r == 0 || total > 0xFFFFFFF0u)
            need = 0;
        else if (total > need)
            need = (uint32_t)total;
    }
    free(st->work);
    st->work = need ? malloc(need) : NULL;
    if (!st->work || eng_set_work(e, st->work, need) != 0) {
        snprintf(err, errlen, "%s: the scene needs %u bytes of work memory, which could not be had", st->name, need);
        free(st->work);
        st->work = NULL;
        return -1;
    }
    return 0;
}

int scene_start_load(scene_start *st, engine *e, const char *spec, const bspc_options *opt, const void *builtin,
                     size_t builtin_len, char *err, size_t errlen)
{
    if (scene_start_open(st, e, spec, opt, builtin, builtin_len, err, errlen) != 0) return -1;
    if (scene_start_work(st, e, NULL, err, errlen) == 0) return 0;
    scene_start_close(st);
    return -1;
}

void scene_start_close(scene_start *st)
{
    free(st->work);
    free(st->blob);
    st->work = NULL;
    st->blob = NULL;
    st->data = NULL;
}
