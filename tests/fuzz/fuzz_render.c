/* fuzz_render.c - the renderer fed arbitrary valid scenes and arbitrary cameras.
 *
 * Input: a camera and a time (FUZZ_VIEW_BYTES), one byte choosing a scene, then a
 * scene text. If the compiler accepts the text, that scene is drawn; otherwise the
 * chosen one of the project's own scenes (tests/scenes, compiled once at start-up,
 * read relative to the working folder or $FUZZ_SCENES), so that every input draws
 * a frame whatever the fuzzer did to the text. Every mode is drawn from the camera,
 * the objects and doors moved to the time. Under ASan and UBSan nothing may fault,
 * and no frame may drop a polygon: the bounds the compiler proved (docs/needs.md)
 * must hold for any camera the renderer takes. */
#include <dirent.h>
#include <string.h>

#include "fuzz_common.h"

#define TEXT_MAX 16384
#define POOL_MAX 64

typedef struct {
    uint8_t *blob;
    size_t len;
} pool_scene;
static pool_scene pool[POOL_MAX];
static size_t npool;

static void add_folder(const char *dir)
{
    DIR *d = opendir(dir);
    if (!d) return;
    struct dirent *e;
    while ((e = readdir(d)) && npool < POOL_MAX) {
        size_t n = strlen(e->d_name);
        if (n < 7 || strcmp(e->d_name + n - 6, ".scene") != 0) continue;
        char path[1024];
        snprintf(path, sizeof path, "%s/%s", dir, e->d_name);
        if (fuzz_compile(path, path, &pool[npool].blob, &pool[npool].len) == 0) npool++;
    }
    closedir(d);
}

int LLVMFuzzerInitialize(int *argc, char ***argv)
{
    (void)argc;
    (void)argv;
    const char *root = getenv("FUZZ_SCENES");
    char dir[1024];
    snprintf(dir, sizeof dir, "%s", root && *root ? root : "tests/scenes");
    add_folder(dir);
    snprintf(dir, sizeof dir, "%s/extreme", root && *root ? root : "tests/scenes");
    add_folder(dir);
    fprintf(stderr, "fuzz_render: %zu scenes to fall back on\n", npool);
    return 0;
}

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    if (size < FUZZ_VIEW_BYTES + 1 || size - FUZZ_VIEW_BYTES - 1 > TEXT_MAX) return 0;
    fuzz_view view = fuzz_view_from(data);
    uint8_t choice = data[FUZZ_VIEW_BYTES];
    const uint8_t *text = data + FUZZ_VIEW_BYTES + 1;
    size_t tlen = size - FUZZ_VIEW_BYTES - 1;
    uint8_t *blob;
    size_t len;
    if (tlen && fuzz_compile_input(text, tlen, ".scene", NULL, &blob, &len) == 0) {
        fuzz_draw(blob, len, &view, 1);
        free(blob);
    } else if (npool) {
        const pool_scene *p = &pool[choice % npool];
        fuzz_draw(p->blob, p->len, &view, 1);
    }
    return 0;
}
