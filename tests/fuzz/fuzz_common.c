/* fuzz_common.c - shared by the engine harnesses: see fuzz_common.h. */
#include "fuzz_common.h"

#include <string.h>
#include <unistd.h>

#include "bspc.h"
#include "engine.h"
#include "hal_null.h"

/* A blob that would need more work memory than this is refused by any target
 * (the largest Freedoom map needs about 9 MB); a harness does not allocate it. */
#define FUZZ_WORK_MAX (64u << 20)

fuzz_view fuzz_view_from(const uint8_t *data)
{
    fuzz_view v;
    v.x = (int32_t)rd32(data);
    v.y = (int32_t)rd32(data + 4);
    v.z = (int32_t)rd32(data + 8);
    v.angle = (int32_t)rd32(data + 12);
    v.look = (int32_t)rd32(data + 16);
    v.t_ms = rd32(data + 20);
    return v;
}

/* data as this process's temporary file ending in suffix; its path (static storage),
 * or NULL if it could not be written. */
static const char *temp_file(const uint8_t *data, size_t size, const char *suffix)
{
    static char path[256];
    const char *dir = getenv("TMPDIR");
    snprintf(path, sizeof path, "%s/fuzz-%ld%s", dir && *dir ? dir : "/tmp", (long)getpid(), suffix);
    FILE *f = fopen(path, "wb");
    if (!f) return NULL;
    size_t put = size ? fwrite(data, 1, size, f) : 0;
    if (fclose(f) != 0 || put != size) return NULL;
    return path;
}

int fuzz_compile(const char *spec, const char *file, uint8_t **blob, size_t *len)
{
    bspc_options opt = bspc_defaults();
    opt.verbose = 0;
    char err[1024] = "";
    *blob = NULL;
    *len = 0;
    if (bspc_compile(spec, &opt, blob, len, NULL, err, sizeof err) == 0) {
        FUZZ_REQUIRE(*blob && *len, "compile succeeded without a blob");
        return 0;
    }
    FUZZ_REQUIRE(*blob == NULL, "a refused compile returned a blob");
    FUZZ_REQUIRE(strstr(err, file) != NULL, "the refusal does not name the file: \"%s\"", err);
    return -1;
}

int fuzz_compile_input(const uint8_t *data, size_t size, const char *suffix, const char *map, uint8_t **blob,
                       size_t *len)
{
    const char *path = temp_file(data, size, suffix);
    if (!path) return -1;
    char spec[300];
    snprintf(spec, sizeof spec, "%s%s%s", path, map ? ":" : "", map ? map : "");
    return fuzz_compile(spec, path, blob, len);
}

static void draw_mode(engine *e, const fuzz_view *view, render_mode mode, int trusted)
{
    cam_start(&e->cam, &e->sc);
    if (view) {
        e->cam.view.x = view->x;
        e->cam.view.y = view->y;
        e->cam.view.z = view->z;
        e->cam.view.angle_deg = view->angle;
        e->cam.view.look = view->look;
    }
    e->mode = mode;
    eng_render(e, NULL);
    FUZZ_REQUIRE(!e->stats.refused, "a frame was refused with the work memory the scene asked for");
    FUZZ_REQUIRE(!trusted || !e->stats.overflow, "mode %s dropped %u polygons: the proven bounds failed",
                 render_mode_name(mode), e->stats.overflow);
}

void fuzz_draw(const uint8_t *blob, size_t len, const fuzz_view *view, int trusted)
{
    /* An exact-size copy, so that a read past the end is a sanitizer report. */
    uint8_t *copy = fuzz_copy_exact(blob, len);
    static engine e;
    memset(&e, 0, sizeof e);
    scene_error se;
    hal_null_reset();
    scene_status st = eng_init(&e, copy, (uint32_t)len, &se);
    FUZZ_REQUIRE(!trusted || st == SCENE_OK, "the loader refused the compiler's output: %s", scene_status_text(st));
    uint32_t need = st == SCENE_OK ? eng_work_bytes(&e) : 0;
    void *work = need && need <= FUZZ_WORK_MAX ? malloc(need) : NULL;
    FUZZ_REQUIRE(!trusted || work, "the compiler's output needs %u bytes of work memory", need);
    if (work) {
        FUZZ_REQUIRE(eng_set_work(&e, work, need) == 0, "the engine refused the work memory it asked for");
        if (view) obj_update(&e.world, &e.sc, view->t_ms, view->t_ms, view->x, view->y);
        for (int m = 0; m < RENDER_MODE_COUNT; m++) draw_mode(&e, view, (render_mode)m, trusted);
    }
    free(work);
    free(copy);
}
